"""Run the seven-cartridge cluster (paper Figs. 10-13) and write its outputs.

:func:`run_cluster` builds the FEM model of a :class:`demfem.scenes.cluster.CartridgeCluster`,
runs it (σ1 of cartridge 1 sampled every ``stress_interval`` = 5 µs, since an impact lasts
~80 µs; ``n_snapshots`` VTK files at regular times), saves the histories to ``run.npz`` and then writes, into ``out``:

* ``forces.csv`` and ``cluster_forces.png`` (Fig. 11): normal and tangential contact force
  on cartridge 1 from 2 and from 3, split into its bottom (region 0) and top (region 1)
  halves, N;
* ``cluster_sigma1.png`` (Fig. 12a,c): σ1 of cartridge 1 against time, the body maximum and
  the maximum in each contact zone (elements within one division around of the impact
  direction, bottom or top half);
* ``cluster_sigma1_through_wall.png`` (Fig. 12b,d): σ1 of the elements on the radial line
  through the zone's peak element, from the inner to the outer surface, at the snapshot of
  that pair's largest zone σ1;
* ``cluster_sigma1_map_1-2_bottom.png`` … (Fig. 13): σ1 on cartridge 1's unrolled outer and
  inner surface (θ, z) at the snapshot nearest each force peak;
* ``cluster_sigma1.gif``: the outer-surface σ1 map over time (needs pillow);
* ``vtk/cluster_NNNN.vtu`` and ``cluster.pvd``: the VTK series (ParaView);
* ``cluster_submodel.csv`` and the ``submodel`` entry of the summary: σ1 (outer, inner) and
  effective areas on 1 from the closed-form contact model at the smoothed force histories,
  per pair and region, and their peaks beside the FEM's zone σ1
  (:mod:`demfem.fem.cluster_submodel`);
* ``summary.json``: peaks, wall time, steps, settings (strict JSON).

The folder (:class:`demfem.jobs.OutputFolder`, record ``settings.json``) is locked while the
run writes it; another command's folder or other settings are refused unless
``fresh=True``.

Resume: every ``checkpoint_every`` s of wall time (30 s) the run saves its exact FEM state
(``checkpoint.state``: displacements, velocities, contact memory, histories, with its own
SHA-256, :meth:`demfem.fem.FemModel.save_state`) and what it has gathered
(``checkpoint.npz``, which names the state's SHA-256: the commit), atomically; a rerun with
the same settings after an interruption (Ctrl-C, kill -9, power loss) restores it and ends
with the numbers of an uninterrupted run. Once ``run.npz`` is there (its SHA-256 in the
record), a rerun only redoes the figures and files. A damaged or altered checkpoint or
``run.npz`` is refused by name (:class:`~demfem.errors.CheckpointError`, ``--fresh``).

Sanity: a cartridge set to hit 1 within the run that never touched it (a peak contact force
of 0 N: a Young's modulus so low, or a step so long, that the impact is not resolved) is a
:class:`~demfem.errors.NumericalError`, not a result.
"""
from __future__ import annotations

import csv
import io
import json
import math
import os
import time as _time
import zipfile
import zlib
from pathlib import Path
from typing import Any, Callable, Optional, Union

import numpy as np

from demfem.errors import (CheckpointError, DemfemError, InvalidParameterError,
                           NumericalError, SimulationInterrupted, check_positive)
from demfem.io.atomic import atomic_path, savefig_atomic, write_text_atomic
from demfem.io.strict_json import write_json_atomic
from demfem.scenes.cluster import SITE_ANGLES_DEG, CartridgeCluster

__all__ = ["run_cluster", "PAIRS", "REGIONS", "PAPER_VALUES"]

#: The two colliding pairs and the regions of cartridge 1.
PAIRS = ("2", "3")
REGIONS = ((0, "bottom"), (1, "top"))

#: What the paper reports for the max case with springs (Figs. 11-12), N and Pa.
PAPER_VALUES = {"normal_force_bottom_N": 55.0, "normal_force_top_N": 80.0,
                "tangential_force_bottom_N": 10.0, "tangential_force_top_N": 14.0,
                "sigma1_peak_Pa": 140e6, "sigma1_through_wall_Pa": 94e6}

#: Moving-average window of the plotted and summarised forces, s.
SMOOTH_S = 10e-6

Log = Callable[[str], None]


def _settings(cluster: CartridgeCluster, duration: float, n_snapshots: int) -> dict:
    return json.loads(json.dumps({"cluster": cluster.to_dict(), "duration_s": duration,
                                  "n_snapshots": n_snapshots}))


