"""How replicas scale with Dask workers: events per wall-second of `assess_replicas` on the
same replicas with 1 and with 2 LocalCluster workers (issue 41's target: at least 0.8 × the
number of workers).

Each repeat runs the same ``--replicas`` replicas (seeds 0 … N − 1, the same settings, each a
fresh assessment up to its risk stage) once on a LocalCluster of 1 worker and once of 2,
alternating which goes first so that the machine's drift hits both alike. The cluster is
started and its workers import demfem first; the rate is the events in the replicas'
statistics windows over the wall time of the replicas on the warm cluster (the scaling of a
long job, whose start-up is negligible), and, beside it, over start-up and replicas
together (what a short job waits for). The result is the median over ``--reps`` repeats,
written to ``docs/data/replica_scaling.json`` with every repeat, each replica's wall and CPU
time (CPU far below wall: other jobs held the cores), the share of a core a busy loop got
just before each set, the machine and its load.

    python benches/replica_scaling.py --replicas 6 --duration 2.0 --reps 3

Beside it, the machine's own ceiling: two busy processes' throughput over one
(:func:`machine_ceiling`), which no number of workers can beat.

The replicas are a small table (``--spheres`` cartridges) so that a repeat takes seconds; a
replica of the default job is minutes, over which the per-replica overhead (worker start,
imports, the calibration stage) weighs less.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "data" / "replica_scaling.json"


def cpu_share(seconds: float = 1.0) -> float:
    """CPU time over wall time of a busy loop in this process: about 1 on an idle core, far
    less where other jobs hold the cores (then no number of workers scales)."""
    t0, c0 = time.perf_counter(), time.process_time()
    x = 0
    while time.perf_counter() - t0 < seconds:
        for i in range(10_000):
            x += i
    return (time.process_time() - c0) / (time.perf_counter() - t0)


def _spin(n: int) -> int:
    """A pure-CPU loop (no memory traffic to speak of), for :func:`machine_ceiling`."""
    s = 0
    for i in range(n):
        s += i * i
    return s


def machine_ceiling(n: int = 20_000_000, reps: int = 3) -> float:
    """Throughput of two busy processes at once over one alone (median of ``reps``): what this
    machine's two cores deliver to any perfectly parallel work. 2.0 on two independent idle
    cores; less where the two virtual CPUs share a physical core or a power budget."""
    import multiprocessing as mp

    ratios = []
    with mp.Pool(2) as pool:
        pool.map(_spin, [1000, 1000])
        for _ in range(reps):
            t0 = time.perf_counter()
            _spin(n)
            one_s = time.perf_counter() - t0
            t0 = time.perf_counter()
            pool.map(_spin, [n, n])
            ratios.append(2.0 * one_s / (time.perf_counter() - t0))
    return statistics.median(ratios)


def _warm() -> None:
    """Import what a replica's stages import (run on every worker before the timing)."""
    import importlib

    for name in ("demfem.assess.run", "demfem.assess.replicas", "demfem.assess.events",
                 "demfem.stress.stage", "demfem.assess.risk_product",
                 "demfem.dem.table_run", "demfem.scenes.perturb"):
        importlib.import_module(name)


def one(table, workers: int, replicas: int, duration: float, where: Path) -> dict:
    """One fresh set of replicas on a LocalCluster of ``workers``: the cluster's start and
    warm-up (imports), then the timed replicas on the warm cluster."""
    from distributed import Client, LocalCluster

    from demfem.assess.replicas import assess_replicas

    t0 = time.perf_counter()
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        client.run(_warm)
        startup = time.perf_counter() - t0
        t0 = time.perf_counter()
        doc = assess_replicas(table, where, replicas, scheduler=cluster.scheduler_address,
                              duration=duration, reports=False, fresh=True,
                              log=lambda line: None)
        wall = time.perf_counter() - t0
    events = int(doc["merged"]["n_events_window"])
    cpu = [r.get("cpu_s", float("nan")) for r in doc["replicas"]]
    return {"workers": workers, "wall_s": wall, "startup_and_imports_s": startup,
            "events": events, "events_per_wall_s": events / wall,
            "events_per_wall_s_with_startup": events / (wall + startup),
            "replica_wall_s": [r["wall_s"] for r in doc["replicas"]], "replica_cpu_s": cpu,
            "busy_fraction": sum(cpu) / (wall * workers),
            "broken_per_hour": doc["merged"]["broken_per_hour"]}


