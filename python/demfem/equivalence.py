"""Are equivalent spheres a fair stand-in for full-shape cartridges? One table, three particles.

The same reduced accumulation table (:class:`demfem.scenes.table.AccumulationTable`) runs with
equivalent spheres (:func:`demfem.dem.from_scene`, plain Hertz–Mindlin so that only the shape
differs), with 632-bead clumped cartridges and with exact cartridge shapes
(:func:`demfem.rigid.from_scene`). Every run samples the bodies still on the table at fixed
intervals after a settling time and logs every contact onset. The study compares:

* speed distributions of the bodies' centres of mass (m/s),
* coordination numbers (body–body contacts per body),
* normal approach speeds at contact onsets (m/s; body–body and body–wall together),

by the two-sample Kolmogorov–Smirnov statistic (``scipy.stats.ks_2samp``) and quantiles; the
fraction of cartridges tilted beyond 5° (and fallen, beyond 60°) at the end; the bodies that
left through the opening; and the wall time per simulated second of each engine in one
process on one machine (the load average is recorded with it). SI units throughout.
"""
from __future__ import annotations

import csv
import dataclasses
import math
import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np

from demfem.io.atomic import atomic_path, write_text_atomic
from demfem.scenes.table import AccumulationTable

__all__ = ["StudyConfig", "RunResult", "run_particle", "compare", "run_study", "PARTICLES"]

PARTICLES = ("sphere", "clump", "cylinder")


@dataclass(frozen=True)
class StudyConfig:
    """The reduced table and the sampling of the study (SI units).

    The table is small (``n_spheres`` bodies) and soft (``young_modulus``, 1 % of the paper's
    45 GPa) so that three runs of ``t_end`` seconds fit in minutes on a laptop; the full
    shapes stand at the spheres' start sites, walls ``wall_height`` high.
    """

    n_spheres: int = 40
    length: float = 0.12
    width: float = 0.12
    tilted_wall_length: float = 0.10
    opening_width: float = 0.03
    gate_amplitude: float = 0.01
    gate_period: float = 1.0
    wall_height: float = 0.07
    young_modulus: float = 45e7
    t_end: float = 2.0
    t_settle: float = 0.3
    sample_every: float = 0.02
    tilt_threshold_deg: float = 5.0
    fallen_threshold_deg: float = 60.0

    def __post_init__(self) -> None:
        from demfem.errors import check_count, check_positive, check_range

        check_count("n_spheres", self.n_spheres, 1)
        for name in ("length", "width", "tilted_wall_length", "opening_width", "gate_period",
                     "wall_height", "young_modulus", "t_end", "sample_every"):
            check_positive(name, getattr(self, name))
        check_range("gate_amplitude", self.gate_amplitude, 0.0, lo_open=False)
        check_range("t_settle", self.t_settle, 0.0, lo_open=False)
        if self.sample_every > self.t_end:
            from demfem.errors import InvalidParameterError

            raise InvalidParameterError(f"invalid sample_every = {self.sample_every!r}: must "
                                        f"not exceed t_end = {self.t_end!r} s")
        for name in ("tilt_threshold_deg", "fallen_threshold_deg"):
            check_range(name, getattr(self, name), 0.0, 90.0)

    def table(self, particle: str) -> AccumulationTable:
        """The table with ``particle`` at the start sites."""
        return AccumulationTable(
            n_spheres=self.n_spheres, length=self.length, width=self.width,
            tilted_wall_length=self.tilted_wall_length, opening_width=self.opening_width,
            gate_amplitude=self.gate_amplitude, gate_period=self.gate_period,
            wall_height=self.wall_height, young_modulus=self.young_modulus, particle=particle)


@dataclass
class RunResult:
    """Samples of one run: speeds (m/s) and coordination numbers of the bodies on the table
    at every sample after the settling time, onset normal approach speeds (m/s), final tilt
    angles (rad, empty for spheres), bodies removed, steps, time step (s) and wall time (s)."""

    particle: str
    speeds: np.ndarray
    coordination: np.ndarray
    onset_speeds: np.ndarray
    tilts: np.ndarray
    removed: int
    n_bodies: int
    steps: int
    dt: float
    wall_seconds: float
    t_end: float

    @property
    def wall_per_simulated_second(self) -> float:
        """Wall-clock seconds per simulated second."""
        return self.wall_seconds / self.t_end


