"""Cost of mesh walls against analytic walls on the default table (840 spheres, 45 GPa).

The same table twice: with its analytic walls (planes and polygons) and with the fixed
vertical walls as one mesh of about 10 000 triangles over the same geometry
(:func:`demfem.scenes.mesh_table.table_walls_as_mesh`; the belt plane and the gate stay
analytic in both). Each table first runs ``--warmup`` s from its start (the belt packs it into
the funnel: the jammed state the table spends its time in) and is checkpointed; each repeat
restores both states and times ``--steps`` steps, alternating which goes first; the ratio is the median over repeats of
mesh time / analytic time (target: at most 1.5). Results go to
``docs/data/mesh_walls_cost.json``.

    python benches/mesh_walls_cost.py --steps 20000 --reps 7 --threads 1
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


def warm_state(description, warmup: float, threads: int, path: Path) -> None:
    """Run the table for ``warmup`` s from its start (the belt packs it into the funnel) and
    checkpoint that state to ``path``."""
    sim = dem.from_scene(description, threads=threads)
    dem.run(sim, warmup)
    sim.save_checkpoint(path)


def timed(description, state: Path, steps: int, threads: int) -> tuple[float, int]:
    """Seconds for ``steps`` steps from the checkpointed ``state``, and the wall contacts at
    the end."""
    sim = dem.from_scene(description, threads=threads)
    sim.load_checkpoint(state)
    sim.step(1)  # the lists after the restore, outside the timing
    t0 = time.perf_counter()
    sim.step(steps)
    return time.perf_counter() - t0, int(sim.wall_contacts().sum())


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--steps", type=int, default=20000)
    p.add_argument("--warmup", type=float, default=0.2,
                   help="simulated time before the timing, s (packs the table; 0.2)")
    p.add_argument("--reps", type=int, default=5)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--triangles", type=int, default=10000)
    p.add_argument("--json", default=str(OUT))
    a = p.parse_args()
    table = AccumulationTable()
    analytic = table.build()
    mesh = table_walls_as_mesh(table, triangles=a.triangles)
    n_tri = int(len(mesh.walls[1]["triangles"]))
    import tempfile

    scratch = Path(tempfile.mkdtemp(prefix="mesh_walls_cost_"))
    states = {"analytic": scratch / "analytic.ck", "mesh": scratch / "mesh.ck"}
    for name, d in (("analytic", analytic), ("mesh", mesh)):
        warm_state(d, a.warmup, a.threads, states[name])
    rows: dict[str, list[float]] = {"analytic": [], "mesh": []}
    contacts = {}
    for r in range(a.reps):
        order = ("analytic", "mesh") if r % 2 == 0 else ("mesh", "analytic")
        for name in order:
            t, c = timed(analytic if name == "analytic" else mesh, states[name], a.steps,
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
        "command": f"python benches/mesh_walls_cost.py --steps {a.steps} --warmup {a.warmup:g} "
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
