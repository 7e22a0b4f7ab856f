#!/usr/bin/env python3
"""What a step of the seven-cartridge cluster costs: the max case with springs (the issue's
benchmark scene), built once per mesh, then stepped --steps steps --reps times from its
start; medians of the wall time per step, and the 3 ms run they imply.

Run: ``python benches/cluster_step_cost.py`` (≈ 3 min on 2 cores); ``--steps``, ``--reps``,
``--meshes tet1,tet2,shell``. Writes ``docs/data/cluster_step_cost.json``. The whole 3 ms
run (``demfem cluster --case max --springs``) is the measurement the target names; this
script is the quick, repeatable part of it (the first steps hold the first impact's
contacts, so they cost about what the rest does).
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from pathlib import Path

from demfem.io.atomic import write_text_atomic
from demfem.scenes import CartridgeCluster


def mesh_case(name: str) -> CartridgeCluster:
    if name == "shell":
        return CartridgeCluster.load_case("max", springs=True, elements="shell")
    if name.startswith("tet") and name[3:].isdigit():
        return CartridgeCluster.load_case("max", springs=True, elements="tet",
                                          layers=int(name[3:]))
    raise SystemExit(f"unknown mesh {name!r}: tet1..tet4 or shell")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--meshes", default="tet1,tet2,shell")
    ap.add_argument("--out", default=str(Path(__file__).resolve().parents[1]
                                         / "docs" / "data" / "cluster_step_cost.json"))
    a = ap.parse_args()
    rows = []
    for name in a.meshes.split(","):
        cluster = mesh_case(name)
        per_step = []
        for _ in range(a.reps):
            model = cluster.build_model()
            dt = model.dt_step
            t0 = time.perf_counter()
            model.run(a.steps * dt)
            per_step.append((time.perf_counter() - t0) / a.steps)
        med = statistics.median(per_step)
        steps_3ms = int(round(3e-3 / dt))
        rows.append({"mesh": name, "elements": int(model.mesh.n_elements), "dt_s": dt,
                     "ms_per_step_median": 1e3 * med,
                     "ms_per_step_all": [1e3 * x for x in per_step],
                     "steps_3ms": steps_3ms, "run_3ms_min": med * steps_3ms / 60.0})
        print(f"{name}: {model.mesh.n_elements} elements, dt {dt:.3g} s, "
              f"{1e3 * med:.2f} ms/step (median of {a.reps}; "
              f"{min(per_step) * 1e3:.2f}-{max(per_step) * 1e3:.2f}), "
              f"3 ms = {steps_3ms} steps = {med * steps_3ms / 60.0:.1f} min", flush=True)
    write_text_atomic(Path(a.out), json.dumps(
        {"steps": a.steps, "reps": a.reps, "threads": os.cpu_count(), "rows": rows},
        indent=1) + "\n")
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