#: The job's name in its folder's record, and the record.
COMMAND = "demfem cluster"
_RECORD = "settings.json"

#: What the run writes (glob patterns), checkpoint included: removed by a fresh start.
OUTPUT_FILES = ("run.npz", "summary.json", "forces.csv", "cluster.pvd", "cluster_*",
                "vtk/cluster_*.vtu", "checkpoint.*")


def run_cluster(cluster: CartridgeCluster, duration: float = 3e-3,
                out: Union[str, Path] = "demfem_out/cluster", progress: bool = True,
                n_snapshots: int = 40, fresh: bool = False,
                log: Optional[Log] = None, stress_interval: float = 5e-6,
                checkpoint_every: float = 30.0) -> dict:
    """Run ``cluster`` for ``duration`` s and write every output into ``out``; returns the
    summary (also ``out/summary.json``). See the module text for the files.

    ``n_snapshots`` VTK files at regular times; σ1 of cartridge 1 is sampled every
    ``stress_interval`` s (5 µs: an impact lasts ~80 µs) for the σ1 curves and maps;
    ``checkpoint_every``: wall time between checkpoints, s."""
    if not isinstance(cluster, CartridgeCluster):
        raise InvalidParameterError(f"invalid cluster = {cluster!r}: must be a CartridgeCluster")
    duration = check_positive("duration", duration)
    if duration > 1.0:
        raise InvalidParameterError(f"invalid duration = {duration!r}: must be at most 1 s "
                                    "(an explicit FEM step is ~5e-8 s)")
    if isinstance(n_snapshots, bool) or not isinstance(n_snapshots, int) or not 1 <= n_snapshots <= 1000:
        raise InvalidParameterError(f"invalid n_snapshots = {n_snapshots!r}: must be an integer in [1, 1000]")
    log = log or (lambda line: None)
    out = Path(out)
    check_positive("stress_interval", stress_interval)
    check_positive("checkpoint_every", checkpoint_every)
    settings = _settings(cluster, duration, n_snapshots)
    settings["stress_interval_s"] = float(stress_interval)
    from demfem.jobs import OutputFolder

    with OutputFolder(out, COMMAND, settings, fresh=fresh, outputs=OUTPUT_FILES,
                      record=_RECORD) as folder:
        data = _finished_run(folder, log)
        if data is None:
            data = _simulate(cluster, duration, n_snapshots, out, progress, log,
                             stress_interval, checkpoint_every)
            _check_contacts(cluster, data, duration)
            run_path = out / "run.npz"
            with atomic_path(run_path, suffix=".npz") as tmp:
                np.savez_compressed(tmp, **data)
            folder.add_files([run_path])
            for name in _CHECKPOINT:
                (out / name).unlink(missing_ok=True)
        return _write_outputs(cluster, data, out, log)


def _finished_run(folder: Any, log: Log) -> Optional[dict]:
    """The histories of the finished FEM run in the folder (``run.npz``, checked against
    its SHA-256 in the record), or None when there is none. ``run.npz`` from an earlier
    version, whose record held no SHA-256, is taken as it is and recorded."""
    run_path = folder.path / "run.npz"
    if not run_path.exists():
        return None
    if folder.relative(run_path) not in folder.files:
        if folder.previous is None or folder.previous.get("format") == 2:
            # saved, but killed before its SHA-256 was recorded: the checkpoint is still
            # there, so the run is redone from it
            run_path.unlink()
            return None
        folder.add_files([run_path])
        log(f"{run_path} of an earlier demfem version (no SHA-256 then): recorded now")
    folder.verify(run_path)
    log(f"reusing the finished FEM run in {run_path} (figures and files are redone)")
    try:
        with np.load(run_path, allow_pickle=False) as z:
            return {k: z[k] for k in z.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError, zlib.error) as exc:
        raise CheckpointError(f"damaged run file {run_path}: {exc}; start afresh "
                              f"({folder.fresh_hint})") from None


