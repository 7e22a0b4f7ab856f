"""One recorded run of the accumulation table, sampled at fixed intervals, and its sweep runner.

:func:`run_table` builds the DEM engine from an :class:`~demfem.scenes.AccumulationTable`,
advances it in steps of ``sample_interval`` and records, at each sample time, what the paper's
Figs. 5-9 are made of: centres, velocities, coordination numbers, net contact forces and the
gate opening. It also keeps every particle-particle contact onset with the coordination of
both partners. The result is a :class:`TableRun`, saved as one ``.npz`` file (no pickle).

Long runs checkpoint: every ``checkpoint_every`` seconds of wall time the engine state goes to
``checkpoint`` and the record so far to ``checkpoint + ".record.npz"``; a run started with the
same arguments and an existing checkpoint resumes from it and reaches the same final state as
an uninterrupted run.

SI units throughout: m, s, m/s, N, Pa.
"""
from __future__ import annotations

import dataclasses
import json
import math
import os
import time as _time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping, Optional

import numpy as np

from demfem.analysis.collisions import ONSET_DTYPE
from demfem.analysis.forces import first_line_force, force_statistics
from demfem.analysis.coordination import mean_coordination
from demfem.errors import DemfemIOError, InvalidParameterError
from demfem.io.atomic import atomic_path
from demfem.progress import ProgressBar
from demfem.scenes.table import AccumulationTable

__all__ = ["TableRun", "run_table", "sweep_point", "table_from_params", "RUN_OPTIONS"]

#: Keys of a sweep point that configure the run rather than the table (see :func:`sweep_point`).
RUN_OPTIONS = ("duration", "sample_interval", "model", "run_dir", "checkpoint_every",
               "discard_before", "quantile", "narrowest_opening")

_ARRAYS = ("times", "positions", "velocities", "coordination", "forces", "opening",
           "riding_up", "max_overlap", "kinetic_energy")


