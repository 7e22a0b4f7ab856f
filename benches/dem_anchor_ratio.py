"""demfem's speed as a ratio to Yade and LIGGGHTS on the anchor table, measured in one run.

The anchor scripts (``run_liggghts.py``, ``yade_bench.py``, ``bench_all.py``, ``scene.py``) run
the identical scene (840 glass spheres of 16 mm, E = 45 GPa, Hertz–Mindlin, μ 0.2, e 0.5, belt
0.2 m/s, funnel, dt = 0.5 r √(ρ/E)); this script runs them and demfem back to back, from the
``start`` state (square packing, ``--settle`` untimed steps, then ``--steps`` timed steps), and
prints particle-steps per second and demfem's ratio to each. Because the codes run in the same
session, the ratio is robust to the load of a shared machine; the absolute numbers are not.
demfem's side is the same scene built by a benchmark fixture of the engine
(``DemSimulation._anchor_table``), not a public API.

**Where the anchors are.** They are not in this repository: they are the project's shared
anchor folder ``shared/anchors/dem``, delivered beside the repository (``../shared/anchors/dem``
from the repository root, the default of ``--anchors``). Point ``--anchors DIR`` at another
copy; ``--state packed`` needs a writable copy, in which the anchors' packed states are made
once (≈ 40 min) by ``python3 bench_all.py prepare --E 45e9``.

    python benches/dem_anchor_ratio.py --steps 20000 --settle 2000 [--threads 1 2] [--skip-yade]
    python benches/dem_anchor_ratio.py --anchors COPY --state packed --steps 20000 --reps 5 \
        --threads 1 2 --json docs/data/dem_anchor_ratio_packed.json

Needs the Debian packages yade and liggghts for the anchors, and demfem built
(``maturin develop --release``).
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

from demfem.io.atomic import write_text_atomic

# Issue 5's targets for the packed state, and the anchors' speeds on the machine where they
# were set (a 2-core machine; particle-steps/s, one process each)
TARGET_RATE = {1: 1.5e7, 2: 2.5e7}
TARGET_RATIO = {"yade": 15.0, "liggghts": 3.0}
REFERENCE_RATE = {"yade": 1.0e6, "liggghts": 4.4e6}

#: The default anchor folder: ``shared/anchors/dem`` beside the repository (not in it).
DEFAULT_ANCHORS = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                                "shared", "anchors", "dem"))
#: What the script runs from the anchor folder.
ANCHOR_FILES = ("run_liggghts.py", "yade_bench.py", "bench_all.py", "scene.py")


def check_anchors(anchors: str) -> str:
    """The anchor folder as an absolute path; exits with a message naming the path and how to
    get the anchors when it or one of :data:`ANCHOR_FILES` is missing."""
    anchors = os.path.abspath(anchors)
    missing = [f for f in ANCHOR_FILES if not os.path.isfile(os.path.join(anchors, f))]
    if missing:
        where = "does not exist" if not os.path.isdir(anchors) else f"lacks {', '.join(missing)}"
        sys.exit(f"dem_anchor_ratio: the anchor folder {anchors} {where}. The Yade and LIGGGHTS "
                 f"anchor scripts ({', '.join(ANCHOR_FILES)}) are not in this repository: they are "
                 f"the project's shared folder shared/anchors/dem, expected beside the repository "
                 f"at {DEFAULT_ANCHORS}. Copy it there or pass --anchors DIR.")
    return anchors


def run_anchor(cmd: list[str], cwd: str) -> dict:
    out = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, check=False)
    for line in out.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[len("RESULT "):])
    raise RuntimeError(f"{cmd[0]} gave no RESULT line:\n{out.stdout[-2000:]}\n{out.stderr[-2000:]}")


def anchors_module(anchors: str):
    """The anchors' ``bench_all.py``: their own definitions of the packed-state recipe and
    files, so that all codes agree."""
    if anchors not in sys.path:
        sys.path.insert(0, anchors)
    import bench_all  # noqa: E402

    return bench_all


def demfem_packed_state(e: float, anchors: str, cache: str) -> str:
    """demfem's packed state made exactly as the anchors make theirs (bench_all.py prepare):
    the square start with every sphere moving at the belt speed, run for 1.511 s; cached."""
    from demfem.dem import DemSimulation

    path = os.path.join(cache, f"demfem_funnel_E{e:g}.ck")
    if not os.path.exists(path):
        n = int(anchors_module(anchors).prep_steps(e))
        print(f"preparing demfem's packed state: {n} steps (cached in {path})", flush=True)
        sim = DemSimulation._anchor_table(e, start="square", threads=2, initial_vx=0.2)
        sim.step(n)
        os.makedirs(cache, exist_ok=True)
        sim.save_checkpoint(path)
    return path


def run_demfem(e: float, steps: int, settle: int, threads: int, start: str, load: str | None = None) -> dict:
    from demfem.dem import DemSimulation

    sim = DemSimulation._anchor_table(e, start=start, threads=threads, initial_vx=0.2 if load else 0.0)
    if load:
        sim.load_checkpoint(load)
    else:
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


def target_report(per_rep: dict[str, list[float]], demfem_rate: dict[int, float],
                  anchor_rate: dict[str, float]) -> list[str]:
    """Lines stating each of issue 5's targets against this run.

    ``per_rep[code]``: demfem's one-thread rate over that code's, one value per repetition;
    ``demfem_rate[threads]`` and ``anchor_rate[code]``: medians, particle-steps/s. The absolute
    targets were set on a machine where the anchors ran at ``REFERENCE_RATE``; each is also
    given scaled by this machine's speed, the anchor's rate here over its reference rate
    (LIGGGHTS first: its speed tracks demfem's more closely than Yade's does).
    """
    lines = []
    for code, want in TARGET_RATIO.items():
        got = per_rep.get(code)
        if got:
            m = statistics.median(got)
            lines.append(f"target >= {want:g}x {code} on 1 thread: {m:.2f}x (median of {len(got)} "
                         f"repetitions, {min(got):.2f}-{max(got):.2f}): "
                         f"{'met' if m >= want else 'not met'}")
    for t, want in TARGET_RATE.items():
        got = demfem_rate.get(t)
        if got is None:
            continue
        line = f"target >= {want:.3g} particle-steps/s on {t} thread(s): {got:.3g}: " \
               f"{'met' if got >= want else 'not met'}"
        for code in ("liggghts", "yade"):
            if code in anchor_rate:
                f = anchor_rate[code] / REFERENCE_RATE[code]
                scaled = want * f
                line += (f"; scaled by {code}'s speed here ({f:.2f} of its reference "
                         f"{REFERENCE_RATE[code]:.2g}): {scaled:.3g}, "
                         f"{'met' if got >= scaled else 'not met'}")
        lines.append(line)
    return lines


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--anchors", default=DEFAULT_ANCHORS,
                   help="the anchor folder (shared/anchors/dem: run_liggghts.py, yade_bench.py, "
                        "bench_all.py, scene.py); default: beside the repository, %(default)s")
    p.add_argument("--E", type=float, default=45e9)
    p.add_argument("--steps", type=int, default=20000)
    p.add_argument("--settle", type=int, default=2000)
    p.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    p.add_argument("--skip-yade", action="store_true")
    p.add_argument("--skip-liggghts", action="store_true")
    p.add_argument("--state", choices=["start", "packed"], default="start",
                   help="start: square packing after --settle steps; packed: each code's packed state "
                        "made by the anchors' recipe (bench_all.py prepare; demfem's own made and cached here)")
    p.add_argument("--reps", type=int, default=1, help="repetitions; the median is reported")
    p.add_argument("--json", default=None, help="write every run's result to this file")
    p.add_argument("--cache", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".states"),
                   help="where demfem's packed state is cached")
    a = p.parse_args()
    anchors = check_anchors(a.anchors)
    packed = a.state == "packed"
    if packed:
        bench_all = anchors_module(anchors)
        lig_state, yade_state = bench_all.state_file("liggghts", a.E), bench_all.state_file("yade", a.E)
        for f in (lig_state, yade_state):
            if not os.path.exists(f):
                sys.exit(f"missing anchor state {f}: run `python3 bench_all.py prepare --E {a.E:g}` in {anchors}")
        ours_state = demfem_packed_state(a.E, anchors, a.cache)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for rep in range(a.reps):
            first = len(rows)
            for t in a.threads:
                rows.append(run_demfem(a.E, a.steps, a.settle, t, "square", ours_state if packed else None))
            if not a.skip_liggghts:
                cmd = [sys.executable, os.path.join(anchors, "run_liggghts.py"), "--E", str(a.E),
                       "--steps", str(a.steps), "--np", "1", "--dir", os.path.join(tmp, "lig")]
                cmd += ["--settle", "0", "--load-restart", lig_state] if packed else ["--settle", str(a.settle)]
                r = run_anchor(cmd, tmp)
                r["code"], r["threads"] = "liggghts", 1
                rows.append(r)
            if not a.skip_yade:
                cmd = ["yade", "-n", "-x", "-j1", os.path.join(anchors, "yade_bench.py"), "--E", str(a.E),
                       "--steps", str(a.steps)]
                cmd += ["--settle", "0", "--load", yade_state] if packed else ["--settle", str(a.settle)]
                r = run_anchor(cmd, tmp)
                r["code"], r["threads"] = "yade", 1
                rows.append(r)
            for r in rows[first:]:
                r["rep"] = rep
            print(f"rep {rep}: " + ", ".join(f"{r['code']} {r['threads']}: {r['particle_steps_per_s']:.3e}"
                                            for r in rows[first:]), flush=True)
    med: dict[tuple[str, int], float] = {}
    for key in sorted({(r["code"], r["threads"]) for r in rows}):
        med[key] = statistics.median(r["particle_steps_per_s"] for r in rows if (r["code"], r["threads"]) == key)
    what = "packed state (each code's own, anchors' recipe)" if packed else f"start state after {a.settle} settle steps"
    print(f"{what}, E = {a.E:g} Pa, {a.steps} timed steps, median of {a.reps}")
    print(f"{'code':10s} {'threads':>7s} {'particle-steps/s':>17s}")
    for (code, t), v in med.items():
        print(f"{code:10s} {t:>7} {v:17.3e}")
    # the machine's speed drifts between minutes: the ratio within each repetition (codes run
    # back to back) is steadier than the ratio of the medians
    def rate(code: str, t: int, rep: int) -> float:
        return next(r["particle_steps_per_s"] for r in rows if (r["code"], r["threads"], r["rep"]) == (code, t, rep))

    one_thread: dict[str, list[float]] = {}
    for (code, t), v in med.items():
        if code != "demfem":
            for (c2, t2), ours in med.items():
                if c2 == "demfem":
                    per_rep = [rate("demfem", t2, k) / rate(code, t, k) for k in range(a.reps)]
                    if t2 == 1 and t == 1:
                        one_thread[code] = per_rep
                    print(f"demfem {t2} thread(s) / {code} {t}: {ours / v:.2f}x (ratio of medians); "
                          f"per repetition {', '.join(f'{x:.2f}' for x in per_rep)}, median {statistics.median(per_rep):.2f}x")
    if packed:
        ours = {t: v for (c, t), v in med.items() if c == "demfem"}
        theirs = {c: v for (c, t), v in med.items() if c != "demfem" and t == 1}
        for line in target_report(one_thread, ours, theirs):
            print(line)
    if a.json:
        write_text_atomic(a.json, json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
