"""The continuous infeed of a :class:`~demfem.scenes.mesh_table.MeshTable`: cartridges
inserted at the line's rate at free inlet sites, counted out at the outlet, and the table's
throughput, residence time and steadiness.

The engine holds a fixed pool of spheres; the spheres not on the table are removed
(:meth:`DemSimulation.remove_particle`) and parked. The run advances in chunks of at most a
quarter of the insertion interval; before each chunk, the cartridges due by then
(``floor(t · rate / 60) + 1`` since t = 0) are put back at the first free sites of the inlet
(:meth:`DemSimulation.reinsert_particle`, never overlapping a sphere; the search starts
after the site last used, so the inlet fills across its width), moving at the infeed
velocity without spin. A cartridge that finds no free site, or no parked sphere, waits (the
*backlog*, reported). Spheres the engine removes at the outlet plane are *exits*, with their
residence time (exit − insertion); spheres that fall below ``lost_below`` are *lost*. Both go
back to the pool.

Steadiness: the run is cut into windows of ``window`` s; per window, the spheres inserted,
exited and lost, the mean number on the table and the particle–particle collisions (contact
onsets). The table is *steady* over the second half of the run when the exit rate there is
within 10 % of the infeed rate, the population of the last window is within 10 % of the one
before, and the backlog does not grow. Units: s, m, cartridges per minute.
"""
from __future__ import annotations

import collections
import math
import time as _time
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np

from demfem.scenes.mesh_table import MeshTable

__all__ = ["run_mesh_table", "steadiness", "OUTPUT_FILES"]

#: What a run writes into its output folder.
OUTPUT_FILES = ("summary.json", "windows.csv", "exits.csv")


def run_mesh_table(table: MeshTable, out: str | Path, *, duration: Optional[float] = None,
                   threads: Optional[int] = None,
                   log: Optional[Callable[[str], None]] = None) -> dict[str, Any]:
    """Run ``table`` for ``duration`` s (default: the scene's) with its continuous infeed;
    write ``summary.json``, ``windows.csv`` (the steadiness windows) and ``exits.csv`` (time
    and residence of each exit) into ``out``; return the summary."""
    from demfem import dem
    from demfem.errors import check_positive
    from demfem.io.atomic import write_text_atomic
    from demfem.io.strict_json import write_json_atomic

    duration = table.duration if duration is None else check_positive("duration", duration)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    say = log or (lambda line: None)
    sim = dem.from_scene(table.description(), model=table.model,
                         threads=threads or table.threads, record_onsets=True,
                         expected_max_speed=1.0)
    n = table.pool
    for i in range(n):
        sim.remove_particle(i)
    r = table.sphere_radius
    sites = table.infeed.sites(r, table.packing_gap)
    velocity = (float(table.infeed.velocity[0]), float(table.infeed.velocity[1]), 0.0)
    rate = table.infeed.rate / 60.0  # per second
    chunk_time = min(0.01, 0.25 / rate)
    steps = max(1, int(round(chunk_time / sim.dt)))
    parked = collections.deque(range(n))
    inserted_at = np.full(n, np.nan)
    n_inserted = n_lost = removals_seen = cursor = 0
    exits: list[tuple[float, float]] = []
    max_backlog = 0
    backlog_end_first_half = None
    window = table.window
    n_windows = max(1, int(math.ceil(duration / window - 1e-9)))
    win = {k: np.zeros(n_windows) for k in ("inserted", "exited", "lost", "collisions",
                                            "population", "samples")}
    wall_start = _time.perf_counter()
    last_log = wall_start
    say(f"mesh table {table.source}: {sum(len(m.triangles) for m in table.meshes)} wall "
        f"triangles, {len(table.belts)} belt(s), infeed {table.infeed.rate:g}/min, "
        f"dt = {sim.dt:.3g} s, {steps} steps per chunk")
    while sim.time < duration - 0.5 * sim.dt:
        t = sim.time
        w = min(n_windows - 1, int(t / window))
        due = int(math.floor(t * rate + 1e-9)) + 1 - n_inserted
        if due > 0 and parked:
            alive = np.asarray(sim.alive(), bool)
            occupied = np.asarray(sim.positions())[alive]
            tried = 0
            while due > 0 and parked and tried < len(sites):
                # round robin over the sites, so the inlet fills across its width
                site = sites[cursor]
                cursor = (cursor + 1) % len(sites)
                tried += 1
                if len(occupied) and np.min(np.linalg.norm(occupied - site, axis=1)) < 2 * r:
                    continue
                i = parked.popleft()
                sim.reinsert_particle(i, (float(site[0]), float(site[1]), float(site[2])),
                                      velocity)
                inserted_at[i] = t
                occupied = np.vstack([occupied, site]) if len(occupied) else site[None, :]
                n_inserted += 1
                due -= 1
                win["inserted"][w] += 1
        backlog = int(math.floor(t * rate + 1e-9)) + 1 - n_inserted
        max_backlog = max(max_backlog, backlog)
        if backlog_end_first_half is None and t >= 0.5 * duration:
            backlog_end_first_half = backlog
        sim.step(min(steps, max(1, int(round((duration - t) / sim.dt)))))
        times, index = sim.removals()
        for k in range(removals_seen, len(times)):
            i = int(index[k])
            exits.append((float(times[k]), float(times[k] - inserted_at[i])))
            win["exited"][min(n_windows - 1, int(times[k] / window))] += 1
            parked.append(i)
        removals_seen = len(times)
        alive = np.asarray(sim.alive(), bool)
        z = np.asarray(sim.positions())[:, 2]
        for fallen in np.flatnonzero(alive & (z < table.lost_below)):
            sim.remove_particle(int(fallen))
            parked.append(int(fallen))
            n_lost += 1
            win["lost"][w] += 1
        alive = np.asarray(sim.alive(), bool)
        onsets = sim.onsets()
        win["collisions"][w] += int(np.count_nonzero(~np.asarray(onsets["partner_is_wall"],
                                                                 bool)))
        sim.clear_records()
        win["population"][w] += int(alive.sum())
        win["samples"][w] += 1
        now = _time.perf_counter()
        if now - last_log > 5.0:
            last_log = now
            say(f"  t = {sim.time:.2f} / {duration:g} s: on the table {int(alive.sum())}, "
                f"in {n_inserted}, out {len(exits)}, lost {n_lost}, backlog {backlog}")
    wall_time = _time.perf_counter() - wall_start
    # cartridges due strictly before the end (t = k / rate < t_end) and not placed
    final_backlog = int(math.ceil(duration * rate - 1e-9)) - n_inserted
    population = np.divide(win["population"], np.maximum(win["samples"], 1))
    summary = {
        **table.summary_fields(),
        "simulated_s": sim.time, "steps": int(sim.steps), "dt_s": sim.dt,
        "wall_time_s": wall_time,
        "inserted": n_inserted, "exited": len(exits), "lost": n_lost,
        "on_table_at_end": int(np.asarray(sim.alive(), bool).sum()),
        "backlog_at_end": final_backlog, "backlog_max": max_backlog,
        "throughput_per_minute": _throughput(exits, 0.0, sim.time),
        **steadiness(exits, win, population, window, sim.time, table.infeed.rate,
                     backlog_end_first_half or 0, final_backlog),
    }
    write_json_atomic(out / "summary.json", summary)
    rows = ["window_start_s,window_end_s,inserted,exited,lost,mean_on_table,collisions,"
            "exit_rate_per_minute"]
    for k in range(n_windows):
        t0, t1 = k * window, min((k + 1) * window, sim.time)
        span = max(t1 - t0, 1e-12)
        rows.append(f"{t0:.6g},{t1:.6g},{int(win['inserted'][k])},{int(win['exited'][k])},"
                    f"{int(win['lost'][k])},{population[k]:.6g},{int(win['collisions'][k])},"
                    f"{win['exited'][k] / span * 60.0:.6g}")
    write_text_atomic(out / "windows.csv", "\n".join(rows) + "\n")
    write_text_atomic(out / "exits.csv", "time_s,residence_s\n" + "".join(
        f"{a:.6g},{b:.6g}\n" for a, b in exits))
    say(f"throughput {summary['throughput_steady_per_minute']:.4g}/min over the second half "
        f"(infeed {table.infeed.rate:g}/min), residence mean "
        f"{summary['residence_mean_s']:.3g} s, median {summary['residence_median_s']:.3g} s, "
        f"steady: {summary['steady']} ({wall_time:.1f} s wall); wrote {out / 'summary.json'}")
    return summary