@dataclass
class TableRun:
    """A sampled run of the accumulation table.

    Attributes:
        parameters: the table's fields (:class:`AccumulationTable`), SI units.
        times: (F,) sample times, s (the first is 0).
        positions: (F, N, 3) centres, m; NaN rows for spheres that have left.
        velocities: (F, N, 3) velocities, m/s; NaN rows for spheres that have left.
        coordination: (F, N) sphere-sphere contacts per sphere (float); NaN when removed.
        forces: (F, N, 3) net contact force on each sphere, N; NaN rows when removed.
        opening: (F,) gate opening w(t), m.
        riding_up: (F,) spheres whose centre is more than 2 mm above resting on the belt.
        max_overlap: (F,) largest overlap, m.
        kinetic_energy: (F,) kinetic energy of all spheres, J.
        tags: (N,) tag codes (:class:`demfem.scenes.Tag`).
        radii: (N,) radii, m.
        removal_times: (N,) time each sphere left through the opening, s; NaN if it did not.
        onsets: particle-particle contact onsets, :data:`demfem.analysis.ONSET_DTYPE` (speeds in
            m/s as the engine logs them, impact angle atan2(v_t, v_n) in rad, coordination of
            both partners at the sample nearest the onset).
        info: run metadata: model, dt (s), effects, steps, wall_time_s, completed.
    """

    parameters: dict[str, Any]
    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    coordination: np.ndarray
    forces: np.ndarray
    opening: np.ndarray
    riding_up: np.ndarray
    max_overlap: np.ndarray
    kinetic_energy: np.ndarray
    tags: np.ndarray
    radii: np.ndarray
    removal_times: np.ndarray
    onsets: np.ndarray
    info: dict[str, Any] = field(default_factory=dict)

    @property
    def n_frames(self) -> int:
        """Number of samples F."""
        return len(self.times)

    @property
    def n_particles(self) -> int:
        """Number of spheres N at t = 0."""
        return len(self.tags)

    @property
    def sample_times(self) -> np.ndarray:
        """(F,) nominal sample times k * sample_interval, s: uniformly spaced, as period
        analyses need; :attr:`times` (the step times actually sampled) is later by less than
        one time step."""
        return float(self.info["sample_interval"]) * np.arange(self.n_frames)

    @property
    def table(self) -> AccumulationTable:
        """The table this run was made with."""
        return AccumulationTable.from_dict(self.parameters)

    @property
    def present(self) -> np.ndarray:
        """(F, N) bool: sphere still on the table at each sample."""
        return np.all(np.isfinite(self.positions), axis=2)

    def first_line_force(self, part: str = "total") -> np.ndarray:
        """(F,) mean magnitude of the net contact force on the first-line spheres, N (paper
        Fig. 5).

        ``part="total"``: the whole net contact force, as Yade's ``O.forces.f`` that the paper
        plots; for a sphere on the belt it contains the belt's support, about m g = 0.048 N,
        the same in every set-up. ``part="in_plane"``: only its horizontal (x, y) part, the
        push of the neighbours, walls and belt friction along the table.
        """
        if part == "total":
            return first_line_force(self.forces, self.tags)
        if part == "in_plane":
            return first_line_force(np.linalg.norm(self.forces[..., :2], axis=2), self.tags)
        raise InvalidParameterError(f"invalid part = {part!r}: must be 'total' or 'in_plane'")

    def mean_coordination(self, select: Optional[np.ndarray] = None) -> np.ndarray:
        """(F,) mean coordination of the present spheres (all, or a mask / index selection)."""
        z = np.where(self.present, self.coordination, 0.0)
        return np.asarray(mean_coordination(z, select, self.present))

    def save(self, path: str | Path) -> Path:
        """Write the run to ``path`` (``.npz``) atomically; returns the path."""
        arrays = {name: getattr(self, name) for name in _ARRAYS}
        arrays.update(tags=self.tags, radii=self.radii, removal_times=self.removal_times,
                      onsets=self.onsets)
        document = json.dumps({"parameters": self.parameters, "info": self.info},
                              default=_json_default)
        target = Path(path)
        with atomic_path(target, suffix=".npz") as tmp:
            with open(tmp, "wb") as fh:
                np.savez_compressed(fh, document=np.array(document), **arrays)
        return target

    @classmethod
    def load(cls, path: str | Path) -> "TableRun":
        """Read a run written by :meth:`save`."""
        path = Path(path)
        try:
            with np.load(path, allow_pickle=False) as data:
                document = json.loads(str(data["document"]))
                arrays = {k: data[k] for k in data.files if k != "document"}
        except OSError as exc:
            raise DemfemIOError(f"i/o error on {path}: {exc}") from None
        except (KeyError, ValueError) as exc:
            raise InvalidParameterError(f"invalid table run file {path}: {exc}") from None
        missing = [k for k in (*_ARRAYS, "tags", "radii", "removal_times", "onsets")
                   if k not in arrays]
        if missing:
            raise InvalidParameterError(f"invalid table run file {path}: missing "
                                        + ", ".join(missing))
        return cls(parameters=document["parameters"], info=document["info"], **arrays)

    def summary(self, discard_before: float = 0.0, quantile: float = 0.95) -> dict[str, float]:
        """Numbers for a sweep table: first-line force mean / peak / quantile (N) after
        ``discard_before`` (s), total and in-plane (see :meth:`first_line_force`), mean coordination of the present spheres, spheres removed,
        spheres riding up at the end, largest overlap (m)."""
        keep = self.times >= discard_before
        stats = force_statistics(self.first_line_force()[keep], quantile)
        plane = force_statistics(self.first_line_force("in_plane")[keep], quantile)
        z = self.mean_coordination()
        return {
            "force_mean_N": stats["mean"],
            "force_peak_N": stats["peak"],
            "force_q95_N" if quantile == 0.95 else f"force_q{quantile:g}_N": stats["quantile"],
            "in_plane_force_mean_N": plane["mean"],
            "in_plane_force_peak_N": plane["peak"],
            "in_plane_force_quantile_N": plane["quantile"],
            "coordination_mean": float(np.nanmean(z[keep])),
            "n_removed": int(np.isfinite(self.removal_times).sum()),
            "riding_up_end": int(self.riding_up[-1]),
            "riding_up_max": int(self.riding_up.max()),
            "max_overlap_m": float(np.nanmax(self.max_overlap)),
            "n_onsets": int(len(self.onsets)),
            "dt_s": float(self.info.get("dt", math.nan)),
            "sim_wall_time_s": float(self.info.get("wall_time_s", math.nan)),
        }


