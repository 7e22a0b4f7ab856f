"""How evenly the engine's threads share the default table (the studies' and `demfem run`'s
scene, `demfem.scenes.AccumulationTable()` at 45 GPa, Hertz–Reissner–Mindlin).

For each start time the table runs from its start state to that time, then `--span` s more
with the per-thread phase clock on, and prints each thread's force and particle phase time
(s), the wall time of the span and where the threads' blocks begin (`block_cuts()`). The
results of the run never depend on the cuts; only the wall time does.

    python benches/table_balance.py --at 0.1 0.6 0.9 --span 0.03 --threads 2
"""
from __future__ import annotations

import argparse
import time

from demfem.dem import from_scene
from demfem.scenes import AccumulationTable


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--at", type=float, nargs="+", default=[0.1, 0.6, 0.9],
                    help="simulated times (s) at which each timed span starts")
    ap.add_argument("--span", type=float, default=0.03, help="simulated time timed, s")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--E", type=float, default=45e9, help="Young's modulus, Pa")
    args = ap.parse_args()
    for start in args.at:
        sim = from_scene(AccumulationTable(young_modulus=args.E).build(),
                         model="hertz_reissner_mindlin", threads=args.threads, record_onsets=True)
        sim.run_until(start)
        sim.set_phase_timing(True)
        steps, t0 = sim.steps, time.perf_counter()
        sim.run_until(start + args.span)
        wall = time.perf_counter() - t0
        per_thread = ", ".join(f"thread {k}: {f:.3f} + {p:.3f} s" for k, (f, p) in enumerate(sim.phase_times()))
        print(f"from {start:g} s, {sim.steps - steps} steps: wall {wall:.2f} s; "
              f"force + particle phase {per_thread}; blocks begin at {sim.block_cuts()}")


if __name__ == "__main__":
    main()