def run_particle(config: StudyConfig, particle: str,
                 progress: Optional[Callable[[str], None]] = None) -> RunResult:
    """Run the table with ``particle`` ("sphere", "clump" or "cylinder") and sample it."""
    from demfem import dem, rigid

    description = config.table(particle).build()
    sim: Any
    if particle == "sphere":
        sim = dem.from_scene(description, model="hertz_mindlin", record_onsets=True)
    else:
        sim = rigid.from_scene(description, particle=particle, record_onsets=True)
    speeds: list[np.ndarray] = []
    coordination: list[np.ndarray] = []
    wall = 0.0
    t = 0.0
    while t < config.t_end - 1e-12:
        t = min(config.t_end, t + config.sample_every)
        start = time.perf_counter()
        sim.run_until(t)
        wall += time.perf_counter() - start
        if t >= config.t_settle:
            alive = np.asarray(sim.alive(), bool)
            v = np.linalg.norm(np.asarray(sim.velocities())[alive], axis=1)
            speeds.append(v)
            coordination.append(np.asarray(sim.coordination())[alive].astype(float))
        if progress is not None and abs(t / 0.5 - round(t / 0.5)) < 1e-9:
            progress(f"{particle}: t = {t:.2f} s, wall {wall:.1f} s")
    onsets = sim.onsets()
    onset_speeds = np.asarray(onsets["normal_speed"], float)
    onset_times = np.asarray(onsets["time"], float)
    onset_speeds = onset_speeds[(onset_times >= config.t_settle) & (onset_speeds > 0)]
    alive = np.asarray(sim.alive(), bool)
    tilts = np.asarray(sim.tilt_angles())[alive] if particle != "sphere" else np.zeros(0)
    return RunResult(
        particle=particle,
        speeds=np.concatenate(speeds) if speeds else np.zeros(0),
        coordination=np.concatenate(coordination) if coordination else np.zeros(0),
        onset_speeds=onset_speeds, tilts=tilts,
        removed=int(len(sim.removals()[0])), n_bodies=len(sim), steps=int(sim.steps),
        dt=float(sim.dt), wall_seconds=wall, t_end=config.t_end)


def _quantiles(x: np.ndarray) -> tuple[float, float, float]:
    if len(x) == 0:
        return (math.nan, math.nan, math.nan)
    q = np.quantile(x, [0.1, 0.5, 0.9])
    return (float(q[0]), float(q[1]), float(q[2]))


def compare(results: dict[str, RunResult], config: StudyConfig) -> list[dict[str, Any]]:
    """One row per particle: quantiles (10 %, 50 %, 90 %) of each sample, the KS statistic
    and p-value against the spheres, tilt and fall fractions, removals and cost."""
    from scipy.stats import ks_2samp

    ref = results["sphere"]
    rows = []
    for name, r in results.items():
        row: dict[str, Any] = {"particle": name}
        for key in ("speeds", "coordination", "onset_speeds"):
            x = getattr(r, key)
            q10, q50, q90 = _quantiles(x)
            row[f"{key}_q10"], row[f"{key}_q50"], row[f"{key}_q90"] = q10, q50, q90
            y = getattr(ref, key)
            if name == "sphere" or len(x) == 0 or len(y) == 0:
                row[f"{key}_ks"], row[f"{key}_p"] = math.nan, math.nan
            else:
                test = ks_2samp(x, y)
                row[f"{key}_ks"], row[f"{key}_p"] = float(test.statistic), float(test.pvalue)
        row["onsets"] = len(r.onset_speeds)
        if len(r.tilts):
            deg = np.degrees(r.tilts)
            row["tilted_fraction"] = float(np.mean(deg > config.tilt_threshold_deg))
            row["fallen_fraction"] = float(np.mean(deg > config.fallen_threshold_deg))
        else:
            row["tilted_fraction"], row["fallen_fraction"] = math.nan, math.nan
        row["removed"] = r.removed
        row["n_bodies"] = r.n_bodies
        row["dt_s"] = r.dt
        row["steps"] = r.steps
        row["wall_s_per_sim_s"] = r.wall_per_simulated_second
        row["cost_vs_sphere"] = r.wall_per_simulated_second / ref.wall_per_simulated_second
        rows.append(row)
    return rows


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        if math.isnan(v):
            return "–"
        return f"{v:.3g}"
    return str(v)