def _json_default(x: Any) -> Any:
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    raise TypeError(f"not JSON serialisable: {type(x).__name__}")


# --------------------------------------------------------------------------------------------
# Recording
# --------------------------------------------------------------------------------------------

class _Recorder:
    """Accumulates samples and onsets; can be saved to / restored from a partial record."""

    def __init__(self, n: int) -> None:
        self.n = n
        self.frames: dict[str, list[np.ndarray]] = {k: [] for k in _ARRAYS}
        self.onset_parts: list[dict[str, np.ndarray]] = []
        self.removal_times = np.full(n, np.nan)

    def sample(self, sim, table: AccumulationTable) -> None:
        alive = np.asarray(sim.alive(), bool)
        gone = ~alive
        pos = np.array(sim.positions(), float)
        vel = np.array(sim.velocities(), float)
        force = np.array(sim.contact_force_sums(), float)
        z = np.asarray(sim.coordination(), float)
        for a in (pos, vel, force):
            a[gone] = np.nan
        z = np.where(alive, z, np.nan)
        t = float(sim.time)
        f = self.frames
        f["times"].append(np.array(t))
        f["positions"].append(pos)
        f["velocities"].append(vel)
        f["coordination"].append(z)
        f["forces"].append(force)
        f["opening"].append(np.array(float(table.opening_width_at(t))))
        f["riding_up"].append(np.array(int(sim.riding_up_count())))
        f["max_overlap"].append(np.array(float(sim.max_overlap())))
        f["kinetic_energy"].append(np.array(float(sim.kinetic_energy())))

    def collect_events(self, sim) -> None:
        """Move the engine's onset log and removals into the record (and clear the log)."""
        o = sim.onsets()
        keep = ~np.asarray(o["partner_is_wall"], bool)
        self.onset_parts.append({
            "i": np.asarray(o["particle"], np.int64)[keep],
            "j": np.asarray(o["partner"], np.int64)[keep],
            "time": np.asarray(o["time"], float)[keep],
            "normal_speed": np.asarray(o["normal_speed"], float)[keep],
            "tangential_speed": np.asarray(o["tangential_speed"], float)[keep],
        })
        sim.clear_records()
        times, index = sim.removals()
        index = np.asarray(index, np.int64)
        new = np.isnan(self.removal_times[index])
        self.removal_times[index[new]] = np.asarray(times, float)[new]

    def stacked(self) -> dict[str, np.ndarray]:
        return {k: np.stack(v) if v else np.zeros(0) for k, v in self.frames.items()}

    def raw_onsets(self) -> dict[str, np.ndarray]:
        names = ("i", "j", "time", "normal_speed", "tangential_speed")
        if not self.onset_parts:
            return {k: np.zeros(0, np.int64 if k in "ij" else float) for k in names}
        return {k: np.concatenate([p[k] for p in self.onset_parts]) for k in names}

    def onset_table(self, times: np.ndarray, coordination: np.ndarray) -> np.ndarray:
        raw = self.raw_onsets()
        table = np.zeros(len(raw["time"]), ONSET_DTYPE)
        for k in ("i", "j", "time", "normal_speed", "tangential_speed"):
            table[k] = raw[k]
        table["impact_angle"] = np.arctan2(raw["tangential_speed"], raw["normal_speed"])
        if len(table):
            frame = _nearest_frame(times, raw["time"])
            zi = coordination[frame, raw["i"]]
            zj = coordination[frame, raw["j"]]
            table["coordination_i"] = np.where(np.isfinite(zi), zi, -1).astype(np.int64)
            table["coordination_j"] = np.where(np.isfinite(zj), zj, -1).astype(np.int64)
        return table[np.argsort(table["time"], kind="stable")]

    def save_partial(self, path: Path) -> None:
        arrays: dict[str, Any] = {f"frame_{k}": v for k, v in self.stacked().items()}
        arrays.update({f"onset_{k}": v for k, v in self.raw_onsets().items()})
        arrays["removal_times"] = self.removal_times
        with atomic_path(path, suffix=".npz") as tmp:
            with open(tmp, "wb") as fh:
                np.savez(fh, **arrays)

    def load_partial(self, path: Path) -> None:
        with np.load(path, allow_pickle=False) as data:
            for k in _ARRAYS:
                self.frames[k] = list(data[f"frame_{k}"])
            self.onset_parts = [{k: data[f"onset_{k}"] for k in
                                 ("i", "j", "time", "normal_speed", "tangential_speed")}]
            self.removal_times = np.array(data["removal_times"], float)


