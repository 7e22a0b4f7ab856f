"""Cycles and instructions per particle-step of two or more builds of ``examples/dem_instr``,
alternated round by round, so the machine's drift hits every build alike.

Each round runs every build twice from the same checkpoint (``--short`` and ``--long`` steps)
under ``perf stat -e cycles:u,instructions:u,L1-dcache-load-misses:u``; the difference,
divided by 840 × (long − short), is the cost of one particle-step without the setup. Counts are
of the process itself, so the VM's steal time does not enter them; cache contention from other
tenants still does, hence the alternation and the medians.

    cargo build --release --example dem_instr && cp target/release/examples/dem_instr /tmp/new
    (build the other revision the same way into /tmp/old)
    python benches/dem_cycles_ab.py /tmp/old /tmp/new --state /tmp/packed.ck --reps 7

The checkpoint is made by the first ``dem_instr <path> 0`` run (60 000 settling steps) if it
does not exist; ``benches/.states/demfem_funnel_E4.5e+10.ck`` (the anchors' recipe, made by
``dem_anchor_ratio.py --state packed``) works too. Needs Linux ``perf``.
"""
from __future__ import annotations

import argparse
import statistics
import subprocess

EVENTS = "cycles:u,instructions:u,L1-dcache-load-misses:u"


def counts(binary: str, state: str, steps: int) -> dict[str, int]:
    r = subprocess.run(["perf", "stat", "-e", EVENTS, "-x,", binary, state, str(steps)],
                       capture_output=True, text=True, check=True)
    out = {}
    for line in r.stderr.splitlines():
        f = line.split(",")
        if len(f) > 2 and f[0].isdigit():
            out[f[2].split(":")[0]] = int(f[0])
    return out


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("binaries", nargs="+", help="dem_instr builds to compare")
    p.add_argument("--state", default="/tmp/packed.ck", help="checkpoint of the packed table")
    p.add_argument("--reps", type=int, default=7)
    p.add_argument("--short", type=int, default=3000)
    p.add_argument("--long", type=int, default=9000)
    a = p.parse_args()
    per = 840 * (a.long - a.short)
    res: dict[str, list[dict[str, float]]] = {b: [] for b in a.binaries}
    for _ in range(a.reps):
        for b in a.binaries:
            lo, hi = counts(b, a.state, a.short), counts(b, a.state, a.long)
            res[b].append({k: (hi[k] - lo[k]) / per for k in lo})
    for b, runs in res.items():
        med = {k: statistics.median(r[k] for r in runs) for k in runs[0]}
        print(f"{b}: " + ", ".join(f"{k} {v:.1f}" for k, v in med.items())
              + " per particle-step (medians); cycles by round: " + " ".join(f"{r['cycles']:.0f}" for r in runs))


if __name__ == "__main__":
    main()
