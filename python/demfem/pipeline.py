"""The main job: the paper's pipeline on the built-in default scene, from one call.

:func:`run_pipeline` runs, in order, every stage of the method that demfem has today:

1. **Calibration** of the equivalent sphere of the default 3 mL cartridge: mass, diameter,
   Reissner shell stiffness, Hertz contact time, Rayleigh step, and the Fig. 3 analogue (the
   maximum force of two colliding cartridges against E, for each contact law).
2. **DEM** of the default accumulation table (840 equivalent spheres of that cartridge, E =
   45 GPa, belt 0.2 m/s into the funnel, gate A = 2 cm, T = 2 s), recorded every
   ``sample_interval`` s, with every sphere-sphere contact onset logged. The run checkpoints
   into the output folder and resumes from it when started again with the same arguments.
3. **Analysis**: first-line force, coordination numbers, speeds of the tagged spheres,
   collision statistics (impact speeds and angles at contact onset), spheres that left
   through the opening.

The FEM of the seven-cartridge cluster and the breakage risk (stages 4-5 of the paper) are
not in demfem yet; the report says so instead of inventing numbers.

Outputs in ``out``: ``calibration.csv`` and ``calibration_force_vs_E.png``, ``table_run.npz``
(the whole record, :class:`demfem.studies.table_run.TableRun`), ``collisions.csv`` (one row
per contact onset), ``summary.json``, ``table_time_series.png``, ``collisions.png``,
``table_end.png`` and a ParaView series ``vtk/table.pvd``. Every file is written atomically.

SI units throughout: m, s, kg, N, Pa.
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np

from demfem.errors import SimulationInterrupted, check_positive, check_range

__all__ = ["run_pipeline", "NOT_YET"]

#: The paper's stages demfem does not run yet (printed by the report, kept in the summary).
NOT_YET = ("FEM of the seven-cartridge cluster (stage 4)",
           "breakage probability per cartridge from the DEM collisions (stage 5)")


def run_pipeline(out: str | Path = "demfem_out/run", duration: float = 1.0,
                 young_modulus: Optional[float] = None, sample_interval: float = 0.02,
                 threads: int = 1, v_rel: float = 0.2, discard_before: Optional[float] = None,
                 checkpoint_every: float = 15.0,
                 log: Callable[[str], None] = print,
                 progress: bool | Callable[[float, int], None] = False) -> dict[str, Any]:
    """Run calibration, the DEM of the default table and its analysis; write the outputs.

    Args:
        out: output folder (created).
        duration: simulated time of the table run, s.
        young_modulus: Young's modulus of the glass, Pa (default: the paper's 45 GPa).
        sample_interval: time between recorded samples, s.
        threads: DEM engine threads (results are bitwise the same on any number).
        v_rel: relative impact speed of the calibration's two cartridges, m/s.
        discard_before: start of the force and coordination statistics, s (default: half
            the run, after the pack has begun to form).
        checkpoint_every: wall time between checkpoints of the table run, s. An interrupted
            job (Ctrl-C) started again with the same arguments resumes from the last one.
        log: where the report's lines go.
        progress: callback ``progress(sim_time_s, steps)`` of the table run, or ``True`` for
            a :class:`demfem.progress.ProgressBar` on standard error started with the run.

    Returns:
        The summary (also written to ``summary.json``): calibration, the run's numbers,
        collision statistics and the output paths.
    """
    from demfem.analysis.collisions import onset_histogram, onset_quantiles
    from demfem.analysis.kinematics import tagged_speed
    from demfem.calibration import calibration_report, force_vs_modulus, write_calibration
    from demfem.cartridge import Cartridge
    from demfem.io.atomic import savefig_atomic, write_text_atomic
    from demfem.plots import plot_table_snapshot
    from demfem.progress import ProgressBar
    from demfem.scenes.table import AccumulationTable, Tag
    from demfem.studies.figures import _write_vtk_series
    from demfem.studies.table_run import _check_run_arguments, _checkpoint_files, run_table

    # every argument checked before any work
    _check_run_arguments(duration, sample_interval, threads)
    v_rel = check_positive("v_rel", v_rel)
    discard = 0.5 * duration if discard_before is None else check_range(
        "discard_before", discard_before, hi=duration, hi_open=False)
    table = AccumulationTable() if young_modulus is None else AccumulationTable(
        young_modulus=young_modulus)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)

    # 1. calibration
    log("== 1. calibration: the equivalent sphere ==")
    log(calibration_report(v_rel))
    cal = force_vs_modulus(Cartridge(), np.logspace(7, 11, 9), v_rel)
    log(f"\nMaximum contact force, two cartridges at v_rel = {v_rel:g} m/s (Fig. 3 analogue):")
    log(cal.format())
    cal_csv, cal_png = write_calibration(out, cal)

    # 2. DEM of the table
    log(f"\n== 2. DEM: the accumulation table, {table.n_spheres} spheres, "
        f"E = {table.young_modulus:.3g} Pa, {duration:g} s ==")
    bar = ProgressBar(duration, label="table") if progress is True else None
    callback = bar if bar is not None else (progress if callable(progress) else None)
    checkpoint = out / "table.ck"
    try:
        try:
            run = run_table(table, duration, sample_interval, threads=threads,
                            progress=callback, checkpoint=checkpoint,
                            checkpoint_every=checkpoint_every)
        finally:
            if bar is not None:
                bar.close()
    except SimulationInterrupted:
        saved = _checkpoint_files(checkpoint)[2]  # its wall and simulated time
        if saved.exists() and "sim_time_s" in (state := json.loads(saved.read_text())):
            log(f"interrupted: started again with the same arguments, the job resumes from "
                f"its checkpoint at t = {state['sim_time_s']:.4g} s ({checkpoint})")
        else:
            log(f"interrupted before the first checkpoint (every {checkpoint_every:g} s of "
                "wall time): nothing to resume")
        raise
    run_path = run.save(out / "table_run.npz")
    info = run.info
    log(f"  {info['steps']} steps of {info['dt']:.3g} s in {info['wall_time_s']:.1f} s wall "
        f"({table.n_spheres * info['steps'] / max(info['wall_time_s'], 1e-9):.3g} "
        f"particle-steps/s), effects: {', '.join(info['effects'])}")

    # 3. analysis
    log("\n== 3. analysis ==")
    summary = run.summary(discard_before=discard)
    onsets = run.onsets
    q = (0.5, 0.9, 0.99, 1.0)
    collisions = {
        "n_onsets": int(len(onsets)),
        "onsets_per_s": float(len(onsets) / duration),
        "quantiles": list(q),
        "normal_speed_m_s": onset_quantiles(onsets, "normal_speed", q).tolist(),
        "tangential_speed_m_s": onset_quantiles(onsets, "tangential_speed", q).tolist(),
        "impact_angle_deg": np.degrees(onset_quantiles(onsets, "impact_angle", q)).tolist(),
    }
    speeds = {name: tagged_speed(run.velocities, run.tags, tag)
              for name, tag in (("triangular_centre", Tag.TRIANGULAR_CENTRE),
                                ("rectangular_centre", Tag.RECTANGULAR_CENTRE),
                                ("first_line", Tag.FIRST_LINE))}
    keep = run.times >= discard
    tagged = {f"{name}_mean_speed_mm_s": float(1e3 * np.nanmean(s[keep])) if np.isfinite(
        s[keep]).any() else math.nan for name, s in speeds.items()}
    log(f"  statistics from t = {discard:g} s on")
    log(f"  first-line force: mean {summary['force_mean_N']:.4g} N, 95 % "
        f"{summary['force_q95_N']:.4g} N, peak {summary['force_peak_N']:.4g} N "
        f"(in the plane: mean {summary['in_plane_force_mean_N']:.4g} N)")
    log(f"  mean coordination {summary['coordination_mean']:.3f}; spheres out through the "
        f"opening {summary['n_removed']}; riding up at the end {summary['riding_up_end']}; "
        f"largest overlap {summary['max_overlap_m']:.3g} m")
    for name in speeds:
        log(f"  {name.replace('_', ' ')}: mean speed {tagged[f'{name}_mean_speed_mm_s']:.3g} mm/s")
    log(f"  collisions: {collisions['n_onsets']} contact onsets "
        f"({collisions['onsets_per_s']:.3g} per s); normal impact speed median / 90 % / "
        f"99 % / max " + " / ".join(f"{1e3 * v:.3g}" for v in collisions["normal_speed_m_s"])
        + " mm/s")

    csv_lines = ["i,j,time_s,normal_speed_m_s,tangential_speed_m_s,impact_angle_rad,"
                 "coordination_i,coordination_j"]
    csv_lines += [f"{r['i']},{r['j']},{r['time']:.9g},{r['normal_speed']:.9g},"
                  f"{r['tangential_speed']:.9g},{r['impact_angle']:.9g},"
                  f"{r['coordination_i']},{r['coordination_j']}" for r in onsets]
    coll_csv = write_text_atomic(out / "collisions.csv", "\n".join(csv_lines) + "\n")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = run.times
    fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    axes[0].plot(t, run.first_line_force(), lw=0.9, label="total")
    axes[0].plot(t, run.first_line_force("in_plane"), lw=0.9, label="in the plane")
    axes[0].set_ylabel("first-line force (N)")
    axes[0].legend(fontsize="small")
    axes[1].plot(t, run.mean_coordination(), lw=0.9, color="black")
    axes[1].set_ylabel("mean coordination")
    for name, s in speeds.items():
        axes[2].plot(t, 1e3 * s, lw=0.9, label=name.replace("_", " "))
    axes[2].set_ylabel("speed (mm/s)")
    axes[2].set_xlabel("time (s)")
    axes[2].legend(fontsize="small")
    fig.suptitle(f"default table, E = {table.young_modulus:.3g} Pa", fontsize="medium")
    fig.tight_layout()
    series_png = savefig_atomic(fig, out / "table_time_series.png", dpi=110)
    plt.close(fig)

    fig, axes = plt.subplots(1, 2, figsize=(9, 3.5))
    for ax, field, scale, label in ((axes[0], "normal_speed", 1e3, "normal impact speed (mm/s)"),
                                    (axes[1], "impact_angle", 180 / math.pi,
                                     "impact angle (deg)")):
        if len(onsets):
            counts, edges = onset_histogram(onsets, field, bins=40)
            ax.stairs(counts, scale * edges, fill=True)
        ax.set_xlabel(label)
        ax.set_ylabel("contact onsets")
    fig.tight_layout()
    coll_png = savefig_atomic(fig, out / "collisions.png", dpi=110)
    plt.close(fig)

    end_png = plot_table_snapshot(out / "table_end.png", table.build(), run.positions[-1],
                                  time=float(t[-1]))
    pvd = _write_vtk_series(out / "vtk", run, max(sample_interval, duration / 20))

    log("\n== not in demfem yet ==")
    for stage in NOT_YET:
        log(f"  {stage}")
    result = {
        "calibration": {"v_rel_m_s": v_rel, "young_modulus_Pa": cal.E.tolist(),
                        "models": list(cal.models),
                        "max_force_N": cal.forces.tolist()},
        "table": {"young_modulus_Pa": table.young_modulus, "n_spheres": table.n_spheres,
                  "duration_s": duration, "statistics_from_s": discard, **summary, **tagged},
        "collisions": collisions,
        "not_yet": list(NOT_YET),
        "files": [str(p) for p in (cal_csv, cal_png, run_path, coll_csv, series_png, coll_png,
                                   end_png, pvd)],
    }
    summary_path = write_text_atomic(out / "summary.json",
                                     json.dumps(result, indent=1, default=float) + "\n")
    log(f"\nwritten to {out}: " + ", ".join(str(Path(p).relative_to(out))
                                          for p in result["files"])
        + f", {summary_path.name}")
    return result
