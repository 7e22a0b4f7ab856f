"""Cost of the stress stage: demfem.stress.contact_stresses on N contact events.

Forces drawn like the table's collisions (normal force log-uniform in [0.1, 50] N, tangential
force up to half of it). For each geometry the first call in a fresh process ("cold": the
dimensionless tables are built then, once per process) and the median of ``--reps`` further
calls ("warm") are timed; the import of demfem is not counted. Prints a table; ``--json``
writes it.

    python benches/stress_cost.py --events 1000000 --reps 3
"""
from __future__ import annotations

import argparse
import json
import platform
import statistics
import subprocess
import sys
import time

CASES = {
    "crossed 90 deg": "dict()",
    "crossed 45 deg": "dict(crossing_angle_deg=45.0)",
    "wall, line contact 40 mm": "dict(geometry='wall', contact_length=0.04)",
    "crossed 90 deg, flaw depth 20 um": "dict(flaw_depth=20e-6)",
    "crossed 90 deg at the rim": "dict(location='rim')",
    "crossed 90 deg at the shoulder": "dict(location='shoulder')",
}

_CHILD = """
import json, sys, time
import numpy as np
from demfem.stress import contact_stresses
n, reps, kw = int(sys.argv[1]), int(sys.argv[2]), eval(sys.argv[3])
rng = np.random.default_rng(0)
f = np.exp(rng.uniform(np.log(0.1), np.log(50.0), n))
q = f * rng.uniform(0.0, 0.5, n)
t0 = time.perf_counter(); contact_stresses(f, q, **kw); cold = time.perf_counter() - t0
warm = []
for _ in range(reps):
    t0 = time.perf_counter(); contact_stresses(f, q, **kw); warm.append(time.perf_counter() - t0)
print(json.dumps({"cold_s": cold, "warm_s": warm}))
"""


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--events", type=int, default=1_000_000)
    p.add_argument("--reps", type=int, default=3)
    p.add_argument("--json", default=None, help="write the results to this file")
    a = p.parse_args()
    rows = {}
    print(f"{a.events} events; {platform.processor() or platform.machine()}, "
          f"Python {platform.python_version()}")
    print(f"{'case':36s} {'cold s':>8s} {'warm s':>8s} {'warm us/event':>14s}")
    for name, kw in CASES.items():
        out = subprocess.run([sys.executable, "-c", _CHILD, str(a.events), str(a.reps), kw],
                             capture_output=True, text=True, check=True)
        r = json.loads(out.stdout.strip().splitlines()[-1])
        warm = statistics.median(r["warm_s"])
        rows[name] = {"cold_s": r["cold_s"], "warm_s": warm,
                      "warm_us_per_event": 1e6 * warm / a.events}
        print(f"{name:36s} {r['cold_s']:8.2f} {warm:8.2f} {1e6 * warm / a.events:14.2f}")
    if a.json:
        with open(a.json, "w", encoding="utf-8") as fh:
            json.dump({"events": a.events, "reps": a.reps, "cases": rows,
                       "machine": platform.platform(), "time": time.strftime("%Y-%m-%d")},
                      fh, indent=1)


if __name__ == "__main__":
    main()