def _check_contacts(cluster: CartridgeCluster, data: dict, duration: float) -> None:
    """Refuse a run in which 2 or 3, set to hit 1 within it, never touched 1 (no contact
    force at all): the impact was not resolved, its numbers would be meaningless."""
    centres = cluster.centres()
    velocities = cluster.velocities()
    stats = data["stats"]
    for k, pair in ((1, "2"), (2, "3")):
        towards = centres[0] - centres[k]
        closing = float(np.dot(velocities[k][:2], towards / np.linalg.norm(towards)))
        if closing <= 0 or cluster.impact_gap / closing >= 0.5 * duration:
            continue  # not aimed at 1, or arriving late in the run
        peak = max((float(np.max(data[f"fn_1{pair}_{r}"], initial=0.0)) for _, r in REGIONS))
        if not peak > 0:
            raise NumericalError(
                f"no contact between cartridges 1 and {pair} in the cluster run: {pair} was "
                f"set to reach 1 at t = {cluster.impact_gap / closing:.3g} s (impact_gap "
                f"{cluster.impact_gap:g} m at {closing:.3g} m/s) within the {duration:g} s "
                f"run, but the contact force stayed 0 N ({int(stats[1])} steps of dt = "
                f"{stats[2]:.3g} s, E = {cluster.material.E:.3g} Pa): the impact was not "
                "resolved; check the material (a Young's modulus this low makes the step "
                "too long) and the duration")


# ---------------------------------------------------------------------- the FEM run
#: The checkpoint's two files: the FEM state, and what the run has gathered (written second;
#: it names the state's step count, so a state without its record is never used).
_CHECKPOINT = ("checkpoint.state", "checkpoint.npz")
_STATE_NEW = "checkpoint.state.new"


def _save_checkpoint(out: Path, model: Any, k_next: int, wall: float, energy: list,
                     snaps_t: list, sig: list, press: list, frames: list) -> None:
    """Commit a checkpoint like a journal: the FEM state to ``checkpoint.state.new``, then
    ``checkpoint.npz`` naming its SHA-256 (the commit), then the state renamed into place;
    a crash at any point leaves a checkpoint :func:`_load_checkpoint` restores."""
    from demfem.jobs import sha256_file

    state, new_state = out / _CHECKPOINT[0], out / _STATE_NEW
    model.save_state(new_state)
    en = np.vstack(energy) if energy else np.zeros((0, 10))
    with atomic_path(out / _CHECKPOINT[1], suffix=".npz") as tmp:
        np.savez(tmp, k_next=k_next, steps=int(model.solver.steps), wall=wall, energy=en,
                 energy_rows=np.array([len(e) for e in energy], int),
                 snap_time=np.asarray(snaps_t, float),
                 sigma1=np.asarray(sig, np.float32).reshape(len(sig), -1),
                 pressure=np.asarray(press, np.float32).reshape(len(press), -1),
                 frame_time=np.array([f[0] for f in frames], float),
                 frame_name=np.array([f[1] for f in frames], dtype="U64"),
                 state_sha256=np.array(sha256_file(new_state)))
    os.replace(new_state, state)


def _load_checkpoint(out: Path, model: Any, log: Log) -> Optional[dict]:
    """Restore the model from the checkpoint in ``out``; its gathered lists, or None when
    there is none. A damaged one raises CheckpointError naming the file and ``--fresh``."""
    from demfem.jobs import sha256_file

    rec, state, new_state = out / _CHECKPOINT[1], out / _CHECKPOINT[0], out / _STATE_NEW
    if not rec.exists():
        new_state.unlink(missing_ok=True)  # written before a crash, never committed
        return None

    def damaged(path: Path, why: str) -> CheckpointError:
        return CheckpointError(f"damaged cluster checkpoint {path}: {why}; start afresh "
                               "(fresh=True, demfem cluster --fresh)")

    try:
        with np.load(rec, allow_pickle=False) as z:
            c = {k: z[k] for k in z.files}
        digest = str(c["state_sha256"])
        steps = int(c["steps"])
    except KeyError as exc:
        raise damaged(rec, f"no entry {exc} (a checkpoint of an earlier version?)") from None
    except (OSError, ValueError, zipfile.BadZipFile, EOFError, zlib.error) as exc:
        raise damaged(rec, str(exc)) from None
    if new_state.exists():  # finish an interrupted commit, or drop an uncommitted state
        if sha256_file(new_state) == digest:
            os.replace(new_state, state)
        else:
            new_state.unlink()
    if not state.exists():
        raise damaged(state, f"it is missing ({rec.name} names its SHA-256)")
    if sha256_file(state) != digest:
        raise damaged(state, f"its SHA-256 differs from the one {rec.name} recorded "
                             "(damaged or altered)")
    try:
        model.restore_state(state)
    except DemfemError as exc:
        raise damaged(state, str(exc)) from None
    if int(model.solver.steps) != steps:
        raise damaged(rec, f"{state.name} is at step {int(model.solver.steps)}, "
                           f"{rec.name} at {steps}")
    rows = np.cumsum(np.concatenate([[0], c["energy_rows"]]))
    c["energy_list"] = [c["energy"][a:b] for a, b in zip(rows[:-1], rows[1:])]
    log(f"cluster: resuming from the checkpoint at t = {model.time * 1e3:.4g} ms "
        f"(step {steps})")
    return c