def _nearest_frame(frame_times: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Index of the sample nearest each time in ``t``."""
    k = np.clip(np.searchsorted(frame_times, t), 1, len(frame_times) - 1)
    left_nearer = (t - frame_times[k - 1]) <= (frame_times[k] - t)
    return np.where(left_nearer, k - 1, k)


def _check_run_arguments(duration: float, sample_interval: float, threads: int) -> None:
    for name, value in (("duration", duration), ("sample_interval", sample_interval)):
        if not (isinstance(value, (int, float, np.floating)) and math.isfinite(value)
                and value > 0):
            raise InvalidParameterError(f"invalid {name} = {value!r}: must be a finite "
                                        "number of seconds > 0")
    if sample_interval > duration:
        raise InvalidParameterError(f"invalid sample_interval = {sample_interval!r}: must not "
                                    f"exceed duration = {duration!r} s")
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise InvalidParameterError(f"invalid threads = {threads!r}: must be a whole number "
                                    ">= 1")


def run_table(table: AccumulationTable, duration: float, sample_interval: float = 0.05,
              threads: int = 1, model: str = "hertz_reissner_mindlin",
              progress: Optional[Callable[[float, int], None]] = None,
              checkpoint: Optional[str | Path] = None, checkpoint_every: float = 300.0,
              dt: Optional[float] = None) -> TableRun:
    """Run ``table`` for ``duration`` s of simulated time and sample it every
    ``sample_interval`` s (samples at 0, Δ, 2Δ, ... up to ``duration``).

    Args:
        table: the scene's parameters.
        duration: simulated time, s.
        sample_interval: time between samples, s.
        threads: engine threads; results are bitwise the same on any number. On a 2-core
            machine, 2 threads run the default table 1.4x faster than 1 (a sweep gains more
            from one run per core).
        model: contact law, see :func:`demfem.dem.from_scene`.
        progress: callback ``progress(sim_time_s, steps)``, e.g. a
            :class:`demfem.progress.ProgressBar`.
        checkpoint: engine checkpoint file; if it exists (with its ``.record.npz``), the run
            resumes from it. Written every ``checkpoint_every`` wall seconds; removed at the end.
        checkpoint_every: wall time between checkpoints, s.
        dt: time step, s (default: the engine's safe step).

    Returns:
        The :class:`TableRun`.
    """
    from demfem.dem import from_scene, refeed_removed

    _check_run_arguments(duration, sample_interval, threads)
    if not (math.isfinite(checkpoint_every) and checkpoint_every > 0):
        raise InvalidParameterError(f"invalid checkpoint_every = {checkpoint_every!r}: must "
                                    "be a finite number of seconds > 0")
    scene = table.build()
    sim = from_scene(scene, model=model, threads=threads, record_onsets=True, dt=dt)
    n_samples = int(math.floor(duration / sample_interval + 1e-9))
    sample_times = sample_interval * np.arange(n_samples + 1)
    rec = _Recorder(len(scene.radii))
    wall_before = 0.0
    ckpt = Path(checkpoint) if checkpoint is not None else None
    files = _checkpoint_files(ckpt) if ckpt is not None else None
    if files is not None and all(p.exists() for p in files[:2]):
        sim.load_checkpoint(files[0])
        rec.load_partial(files[1])
        if files[2].exists():
            wall_before = float(json.loads(files[2].read_text())["wall_time_s"])
        if not math.isclose(float(rec.frames["times"][-1]), float(sim.time), rel_tol=0.0,
                            abs_tol=0.5 * float(sim.dt)):
            # A crash between the renames of a checkpoint: the pair does not belong together.
            sim = from_scene(scene, model=model, threads=threads, record_onsets=True, dt=dt)
            rec, wall_before = _Recorder(len(scene.radii)), 0.0
    if not rec.frames["times"]:
        rec.sample(sim, table)
    start = _time.perf_counter()
    last_checkpoint = start
    k = len(rec.frames["times"])
    while k <= n_samples:
        # Steps are whole: advance to the first step at or after the sample time.
        sim.run_until(float(sample_times[k]))
        if scene.refeed is not None:
            refeed_removed(sim, scene.refeed["sites"], scene.refeed["velocity"])
        rec.collect_events(sim)
        rec.sample(sim, table)
        k += 1
        if progress is not None:
            progress(float(sim.time), int(sim.steps))
        now = _time.perf_counter()
        if files is not None and now - last_checkpoint >= checkpoint_every and k <= n_samples:
            _write_checkpoint(sim, rec, files, wall_before + now - start)
            last_checkpoint = now
    frames = rec.stacked()
    run = TableRun(
        parameters=dataclasses.asdict(table),
        tags=np.asarray(scene.tags, np.int64),
        radii=np.asarray(scene.radii, float),
        removal_times=rec.removal_times,
        onsets=rec.onset_table(frames["times"], frames["coordination"]),
        info={"model": model, "dt": float(sim.dt), "effects": list(scene.effects),
              "steps": int(sim.steps), "threads": int(threads),
              "sample_interval": float(sample_interval), "duration": float(duration),
              "wall_time_s": wall_before + _time.perf_counter() - start},
        **frames,
    )
    if files is not None:
        for p in files:
            p.unlink(missing_ok=True)
    return run


def _checkpoint_files(ckpt: Path) -> tuple[Path, Path, Path]:
    """The engine checkpoint, the record so far (``.record.npz``) and the wall time used
    (``.json``)."""
    return ckpt, Path(str(ckpt) + ".record.npz"), Path(str(ckpt) + ".json")


def _write_checkpoint(sim, rec: _Recorder, files: tuple[Path, Path, Path],
                      wall_time: float) -> None:
    """Engine state, record so far and wall time used. Each file is replaced atomically; a
    crash between the two renames leaves an engine state and a record of different times,
    which :func:`run_table` detects (the record's last sample time is the engine's time) and
    then starts afresh."""
    from demfem.io.atomic import write_text_atomic

    ckpt, record_file, wall_file = files
    ckpt.parent.mkdir(parents=True, exist_ok=True)
    # Both written in full under temporary names first, then renamed one after the other.
    tmp_ckpt = ckpt.with_name(ckpt.name + ".new")
    sim.save_checkpoint(tmp_ckpt)
    rec.save_partial(record_file.with_name(record_file.name + ".new.npz"))
    os.replace(tmp_ckpt, ckpt)
    os.replace(record_file.with_name(record_file.name + ".new.npz"), record_file)
    write_text_atomic(wall_file, json.dumps({"wall_time_s": wall_time,
                                             "sim_time_s": float(sim.time)}))


# --------------------------------------------------------------------------------------------
# Sweep runner
# --------------------------------------------------------------------------------------------

def table_from_params(params: Mapping[str, Any]) -> AccumulationTable:
    """The table of a sweep point: every key that is not a run option (:data:`RUN_OPTIONS`)
    must be a field of :class:`AccumulationTable` (unknown keys are errors).

    ``narrowest_opening`` (m), if given, sets ``opening_width = gate_amplitude +
    narrowest_opening``, so that a sweep over A keeps the narrowest opening w0 - A fixed on one
    geometry (the recipe of :mod:`demfem.scenes.table`: 0.02 m with tilted_wall_length
    0.24 m); giving both it and ``opening_width`` is an error."""
    fields = {k: v for k, v in params.items() if k not in RUN_OPTIONS}
    if "narrowest_opening" in params:
        if "opening_width" in params:
            raise InvalidParameterError(
                "invalid sweep point: give either narrowest_opening or opening_width, not both")
        amplitude = float(fields.get("gate_amplitude",
                                     AccumulationTable.gate_amplitude))  # type: ignore[arg-type]
        fields["opening_width"] = amplitude + float(params["narrowest_opening"])
    return AccumulationTable.from_dict(fields, source="sweep point")


def sweep_point(params: Mapping[str, Any]) -> dict[str, Any]:
    """Runner for :func:`demfem.sweep.sweep`: one table run, summarised.

    Keys of ``params``: any :class:`AccumulationTable` field (e.g. ``gate_amplitude`` in m,
    ``gate_period`` in s, ``belt_velocity`` in m/s, ``young_modulus`` in Pa) plus the run
    options ``duration`` (s, required), ``sample_interval`` (s, 0.05), ``model``,
    ``discard_before`` (s, 0: start of the force statistics), ``quantile`` (0.95),
    ``checkpoint_every`` (wall s, 300) and ``run_dir``: if given, the :class:`TableRun` is
    saved as ``<run_dir>/<run_key(params)>.npz``, i.e. next to the sweep's own record
    ``<run_key>.json`` when ``run_dir`` is the sweep's ``runs`` folder, and the run
    checkpoints to ``<run_key>.ckpt`` there (a killed sweep resumes mid-run).

    Returns:
        ``force_mean_N``, ``force_peak_N``, ``force_q95_N`` (first-line force statistics, N),
        ``coordination_mean``, ``n_removed``, ``riding_up_end``, ``riding_up_max``,
        ``max_overlap_m``, ``n_onsets``, ``dt_s``, ``sim_wall_time_s`` and ``run_file``.
    """
    from demfem.sweep import run_key

    if "duration" not in params:
        raise InvalidParameterError("invalid sweep point: missing 'duration' (simulated s)")
    table = table_from_params(params)
    run_dir = params.get("run_dir")
    key = run_key(dict(params))
    checkpoint = Path(run_dir) / f"{key}.ckpt" if run_dir else None
    duration = float(params["duration"])
    # On a worker, stderr goes to the sweep's log: one progress line a minute.
    bar = ProgressBar(duration, label=key[:48], log_interval=60.0)
    run = run_table(table, duration,
                    sample_interval=float(params.get("sample_interval", 0.05)),
                    model=str(params.get("model", "hertz_reissner_mindlin")),
                    checkpoint=checkpoint,
                    checkpoint_every=float(params.get("checkpoint_every", 300.0)),
                    progress=bar)
    bar.close()
    result: dict[str, Any] = run.summary(float(params.get("discard_before", 0.0)),
                                         float(params.get("quantile", 0.95)))
    result["run_file"] = ""
    if run_dir:
        result["run_file"] = str(run.save(Path(run_dir) / f"{key}.npz"))
    return result
