"""Wall-clock A/B of two or more builds of `dem_instr` on one packed state, alternating.

For machines without hardware counters (where `dem_cycles_ab.py` cannot read cycles): each
round runs every build for `--steps` steps and once for 0 steps (load and setup only), in
alternating order, and takes particle-steps per second from the difference. Prints each
build's median and, for every build after the first, the median of its per-round ratio to the
first (> 1: faster), which is what to quote on a noisy machine, and the ratio of the best
rounds (a machine whose noise comes in bursts slows some rounds, never speeds one up).

    python benches/dem_wall_ab.py /tmp/old /tmp/new --state benches/.states/demfem_funnel_E4.5e+10.ck \
        --steps 20000 --reps 7 --threads 1
"""
from __future__ import annotations

import argparse
import statistics
import subprocess
import time

PARTICLES = 840


def timed(binary: str, state: str, steps: int, threads: int) -> float:
    """Wall time, s, of one `dem_instr` run."""
    t0 = time.perf_counter()
    subprocess.run([binary, state, str(steps), str(threads)], capture_output=True, check=True)
    return time.perf_counter() - t0


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("binaries", nargs="+", help="builds of examples/dem_instr (first = reference)")
    p.add_argument("--state", required=True, help="checkpoint of the packed table")
    p.add_argument("--steps", type=int, default=20000)
    p.add_argument("--reps", type=int, default=7)
    p.add_argument("--threads", type=int, default=1)
    a = p.parse_args()
    rates: dict[str, list[float]] = {b: [] for b in a.binaries}
    for r in range(a.reps):
        order = a.binaries if r % 2 == 0 else a.binaries[::-1]
        for b in order:
            run = timed(b, a.state, a.steps, a.threads)
            setup = timed(b, a.state, 0, a.threads)
            rates[b].append(PARTICLES * a.steps / max(run - setup, 1e-9))
    first = rates[a.binaries[0]]
    for b in a.binaries:
        print(f"{b}: median {statistics.median(rates[b]):.3e} particle-steps/s  "
              + " ".join(f"{x:.2e}" for x in rates[b]))
    for b in a.binaries[1:]:
        ratio = statistics.median(x / y for x, y in zip(rates[b], first))
        best = max(rates[b]) / max(first)
        print(f"{b} / {a.binaries[0]}: per-round ratio median {ratio:.3f} over {a.reps} rounds, "
              f"best-of ratio {best:.3f}")


if __name__ == "__main__":
    main()