def _simulate(cluster: CartridgeCluster, duration: float, n_snapshots: int, out: Path,
              progress: bool, log: Log, stress_interval: float,
              checkpoint_every: float = 30.0) -> dict:
    from demfem import _core
    from demfem.fem.result import FemResult
    from demfem.io.vtk import write_pvd

    t_build = _time.perf_counter()
    parts = cluster.parts()
    model = cluster.build_model(parts)
    build_s = _time.perf_counter() - t_build
    e1 = model.body_elements(0)
    n1 = model.body_nodes(0)
    shell = cluster.elements == "shell"
    kind = ("shell triangles (σ1 on the inner and outer faces" if shell else
            f"tets ({cluster.layers} through the wall")
    log(f"cluster: {model.mesh.n_elements} {kind}, "
        f"n_theta = {parts.n_theta}), dt = {model.dt_step:.3g} s, about "
        f"{int(math.ceil(duration / model.dt_step))} steps; springs: {cluster.springs}")
    bar = None
    if progress:
        from demfem.progress import ProgressBar
        bar = ProgressBar(duration, "cluster")
    vtk_times = [duration * (k + 1) / n_snapshots for k in range(n_snapshots)]
    n_s = max(1, int(round(duration / stress_interval)))
    targets = sorted({round(t, 15) for t in vtk_times} |
                     {round(duration * (k + 1) / n_s, 15) for k in range(n_s)})
    vtk_set = {round(t, 15) for t in vtk_times}
    vtk = out / "vtk"
    vtk.mkdir(parents=True, exist_ok=True)
    energy: list[Any] = []
    snaps_t: list[Any] = []
    sig: list[Any] = []
    press: list[Any] = []
    frames: list[Any] = []
    t_wall = _time.perf_counter()
    steps0 = int(model.solver.steps)
    k_start, wall_before = 0, 0.0
    saved = _load_checkpoint(out, model, log)
    if saved is not None:
        k_start, wall_before = int(saved["k_next"]), float(saved["wall"])
        energy = list(saved["energy_list"])
        snaps_t = [float(x) for x in saved["snap_time"]]
        sig, press = list(saved["sigma1"]), list(saved["pressure"])
        frames = [(float(t), str(n)) for t, n in zip(saved["frame_time"], saved["frame_name"])]
    last_save = _time.perf_counter()
    try:
        for k, t_target in enumerate(targets):
            if k < k_start:
                continue
            left = t_target - model.time
            if left > 0.5 * model.dt_step:
                cb = (lambda done, t: bar(t, int(model.solver.steps) - steps0)) if bar else False
                r = model.run(left, progress=cb)
                if r.energy.size:
                    energy.append(r.energy)
            if shell:
                s1 = _shell_sigma1(model, e1, parts.meshes[0])
            else:
                stress = np.asarray(model.solver.element_stresses())[e1]
                p1, _ = _core.fem_stress_invariants(np.ascontiguousarray(stress))
                s1 = np.asarray(p1)[:, 0]
            snaps_t.append(model.time)
            sig.append(s1.astype(np.float32))
            press.append(np.asarray(model.solver.contact_pressure())[n1].astype(np.float32))
            if t_target in vtk_set:
                name = f"cluster_{len(frames):04d}.vtu"
                model.write_vtu(vtk / name)
                frames.append((model.time, f"vtk/{name}"))
            if _time.perf_counter() - last_save >= checkpoint_every and k + 1 < len(targets):
                _save_checkpoint(out, model, k + 1, wall_before + _time.perf_counter() - t_wall,
                                 energy, snaps_t, sig, press, frames)
                last_save = _time.perf_counter()
    except SimulationInterrupted:
        if bar is not None:
            bar.close()
        where = ("the last checkpoint" if (out / _CHECKPOINT[1]).exists() else "t = 0 (no "
                 "checkpoint yet)")
        raise SimulationInterrupted(
            f"cluster run stopped at t = {model.time * 1e3:.3g} ms of {duration * 1e3:.3g} ms; "
            f"the same command resumes from {where}") from None
    if bar is not None:
        bar.close()
    wall = wall_before + _time.perf_counter() - t_wall
    write_pvd(out / "cluster.pvd", frames)
    en = np.vstack(energy) if energy else np.zeros((0, 10))
    res = FemResult.from_model(model, en, [], 0.0)
    steps = int(model.solver.steps) - steps0
    log(f"cluster: {steps} steps in {wall:.1f} s ({steps / max(wall, 1e-9):.1f} steps/s)")
    data: dict[str, np.ndarray] = {"time": res.time}
    for kk in PAIRS:
        for r, rname in REGIONS:
            c = res.channel("1", kk, r)
            data[f"fn_1{kk}_{rname}"] = res.normal_force[:, c]
            data[f"ft_1{kk}_{rname}"] = res.tangential_force[:, c]
    mesh1 = parts.meshes[0]
    data.update({
        "snap_time": np.asarray(snaps_t), "sigma1": np.asarray(sig),
        "pressure": np.asarray(press),
        "nodes_1": mesh1.nodes,
        **({"tris_1": mesh1.triangles} if shell else {"tets_1": mesh1.tets}),
        "stats": np.array([wall, steps, model.dt_step, model.mesh.n_elements, build_s,
                           res.energy_balance_error(), parts.spring_stiffness_per_contact,
                           parts.n_theta], float),
        "spring_energy": en[:, [0, 6]] if en.size else np.zeros((0, 2)),
    })
    return data


