"""Refit the stress model from FEM runs: a designed grid of two-cartridge collisions
(closing speed × crossing angle) run through :func:`demfem.sweep.sweep` (a Dask
LocalCluster, a cluster's scheduler, or serial), β_inner and β_outer fitted on the training
runs by :meth:`StressModel.fit` (the thin-shell scaling σ1 = β F/t² is the mechanics; only β
is fitted), and the fit's error measured on runs held back from it.

    demfem stress-model --out demfem_out/stress_model            # 45 GPa, 2 layers
    demfem assess --stress-model demfem_out/stress_model/stress_model.json

Each run is :func:`demfem.fem.collide_cartridges` with σ1 sampled on cartridge a's inner and
outer body surfaces over the contact; its peak contact force (smoothed over t_c/20) is the F
of the scaling. The held-back runs are every ``hold_out_every``-th point of the grid in its
key order (deterministic), so a rerun holds back the same ones. SI units throughout.
"""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any, Mapping, Optional, Sequence

import numpy as np

from demfem.stress.stress_model import StressModel
from demfem.errors import InvalidParameterError, check_count, check_positive
from demfem.io.strict_json import write_json_atomic

__all__ = ["DEFAULT_GRID", "QUICK_GRID", "collision_point", "fit_from_fem"]

#: The designed grid: closing speeds (m/s) spanning the table's collisions, and crossing
#: angles from parallel (0°, a line contact) to crossed (90°, a point contact).
DEFAULT_GRID: dict[str, list[float]] = {"v_rel": [0.05, 0.1, 0.2, 0.4],
                                        "tilt_deg": [90.0, 60.0, 30.0]}
#: A small grid for a smoke run.
QUICK_GRID: dict[str, list[float]] = {"v_rel": [0.1, 0.3], "tilt_deg": [90.0, 45.0]}


def collision_point(params: Mapping[str, Any]) -> dict[str, Any]:
    """One FEM run of the grid (a :func:`demfem.sweep.sweep` runner). ``params``: ``v_rel``
    (m/s), ``tilt_deg`` (degrees), ``layers``, ``young_modulus`` (Pa), optional
    ``tube_length`` (m; a plain tube of the default cartridge's body instead of the full
    cartridge), ``stress_samples``. Returns the peak force (N), the peak σ1 on the inner
    and outer surfaces (Pa), the elements and the wall time (s)."""
    from demfem.cartridge import Cartridge
    from demfem.fem import collide_cartridges

    base = Cartridge()
    mat = dataclasses.replace(base.material, E=float(params["young_modulus"]))
    length = params.get("tube_length")
    cart = (Cartridge.tube(base.body_outer_diameter, base.wall_thickness, float(length),
                           material=mat) if length else dataclasses.replace(base, material=mat))
    r = collide_cartridges(cart, cart, v_rel=float(params["v_rel"]),
                           tilt_deg=float(params["tilt_deg"]), layers=int(params["layers"]),
                           stress_samples=int(params.get("stress_samples", 20)))
    return {"max_force_N": r.max_force, "sigma1_inner_Pa": r.peak_sigma1_inner,
            "sigma1_outer_Pa": r.peak_sigma1_outer, "contact_duration_s": r.contact_duration,
            "n_elements": r.n_elements, "energy_balance_error": r.energy_balance_error,
            "fem_wall_s": r.wall_time}