def markdown_table(rows: list[dict[str, Any]]) -> str:
    """The study's main table as markdown (speeds and onset speeds in m/s)."""
    head = ("| particle | speed q10/q50/q90 (m/s) | KS speed | coordination q50/q90 | KS coord. "
            "| onset v_n q10/q50/q90 (m/s) | KS onset | tilted > 5° | fallen > 60° "
            "| removed | dt (s) | wall s / sim s | cost vs spheres |")
    lines = [head, "|" + "---|" * 13]
    for r in rows:
        lines.append(
            f"| {r['particle']} | {_fmt(r['speeds_q10'])} / {_fmt(r['speeds_q50'])} / "
            f"{_fmt(r['speeds_q90'])} | {_fmt(r['speeds_ks'])} | {_fmt(r['coordination_q50'])} / "
            f"{_fmt(r['coordination_q90'])} | {_fmt(r['coordination_ks'])} | "
            f"{_fmt(r['onset_speeds_q10'])} / {_fmt(r['onset_speeds_q50'])} / "
            f"{_fmt(r['onset_speeds_q90'])} | {_fmt(r['onset_speeds_ks'])} | "
            f"{_fmt(r['tilted_fraction'])} | {_fmt(r['fallen_fraction'])} | {r['removed']}/"
            f"{r['n_bodies']} | {_fmt(r['dt_s'])} | {_fmt(r['wall_s_per_sim_s'])} | "
            f"{_fmt(r['cost_vs_sphere'])} |")
    return "\n".join(lines) + "\n"


def plot(results: dict[str, RunResult], path: Path) -> Path:
    """Empirical CDFs of speeds and onset speeds and the coordination histogram (PNG,
    written atomically)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    for name, r in results.items():
        for ax, x in ((axes[0], r.speeds), (axes[1], r.onset_speeds)):
            if len(x):
                s = np.sort(x)
                ax.step(s, np.arange(1, len(s) + 1) / len(s), where="post", label=name)
        if len(r.coordination):
            k = np.arange(0, int(r.coordination.max()) + 2)
            h, _ = np.histogram(r.coordination, bins=k - 0.5)
            axes[2].plot(k[:-1], h / h.sum(), marker="o", label=name)
    axes[0].set(xlabel="speed of the centre of mass (m/s)", ylabel="CDF", xscale="log")
    axes[1].set(xlabel="normal approach speed at contact onset (m/s)", ylabel="CDF", xscale="log")
    axes[2].set(xlabel="coordination number", ylabel="fraction of samples")
    for ax in axes:
        ax.legend()
        ax.grid(alpha=0.3)
    fig.tight_layout()
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    return Path(path)


def run_study(config: StudyConfig, out: str | Path,
              progress: Optional[Callable[[str], None]] = None) -> dict[str, Any]:
    """Run the three particles, write ``equivalence.csv``, ``equivalence.md`` and
    ``equivalence.png`` to ``out``; returns the rows and the load average of the run."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    load_before = os.getloadavg()
    results = {p: run_particle(config, p, progress) for p in PARTICLES}
    load_after = os.getloadavg()
    rows = compare(results, config)
    with atomic_path(out / "equivalence.csv", suffix=".csv") as tmp:
        with open(tmp, "w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
    params = ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}"
                       for k, v in dataclasses.asdict(config).items())
    text = (f"Equivalence study ({params}); load average (1 min) {load_before[0]:.1f} before, "
            f"{load_after[0]:.1f} after, {os.cpu_count()} CPUs.\n\n" + markdown_table(rows))
    write_text_atomic(out / "equivalence.md", text)
    plot(results, out / "equivalence.png")
    return {"rows": rows, "load": (load_before, load_after), "markdown": text}