def main() -> None:

    from demfem.scenes.table import AccumulationTable

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--replicas", type=int, default=6, help="replicas per set (6)")
    p.add_argument("--duration", type=float, default=0.2, help="simulated time, s (0.2)")
    p.add_argument("--spheres", type=int, default=30, help="cartridges on the table (30)")
    p.add_argument("--reps", type=int, default=3, help="repeats (3)")
    p.add_argument("--out", default=str(OUT), help="result file")
    a = p.parse_args()
    table = AccumulationTable(width=0.1, length=0.1, tilted_wall_length=0.05,
                              n_spheres=a.spheres)
    load_before = os.getloadavg()
    runs: dict[int, list[dict]] = {1: [], 2: []}
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="replica_bench_") as tmp:
        for rep in range(a.reps):
            for w in ((1, 2) if rep % 2 == 0 else (2, 1)):
                share = cpu_share()
                r = one(table, w, a.replicas, a.duration, Path(tmp) / f"r{rep}_w{w}")
                r["cpu_share_before"] = share
                runs[w].append(r)
                print(f"repeat {rep + 1}, {w} worker(s): {r['wall_s']:.1f} s wall, "
                      f"{r['events']} events, {r['events_per_wall_s']:.1f} events/s (start "
                      f"and imports {r['startup_and_imports_s']:.1f} s before; CPU "
                      f"{r['busy_fraction']:.0%} of the workers' wall; a busy loop got "
                      f"{share:.0%} of a core just before)", flush=True)
    ceiling = machine_ceiling()
    same = len({r["events"] for rs in runs.values() for r in rs}) == 1
    rate = {w: statistics.median(r["events_per_wall_s"] for r in rs) for w, rs in runs.items()}
    cold = {w: statistics.median(r["events_per_wall_s_with_startup"] for r in rs)
            for w, rs in runs.items()}
    speedup = rate[2] / rate[1]
    result = {
        "what": "events per wall-second of assess_replicas, the same replicas on a warm "
                "LocalCluster of 1 and of 2 workers (started and imports done before the "
                "timing; events_per_wall_s_with_startup counts them too), medians of "
                f"{a.reps} alternating repeats",
        "command": f"python benches/replica_scaling.py --replicas {a.replicas} --duration "
                   f"{a.duration} --spheres {a.spheres} --reps {a.reps}",
        "table": {"n_spheres": a.spheres, "width_m": 0.1, "length_m": 0.1,
                  "tilted_wall_length_m": 0.05, "duration_s": a.duration,
                  "replicas": a.replicas, "stages": "calibration to risk (no report)"},
        "events_per_wall_s": {str(w): v for w, v in rate.items()},
        "events_per_wall_s_with_startup": {str(w): v for w, v in cold.items()},
        "speedup_2_over_1": speedup,
        "speedup_2_over_1_with_startup": cold[2] / cold[1], "efficiency": speedup / 2.0, "target_efficiency": 0.8,
        "target_met": bool(speedup / 2.0 >= 0.8),
        "machine_two_process_ceiling": ceiling,
        "share_of_machine_ceiling": speedup / ceiling,
        "same_numbers_on_1_and_2_workers": same,
        "runs": {str(w): rs for w, rs in runs.items()},
        "machine": {"cpu_count": os.cpu_count(), "platform": platform.platform(),
                    "python": platform.python_version(),
                    "load_average_before": list(load_before),
                    "load_average_after": list(os.getloadavg())},
        "bench_wall_s": time.perf_counter() - started}
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(json.dumps(result, indent=1) + "\n", encoding="utf-8")
    print(f"events per wall-second: 1 worker {rate[1]:.1f}, 2 workers {rate[2]:.1f}: "
          f"speedup {speedup:.2f} = {speedup / 2:.0%} of 2 (target 80 %); with start-up "
          f"{cold[1]:.1f} and {cold[2]:.1f}; same numbers on both: {same}; two busy loops "
          f"get {ceiling:.2f}x one on this machine, so the replicas reach "
          f"{speedup / ceiling:.0%} of what its two cores deliver; written {a.out}")


if __name__ == "__main__":
    main()
