"""Cost of mesh walls against analytic walls on the default table (840 spheres, 45 GPa).

The same table twice: with its analytic walls (planes and polygons) and with the fixed
vertical walls as one mesh of about 10 000 triangles over the same geometry
(:func:`demfem.scenes.mesh_table.table_walls_as_mesh`; the belt plane and the gate stay
analytic in both). Each repeat builds both simulations, runs ``--warmup`` steps, then times
``--steps`` steps, alternating which goes first; the ratio is the median over repeats of
mesh time / analytic time (target: at most 1.5). Results go to
``docs/data/mesh_walls_cost.json``.

    python benches/mesh_walls_cost.py --steps 20000 --reps 5 --threads 1
"""
from __future__ import annotations

import argparse
import json
import platform
import statistics
import time
from pathlib import Path

from demfem import dem
from demfem.scenes import AccumulationTable
from demfem.scenes.mesh_table import table_walls_as_mesh

OUT = Path(__file__).resolve().parent.parent / "docs" / "data" / "mesh_walls_cost.json"


def timed(description, warmup: int, steps: int, threads: int) -> tuple[float, int]:
    """Seconds for ``steps`` steps after ``warmup`` steps, and the wall slots at the end."""
    sim = dem.from_scene(description, threads=threads)
    sim.step(warmup)
    t0 = time.perf_counter()
    sim.step(steps)
    return time.perf_counter() - t0, int(sim.wall_contacts().sum())


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--steps", type=int, default=20000)
    p.add_argument("--warmup", type=int, default=2000)
    p.add_argument("--reps", type=int, default=5)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--triangles", type=int, default=10000)
    p.add_argument("--json", default=str(OUT))
    a = p.parse_args()
    table = AccumulationTable()
    analytic = table.build()
    mesh = table_walls_as_mesh(table, triangles=a.triangles)
    n_tri = int(len(mesh.walls[1]["triangles"]))
    rows: dict[str, list[float]] = {"analytic": [], "mesh": []}
    contacts = {}
    for r in range(a.reps):
        order = ("analytic", "mesh") if r % 2 == 0 else ("mesh", "analytic")
        for name in order:
            t, c = timed(analytic if name == "analytic" else mesh, a.warmup, a.steps,
                         a.threads)
            rows[name].append(t)
            contacts[name] = c
        print(f"repeat {r}: analytic {rows['analytic'][-1]:.3f} s, mesh {rows['mesh'][-1]:.3f} s")
    ratios = [m / s for m, s in zip(rows["mesh"], rows["analytic"])]
    result = {
        "scene": "default accumulation table, 840 spheres, E = 45 GPa, hertz_reissner_mindlin",
        "mesh_triangles": n_tri, "steps": a.steps, "warmup": a.warmup, "reps": a.reps,
        "threads": a.threads,
        "analytic_s": rows["analytic"], "mesh_s": rows["mesh"],
        "analytic_particle_steps_per_s": 840 * a.steps / statistics.median(rows["analytic"]),
        "mesh_particle_steps_per_s": 840 * a.steps / statistics.median(rows["mesh"]),
        "ratio_median": statistics.median(ratios), "ratio_min": min(ratios),
        "ratio_max": max(ratios), "target": 1.5,
        "wall_contacts_at_end": contacts,
        "machine": f"{platform.machine()}, {platform.python_implementation()} "
                   f"{platform.python_version()}",
        "command": f"python benches/mesh_walls_cost.py --steps {a.steps} --warmup {a.warmup} "
                   f"--reps {a.reps} --threads {a.threads}",
    }
    print(f"mesh ({n_tri} triangles) / analytic: median {result['ratio_median']:.3f} "
          f"(min {result['ratio_min']:.3f}, max {result['ratio_max']:.3f}) over {a.reps} "
          f"repeats; target <= 1.5")
    if a.json:
        Path(a.json).parent.mkdir(parents=True, exist_ok=True)
        Path(a.json).write_text(json.dumps(result, indent=1) + "\n")
        print(f"wrote {a.json}")


if __name__ == "__main__":
    main()
