#!/usr/bin/env python3
"""What contact costs in the explicit FEM: the two-cartridge collision (default cartridges,
crossed, 0.2 m/s, E = 45 GPa, 2 layers through the wall) stepped N times at the same step
with and without contact, on the same mesh; medians of --reps runs each, alternating.

The issue's target: contact at most 30 % of the element work. Prints the per-step times,
the ratio, the active contacts and the broad-phase rebuilds, and writes
``docs/data/fem_contact_cost.json``.

Run: ``python benches/fem_contact_cost.py`` (≈ 1 min); ``--steps``, ``--reps``, ``--layers``.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from pathlib import Path

import numpy as np

from demfem import _core
from demfem.cartridge import Cartridge
from demfem.fem import Body, FemModel, cartridge_tet_mesh, rotation_about
from demfem.io.atomic import write_text_atomic


def build(layers: int):
    c = Cartridge()
    m = cartridge_tet_mesh(c, layers=layers)
    za, ra = 0.5 * c.body_length, 0.5 * c.body_outer_diameter
    a = m.placed(None, (0.0, 0.0, -za))
    b = m.placed(None, (0.0, 0.0, -za)).placed(rotation_about((1, 0, 0), 90.0),
                                                (2 * ra + 1e-7, 0.0, 0.0))
    return c, [Body(a, name="a"), Body(b, velocity=(-0.2, 0.0, 0.0), name="b")]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=1500)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--layers", type=int, default=2)
    ap.add_argument("--out", default=str(Path(__file__).resolve().parents[1] / "docs/data/fem_contact_cost.json"))
    args = ap.parse_args()
    c, bodies = build(args.layers)
    with_c, without, info = [], [], {}
    for _ in range(args.reps):
        model = FemModel(bodies, c.material)
        dt = model.dt_step
        t0 = time.perf_counter()
        model.solver.run(args.steps, chunk=args.steps)
        with_c.append((time.perf_counter() - t0) / args.steps)
        info = model.solver.contact_info() or {}
        mesh = model.mesh
        s = _core.FemTetSolver(mesh.nodes, mesh.tets, c.material.E, c.material.nu,
                               c.material.density, dt=dt, energy_interval=0)
        vel = np.zeros((mesh.n_nodes, 3))
        vel[model.body_nodes(1)] = (-0.2, 0.0, 0.0)
        s.set_initial_velocity(vel)
        t0 = time.perf_counter()
        s.run(args.steps, chunk=args.steps)
        without.append((time.perf_counter() - t0) / args.steps)
    tw, tn = statistics.median(with_c), statistics.median(without)
    share = (tw - tn) / tn
    res = {"elements": int(model.mesh.n_elements), "steps": args.steps, "dt_s": dt,
           "step_with_contact_s": tw, "step_without_contact_s": tn,
           "contact_over_element_work": share, "active_contacts_at_end": info.get("active_contacts"),
           "broad_phase_builds": info.get("broad_phase_builds"),
           "surface_nodes": info.get("surface_nodes"), "threads": os.cpu_count(),
           "date": time.strftime("%Y-%m-%d")}
    print(f"{res['elements']} tets, {args.steps} steps of {dt:.3e} s: with contact "
          f"{tw * 1e3:.3f} ms/step, without {tn * 1e3:.3f} ms/step -> contact = "
          f"{100 * share:.1f} % of the element work (target <= 30 %); "
          f"{res['active_contacts_at_end']} contacts active, {res['broad_phase_builds']} broad-phase builds")
    write_text_atomic(args.out, json.dumps(res, indent=1) + "\n")


if __name__ == "__main__":
    main()
