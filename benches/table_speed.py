"""Particle-steps per second of the default accumulation table (the studies' scene,
`demfem.scenes.AccumulationTable()` at a given E, built by `demfem.dem.from_scene` with the
studies' contact law) on one engine thread.

The table first runs `--settle-time` s of simulated time from its start state (the spheres,
started with 1 % gaps, close up and pile against the funnel: mean coordination ≈ 2.5 at
0.5 s), then `--steps` more steps are timed. Wall-clock and process CPU time
are both reported: on a shared machine the CPU-time rate is what a free core would give.

Run (after `maturin develop --release`):

    python benches/table_speed.py --E 1e7 45e9
    python benches/table_speed.py --E 1e7 45e9 --model hertz_mindlin   # the same without shells
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from demfem.dem import CONTACT_MODELS, from_scene
from demfem.scenes import AccumulationTable


def measure(e: float, model: str, settle_time: float, steps: int) -> dict[str, float]:
    """Time `steps` steps of the default table at Young's modulus `e` (Pa) after
    `settle_time` s of simulated time."""
    sim = from_scene(AccumulationTable(young_modulus=e).build(), model=model, threads=1)
    sim.run_until(settle_time)
    n = int(np.count_nonzero(sim.alive()))
    wall0, cpu0 = time.perf_counter(), time.process_time()
    sim.step(steps)
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    z = np.asarray(sim.coordination(), float)
    w = np.asarray(sim.wall_contacts(), float)
    return {"E": e, "dt": sim.dt, "particles": n, "wall_rate": n * steps / wall,
            "cpu_rate": n * steps / cpu, "coordination": float(z.mean()),
            "wall_contacts": float(w.mean())}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--E", type=float, nargs="+", default=[1e7, 45e9], help="Young's moduli, Pa")
    p.add_argument("--model", default="hertz_reissner_mindlin", choices=CONTACT_MODELS)
    p.add_argument("--settle-time", type=float, default=0.5, help="untimed simulated time first, s")
    p.add_argument("--steps", type=int, default=20000, help="timed steps")
    a = p.parse_args()
    for e in a.E:
        r = measure(e, a.model, a.settle_time, a.steps)
        print(f"E = {r['E']:.3g} Pa ({a.model}, dt = {r['dt']:.3g} s, {r['particles']} spheres, "
              f"mean coordination {r['coordination']:.2f}, wall contacts {r['wall_contacts']:.2f}): "
              f"{r['wall_rate']:.3e} particle-steps/s wall, {r['cpu_rate']:.3e} per CPU-s",
              flush=True)


if __name__ == "__main__":
    main()