def _throughput(exits: list[tuple[float, float]], t0: float, t1: float) -> float:
    """Exits per minute between t0 and t1 (s)."""
    k = sum(1 for t, _ in exits if t0 <= t < t1)
    return k / max(t1 - t0, 1e-12) * 60.0


def steadiness(exits: list[tuple[float, float]], win: dict[str, np.ndarray],
               population: np.ndarray, window: float, t_end: float, rate: float,
               backlog_half: int, backlog_end: int) -> dict[str, Any]:
    """The second-half measures: throughput and residence (mean, median) of the exits after
    t_end / 2, the exit rate against the infeed ``rate`` (per minute), the change of the
    population between the last two windows, and whether the table is steady (see the
    module docs)."""
    half = 0.5 * t_end
    late = np.array([r for t, r in exits if t >= half])
    every = np.array([r for _, r in exits])
    throughput = _throughput(exits, half, t_end)
    ratio = throughput / rate if rate > 0 else math.nan
    full = [k for k in range(len(population)) if (k + 1) * window <= t_end + 1e-9]
    drift = math.nan
    if len(full) >= 2 and population[full[-2]] > 0:
        drift = float(population[full[-1]] / population[full[-2]] - 1.0)
    steady = bool(len(late) > 0 and abs(ratio - 1.0) < 0.1 and math.isfinite(drift)
                  and abs(drift) < 0.1 and backlog_end <= backlog_half + 1)
    exit_rates = [float(win["exited"][k] / window * 60.0) for k in full]
    return {
        "throughput_steady_per_minute": throughput,
        "exit_to_infeed_ratio": ratio,
        "residence_mean_s": float(late.mean()) if len(late) else math.nan,
        "residence_median_s": float(np.median(late)) if len(late) else math.nan,
        "residence_mean_all_s": float(every.mean()) if len(every) else math.nan,
        "population_drift_last_window": drift,
        "window_exit_rate_per_minute": exit_rates,
        "window_mean_on_table": [float(population[k]) for k in full],
        "window_collisions_per_s": [float(win["collisions"][k] / window) for k in full],
        "steady": steady,
    }
