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
from typing import Any, Optional

__all__ = ["SUMMARY_KEYS", "SweepPoint", "risk_point", "sweep_point"]

#: Summary numbers a risk sweep returns.
SUMMARY_KEYS = ("broken_per_hour", "p_passage", "discharge_per_hour", "n_events_window",
         "n_wall_events_window", "wall_share", "max_force_N", "max_sigma_inner_Pa",
         "max_sigma_outer_Pa", "event_rate_per_s")


@dataclasses.dataclass(frozen=True)
class SweepPoint:
    """One grid point of a risk sweep, parsed: the default table with the point's fields
    replaced, the assessment's ``duration`` (s, None: until steady) and ``throughput``
    (cartridges per hour, None: the table's own discharge), its folder (a temporary one
    when ``temporary``) and the numbers kept from its summary (:data:`SUMMARY_KEYS`)."""

    table: Any
    duration: Optional[float]
    throughput: Optional[float]
    out: Path
    temporary: bool
    extra: dict

    def remove_temporary(self) -> None:
        """Remove the point's folder if it is a temporary one."""
        if self.temporary:
            shutil.rmtree(self.out, ignore_errors=True)

    @staticmethod
    def numbers(risk: dict) -> dict[str, Any]:
        """The summary numbers a risk sweep returns, and whether the run was steady."""
        s = risk["summary"]
        res: dict[str, Any] = {k: s[k] for k in SUMMARY_KEYS if k in s}
        res["steady"] = bool(risk["steady_state"]["steady"])
        return res


def sweep_point(params: dict, extra: tuple[str, ...] = (), *,
                prefix: str = "demfem_risk_") -> SweepPoint:
    """Parse a risk sweep's grid point: ``duration``, ``throughput``, ``run_dir``, the names
    in ``extra`` (returned as they are in ``SweepPoint.extra``) and fields of
    :class:`~demfem.scenes.table.AccumulationTable`; anything else is refused naming the
    allowed keys. The folder is ``run_dir/<key>`` when ``run_dir`` is given, else a new
    temporary folder (``prefix``)."""
    from demfem.errors import InvalidParameterError
    from demfem.scenes.table import AccumulationTable
    from demfem.sweep import run_key

    p = dict(params)
    raw = p.pop("duration", None)
    raw_q = p.pop("throughput", None)
    run_dir = p.pop("run_dir", None)
    found = {k: p.pop(k) for k in extra if k in p}
    fields = {f.name for f in dataclasses.fields(AccumulationTable)}
    unknown = sorted(set(p) - fields)
    if unknown:
        allowed = ", ".join((*extra, "duration", "throughput", "run_dir"))
        raise InvalidParameterError(
            f"invalid sweep parameter(s) {unknown}: allowed are {allowed} and the table's "
            f"fields {sorted(fields)}")
    table = dataclasses.replace(AccumulationTable(), **p)
    temporary = run_dir is None
    out = Path(tempfile.mkdtemp(prefix=prefix)) if temporary else Path(run_dir) / run_key(params)
    return SweepPoint(table=table, duration=None if raw is None else float(raw),
                      throughput=None if raw_q is None else float(raw_q), out=out,
                      temporary=temporary, extra=found)


def risk_point(params: dict) -> dict:
    """Sweep runner: the risk of the default table with ``params`` applied (see the module
    text); unknown fields are refused naming the allowed ones."""
    from demfem.assess import assess

    point = sweep_point(params)
    try:
        risk = assess(point.table, out=point.out, duration=point.duration,
                      throughput=point.throughput, log=lambda line: None)
    finally:
        point.remove_temporary()
    return SweepPoint.numbers(risk)