def _outer_is_top(mesh: Any) -> np.ndarray:
    """Per triangle of a placed shell mesh of one cartridge: whether its top face (+t/2
    along its right-hand normal) is the outer surface (the normal points away from the axis)."""
    x = mesh.nodes[mesh.triangles]
    n = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    cen = x.mean(axis=1)
    axis = mesh.nodes[:, :2].mean(axis=0)
    radial = np.column_stack([cen[:, 0] - axis[0], cen[:, 1] - axis[1], np.zeros(len(cen))])
    return np.einsum("ij,ij->i", n, radial) > 0


def _shell_sigma1(model: Any, e1: slice, mesh1: Any) -> np.ndarray:
    """σ1 of cartridge 1's triangles: (2T,) Pa, the inner faces, then the outer faces."""
    s = np.asarray(model.solver.surface_sigma1())[e1]
    top_out = _outer_is_top(mesh1)
    inner = np.where(top_out, s[:, 0], s[:, 2])
    outer = np.where(top_out, s[:, 2], s[:, 0])
    return np.concatenate([inner, outer])


# ---------------------------------------------------------------------- outputs
def _shell_geometry(cluster: CartridgeCluster, data: dict) -> dict:
    """As :func:`_geometry` for shells: the entries are the inner faces of 1's triangles,
    then their outer faces (r = the inner and outer radius of the wall)."""
    nodes, tris = data["nodes_1"], data["tris_1"].astype(np.int64)
    c = cluster.cartridge
    cen = nodes[tris].mean(axis=1)
    zc = cen[:, 2] - cluster.lift
    ri, ro = c.radii_at(np.clip(zc, 0.0, c.length))
    body = zc <= c.body_length
    nt = len(tris)
    two = lambda a: np.concatenate([a, a])  # noqa: E731
    theta = np.degrees(np.arctan2(cen[:, 1], cen[:, 0]))
    return {
        "theta": two(theta), "r": np.concatenate([ri, ro]), "z": two(zc),
        "outer": np.concatenate([np.zeros(nt, bool), body]),
        "inner": np.concatenate([body, np.zeros(nt, bool)]),
        "bottom": two(zc < 0.5 * c.length), "body": two(body),
        "dtheta": 360.0 / float(data["stats"][7]),
    }


def _geometry(cluster: CartridgeCluster, data: dict) -> dict:
    if "tris_1" in data:
        return _shell_geometry(cluster, data)
    nodes, tets = data["nodes_1"], data["tets_1"].astype(np.int64)
    c = cluster.cartridge
    cen = nodes[tets].mean(axis=1)
    r_node = np.hypot(nodes[:, 0], nodes[:, 1])
    ri, ro = c.radii_at(np.clip(nodes[:, 2] - cluster.lift, 0.0, c.length))
    tol = 1e-6 * c.body_outer_diameter
    on_out = np.abs(r_node - ro) < tol
    on_in = np.abs(r_node - ri) < tol
    zc = cen[:, 2] - cluster.lift
    body = zc <= c.body_length
    return {
        "theta": np.degrees(np.arctan2(cen[:, 1], cen[:, 0])), "r": np.hypot(cen[:, 0], cen[:, 1]),
        "z": zc, "outer": (on_out[tets].sum(axis=1) >= 3) & body,
        "inner": (on_in[tets].sum(axis=1) >= 3) & body,
        "bottom": zc < 0.5 * c.length, "body": body,
        "dtheta": 360.0 / float(data["stats"][7]),
    }


