"""The paper's DEM studies (Boso et al. 2021, Figs. 5-9) as functions that run, analyse and plot.

Every study runs its table runs through :func:`demfem.sweep.sweep` (a Dask LocalCluster by
default, one run per worker, ``threads=1`` per run) with :func:`demfem.dem.table_run.sweep_point` as
the runner, into one shared folder ``<out>/runs``: a run asked for by two studies (same
parameters, E and duration) is made once and a re-launched study only runs what is missing.

Geometry: the paper's A sweep on one table (module docstring of :mod:`demfem.scenes.table`):
tilted_wall_length = 0.24 m and the narrowest opening w0 - A = 2 cm for every A. The other
table parameters keep their defaults (840 spheres, E as asked, friction 0.2, restitution 0.5,
no "planar" effect: spheres may ride up, and the studies report how many do).

SI units: m, s, m/s, N, Pa.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping, Optional, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import numpy as np  # noqa: E402

from demfem.analysis import (  # noqa: E402
    middle_mean,
    period_of_oscillation,
    rank_setups,
    tag_mask,
    tagged_speed,
)
from demfem.errors import InvalidParameterError  # noqa: E402
from demfem.io import (json_dumps, savefig_atomic, write_json_atomic,  # noqa: E402
                       write_text_atomic, write_vtk_series)
from demfem.scenes.table import Tag  # noqa: E402
from demfem.dem.table_run import TableRun, table_from_params  # noqa: E402

__all__ = [
    "StudyOptions",
    "SWEEP_GEOMETRY",
    "FIG5_PANELS",
    "FIG5_OPTIMUM",
    "fig5",
    "fig6",
    "fig7",
    "fig8_9",
    "speed_windows",
    "discharge_speeds",
    "moving_average",
]

#: Table parameters shared by all studies (one geometry for the whole A sweep).
SWEEP_GEOMETRY: dict[str, Any] = {"tilted_wall_length": 0.24, "narrowest_opening": 0.02}

#: Fig. 5 panels: (title, grid of gate_amplitude (m), gate_period (s), belt_velocity (m/s)).
FIG5_PANELS: tuple[tuple[str, dict[str, list[float]]], ...] = (
    ("(a) V_belt = 0.2 m/s, T = 1 s",
     {"gate_amplitude": [0.01, 0.02, 0.05, 0.075], "gate_period": [1.0], "belt_velocity": [0.2]}),
    ("(b) V_belt = 0.3 m/s, A = 5 cm",
     {"gate_amplitude": [0.05], "gate_period": [0.5, 1.0, 2.0], "belt_velocity": [0.3]}),
    ("(c) T = 2 s, A = 5 cm",
     {"gate_amplitude": [0.05], "gate_period": [2.0], "belt_velocity": [0.1, 0.2, 0.3]}),
)

#: The paper's choice (A = 2 cm, T = 2 s, V_belt = 0.2 m/s), run too so that it is ranked.
FIG5_OPTIMUM: dict[str, list[float]] = {
    "gate_amplitude": [0.02], "gate_period": [2.0], "belt_velocity": [0.2]}

#: Fig. 6/7 set-up (paper's caption of Fig. 6).
FIG6_SETUP: dict[str, Any] = {"gate_amplitude": 0.02, "gate_period": 2.0, "belt_velocity": 0.1}


@dataclass(frozen=True)
class StudyOptions:
    """How a study runs: output folder, simulated duration (s), Young's moduli (Pa), sample
    interval (s), Dask scheduler (None: LocalCluster; "serial"; or an address), workers, and
    ``table``: extra :class:`~demfem.scenes.AccumulationTable` fields that override
    :data:`SWEEP_GEOMETRY` and the defaults (e.g. a small table for a smoke test)."""

    out: Path
    duration: float
    moduli: tuple[float, ...]
    sample_interval: float = 0.05
    scheduler: Optional[str] = None
    workers: Optional[int] = None
    log: Callable[[str], None] = print
    table: Optional[dict[str, Any]] = None

    def __post_init__(self) -> None:
        if not (math.isfinite(self.duration) and self.duration > 0):
            raise InvalidParameterError(f"invalid duration = {self.duration!r}: must be > 0 s")
        if not self.moduli or any(not (math.isfinite(e) and e > 0) for e in self.moduli):
            raise InvalidParameterError(f"invalid moduli = {self.moduli!r}: give at least one "
                                        "Young's modulus > 0 Pa")


# --------------------------------------------------------------------------------------------
# Running
# --------------------------------------------------------------------------------------------

def _sweep_runs(opts: StudyOptions, grid: dict[str, list[Any]], duration: float,
                label: str) -> list[tuple[dict, TableRun]]:
    """Run a grid through demfem.sweep into ``<out>/runs``; (params, TableRun) per point."""
    from demfem.sweep import sweep

    runs_dir = opts.out / "runs"
    fixed = {**SWEEP_GEOMETRY, **(opts.table or {}), "duration": float(duration),
             "sample_interval": float(opts.sample_interval),
             # absolute, so that `--out s` and `--out /abs/s` name (and reuse) the same runs
             "run_dir": str(runs_dir.resolve())}

    def progress(done: int, total: int) -> None:
        opts.log(f"  {label}: runs finished {done}/{total}")

    result = sweep(grid, "demfem.dem.table_run:sweep_point", opts.out,
                   scheduler=opts.scheduler, n_workers=opts.workers, fixed=fixed,
                   progress=progress)
    return [(r["params"], TableRun.load(r["result"]["run_file"])) for r in result.records]


def _label(params: dict) -> str:
    return (f"A={100 * params['gate_amplitude']:g}cm T={params['gate_period']:g}s "
            f"V={params['belt_velocity']:g}m/s")


def _e_label(e: float) -> str:
    return f"E = {e:.3g} Pa"


# --------------------------------------------------------------------------------------------
# Fig. 5
# --------------------------------------------------------------------------------------------

def fig5(opts: StudyOptions, discard_before: float = 1.0) -> dict[str, Any]:
    """Fig. 5: first-line average force against time for the paper's A, T and V_belt values,
    at E = ``opts.moduli[0]``, and the ranking of all runs by
    :func:`demfem.analysis.gentleness_score` (mean, peak and 95 % quantile of the first-line
    force after ``discard_before`` s, each relative to the median run).

    The ranking that decides is on the in-plane part of the net contact force
    (:meth:`TableRun.first_line_force` ``part="in_plane"``): the total net force of a sphere on
    the belt is dominated by the belt's support m g, the same in every set-up, which would
    hide the differences. The ranking on the total force (the paper's quantity) is written too.

    Writes ``fig5_first_line_force.png``, ``fig5_ranking.csv`` and ``fig5_ranking.txt`` into
    ``opts.out``; returns {"ranking": in-plane ranking, "ranking_total": ..., "gentlest":
    label, "runs": {label: (params, TableRun)}}.
    """
    e = float(opts.moduli[0])
    panels = []
    seen: dict[str, tuple[dict, TableRun]] = {}
    for title, grid in (*FIG5_PANELS, ("optimum", FIG5_OPTIMUM)):
        runs = _sweep_runs(opts, {**grid, "young_modulus": [e]}, opts.duration, f"fig5 {title}")
        for params, run in runs:
            seen[_label(params)] = (params, run)
        panels.append((title, runs))
    labels = list(seen)
    if discard_before >= opts.duration:
        discard_before = 0.5 * opts.duration
        opts.log(f"  (discard_before cut to {discard_before:g} s, half the duration)")
    rankings = {part: rank_setups([seen[k][1].times for k in labels],
                                  [seen[k][1].first_line_force(part) for k in labels], labels,
                                  discard_before=discard_before)
                for part in ("in_plane", "total")}
    text = "\n\n".join(_format_ranking(rankings[part], part, seen, discard_before, e,
                                        opts.duration) for part in ("in_plane", "total"))
    opts.log(text)
    write_text_atomic(opts.out / "fig5_ranking.txt", text + "\n")
    csv = ["force,rank,label,mean_N,peak_N,q95_N,score,removed,riding_up_max"] + [
        f"{part},{r['rank']},{r['label']},{r['mean']:.6g},{r['peak']:.6g},{r['quantile']:.6g},"
        f"{r['score']:.6g},{int(np.isfinite(seen[str(r['label'])][1].removal_times).sum())},"
        f"{int(seen[str(r['label'])][1].riding_up.max())}"
        for part, ranking in rankings.items() for r in ranking]
    write_text_atomic(opts.out / "fig5_ranking.csv", "\n".join(csv) + "\n")

    ranking = rankings["in_plane"]
    fig, axes = plt.subplots(3, 1, figsize=(8, 10), sharex=True)
    for ax, (title, runs) in zip(axes, panels[:3]):
        for params, run in runs:
            ax.plot(run.times, run.first_line_force("in_plane"), lw=0.9, label=_label(params))
        ax.set_title(title, fontsize="medium")
        ax.set_ylabel("first-line in-plane force (N)")
        ax.legend(fontsize="small")
    axes[-1].set_xlabel("time (s)")
    fig.suptitle(f"Fig. 5 analogue, E = {e:.3g} Pa, {opts.duration:g} s; gentlest: "
                 f"{ranking['label'][0]}", fontsize="medium")
    fig.tight_layout()
    savefig_atomic(fig, opts.out / "fig5_first_line_force.png", dpi=120)
    plt.close(fig)
    return {"ranking": ranking, "ranking_total": rankings["total"],
            "gentlest": str(ranking["label"][0]), "runs": seen}


def _format_ranking(ranking: np.ndarray, part: str, seen: dict, discard_before: float,
                    e: float, duration: float) -> str:
    what = "in-plane part of the" if part == "in_plane" else "total"
    lines = [f"Gentleness ranking on the {what} first-line net contact force, t >= "
             f"{discard_before:g} s, E = {e:.3g} Pa, {duration:g} s simulated (score = (mean/"
             "median + peak/median + q95/median) / 3; lower is gentler)",
             f"{'rank':>4}  {'set-up':<28} {'mean N':>9} {'peak N':>9} {'q95 N':>9} "
             f"{'score':>6} {'removed':>7} {'ride-up':>7}"]
    for row in ranking:
        run = seen[str(row["label"])][1]
        lines.append(f"{row['rank']:>4}  {row['label']:<28} {row['mean']:9.4g} "
                     f"{row['peak']:9.4g} {row['quantile']:9.4g} {row['score']:6.3f} "
                     f"{int(np.isfinite(run.removal_times).sum()):7d} "
                     f"{int(run.riding_up.max()):7d}")
    return "\n".join(lines)


# --------------------------------------------------------------------------------------------
# Figs. 6 and 7
# --------------------------------------------------------------------------------------------

def _durations(opts: StudyOptions, long_modulus_duration: Optional[float],
               per_modulus: Optional[Mapping[float, float]] = None) -> dict[float, float]:
    """Simulated time per E, s: ``per_modulus[E]`` where given, else ``long_modulus_duration``
    for E > 1e9 Pa if given (the stiff runs cost ~E^0.4 more steps per simulated second),
    else ``opts.duration``. Every key of ``per_modulus`` must be one of ``opts.moduli``."""
    per = dict(per_modulus or {})
    for e, d in per.items():
        if not any(math.isclose(float(e), m, rel_tol=1e-12) for m in opts.moduli):
            raise InvalidParameterError(
                f"invalid durations key E = {e!r} Pa: must be one of the moduli "
                f"{tuple(opts.moduli)} Pa")
        if not (isinstance(d, (int, float)) and math.isfinite(d) and d > 0):
            raise InvalidParameterError(
                f"invalid durations[{e!r}] = {d!r}: must be a finite simulated time > 0 s")

    def duration(e: float) -> float:
        for k, d in per.items():
            if math.isclose(float(k), e, rel_tol=1e-12):
                return float(d)
        return (long_modulus_duration if long_modulus_duration and e > 1e9
                else opts.duration)

    return {e: duration(e) for e in opts.moduli}


def _run_all_moduli(opts: StudyOptions, stiff_duration: Optional[float],
                    durations_by_modulus: Optional[Mapping[float, float]] = None
                    ) -> list[tuple[float, TableRun]]:
    """All E runs in one sweep per duration group (so two run at once)."""
    durations = _durations(opts, stiff_duration, durations_by_modulus)
    runs: dict[float, TableRun] = {}
    for duration in sorted(set(durations.values())):
        es = [e for e in opts.moduli if durations[e] == duration]
        grid = {k: [v] for k, v in FIG6_SETUP.items()}
        grid["young_modulus"] = [float(e) for e in es]
        for params, run in _sweep_runs(opts, grid, duration, f"E in {es}"):
            runs[float(params["young_modulus"])] = run
    return [(float(e), runs[float(e)]) for e in opts.moduli]


def moving_average(x: np.ndarray, n: int) -> np.ndarray:
    """Centred running mean of ``x`` over ``n`` samples, NaN-aware: each output averages the
    finite samples of its window (fewer at the ends); NaN where the window has none."""
    if not (isinstance(n, (int, np.integer)) and n >= 1):
        raise InvalidParameterError(f"invalid n = {n!r}: must be a whole number of samples >= 1")
    x = np.asarray(x, float)
    n = min(int(n), len(x)) if len(x) else 1
    kernel = np.ones(n)
    finite = np.isfinite(x)
    total = np.convolve(np.where(finite, x, 0.0), kernel, mode="same")
    count = np.convolve(finite.astype(float), kernel, mode="same")
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / np.where(count > 0, count, 1.0), np.nan)


def coordination_findings(times: np.ndarray, z: np.ndarray, period: float,
                          discard_before: float) -> dict[str, float]:
    """Numbers behind "oscillates between 4 and 6 with period T": the measured period
    (autocorrelation and FFT, s), and the 5 % and 95 % quantiles of ``z`` after
    ``discard_before`` s, with the gate period T for comparison.

    The period is measured on ``z`` minus its running mean over one gate period
    (:func:`moving_average`): that removes what is slower than T — the fall of the
    coordination while the table drains, which dominates long records — and leaves a
    T-periodic part unchanged (its mean over a whole period is zero). The quantiles are
    those of ``z`` itself."""
    keep = times >= discard_before
    t, x = times[keep], z[keep]
    if len(t) < 8:
        return {"period_acf_s": math.nan, "period_fft_s": math.nan, "q05": math.nan,
                "q95": math.nan, "gate_period_s": period}
    step = float(np.median(np.diff(t)))
    fast = x - moving_average(x, max(1, int(round(period / step))))
    return {"period_acf_s": period_of_oscillation(t, fast, "autocorrelation"),
            "period_fft_s": period_of_oscillation(t, fast, "fft"),
            "q05": float(np.nanquantile(x, 0.05)), "q95": float(np.nanquantile(x, 0.95)),
            "gate_period_s": period}


def fig6(opts: StudyOptions, stiff_duration: Optional[float] = None,
         discard_before: float = 2.0,
         durations: Optional[Mapping[float, float]] = None) -> dict[str, Any]:
    """Fig. 6: coordination number against time for each E in ``opts.moduli`` (all spheres,
    first line, rectangular centre), V_belt = 0.1 m/s, T = 2 s, A = 2 cm. Each run lasts
    ``durations[E]`` s where given, else ``stiff_duration`` s for E > 1e9 Pa if given, else
    ``opts.duration`` s.

    Tests the paper's claims on the recording: the period of each curve after
    ``discard_before`` s (:func:`period_of_oscillation`) against T, the range (5-95 %
    quantiles) against 4-6, and E-independence as the largest time-averaged difference
    between the all-sphere mean coordination at any E and at the smallest E, over the common
    time span. Writes ``fig6_coordination.png`` and ``fig6_findings.json``.
    """
    runs = _run_all_moduli(opts, stiff_duration, durations)
    groups = (("all spheres", None), ("first line", Tag.FIRST_LINE),
              ("rectangular centre", Tag.RECTANGULAR_CENTRE))
    findings: dict[str, Any] = {"setup": FIG6_SETUP, "moduli_Pa": list(opts.moduli),
                                "durations_s": {}, "groups": {}}
    fig, axes = plt.subplots(3, 1, figsize=(8, 10), sharex=True)
    curves: dict[float, np.ndarray] = {}
    for e, run in runs:
        findings["durations_s"][f"{e:.3g}"] = float(run.times[-1])
        for ax, (name, tag) in zip(axes, groups):
            select = None if tag is None else tag_mask(run.tags, tag)
            z = run.mean_coordination(select)
            if tag is None:
                curves[e] = z
            ax.plot(run.times, z, lw=0.9, label=_e_label(e))
            f = coordination_findings(run.sample_times, z, FIG6_SETUP["gate_period"],
                                      discard_before)
            findings["groups"].setdefault(name, {})[f"{e:.3g}"] = f
    for ax, (name, _) in zip(axes, groups):
        ax.set_title(f"coordination number: {name}", fontsize="medium")
        ax.set_ylabel("coordination")
        ax.legend(fontsize="small")
    axes[-1].set_xlabel("time (s)")
    fig.suptitle("Fig. 6 analogue: V_belt = 0.1 m/s, T = 2 s, A = 2 cm", fontsize="medium")
    fig.tight_layout()
    savefig_atomic(fig, opts.out / "fig6_coordination.png", dpi=120)
    plt.close(fig)

    e_ref = min(curves)
    differences = {}
    for e, run in runs:
        n = min(len(curves[e]), len(curves[e_ref]))
        diff = np.abs(curves[e][:n] - curves[e_ref][:n])
        differences[f"{e:.3g}"] = float(np.nanmean(diff))
    findings["mean_abs_difference_to_smallest_E"] = differences
    findings["riding_up_max"] = {f"{e:.3g}": int(run.riding_up.max()) for e, run in runs}
    findings["wall_time_s"] = {f"{e:.3g}": float(run.info["wall_time_s"]) for e, run in runs}
    write_json_atomic(opts.out / "fig6_findings.json", findings)
    opts.log(_format_fig6(findings))
    return findings


def _format_fig6(f: dict[str, Any]) -> str:
    lines = ["Fig. 6 findings (gate period T = 2 s):"]
    for name, per_e in f["groups"].items():
        for e, g in per_e.items():
            lines.append(f"  {name:<19} E={e:>8} Pa: period acf {g['period_acf_s']:.3g} s, "
                         f"fft {g['period_fft_s']:.3g} s; z 5-95 % {g['q05']:.2f}-{g['q95']:.2f}")
    lines.append("  mean |z_E - z_Emin| (all spheres): "
                 + ", ".join(f"{e}: {d:.3f}" for e, d in
                             f["mean_abs_difference_to_smallest_E"].items()))
    lines.append("  durations (s): " + ", ".join(f"{e}: {d:g}" for e, d in
                                                  f["durations_s"].items()))
    return "\n".join(lines)


def speed_windows(times: np.ndarray, speed: np.ndarray, width: float) -> list[dict[str, float]]:
    """Mean and peak of ``speed`` (m/s, NaN once the sphere has left) over consecutive windows
    of ``width`` s from t = 0, in mm/s, with the fraction of each window's samples that are
    finite; windows with no finite sample are left out."""
    if not (math.isfinite(width) and width > 0):
        raise InvalidParameterError(f"invalid width = {width!r}: must be a finite time > 0 s")
    out: list[dict[str, float]] = []
    if len(times) == 0:
        return out
    t_end = float(times[-1])
    # a run ends on the first step at or after its last sample time: no window for that
    # overshoot, only for whole sample intervals
    half = 0.5 * float(np.median(np.diff(times))) if len(times) > 1 else 0.0
    k = 0
    while k * width < t_end - half:
        sel = (times >= k * width) & (times < (k + 1) * width)
        v = speed[sel]
        ok = np.isfinite(v)
        if ok.any():
            out.append({"t0_s": k * width, "t1_s": min((k + 1) * width, t_end),
                        "mean_mm_s": float(1e3 * np.mean(v[ok])),
                        "peak_mm_s": float(1e3 * np.max(v[ok])),
                        "finite_fraction": float(ok.mean())})
        k += 1
    return out


def discharge_speeds(removal_times: np.ndarray, t_end: float, width: float,
                     table_width: float, pitch: float, opening_width: float,
                     belt_velocity: float) -> list[dict[str, float]]:
    """What mass conservation allows the bulk of the rectangular section to move at.

    Per consecutive window of ``width`` s up to ``t_end``: the discharge Q (spheres/s through
    the opening, from ``removal_times``, s) and the mean speed of a pack of table width W
    (``table_width``, m) that feeds it, v = Q a / W, with a the area of one sphere in the
    layer, between hexagonal (√3/2 p²) and square (p²) packing of pitch p (``pitch``, m);
    and the bound V_belt w̄ / W that holds even if the spheres left at the belt speed through
    the mean opening w̄ (``opening_width``, m), filling it. Speeds in mm/s."""
    for name, value in (("width", width), ("table_width", table_width), ("pitch", pitch),
                        ("opening_width", opening_width), ("belt_velocity", belt_velocity)):
        if not (math.isfinite(value) and value > 0):
            raise InvalidParameterError(f"invalid {name} = {value!r}: must be finite and > 0")
    done = np.asarray(removal_times, float)
    done = done[np.isfinite(done)]
    out = []
    k = 0
    # no window for the overshoot of the last step past the last sample (a run ends on the
    # first step at or after it): a window must span at least 1 % of `width`
    while k * width < t_end - 0.01 * width:
        t0, t1 = k * width, min((k + 1) * width, t_end)
        q = float(np.count_nonzero((done >= t0) & (done < t1))) / (t1 - t0)
        out.append({"t0_s": t0, "t1_s": t1, "discharge_per_s": q,
                    "bulk_speed_hexagonal_mm_s": 1e3 * q * math.sqrt(3) / 2 * pitch ** 2
                    / table_width,
                    "bulk_speed_square_mm_s": 1e3 * q * pitch ** 2 / table_width,
                    "bulk_speed_bound_mm_s": 1e3 * belt_velocity * opening_width / table_width})
        k += 1
    return out


def fig7(opts: StudyOptions, stiff_duration: Optional[float] = None,
         durations: Optional[Mapping[float, float]] = None,
         window: float = 10.0) -> dict[str, Any]:
    """Fig. 7: speed of the rectangular centre against time for each E (same runs as Fig. 6;
    durations as there), panel (a) E <= 1e9 Pa, (b) E > 1e9 Pa. Writes
    ``fig7_rectangular_centre_speed.png`` and ``fig7_findings.json``: per E the mean and peak
    speed over the run, over its last 2 s and per ``window`` s (:func:`speed_windows`), the
    time the sphere left the table (None if it did not), the belt's free-rolling speed
    2/7 V_belt, and per window the discharge and the bulk speed it implies
    (:func:`discharge_speeds`), all speeds in mm/s."""
    runs = _run_all_moduli(opts, stiff_duration, durations)
    fig, axes = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    findings: dict[str, Any] = {}
    for e, run in runs:
        s = tagged_speed(run.velocities, run.tags, Tag.RECTANGULAR_CENTRE)
        ax = axes[0] if e <= 1e9 else axes[1]
        # the samples, faint, and their 2 s running mean
        (line,) = ax.plot(run.times, 1e3 * s, lw=0.5, alpha=0.35)
        smooth = moving_average(s, max(1, int(round(2.0 / float(np.median(np.diff(run.times)))))))
        smooth[~np.isfinite(s)] = np.nan
        ax.plot(run.times, 1e3 * smooth, lw=1.3, color=line.get_color(),
                label=f"{_e_label(e)} (2 s mean)")
        late = run.times >= run.times[-1] - 2.0
        gone = np.flatnonzero(np.isnan(s))
        findings[f"{e:.3g}"] = {
            "duration_s": float(run.times[-1]),
            "mean_speed_mm_s": float(1e3 * np.nanmean(s)),
            "peak_speed_mm_s": float(1e3 * np.nanmax(s)),
            "mean_speed_last_2s_mm_s": (float(1e3 * np.nanmean(s[late]))
                                        if np.isfinite(s[late]).any() else None),
            "removed": bool(np.isnan(s[-1])),
            "left_at_s": float(run.times[gone[0]]) if gone.size else None,
            "windows": speed_windows(run.times, s, window),
            "continuity": discharge_speeds(
                run.removal_times, float(run.times[-1]), window,
                float(run.parameters["width"]),
                2.0 * float(run.parameters["sphere_radius"])
                * (1.0 + float(run.parameters["packing_gap"])),
                float(run.parameters["opening_width"]),
                float(run.parameters["belt_velocity"])),
            "n_removed": int(np.isfinite(run.removal_times).sum()),
            "free_rolling_mm_s": 1e3 * 2.0 / 7.0 * FIG6_SETUP["belt_velocity"],
        }
    for ax, title in zip(axes, ("(a) E <= 1e9 Pa", "(b) E > 1e9 Pa")):
        ax.set_title(title, fontsize="medium")
        ax.set_ylabel("speed (mm/s)")
        if ax.lines:
            ax.axhline(1e3 * 2.0 / 7.0 * FIG6_SETUP["belt_velocity"], color="grey", ls=":",
                       lw=0.8, label="2/7 V_belt (free rolling)")
            ax.legend(fontsize="small")
    axes[-1].set_xlabel("time (s)")
    fig.suptitle("Fig. 7 analogue: rectangular-centre speed, V_belt = 0.1 m/s, T = 2 s, "
                 "A = 2 cm", fontsize="medium")
    fig.tight_layout()
    savefig_atomic(fig, opts.out / "fig7_rectangular_centre_speed.png", dpi=120)
    plt.close(fig)
    write_json_atomic(opts.out / "fig7_findings.json", findings)
    opts.log("Fig. 7 findings (rectangular centre speed):\n" + "\n".join(
        f"  E={e:>8} Pa, {v['duration_s']:g} s: mean {v['mean_speed_mm_s']:.1f} mm/s, peak "
        f"{v['peak_speed_mm_s']:.1f} mm/s, left at {v['left_at_s']} s; per {window:g} s: "
        + ", ".join(f"{w['mean_mm_s']:.0f}/{w['peak_mm_s']:.0f}" for w in v["windows"])
        for e, v in findings.items()))
    return findings


# --------------------------------------------------------------------------------------------
# Figs. 8 and 9
# --------------------------------------------------------------------------------------------

def fig8_9(opts: StudyOptions, snapshot_times: Sequence[float] = (9.3, 12.2),
           animation_interval: float = 0.1, vtk_interval: float = 0.25,
           drop: float = 0.1) -> dict[str, Any]:
    """Figs. 8-9 at the paper's chosen set-up (A = 2 cm, T = 2 s, V_belt = 0.2 m/s) and E =
    ``opts.moduli[0]``: coordination and speed of the triangular centre (Fig. 8), snapshots at
    ``snapshot_times`` (s; clipped to the run), the triangular centre's speed with its
    coordination, and the first line's middle-mean speed (``drop`` of the values cut at each
    end) with its mean coordination (Fig. 9). Also writes a GIF like Movie 1 (a frame every
    ``animation_interval`` s) and a ParaView series ``vtk/table.pvd`` (every ``vtk_interval``
    s; point data radius, tag, velocity, force, coordination)."""
    from demfem.plots import animate_table, plot_table_snapshot

    e = float(opts.moduli[0])
    grid = {**FIG5_OPTIMUM, "young_modulus": [e]}
    (params, run), = _sweep_runs(opts, grid, opts.duration, "figs. 8-9")
    t = run.times
    tri = tag_mask(run.tags, Tag.TRIANGULAR_CENTRE)
    first = tag_mask(run.tags, Tag.FIRST_LINE)
    s_tri = tagged_speed(run.velocities, run.tags, Tag.TRIANGULAR_CENTRE)
    z_tri = run.mean_coordination(tri)
    v_first = middle_mean(np.linalg.norm(run.velocities[:, first], axis=2), drop=drop, axis=1)
    z_first = run.mean_coordination(first)

    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    axes[0].plot(t, z_tri, lw=0.9, color="green")
    axes[0].set_ylabel("coordination")
    axes[0].set_title("(a) triangular centre: coordination number", fontsize="medium")
    axes[1].plot(t, 1e3 * s_tri, lw=0.9, color="green")
    axes[1].set_ylabel("speed (mm/s)")
    axes[1].set_title("(b) triangular centre: speed", fontsize="medium")
    axes[1].set_xlabel("time (s)")
    fig.suptitle(f"Fig. 8 analogue: {_label(params)}, E = {e:.3g} Pa", fontsize="medium")
    fig.tight_layout()
    savefig_atomic(fig, opts.out / "fig8_triangular_centre.png", dpi=120)
    plt.close(fig)

    scene = table_from_params(params).build()
    snaps = []
    for ts in snapshot_times:
        k = int(np.argmin(np.abs(t - min(float(ts), float(t[-1])))))
        path = opts.out / f"fig9_snapshot_{t[k]:.1f}s.png"
        plot_table_snapshot(path, scene, run.positions[k], time=float(t[k]))
        snaps.append(str(path))

    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for ax, v, z, title, colour in (
            (axes[0], s_tri, z_tri, "(b) triangular centre", "green"),
            (axes[1], v_first, z_first,
             f"(d) first line: middle-mean speed (drop {100 * drop:g} % each end)", "magenta")):
        ax.plot(t, 1e3 * v, lw=0.9, color=colour)
        ax.set_ylabel("speed (mm/s)")
        twin = ax.twinx()
        twin.plot(t, z, lw=0.8, color="black", alpha=0.6)
        twin.set_ylabel("coordination (black)")
        ax.set_title(title, fontsize="medium")
    axes[1].set_xlabel("time (s)")
    fig.suptitle(f"Fig. 9 analogue: {_label(params)}, E = {e:.3g} Pa", fontsize="medium")
    fig.tight_layout()
    savefig_atomic(fig, opts.out / "fig9_speed_and_coordination.png", dpi=120)
    plt.close(fig)

    stride = max(1, int(round(animation_interval / (t[1] - t[0]))))
    gif = animate_table(opts.out / "movie1_table.gif", scene, run.positions[::stride],
                        t[::stride].tolist(), fps=10, dpi=60)
    pvd = write_vtk_series(opts.out / "vtk", run, vtk_interval)

    present_tri = np.isfinite(s_tri)
    exit_time = float(t[present_tri][-1]) if not present_tri[-1] else math.nan
    findings = {
        "young_modulus_Pa": e, "duration_s": float(t[-1]),
        "triangular_centre_left_at_s": exit_time,
        "triangular_centre_peak_speed_mm_s": float(1e3 * np.nanmax(s_tri)),
        "triangular_centre_period_acf_s": period_of_oscillation(run.sample_times, z_tri),
        "triangular_centre_speed_coordination_correlation": _correlation(s_tri, z_tri),
        "first_line_peak_middle_speed_mm_s": float(1e3 * np.nanmax(v_first)),
        "first_line_coordination_range": [float(np.nanmin(z_first)), float(np.nanmax(z_first))],
        "riding_up_max": int(run.riding_up.max()),
        "snapshots": snaps, "animation": str(gif), "paraview": str(pvd),
    }
    write_json_atomic(opts.out / "fig8_9_findings.json", findings)
    opts.log("Figs. 8-9 findings:\n" + json_dumps(findings, indent=1))
    return findings


def _correlation(a: np.ndarray, b: np.ndarray) -> float:
    """Pearson correlation over the samples where both are finite; NaN if fewer than 3."""
    ok = np.isfinite(a) & np.isfinite(b)
    if ok.sum() < 3 or np.std(a[ok]) == 0 or np.std(b[ok]) == 0:
        return math.nan
    return float(np.corrcoef(a[ok], b[ok])[0, 1])
