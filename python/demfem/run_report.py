"""Stage 3 of the main job (:func:`demfem.pipeline.run_pipeline`): the analysis of a table run
and its outputs: ``collisions.csv``, ``table_time_series.png``, ``collisions.png``,
``table_end.png`` and the ParaView series ``vtk/table.pvd``.

Conventions of every output: SI units, named in each key or column (``_N``, ``_m``,
``_m_per_s``, ``_s``, ``_Pa``); angles in degrees (``_deg``); the impact angle of a contact
onset is atan2(v_t, v_n): 0 deg for a head-on impact, 90 deg for a grazing one.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Callable

import numpy as np

__all__ = ["write_analysis", "COLLISION_COLUMNS"]

#: Columns of ``collisions.csv`` (one row per sphere-sphere contact onset).
COLLISION_COLUMNS = ("i", "j", "time_s", "normal_speed_m_per_s", "tangential_speed_m_per_s",
                     "impact_angle_deg", "coordination_i", "coordination_j")

_ANGLE_LABEL = "impact angle atan2(v_t, v_n) (deg; 0 = head-on, 90 = grazing)"


def write_analysis(out: Path, run: Any, table: Any, duration: float, discard: float,
                   sample_interval: float, log: Callable[[str], None]) -> dict[str, Any]:
    """Analyse ``run`` (a :class:`~demfem.dem.table_run.TableRun` of ``table``) from ``discard``
    (s) on, log the numbers and write the files; returns the ``table`` and ``collisions``
    sections of the summary and the ``files`` written."""
    from demfem.analysis.collisions import onset_quantiles
    from demfem.analysis.kinematics import tagged_speed
    from demfem.io.atomic import write_text_atomic
    from demfem.io.vtk import write_vtk_series
    from demfem.plots import plot_table_snapshot
    from demfem.scenes.table import Tag

    log("\n== 3. analysis ==")
    summary = run.summary(discard_before=discard)
    onsets = run.onsets
    q = (0.5, 0.9, 0.99, 1.0)
    collisions = {
        "n_onsets": int(len(onsets)),
        "onset_rate_per_s": float(len(onsets) / duration),
        "quantiles": list(q),
        "normal_speed_m_per_s": onset_quantiles(onsets, "normal_speed", q).tolist(),
        "tangential_speed_m_per_s": onset_quantiles(onsets, "tangential_speed", q).tolist(),
        "impact_angle_deg": np.degrees(onset_quantiles(onsets, "impact_angle", q)).tolist(),
    }
    speeds = {name: tagged_speed(run.velocities, run.tags, tag)
              for name, tag in (("triangular_centre", Tag.TRIANGULAR_CENTRE),
                                ("rectangular_centre", Tag.RECTANGULAR_CENTRE),
                                ("first_line", Tag.FIRST_LINE))}
    keep = run.times >= discard
    tagged = {f"{name}_mean_speed_m_per_s": float(np.nanmean(s[keep])) if np.isfinite(
        s[keep]).any() else math.nan for name, s in speeds.items()}
    weight = float(table.sphere_mass * table.gravity)
    log(f"  statistics from t = {discard:g} s on")
    log(f"  first-line force per sphere: mean {summary['first_line_force_mean_N']:.4g} N, "
        f"95 % {summary['first_line_force_q95_N']:.4g} N, peak "
        f"{summary['first_line_force_peak_N']:.4g} N (in the plane: mean "
        f"{summary['first_line_in_plane_force_mean_N']:.4g} N; one sphere's weight m g = "
        f"{weight:.3g} N)")
    log(f"  mean coordination {summary['mean_coordination']:.3f}; spheres out through the "
        f"opening {summary['n_removed']}; riding up at the end {summary['n_riding_up_end']}; "
        f"largest overlap {summary['max_overlap_m']:.3g} m")
    for name in speeds:
        log(f"  {name.replace('_', ' ')}: mean speed "
            f"{1e3 * tagged[f'{name}_mean_speed_m_per_s']:.3g} mm/s")
    log(f"  collisions: {collisions['n_onsets']} contact onsets "
        f"({collisions['onset_rate_per_s']:.3g} per s); normal impact speed median / 90 % / "
        f"99 % / max " + " / ".join(f"{1e3 * v:.3g}" for v in
                                     collisions["normal_speed_m_per_s"]) + " mm/s")

    lines = [",".join(COLLISION_COLUMNS)]
    lines += [f"{r['i']},{r['j']},{r['time']:.9g},{r['normal_speed']:.9g},"
              f"{r['tangential_speed']:.9g},{math.degrees(r['impact_angle']):.9g},"
              f"{r['coordination_i']},{r['coordination_j']}" for r in onsets]
    coll_csv = write_text_atomic(out / "collisions.csv", "\n".join(lines) + "\n")
    series_png = _time_series(out / "table_time_series.png", run, speeds, discard, weight,
                              table.young_modulus)
    coll_png = _collision_histograms(out / "collisions.png", onsets)
    end_png = plot_table_snapshot(out / "table_end.png", table.build(), run.positions[-1],
                                  time=float(run.times[-1]))
    pvd = write_vtk_series(out / "vtk", run, max(sample_interval, duration / 20))
    return {
        "table": {"young_modulus_Pa": table.young_modulus, "n_spheres": table.n_spheres,
                  "duration_s": duration, "statistics_from_s": discard,
                  "sphere_weight_N": weight, **summary, **tagged},
        "collisions": collisions,
        "files": [str(p) for p in (coll_csv, series_png, coll_png, end_png, pvd)],
    }


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _time_series(path: Path, run: Any, speeds: dict[str, np.ndarray], discard: float,
                 weight: float, young_modulus: float) -> Path:
    from demfem.io.atomic import savefig_atomic

    plt = _pyplot()
    t = run.times
    fig, axes = plt.subplots(3, 1, figsize=(8, 8.5), sharex=True)
    for ax in axes:
        ax.axvspan(discard, float(t[-1]), color="0.9", zorder=0)
    axes[0].plot(t, run.first_line_force(), lw=0.9, label="total")
    axes[0].plot(t, run.first_line_force("in_plane"), lw=0.9, label="in the plane (x, y)")
    axes[0].axhline(weight, color="black", ls=":", lw=0.9)
    axes[0].annotate(f"plateau m g = {weight:.3g} N (one sphere's weight)", xy=(0.01, weight),
                     xycoords=("axes fraction", "data"), xytext=(0, 3),
                     textcoords="offset points", fontsize="small", va="bottom")
    axes[0].set_ylabel("first-line force,\nmean per sphere (N)")
    axes[0].legend(fontsize="small", loc="upper right")
    axes[0].text(0.5 * (discard + float(t[-1])), 1.0, "statistics window",
                 transform=axes[0].get_xaxis_transform(), ha="center", va="bottom",
                 fontsize="small", color="0.35")
    axes[1].plot(t, run.mean_coordination(), lw=0.9, color="black")
    axes[1].set_ylabel("mean coordination\n(contacts per sphere)")
    for name, s in speeds.items():
        axes[2].plot(t, 1e3 * s, lw=0.9, label=name.replace("_", " "))
    axes[2].set_ylabel("tagged sphere speed (mm/s)")
    axes[2].set_xlabel("time (s)")
    axes[2].legend(fontsize="small")
    fig.suptitle(f"accumulation table, E = {young_modulus:.3g} Pa; shaded: statistics "
                 f"window (t >= {discard:g} s)", fontsize="medium")
    fig.tight_layout()
    try:
        return savefig_atomic(fig, path, dpi=110)
    finally:
        plt.close(fig)


def _collision_histograms(path: Path, onsets: np.ndarray) -> Path:
    from demfem.io.atomic import savefig_atomic

    plt = _pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    speed = 1e3 * np.asarray(onsets["normal_speed"], float)
    angle = np.degrees(np.asarray(onsets["impact_angle"], float))
    positive = speed[speed > 0]
    if len(positive):
        lo, hi = positive.min(), positive.max()
        bins = np.logspace(np.log10(lo), np.log10(hi if hi > lo else 10 * lo), 41)
        axes[0].hist(positive, bins=bins, color="tab:blue")
        axes[0].set_xscale("log")
    axes[0].set_xlabel("normal impact speed at contact onset (mm/s)")
    if len(angle):
        axes[1].hist(angle, bins=np.linspace(0.0, 90.0, 46), color="tab:orange")
    axes[1].set_xlim(0.0, 90.0)
    axes[1].set_xlabel(_ANGLE_LABEL)
    for ax in axes:
        ax.set_ylabel("contact onsets")
        if len(angle):
            ax.set_yscale("log")
    fig.suptitle(f"{len(angle)} sphere-sphere contact onsets", fontsize="medium")
    fig.tight_layout()
    try:
        return savefig_atomic(fig, path, dpi=110)
    finally:
        plt.close(fig)