def fit_from_fem(out: str | Path = "demfem_out/stress_model",
                 grid: Optional[Mapping[str, Sequence[float]]] = None, layers: int = 2,
                 young_modulus: float = 45e9, hold_out_every: int = 4,
                 tube_length: Optional[float] = None, scheduler: Optional[str] = None,
                 n_workers: Optional[int] = None,
                 log: Any = print) -> dict[str, Any]:
    """Run the grid (finished runs in ``out/runs`` are reused), fit the model on the
    training runs, report its error on the held-back ones and against the closed form.

    Writes ``out/stress_model.json`` (load with :meth:`StressModel.load`, use with
    ``demfem assess --stress-model``) and ``out/fit_report.json``; returns the report.
    """
    from demfem.sweep import run_key, sweep

    grid = dict(grid or DEFAULT_GRID)
    for key in ("v_rel", "tilt_deg"):
        if key not in grid or not len(grid[key]):
            raise InvalidParameterError(f"invalid grid: needs a non-empty {key!r} axis")
    check_count("layers", layers, 1)
    check_positive("young_modulus", young_modulus)
    check_count("hold_out_every", hold_out_every, 2)
    fixed: dict[str, Any] = {"layers": int(layers), "young_modulus": float(young_modulus)}
    if tube_length is not None:
        fixed["tube_length"] = check_positive("tube_length", tube_length)
    out = Path(out)
    n_points = math.prod(len(v) for v in grid.values())
    if n_points < hold_out_every:
        raise InvalidParameterError(
            f"invalid grid: {n_points} points; need at least hold_out_every = "
            f"{hold_out_every} to hold one back")
    log(f"stress model: {n_points} FEM collisions ({layers} layers, E = {young_modulus:.3g} "
        f"Pa), every {hold_out_every}th held back")
    result = sweep(grid, "demfem.stress.fem_fit:collision_point", out, scheduler=scheduler,
                   n_workers=n_workers, fixed=fixed,
                   progress=lambda d, n: log(f"  FEM runs done {d}/{n}"))
    records = sorted(result.records, key=lambda r: run_key(r["params"]))
    held = [r for k, r in enumerate(records) if k % hold_out_every == hold_out_every - 1]
    train = [r for k, r in enumerate(records) if k % hold_out_every != hold_out_every - 1]

    def arrays(rs: list[dict]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return tuple(np.array([r["result"][k] for r in rs], float)  # type: ignore[return-value]
                     for k in ("max_force_N", "sigma1_inner_Pa", "sigma1_outer_Pa"))

    f_t, si_t, so_t = arrays(train)
    f_h, si_h, so_h = arrays(held)
    closed = StressModel.default()
    model = StressModel.fit(f_t, si_t, so_t, source=(
        f"fitted to {len(train)} FEM collisions ({layers} layers, E = {young_modulus:.3g} Pa, "
        f"v_rel {min(grid['v_rel']):g}-{max(grid['v_rel']):g} m/s, crossing "
        f"{min(grid['tilt_deg']):g}-{max(grid['tilt_deg']):g} deg)"), base=closed)
    held_err = model.residuals(f_h, si_h, so_h)
    report: dict[str, Any] = {
        "model": model.to_dict(), "closed_form": closed.to_dict(),
        "beta_inner_fit_over_closed_form": model.beta_inner / closed.beta_inner,
        "beta_outer_fit_over_closed_form": model.beta_outer / closed.beta_outer,
        "training_error": model.residuals(f_t, si_t, so_t),
        "held_back_error": held_err,
        "closed_form_error_on_all": closed.residuals(*arrays(records)),
        "n_training": len(train), "n_held_back": len(held), "layers": int(layers),
        "young_modulus_Pa": float(young_modulus), "grid": grid,
        "runs": [{**r["params"], **r["result"]} for r in records],
    }
    out.mkdir(parents=True, exist_ok=True)
    model.save(out / "stress_model.json")
    write_json_atomic(out / "fit_report.json", report)
    log(f"stress model: beta_inner {model.beta_inner:.3g} (closed form {closed.beta_inner:.3g}), "
        f"beta_outer {model.beta_outer:.3g} (closed form {closed.beta_outer:.3g}); held-back "
        f"RMS error inner {held_err['rms_inner_relative']:.2g}, outer "
        f"{held_err['rms_outer_relative']:.2g}; written to "
        f"{out / 'stress_model.json'}")
    return report
