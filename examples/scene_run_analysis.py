"""Scene → run → analysis from Python: a short DEM run of the accumulation table and the
numbers the studies read from it, with their units.

The scene is the built-in table (``demfem.scenes.AccumulationTable``: 45 GPa glass,
Hertz–Reissner–Mindlin, gate amplitude 2 cm, period 2 s) with two changes, fewer cartridges
(400 instead of 840) and a faster belt (0.3 instead of 0.2 m/s), so that the run takes seconds;
pass a scene file instead (``python examples/scene_run_analysis.py examples/table_default.toml``:
the paper's table, about twice as long). ``demfem.dem.table_run.run_table`` runs it for
``DURATION`` s on two threads and records a frame every 10 ms; ``demfem.analysis`` turns the
record into the first-line force, the coordination, the tagged spheres' speeds and the impact
speeds at every contact onset.

Run from the repository root:  python examples/scene_run_analysis.py [SCENE.toml]

What it prints (2-core machine, shared; abridged):

    scene: 400 spheres of 16.17 mm, E = 4.5e+10 Pa, belt 0.3 m/s, gate 2 cm / 2 s
    run: 0.3 s in 190950 steps of 1.571 us (7.4 s of wall time), 4 spheres out through the opening
    statistics from t = 0.1 s on:
      first-line force per sphere: mean 0.0916 N, 95 % 0.205 N, peak 0.466 N
      mean coordination: 1.67 contacts per sphere
      mean speed: first line 21.7 mm/s, triangular centre 6.42 mm/s, rectangular centre 22.7 mm/s
      contact onsets: 33314 (1.67e+05 per s); normal impact speed median / 90 % / 99 % 1.75 / 9.4 / 42 mm/s
"""
from __future__ import annotations

import sys

import numpy as np

from demfem.analysis import force_statistics, mean_coordination, onset_quantiles, tagged_speed
from demfem.dem.table_run import run_table
from demfem.scenes import AccumulationTable, Tag

DURATION = 0.3      # s of simulated time
DISCARD = 0.1       # s: statistics from here on (the start packing closes up first)


def main(scene_file: str | None = None) -> dict[str, float]:
    # 1. scene: the built-in table, smaller and on a faster belt (or the user's file)
    if scene_file:
        table = AccumulationTable.from_toml(scene_file)
    else:
        table = AccumulationTable(n_spheres=400, belt_velocity=0.3)
    print(f"scene: {table.n_spheres} spheres of {1e3 * table.sphere_diameter:.2f} mm, "
          f"E = {table.young_modulus:g} Pa, belt {table.belt_velocity:g} m/s, "
          f"gate {1e2 * table.gate_amplitude:g} cm / {table.gate_period:g} s")

    # 2. run: the DEM of the table, a frame every 10 ms
    run = run_table(table, duration=DURATION, sample_interval=0.01, threads=2)
    n_out = int(np.isfinite(run.removal_times).sum())
    print(f"run: {run.times[-1]:.3g} s in {run.info['steps']} steps of "
          f"{1e6 * run.info['dt']:.4g} us ({run.info['wall_time_s']:.1f} s of wall time), "
          f"{n_out} spheres out through the opening")

    # 3. analysis, on the frames after DISCARD
    keep = run.times >= DISCARD
    force = force_statistics(run.first_line_force()[keep], 0.95)           # N per sphere
    z_frames = np.asarray(mean_coordination(run.coordination, present=run.present))
    z = float(np.nanmean(z_frames[keep]))                               # contacts per sphere
    speeds = {name: 1e3 * float(np.nanmean(tagged_speed(run.velocities, run.tags, tag)[keep]))
              for name, tag in (("first line", Tag.FIRST_LINE),
                                ("triangular centre", Tag.TRIANGULAR_CENTRE),
                                ("rectangular centre", Tag.RECTANGULAR_CENTRE))}  # mm/s
    onsets = run.onsets[run.onsets["time"] >= DISCARD]
    v50, v90, v99 = 1e3 * onset_quantiles(onsets, "normal_speed", (0.5, 0.9, 0.99))  # mm/s
    print(f"statistics from t = {DISCARD:g} s on:")
    print(f"  first-line force per sphere: mean {force['mean']:.3g} N, 95 % "
          f"{force['quantile']:.3g} N, peak {force['peak']:.3g} N")
    print(f"  mean coordination: {z:.3g} contacts per sphere")
    print("  mean speed: " + ", ".join(f"{k} {v:.3g} mm/s" for k, v in speeds.items()))
    print(f"  contact onsets: {len(onsets)} ({len(onsets) / (DURATION - DISCARD):.3g} per s); "
          f"normal impact speed median / 90 % / 99 % {v50:.3g} / {v90:.3g} / {v99:.3g} mm/s")
    return {"first_line_force_mean_N": force["mean"], "mean_coordination": z,
            "impact_speed_median_mm_per_s": float(v50)}


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
