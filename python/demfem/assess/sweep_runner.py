"""Set-ups ranked by breakage risk through :func:`demfem.sweep.sweep`: one `demfem assess`
per grid point.

    demfem sweep --runner demfem.assess.sweep_runner:risk_point \\
        --grid gate_amplitude=0.01,0.02,0.05 --grid belt_velocity=0.1,0.2 \\
        --rank-by broken_per_hour --out demfem_out/risk_sweep

Each point is the built-in default table with the grid's fields replaced (any
:class:`~demfem.scenes.table.AccumulationTable` field, SI units), run by
:func:`demfem.assess.assess` for ``duration`` s (a grid or a fixed parameter; default: as
``demfem assess``, re-fed until the collision rate is steady)
at ``throughput`` cartridges per hour (default: the table's own discharge). The assessment's folder is
``run_dir/<key>`` when ``run_dir`` is given (kept, resumable), else a temporary folder
that is removed. Returns the risk summary's numbers, each key naming its unit.
"""
from __future__ import annotations

import dataclasses
import shutil
import tempfile
from pathlib import Path
from typing import Any

__all__ = ["risk_point"]

#: Summary numbers a risk sweep returns.
_KEYS = ("broken_per_hour", "p_passage", "discharge_per_hour", "n_events_window",
         "n_wall_events_window", "wall_share", "max_force_N", "max_sigma_inner_Pa",
         "max_sigma_outer_Pa", "event_rate_per_s")


def risk_point(params: dict) -> dict:
    """Sweep runner: the risk of the default table with ``params`` applied (see the module
    text); unknown fields are refused naming the allowed ones."""
    from demfem.assess import assess
    from demfem.errors import InvalidParameterError
    from demfem.scenes.table import AccumulationTable
    from demfem.sweep import run_key

    p = dict(params)
    raw = p.pop("duration", None)
    duration = None if raw is None else float(raw)
    raw_q = p.pop("throughput", None)
    throughput = None if raw_q is None else float(raw_q)
    run_dir = p.pop("run_dir", None)
    fields = {f.name for f in dataclasses.fields(AccumulationTable)}
    unknown = sorted(set(p) - fields)
    if unknown:
        raise InvalidParameterError(
            f"invalid sweep parameter(s) {unknown}: allowed are duration, throughput, run_dir "
            f"and the table's fields {sorted(fields)}")
    table = dataclasses.replace(AccumulationTable(), **p)
    tmp = None
    if run_dir is None:
        tmp = tempfile.mkdtemp(prefix="demfem_risk_")
        out = Path(tmp)
    else:
        out = Path(run_dir) / run_key(params)
    try:
        risk = assess(table, out=out, duration=duration, throughput=throughput,
                      log=lambda line: None)
    finally:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
    s = risk["summary"]
    res: dict[str, Any] = {k: s[k] for k in _KEYS if k in s}
    res["steady"] = bool(risk["steady_state"]["steady"])
    return res
