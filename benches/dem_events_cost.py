"""Cost of the whole-contact event records on the default table (840 spheres, 45 GPa).

The same table with ``record_events`` off and on: it first runs ``--warmup`` s from its start
(the belt packs it into the funnel) and is checkpointed; each repeat restores that state into
both engines and times ``--steps`` steps, alternating which goes first. The ratio is the median
over repeats of time with events / time without. Results go to ``docs/data/dem_events_cost.json``.

    python benches/dem_events_cost.py --steps 20000 --reps 7 --threads 1
"""
from __future__ import annotations

import argparse
import json
import platform
import statistics
import tempfile
import time
from pathlib import Path

from demfem import dem
from demfem.scenes import AccumulationTable

OUT = Path(__file__).resolve().parent.parent / "docs" / "data" / "dem_events_cost.json"


def timed(description, state: Path, steps: int, threads: int, events: bool) -> tuple[float, int]:
    """Seconds for ``steps`` steps from ``state``, and the events logged."""
    sim = dem.from_scene(description, threads=threads, record_events=events)
    sim.load_checkpoint(state)
    sim.step(1)  # the lists after the restore, outside the timing
    t0 = time.perf_counter()
    sim.step(steps)
    elapsed = time.perf_counter() - t0
    return elapsed, len(sim.events()["time"])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--steps", type=int, default=20000)
    p.add_argument("--warmup", type=float, default=0.2,
                   help="simulated time before the timing, s (packs the table; 0.2)")
    p.add_argument("--reps", type=int, default=5)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--json", default=str(OUT))
    a = p.parse_args()
    description = AccumulationTable().build()
    state = Path(tempfile.mkdtemp(prefix="dem_events_cost_")) / "warm.ck"
    sim = dem.from_scene(description, threads=a.threads)
    dem.run(sim, a.warmup)
    sim.save_checkpoint(state)
    rows: dict[str, list[float]] = {"off": [], "on": []}
    logged = 0
    for r in range(a.reps):
        for name in (("off", "on") if r % 2 == 0 else ("on", "off")):
            t, n = timed(description, state, a.steps, a.threads, name == "on")
            rows[name].append(t)
            logged = max(logged, n)
        print(f"repeat {r}: off {rows['off'][-1]:.3f} s, on {rows['on'][-1]:.3f} s")
    ratios = [on / off for on, off in zip(rows["on"], rows["off"])]
    result = {
        "scene": "default accumulation table, 840 spheres, E = 45 GPa, hertz_reissner_mindlin",
        "steps": a.steps, "warmup": a.warmup, "reps": a.reps, "threads": a.threads,
        "off_s": rows["off"], "on_s": rows["on"], "events_logged": logged,
        "ratio_median": statistics.median(ratios), "ratio_min": min(ratios),
        "ratio_max": max(ratios),
        "machine": f"{platform.machine()}, {platform.python_implementation()} "
                   f"{platform.python_version()}",
        "command": f"python benches/dem_events_cost.py --steps {a.steps} --warmup {a.warmup:g} "
                   f"--reps {a.reps} --threads {a.threads}",
    }
    print(f"events on / off: median {result['ratio_median']:.3f} (min {result['ratio_min']:.3f},"
          f" max {result['ratio_max']:.3f}) over {a.reps} repeats; {logged} events logged")
    if a.json:
        Path(a.json).parent.mkdir(parents=True, exist_ok=True)
        Path(a.json).write_text(json.dumps(result, indent=1) + "\n")
        print(f"wrote {a.json}")


if __name__ == "__main__":
    main()
