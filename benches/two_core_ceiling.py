"""What a second core can give on this machine, against what demfem's two threads get.

Each round, on the anchors' packed table (840 spheres, E = 45 GPa) with ``examples/dem_instr``:

1. one 1-thread run alone (its wall-clock rate, particle-steps/s);
2. two independent 1-thread runs at the same time: how much slower each one gets when the
   other core is busy (the machine's "second-core tax": shared caches, memory, the host);
3. one 2-thread run.

The ceiling of a 2-thread run is 2 × (rate alone) / tax, the rate two perfectly independent
halves of the work would reach. The rounds alternate so the machine's drift hits all three
alike; the report gives medians and the per-round ratios.

    cargo build --release --example dem_instr
    python benches/two_core_ceiling.py target/release/examples/dem_instr --state /tmp/packed.ck

The checkpoint is made by the first ``dem_instr <path> 0`` run if it does not exist.
"""
from __future__ import annotations

import argparse
import statistics
import subprocess
import time


def timed(cmds: list[list[str]]) -> float:
    """Wall-clock seconds for the commands started together, until the last one ends."""
    t0 = time.perf_counter()
    procs = [subprocess.Popen(c, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for c in cmds]
    codes = [p.wait() for p in procs]
    if any(codes):
        raise SystemExit(f"dem_instr failed: exit codes {codes}")
    return time.perf_counter() - t0


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("binary", help="a dem_instr build")
    p.add_argument("--state", default="/tmp/packed.ck", help="checkpoint of the packed table")
    p.add_argument("--steps", type=int, default=30000)
    p.add_argument("--reps", type=int, default=7)
    a = p.parse_args()
    one = [a.binary, a.state, str(a.steps), "1"]
    two = [a.binary, a.state, str(a.steps), "2"]
    setup = [a.binary, a.state, "0", "1"]
    timed([setup])  # makes the checkpoint if missing
    work = 840 * a.steps
    alone, tax, threads2, ceiling, eff = [], [], [], [], []
    for _ in range(a.reps):
        s0 = timed([setup])  # loading the state, subtracted from every run
        t1 = timed([one]) - s0
        tp = timed([one, one]) - s0
        t2 = timed([two]) - s0
        r1, r2 = work / t1, work / t2
        alone.append(r1)
        tax.append(tp / t1)
        threads2.append(r2)
        ceiling.append(2 * r1 / tax[-1])
        eff.append(r2 / ceiling[-1])
    med = statistics.median
    print(f"1 thread alone: {med(alone):.3e} particle-steps/s (by round: "
          + " ".join(f"{x:.2e}" for x in alone) + ")")
    print(f"second-core tax (two 1-thread runs at once, slowdown of each): median {med(tax):.2f} "
          "(by round: " + " ".join(f"{x:.2f}" for x in tax) + ")")
    print(f"2-thread ceiling 2 x alone / tax: {med(ceiling):.3e}")
    print(f"2 threads measured: {med(threads2):.3e} (by round: " + " ".join(f"{x:.2e}" for x in threads2) + ")")
    print(f"2 threads / ceiling, per round: median {med(eff):.2f} (" + " ".join(f"{x:.2f}" for x in eff) + ")")


if __name__ == "__main__":
    main()
