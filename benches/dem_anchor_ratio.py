"""demfem's speed as a ratio to Yade and LIGGGHTS on the anchor table, measured in one run.

The anchor scripts in ``shared/anchors/dem`` (``run_liggghts.py``, ``yade_bench.py``) run the
identical scene (840 glass spheres of 16 mm, E = 45 GPa, Hertz–Mindlin, μ 0.2, e 0.5, belt
0.2 m/s, funnel, dt = 0.5 r √(ρ/E)); this script runs them and demfem back to back, from the
``start`` state (square packing, ``--settle`` untimed steps, then ``--steps`` timed steps), and
prints particle-steps per second and demfem's ratio to each. Because the codes run in the same
session, the ratio is robust to the load of a shared machine; the absolute numbers are not.

    python benches/dem_anchor_ratio.py --steps 20000 --settle 2000 [--threads 1 2] [--skip-yade]

Needs the Debian packages yade and liggghts for the anchors, and demfem built
(``maturin develop --release``).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

ANCHORS = os.environ.get("DEMFEM_ANCHORS", os.path.join(os.path.dirname(__file__), "..", "..", "shared", "anchors", "dem"))


def run_anchor(cmd: list[str], cwd: str) -> dict:
    out = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, check=False)
    for line in out.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[len("RESULT "):])
    raise RuntimeError(f"{cmd[0]} gave no RESULT line:\n{out.stdout[-2000:]}\n{out.stderr[-2000:]}")


def run_demfem(e: float, steps: int, settle: int, threads: int, start: str) -> dict:
    from demfem.dem import DemSimulation

    sim = DemSimulation.anchor_table(e, start=start, threads=threads, initial_vx=0.2 if start == "packed" else 0.0)
    sim.step(settle)
    t0 = time.perf_counter()
    sim.step(steps, chunk=steps)
    wall = time.perf_counter() - t0
    return {
        "code": "demfem",
        "threads": threads,
        "wall_s": wall,
        "particle_steps_per_s": len(sim) * steps / wall,
        "Z_sphere_sphere": float(sim.coordination().mean()),
        "dt": sim.dt,
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--E", type=float, default=45e9)
    p.add_argument("--steps", type=int, default=20000)
    p.add_argument("--settle", type=int, default=2000)
    p.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    p.add_argument("--skip-yade", action="store_true")
    p.add_argument("--skip-liggghts", action="store_true")
    a = p.parse_args()
    anchors = os.path.abspath(ANCHORS)
    rows = []
    for t in a.threads:
        rows.append(run_demfem(a.E, a.steps, a.settle, t, "square"))
    with tempfile.TemporaryDirectory() as tmp:
        if not a.skip_liggghts:
            r = run_anchor([sys.executable, os.path.join(anchors, "run_liggghts.py"), "--E", str(a.E), "--steps", str(a.steps),
                            "--settle", str(a.settle), "--np", "1", "--dir", os.path.join(tmp, "lig")], tmp)
            r["code"], r["threads"] = "liggghts", 1
            rows.append(r)
        if not a.skip_yade:
            r = run_anchor(["yade", "-n", "-x", "-j1", os.path.join(anchors, "yade_bench.py"), "--E", str(a.E),
                            "--steps", str(a.steps), "--settle", str(a.settle)], tmp)
            r["code"], r["threads"] = "yade", 1
            rows.append(r)
    ours = {r["threads"]: r["particle_steps_per_s"] for r in rows if r["code"] == "demfem"}
    print(f"start state, E = {a.E:g} Pa, {a.steps} timed steps after {a.settle} settle steps")
    print(f"{'code':10s} {'threads':>7s} {'particle-steps/s':>17s} {'wall s':>8s}")
    for r in rows:
        print(f"{r['code']:10s} {r['threads']:>7} {r['particle_steps_per_s']:17.3e} {r['wall_s']:8.2f}")
    for r in rows:
        if r["code"] != "demfem":
            for t, v in sorted(ours.items()):
                print(f"demfem {t} thread(s) / {r['code']} 1: {v / r['particle_steps_per_s']:.2f}x")


if __name__ == "__main__":
    main()
