"""Cost of full-shape cartridges against equivalent spheres on the same table, in one run.

The same table (the equivalence study's reduced table, 40 bodies, or the default table of
840) runs with each particle: equivalent spheres (``demfem.dem``, plain Hertz–Mindlin), 632-bead
clumps, parry exact shapes (``"cylinder"``) and the analytic bodies of revolution
(``"revolution"``), all in one process. Each engine first runs ``--warmup`` simulated seconds
from the start (untimed: the belt packs the table), then the engines take turns timing the
next ``--window`` simulated seconds, ``--reps`` times, the order rotating each repeat; the
cost of a particle is its wall time per simulated second, and its ratio to the spheres' is
the median over repeats of the per-repeat ratios (the machine's speed drifts; ratios within
one repeat are what to trust). Issue 40's target: the analytic shape at most 10× the spheres.

    python benches/shape_cost.py --young-modulus 1e9 --warmup 0.3 --window 0.1 --reps 5
    python benches/shape_cost.py --table default --particles sphere revolution --warmup 0.2 --window 0.05

Results go to ``docs/data/shape_cost_<table>.json``.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time
from pathlib import Path
from typing import Any

from demfem import dem, rigid
from demfem.equivalence import StudyConfig
from demfem.scenes import AccumulationTable

DATA = Path(__file__).resolve().parent.parent / "docs" / "data"
PARTICLES = ("sphere", "clump", "cylinder", "revolution")


def build(particle: str, table: str, young_modulus: float, threads: int) -> Any:
    """The simulation of ``table`` ("reduced" or "default") with ``particle``."""
    if table == "reduced":
        cfg = StudyConfig(young_modulus=young_modulus)
        description = cfg.table(particle).build()
    else:
        description = AccumulationTable(particle=particle, wall_height=0.07,
                                        young_modulus=young_modulus).build()
    if particle == "sphere":
        return dem.from_scene(description, model="hertz_mindlin", threads=threads)
    return rigid.from_scene(description, particle=particle, record_onsets=False, threads=threads)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--table", choices=("reduced", "default"), default="reduced")
    p.add_argument("--particles", nargs="+", default=list(PARTICLES), choices=PARTICLES)
    p.add_argument("--young-modulus", type=float, default=1e9,
                   help="Pa (1e9: the equivalence study's)")
    p.add_argument("--warmup", type=float, default=0.3, help="untimed simulated time, s")
    p.add_argument("--window", type=float, default=0.1, help="timed simulated time per repeat, s")
    p.add_argument("--reps", type=int, default=5)
    p.add_argument("--threads", type=int, default=1,
                   help="threads of the sphere engine and of the bodies of revolution's geometry")
    p.add_argument("--json", default=None)
    a = p.parse_args()
    if "sphere" not in a.particles:
        p.error("the spheres are the reference: include 'sphere' in --particles")
    sims = {}
    for particle in a.particles:
        start = time.perf_counter()
        sim = build(particle, a.table, a.young_modulus, a.threads)
        sim.run_until(a.warmup)
        print(f"{particle}: warm-up {a.warmup} s in {time.perf_counter() - start:.1f} s wall, "
              f"dt {sim.dt:.3e} s", flush=True)
        sims[particle] = sim
    cost: dict[str, list[float]] = {k: [] for k in a.particles}
    order = list(a.particles)
    for rep in range(a.reps):
        t_end = a.warmup + (rep + 1) * a.window
        for particle in order:
            sim = sims[particle]
            start = time.perf_counter()
            sim.run_until(t_end)
            cost[particle].append((time.perf_counter() - start) / a.window)
        order = order[1:] + order[:1]
        line = ", ".join(f"{k} {cost[k][-1]:.3g}" for k in a.particles)
        print(f"repeat {rep + 1}: wall s per simulated s: {line}", flush=True)
    rows = []
    for particle in a.particles:
        ratios = [c / s for c, s in zip(cost[particle], cost["sphere"])]
        sim = sims[particle]
        rows.append({
            "particle": particle,
            "dt_s": float(sim.dt),
            "wall_s_per_sim_s_median": statistics.median(cost[particle]),
            "ratio_median": statistics.median(ratios),
            "ratio_min": min(ratios),
            "ratio_max": max(ratios),
            "bodies": len(sim),
        })
    print("\n| particle | dt (s) | wall s / sim s | cost vs spheres (median, range) |")
    print("|---|---|---|---|")
    for r in rows:
        print(f"| {r['particle']} | {r['dt_s']:.3g} | {r['wall_s_per_sim_s_median']:.3g} | "
              f"**{r['ratio_median']:.3g}×** ({r['ratio_min']:.3g}–{r['ratio_max']:.3g}) |")
    out = Path(a.json) if a.json else DATA / f"shape_cost_{a.table}.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({
        "command": "python benches/shape_cost.py " + " ".join(
            f"--{k.replace('_', '-')} {' '.join(map(str, v)) if isinstance(v, list) else v}"
            for k, v in vars(a).items() if k != "json"),
        "machine": platform.platform(), "cpus": os.cpu_count(),
        "load_average": os.getloadavg(),
        "rows": rows,
        "per_repeat": cost,
    }, indent=2) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