def _zone(geo: dict, pair: str, region: int, width: float = 1.0) -> np.ndarray:
    phi = SITE_ANGLES_DEG[int(pair) - 2]
    d = (geo["theta"] - phi + 180.0) % 360.0 - 180.0
    half = geo["bottom"] if region == 0 else ~geo["bottom"]
    return (np.abs(d) <= width * geo["dtheta"]) & half


def _smooth(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    from demfem.fem.result import moving_average
    if len(t) < 3:
        return x
    w = max(1, int(round(SMOOTH_S / float(np.median(np.diff(t))))))
    return moving_average(x, w)


def _write_outputs(cluster: CartridgeCluster, data: dict, out: Path, log: Log) -> dict:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = data["time"]
    geo = _geometry(cluster, data)
    ts, sig = data["snap_time"], data["sigma1"].astype(float)
    written: list[str] = []

    # forces.csv + Fig. 11
    cols = [f"{kind}_1{p}_{r}" for p in PAIRS for kind in ("fn", "ft") for _, r in REGIONS]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["time_s"] + [c + "_N" for c in cols])
    for i in range(len(t)):
        w.writerow([f"{t[i]:.9g}"] + [f"{data[c][i]:.6g}" for c in cols])
    write_text_atomic(out / "forces.csv", buf.getvalue())
    written.append("forces.csv")
    fig, axes = plt.subplots(2, 2, figsize=(10, 7), sharex=True)
    peaks: dict[str, dict] = {}
    for col, p in enumerate(PAIRS):
        for row, kind in enumerate(("fn", "ft")):
            ax = axes[row, col]
            for r, rname in REGIONS:
                x = data[f"{kind}_1{p}_{rname}"]
                xs = _smooth(t, x)
                line, = ax.plot(t * 1e3, xs, label=f"{rname}")
                ax.plot(t * 1e3, x, color=line.get_color(), alpha=0.25, lw=0.6)
                k = int(np.argmax(xs)) if len(xs) else 0
                peaks.setdefault(f"1-{p}_{rname}", {})[
                    "normal_N" if kind == "fn" else "tangential_N"] = float(xs[k]) if len(xs) else 0.0
                if kind == "fn":
                    peaks[f"1-{p}_{rname}"]["time_s"] = float(t[k]) if len(t) else 0.0
                    peaks[f"1-{p}_{rname}"]["raw_normal_N"] = float(x.max()) if len(x) else 0.0
            ax.set_title(f"{'normal' if kind == 'fn' else 'tangential'} force, pair 1-{p}")
            ax.set_ylabel("force (N)")
            ax.legend(fontsize=8)
            ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("time (ms)")
    fig.suptitle(f"cluster '{cluster.case}', springs {'on' if cluster.springs else 'off'} "
                 f"(smoothed over {SMOOTH_S * 1e6:g} us; raw faint)")
    fig.tight_layout()
    savefig_atomic(fig, out / "cluster_forces.png", dpi=110)
    plt.close(fig)
    written.append("cluster_forces.png")

    # Fig. 12a,c: sigma1 vs time
    body_max = sig[:, geo["body"]].max(axis=1) if sig.size else np.zeros(0)
    zone_max = {}
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.plot(ts * 1e3, body_max / 1e6, "k-", label="body maximum")
    for p in PAIRS:
        for r, rname in REGIONS:
            zm = sig[:, _zone(geo, p, r)].max(axis=1)
            zone_max[(p, r)] = zm
            ax.plot(ts * 1e3, zm / 1e6, marker=".", label=f"contact 1-{p} {rname}")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel(r"$\sigma_1$ (MPa)")
    ax.set_title(r"max principal stress $\sigma_1$ on cartridge 1")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    savefig_atomic(fig, out / "cluster_sigma1.png", dpi=110)
    plt.close(fig)
    written.append("cluster_sigma1.png")

    # Fig. 12b,d: through the wall at each pair's peak
    c = cluster.cartridge
    through: dict[str, dict] = {}
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for p in PAIRS:
        # at the pair's own force peak (the region where its contact force peaked), never
        # before it first touched
        r = max(((peaks.get(f"1-{p}_{rn}", {}).get("normal_N", 0.0), i)
                 for i, (_, rn) in enumerate(REGIONS)))[1]
        tk = peaks.get(f"1-{p}_{REGIONS[r][1]}", {}).get("time_s", 0.0)
        k = int(np.argmin(np.abs(np.asarray(ts) - tk))) if len(ts) else 0
        zmask = _zone(geo, p, r)
        idx = np.flatnonzero(zmask)
        e_star = idx[int(np.argmax(sig[k, idx]))]
        line = _zone(geo, p, r, width=0.5) & (np.abs(geo["z"] - geo["z"][e_star]) <=
                                              0.6 * cluster.element_size())
        sel = np.flatnonzero(line)
        order = np.argsort(geo["r"][sel])
        # through the local wall (the top contact may sit on the shoulder, not the body)
        ri, ro = c.radii_at(np.clip(geo["z"][sel][order], 0.0, c.length))
        depth = (geo["r"][sel][order] - ri) / (ro - ri)
        vals = sig[k, sel][order]
        ax.plot(depth, vals / 1e6, "o-", label=f"1-{p} {REGIONS[r][1]}, at its force peak, "
                f"t = {ts[k] * 1e3:.3g} ms")
        through[f"1-{p}"] = {"region": REGIONS[r][1], "time_s": float(ts[k]),
                             "z_m": float(geo["z"][e_star]),
                             "depth_fraction": depth.tolist(), "sigma1_Pa": vals.tolist(),
                             "inner_sigma1_Pa": float(vals[0]) if len(vals) else None,
                             "outer_sigma1_Pa": float(vals[-1]) if len(vals) else None}
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlabel("position through the wall: 0 inner surface, 1 outer surface")
    ax.set_ylabel(r"$\sigma_1$ (MPa)")
    ax.set_title(r"$\sigma_1$ through the wall at each pair's contact, at its force peak")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    savefig_atomic(fig, out / "cluster_sigma1_through_wall.png", dpi=110)
    plt.close(fig)
    written.append("cluster_sigma1_through_wall.png")

    # Fig. 13: unrolled maps at the force peaks
    maps: dict[str, dict] = {}
    vlim = float(np.percentile(np.abs(sig[:, geo["body"]]), 99.9)) if sig.size else 1.0
    for p in PAIRS:
        for r, rname in REGIONS:
            key = f"1-{p}_{rname}"
            tk = peaks[key]["time_s"]
            k = int(np.argmin(np.abs(ts - tk)))
            name = f"cluster_sigma1_map_1-{p}_{rname}.png"
            fig = _map_figure(plt, geo, sig[k], vlim, SITE_ANGLES_DEG[int(p) - 2],
                              f"pair 1-{p} {rname}: force peak {tk * 1e3:.3g} ms, "
                              f"snapshot {ts[k] * 1e3:.3g} ms")
            savefig_atomic(fig, out / name, dpi=100)
            plt.close(fig)
            written.append(name)
            zone = _zone(geo, p, r)
            maps[key] = {"snapshot_time_s": float(ts[k]),
                         "outer_zone_min_sigma1_Pa": float(sig[k, zone & geo["outer"]].min()),
                         "inner_zone_max_sigma1_Pa": float(sig[k, zone & geo["inner"]].max()),
                         "file": name}

    # GIF
    gif_note = _write_gif(plt, geo, ts, sig, vlim, out)
    if gif_note is None:
        written.append("cluster_sigma1.gif")
    else:
        log(gif_note)

    # the closed-form submodel on the force histories (demfem.fem.cluster_submodel)
    from demfem.fem.cluster_submodel import SUBMODEL_CSV, evaluate_submodel

    sub = evaluate_submodel(cluster, data)
    write_text_atomic(out / SUBMODEL_CSV, sub.csv_text())
    written.append(SUBMODEL_CSV)
    submodel = sub.summary()
    for p in PAIRS:
        for r, rn in REGIONS:
            entry = submodel["pairs"][f"1-{p}_{rn}"]
            for side in ("outer", "inner"):
                vals = sig[:, _zone(geo, p, r) & geo[side]]
                entry[f"fem_zone_{side}_sigma1_Pa"] = float(vals.max()) if vals.size else None

    stats = data["stats"]
    k_peak = int(np.argmax(body_max)) if len(body_max) else 0
    summary = {
        "case": cluster.case, "springs": cluster.springs, "elements": cluster.elements,
        **({"layers": int(cluster.layers)} if cluster.elements == "tet" else {}),
        "v2_m_s": cluster.v2, "v3_m_s": cluster.v3,
        "direction_2_deg": cluster.direction_2_deg, "direction_3_deg": cluster.direction_3_deg,
        "E_Pa": cluster.material.E, "duration_s": float(ts[-1]) if len(ts) else 0.0,
        "wall_time_s": float(stats[0]), "steps": int(stats[1]),
        "steps_per_s": float(stats[1] / stats[0]) if stats[0] > 0 else None,
        "dt_s": float(stats[2]), "n_elements": int(stats[3]), "n_theta": int(stats[7]),
        "energy_balance_error": float(stats[5]),
        "spring_stiffness_per_contact_N_m": float(stats[6]),
        "force_peaks": peaks, "smoothing_s": SMOOTH_S,
        "sigma1_body_max_Pa": float(body_max.max()) if len(body_max) else None,
        "sigma1_body_max_time_s": float(ts[k_peak]) if len(ts) else None,
        "sigma1_zone_max_Pa": {f"1-{p}_{rn}": float(zone_max[(p, r)].max())
                               for p in PAIRS for r, rn in REGIONS},
        "through_wall": through, "maps": maps, "submodel": submodel, "paper": PAPER_VALUES,
        "files": written + ["summary.json", "cluster.pvd", "vtk/"],
        "gif_note": gif_note,
    }
    write_json_atomic(out / "summary.json", summary)
    return summary


