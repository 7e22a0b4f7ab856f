"""Fig. 7 check: how fast can the belt drive a sphere that does not roll?

The equivalent sphere rolls on the belt: a free sphere dragged by friction ends rolling
without slip at 2/7 V_belt (angular momentum about the contact point is conserved), 28.6 mm/s
at V_belt = 0.1 m/s. An upright cartridge stands on its flat end and cannot roll: it is
dragged towards V_belt itself. This script runs the Fig. 6/7 set-up (A = 2 cm, T = 2 s,
V_belt = 0.1 m/s, the studies' geometry and Hertz-Reissner-Mindlin law) with the effect
"rotation" removed, so friction drags each sphere like a sliding block, and reports the
rectangular-centre speed per window next to the all-sphere mean speed (mm/s).

Writes `<out>/fig7_rotation_check.json` and `.png`.

Run:  python examples/fig7_rotation_check.py [--E 1e7] [--duration 20] [--out DIR]
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
from pathlib import Path

import numpy as np

from demfem.analysis import tag_mask
from demfem.dem import from_scene
from demfem.io import savefig_atomic, write_json_atomic
from demfem.scenes.table import Tag
from demfem.studies.figures import FIG6_SETUP, SWEEP_GEOMETRY, speed_windows
from demfem.dem.table_run import table_from_params


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--E", "--young-modulus", dest="E", type=float, default=1e7,
                   help="Young's modulus, Pa (1e7)")
    p.add_argument("--duration", type=float, default=20.0, help="simulated time, s (20)")
    p.add_argument("--sample-interval", type=float, default=0.05, help="s (0.05)")
    p.add_argument("--window", type=float, default=5.0, help="averaging window, s (5)")
    p.add_argument("--out", default="demfem_out/studies", help="output folder")
    a = p.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    table = table_from_params({**SWEEP_GEOMETRY, **FIG6_SETUP, "young_modulus": a.E})
    scene = table.build()
    scene = dataclasses.replace(scene, effects=tuple(e for e in scene.effects
                                                     if e != "rotation"))
    sim = from_scene(scene, threads=1)
    rect = tag_mask(scene.tags, Tag.RECTANGULAR_CENTRE)
    n = int(math.floor(a.duration / a.sample_interval + 1e-9))
    times, rect_speed, mean_speed = [], [], []
    for k in range(n + 1):
        sim.run_until(k * a.sample_interval)
        v = np.linalg.norm(np.asarray(sim.velocities()), axis=1)
        alive = np.asarray(sim.alive(), bool)
        times.append(sim.time)
        rect_speed.append(float(v[rect & alive].mean()) if (rect & alive).any() else math.nan)
        mean_speed.append(float(v[alive].mean()))
    t, s_rect, s_all = np.array(times), np.array(rect_speed), np.array(mean_speed)
    v_belt = FIG6_SETUP["belt_velocity"]
    found = {"E_Pa": a.E, "duration_s": float(t[-1]), "effects": list(scene.effects),
             "belt_velocity_mm_s": 1e3 * v_belt,
             "free_rolling_mm_s": 1e3 * 2.0 / 7.0 * v_belt,
             "rectangular_centre": speed_windows(t, s_rect, a.window),
             "all_spheres_mean": speed_windows(t, s_all, a.window),
             "removed": int(len(scene.radii) - np.count_nonzero(sim.alive()))}
    write_json_atomic(out / "fig7_rotation_check.json", found)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(t, 1e3 * s_rect, lw=0.7, label="rectangular centre")
    ax.plot(t, 1e3 * s_all, lw=0.9, label="mean of all spheres")
    ax.axhline(1e3 * v_belt, color="k", ls="--", lw=0.8, label="V_belt")
    ax.axhline(1e3 * 2 / 7 * v_belt, color="grey", ls=":", lw=0.8, label="2/7 V_belt")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("speed (mm/s)")
    ax.set_title(f"Fig. 7 set-up without rotation (sliding spheres), E = {a.E:.3g} Pa",
                 fontsize="medium")
    ax.legend(fontsize="small")
    fig.tight_layout()
    savefig_atomic(fig, out / "fig7_rotation_check.png", dpi=120)
    plt.close(fig)
    print(json.dumps({k: found[k] for k in ("rectangular_centre", "all_spheres_mean",
                                            "removed")}, indent=None))


if __name__ == "__main__":
    main()