def _map_figure(plt, geo: dict, s: np.ndarray, vlim: float, phi: float, title: str):
    from matplotlib.tri import Triangulation

    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), sharey=True)
    for ax, which in zip(axes, ("outer", "inner")):
        m = geo[which]
        th = (geo["theta"][m] - phi + 180.0) % 360.0 - 180.0  # impact direction at 0
        tri = Triangulation(th, geo["z"][m] * 1e3)
        pc = ax.tripcolor(tri, s[m] / 1e6, shading="gouraud", cmap="coolwarm",
                          vmin=-vlim / 1e6, vmax=vlim / 1e6)
        ax.axvline(0.0, color="k", lw=1.5)
        ax.annotate("impact", (0, 0.98), xycoords=("data", "axes fraction"), ha="center",
                    va="top", fontsize=8, arrowprops=None)
        ax.set_xlabel("angle from the impact direction (deg)")
        ax.set_title(f"{which} surface")
    axes[0].set_ylabel("height z (mm)")
    fig.colorbar(pc, ax=axes, label=r"$\sigma_1$ (MPa)")
    fig.suptitle(title, fontsize=10)
    return fig


def _write_gif(plt, geo: dict, ts: np.ndarray, sig: np.ndarray, vlim: float, out: Path) -> Optional[str]:
    try:
        import PIL  # noqa: F401
    except ImportError:
        return "cluster_sigma1.gif skipped: pillow is not installed (pip install pillow)"
    from matplotlib.animation import FuncAnimation, PillowWriter
    from matplotlib.tri import Triangulation

    m = geo["outer"]
    tri = Triangulation(geo["theta"][m], geo["z"][m] * 1e3)
    fig, ax = plt.subplots(figsize=(7, 3.6))
    pc = ax.tripcolor(tri, sig[0, m] / 1e6, shading="gouraud", cmap="coolwarm",
                      vmin=-vlim / 1e6, vmax=vlim / 1e6)
    for p in PAIRS:
        ax.axvline(SITE_ANGLES_DEG[int(p) - 2], color="k", lw=0.8)
    fig.colorbar(pc, ax=ax, label=r"$\sigma_1$ (MPa)")
    ax.set_xlabel("angle around cartridge 1 (deg; 2 at 180, 3 at 120)")
    ax.set_ylabel("z (mm)")
    title = ax.set_title("")

    def frame(k: int):
        pc.set_array(sig[k, m] / 1e6)
        title.set_text(f"outer surface of 1, t = {ts[k] * 1e3:.3f} ms")
        return pc, title

    anim = FuncAnimation(fig, frame, frames=range(0, len(ts), max(1, len(ts) // 60)), blit=False)
    with atomic_path(out / "cluster_sigma1.gif", suffix=".gif") as tmp:
        anim.save(str(tmp), writer=PillowWriter(fps=8))
    plt.close(fig)
    return None
