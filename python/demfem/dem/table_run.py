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
import zipfile
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping, Optional

import numpy as np

from demfem.analysis.collisions import WALL_ONSET_DTYPE
from demfem.analysis.contact_events import CONTACT_EVENT_DTYPE
from demfem.analysis.forces import first_line_force, force_statistics
from demfem.analysis.coordination import mean_coordination
from demfem.errors import (CheckpointError, DemfemIOError, InvalidParameterError,
                           SettingsMismatchError)
from demfem.io.atomic import atomic_path
from demfem.io.strict_json import dumps as json_dumps
# the output-folder helpers live with the job runner; re-exported for existing callers
from demfem.jobs.folder import settings_differences, sha256_file
from demfem.progress import ProgressBar
from demfem.scenes.table import AccumulationTable
from demfem.dem.steady import SteadyRule
from demfem.dem.table_record import ARRAYS, Recorder, event_columns, kept_events

__all__ = ["TableRun", "run_table", "sweep_point", "table_from_params", "RUN_OPTIONS",
           "check_run_arguments", "checkpoint_files", "checkpoint_state", "run_settings",
           "settings_differences", "sha256_file", "remove_checkpoint"]

#: Keys of a sweep point that configure the run rather than the table (see :func:`sweep_point`).
RUN_OPTIONS = ("duration", "sample_interval", "model", "run_dir", "checkpoint_every",
               "discard_before", "quantile", "narrowest_opening")



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
        info: run metadata: model, dt (s), effects, steps, wall_time_s, completed, and
            ``wall_names`` (the scene's walls in engine order).
        wall_onsets: sphere-wall contact onsets (belt, side walls, tilted wall, gate),
            :data:`demfem.analysis.collisions.WALL_ONSET_DTYPE`; empty for runs saved before
            they were recorded.
        contact_events: whole contacts (sphere-sphere and sphere-wall) with their measured
            duration, peak forces and impulse,
            :data:`demfem.analysis.contact_events.CONTACT_EVENT_DTYPE`; recorded when the run
            asks (``run_table(record_events=True)``, ``info["events_recorded"]``), else empty.
            Contacts still open at the end are in it with ``complete`` False.
        passage_log: every exit and re-insertion: ``removal_log_time`` (s),
            ``removal_log_index``, ``insertion_log_time`` (s), ``insertion_log_index``
            (:func:`demfem.assess.passages.passages`); empty for runs saved before it was
            recorded (then only the first exit of each sphere is known, ``removal_times``).
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
    wall_onsets: np.ndarray = field(default_factory=lambda: np.zeros(0, WALL_ONSET_DTYPE))
    contact_events: np.ndarray = field(
        default_factory=lambda: np.zeros(0, CONTACT_EVENT_DTYPE))
    passage_log: dict[str, np.ndarray] = field(default_factory=dict)

    def passages(self) -> np.ndarray:
        """The run's passages (:func:`demfem.assess.passages.passages`): each cartridge from
        its insertion to its exit. A run saved without the passage log gives one passage per
        sphere, ending at its first exit."""
        from demfem.assess.passages import passages

        log = self.passage_log
        # the run's own last time (whole steps end at or just after the nominal duration)
        end = max(float(self.info.get("duration", 0.0)),
                  float(self.times[-1]) if len(self.times) else 0.0)
        if log:
            return passages(self.n_particles, log["removal_log_time"],
                            log["removal_log_index"], log["insertion_log_time"],
                            log["insertion_log_index"], end)
        gone = np.flatnonzero(np.isfinite(self.removal_times))
        return passages(self.n_particles, self.removal_times[gone], gone, end_time=end)

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
        arrays = {name: getattr(self, name) for name in ARRAYS}
        arrays.update(tags=self.tags, radii=self.radii, removal_times=self.removal_times,
                      onsets=self.onsets, wall_onsets=self.wall_onsets,
                      contact_events=self.contact_events,
                      **{f"passage_{k}": v for k, v in self.passage_log.items()})
        document = json_dumps({"parameters": self.parameters, "info": self.info})
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
                log = {k[len("passage_"):]: arrays.pop(k) for k in list(arrays)
                       if k.startswith("passage_")}
        except OSError as exc:
            raise DemfemIOError(f"i/o error on {path}: {exc}") from None
        except (zipfile.BadZipFile, EOFError, zlib.error) as exc:
            raise CheckpointError(f"damaged table run file {path}: {exc}") from None
        except (KeyError, ValueError) as exc:
            raise InvalidParameterError(f"invalid table run file {path}: {exc}") from None
        missing = [k for k in (*ARRAYS, "tags", "radii", "removal_times", "onsets")
                   if k not in arrays]
        if missing:
            raise InvalidParameterError(f"invalid table run file {path}: missing "
                                        + ", ".join(missing))
        if "wall_onsets" not in arrays:  # a run saved before wall onsets were recorded
            arrays["wall_onsets"] = np.zeros(0, WALL_ONSET_DTYPE)
        if "contact_events" not in arrays:  # a run saved before events were recorded
            arrays["contact_events"] = np.zeros(0, CONTACT_EVENT_DTYPE)
        return cls(parameters=document["parameters"], info=document["info"], passage_log=log,
                   **arrays)

    def summary(self, discard_before: float = 0.0, quantile: float = 0.95) -> dict[str, float]:
        """Numbers for a sweep table, each key naming its unit (SI; counts ``n_*`` and the
        dimensionless coordination carry none): first-line force mean / peak / quantile
        (N, per-sphere mean, see :meth:`first_line_force`) after ``discard_before`` (s), total
        and in the plane, mean coordination of the present spheres, spheres removed, spheres
        riding up at the end and at most, largest overlap (m), contact onsets, time step (s)
        and wall time (s)."""
        keep = self.times >= discard_before
        stats = force_statistics(self.first_line_force()[keep], quantile)
        plane = force_statistics(self.first_line_force("in_plane")[keep], quantile)
        z = self.mean_coordination()
        q = f"q{100 * quantile:g}"
        return {
            "first_line_force_mean_N": stats["mean"],
            "first_line_force_peak_N": stats["peak"],
            f"first_line_force_{q}_N": stats["quantile"],
            "first_line_in_plane_force_mean_N": plane["mean"],
            "first_line_in_plane_force_peak_N": plane["peak"],
            f"first_line_in_plane_force_{q}_N": plane["quantile"],
            "mean_coordination": float(np.nanmean(z[keep])),
            "n_removed": int(np.isfinite(self.removal_times).sum()),
            "n_riding_up_end": int(self.riding_up[-1]),
            "n_riding_up_max": int(self.riding_up.max()),
            "max_overlap_m": float(np.nanmax(self.max_overlap)),
            "n_onsets": int(len(self.onsets)),
            "time_step_s": float(self.info.get("dt", math.nan)),
            "wall_time_s": float(self.info.get("wall_time_s", math.nan)),
        }




def check_run_arguments(duration: float, sample_interval: float, threads: int) -> None:
    for name, value in (("duration", duration), ("sample_interval", sample_interval)):
        if not (isinstance(value, (int, float, np.floating)) and math.isfinite(value)
                and value > 0):
            raise InvalidParameterError(f"invalid {name} = {value!r}: must be a finite "
                                        "number of seconds > 0")
    if isinstance(duration, bool) or isinstance(sample_interval, bool):
        raise InvalidParameterError("invalid duration or sample_interval: must be a number "
                                    "of seconds, not a boolean")
    if sample_interval > duration:
        raise InvalidParameterError(f"invalid sample_interval = {sample_interval!r}: must not "
                                    f"exceed duration = {duration!r} s")
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise InvalidParameterError(f"invalid threads = {threads!r}: must be a whole number "
                                    ">= 1")


def run_settings(table: AccumulationTable, duration: float, sample_interval: float,
                 model: str, dt: Optional[float], record_events: bool = False) -> dict[str, Any]:
    """What makes a run's result: the table's fields, ``duration_s``, ``sample_interval_s``,
    ``model``, the requested ``dt_s`` (None: the engine's safe step) and, when on,
    ``record_events``. Threads are not in it: results are bitwise the same on any number.
    Strict-JSON values."""
    from demfem.io.strict_json import finite_or_none

    settings = {"scene": dataclasses.asdict(table), "duration_s": float(duration),
                "sample_interval_s": float(sample_interval), "model": model,
                "dt_s": None if dt is None else float(dt)}
    if record_events:
        settings["record_events"] = True
    return finite_or_none(settings)


def run_table(table: AccumulationTable, duration: float, sample_interval: float = 0.05,
              threads: int = 1, model: Optional[str] = None,
              progress: Optional[Callable[[float, int], None]] = None,
              checkpoint: Optional[str | Path] = None, checkpoint_every: float = 300.0,
              dt: Optional[float] = None, fresh: bool = False,
              overlap_fraction: float = 0.1, record_events: bool = False,
              steady: Optional[SteadyRule] = None,
              keep_events: Optional[tuple[float, float]] = None,
              seed: Optional[int] = None) -> TableRun:
    """Run ``table`` for ``duration`` s of simulated time and sample it every
    ``sample_interval`` s (samples at 0, Δ, 2Δ, ... up to ``duration``).

    Args:
        table: the scene's parameters.
        duration: simulated time, s.
        sample_interval: time between samples, s.
        threads: engine threads; results are bitwise the same on any number. On a 2-core
            machine, 2 threads run the default table 1.4x faster than 1 (a sweep gains more
            from one run per core).
        model: contact law, see :func:`demfem.dem.from_scene` (default: the table's
            ``contact_model``; given, it replaces it, and the run's parameters record it).
        progress: callback ``progress(sim_time_s, steps)``, e.g. a
            :class:`demfem.progress.ProgressBar`.
        checkpoint: engine checkpoint file; if it exists (with its ``.record.npz`` and its
            ``.json`` holding the run's settings and the files' SHA-256), the run resumes from
            it. Written every ``checkpoint_every`` wall seconds; removed at the end. A
            checkpoint made with other settings raises :class:`SettingsMismatchError` naming
            them, a damaged one :class:`CheckpointError` naming the file (unless ``fresh``).
        checkpoint_every: wall time between checkpoints, s.
        dt: time step, s (default: the engine's safe step).
        fresh: ignore (and remove) an existing checkpoint and start at t = 0.
        overlap_fraction: physical sanity check at every sample: a sphere sunk into the belt
            or an overlap deeper than this fraction of the radius raises
            :class:`demfem.errors.NumericalError` (see :func:`demfem.dem.check_state`).
        record_events: also record every whole contact with its measured duration, peak
            forces and impulse (:attr:`TableRun.contact_events`); the engine then writes
            every contact's normal force on every step (about 1.3x the step's time on the
            default table, ``benches/dem_events_cost.py``).
        steady: stop before ``duration`` (then the longest run) once the collision rate is
            steady by this :class:`demfem.dem.steady.SteadyRule`, checked at every whole
            period; ``info["steady"]`` holds the last check and ``info["duration"]`` the time
            the run ended.
        keep_events: (min_speed m/s, min_force N): keep only the contact events that began
            at least that fast or reached at least that force (the pack's resting chatter,
            half of all contacts, is then not stored); None keeps every one.
        seed: start from the perturbed start of this seed
            (:func:`demfem.scenes.perturb.perturbed_start`); None: the table's own start.
            In the run's settings (``start_seed``: a checkpoint of another seed is
            refused).

    Returns:
        The :class:`TableRun`.
    """
    from demfem.dem import from_scene, refeed_removed

    from demfem.dem import check_state

    check_run_arguments(duration, sample_interval, threads)
    if model is not None and model != table.contact_model:
        table = dataclasses.replace(table, contact_model=model)
    model = table.contact_model
    if not (math.isfinite(checkpoint_every) and checkpoint_every > 0):
        raise InvalidParameterError(f"invalid checkpoint_every = {checkpoint_every!r}: must "
                                    "be a finite number of seconds > 0")
    scene = table.build()
    if seed is not None:
        from demfem.scenes.perturb import perturbed_start

        scene = perturbed_start(scene, seed)
    belt = _belt_plane(scene)
    sim = from_scene(scene, model=model, threads=threads, record_onsets=True, dt=dt,
                     record_events=record_events)
    n_samples = int(math.floor(duration / sample_interval + 1e-9))
    sample_times = sample_interval * np.arange(n_samples + 1)
    rec = Recorder(len(scene.radii))
    wall_before = 0.0
    settings = run_settings(table, duration, sample_interval, model, dt, record_events)
    if steady is not None:
        settings["steady"] = steady.to_dict()
    if seed is not None:
        settings["start_seed"] = int(seed)
    if record_events and keep_events is not None:
        keep_events = (float(keep_events[0]), float(keep_events[1]))
        settings["keep_events"] = list(keep_events)
    last_check: Optional[dict[str, Any]] = None
    ckpt = Path(checkpoint) if checkpoint is not None else None
    files = checkpoint_files(ckpt) if ckpt is not None else None
    if ckpt is not None and fresh:
        remove_checkpoint(ckpt)
    if ckpt is not None and files is not None and any(p.exists() for p in files):
        wall_before = _resume(sim, rec, ckpt, settings)
    if not rec.frames["times"]:
        rec.sample(sim, table)
    start = _time.perf_counter()
    last_checkpoint = start
    k = len(rec.frames["times"])
    while k <= n_samples:
        # Steps are whole: advance to the first step at or after the sample time.
        sim.run_until(float(sample_times[k]))
        if scene.refeed is not None:
            off = ~np.asarray(sim.alive(), bool)
            refeed_removed(sim, scene.refeed["sites"], scene.refeed["velocity"])
            rec.note_insertions(float(sim.time), np.flatnonzero(off & np.asarray(sim.alive(),
                                                                                  bool)))
        rec.collect_events(sim, record_events, keep_events)
        rec.sample(sim, table)
        check_state(sim, floor=belt, overlap_fraction=overlap_fraction)
        k += 1
        if progress is not None:
            progress(float(sim.time), int(sim.steps))
        if steady is not None and steady.due(float(sample_times[k - 1]), float(sim.dt)):
            last_check = steady.check(float(sample_times[k - 1]), rec.impact_times(steady))
            if last_check["steady"]:
                break
        now = _time.perf_counter()
        if files is not None and now - last_checkpoint >= checkpoint_every and k <= n_samples:
            _write_checkpoint(sim, rec, files, wall_before + now - start, settings)
            last_checkpoint = now
    frames = rec.stacked()
    run = TableRun(
        parameters=dataclasses.asdict(table),
        tags=np.asarray(scene.tags, np.int64),
        radii=np.asarray(scene.radii, float),
        removal_times=rec.removal_times,
        passage_log=rec.logs(),
        onsets=rec.onset_table(frames["times"], frames["coordination"]),
        wall_onsets=rec.wall_onset_table(frames["times"], frames["coordination"]),
        contact_events=(rec.event_table(frames["times"], frames["coordination"],
                                        np.asarray(scene.radii, float),
                                        kept_events(event_columns(sim.open_events()),
                                              keep_events))
                        if record_events else np.zeros(0, CONTACT_EVENT_DTYPE)),
        info={"model": model, "events_recorded": bool(record_events), "dt": float(sim.dt), "effects": list(scene.effects),
              "wall_names": [str(w["name"]) for w in scene.walls],
              "steps": int(sim.steps), "threads": int(threads),
              "sample_interval": float(sample_interval),
              "duration": (float(sample_times[k - 1]) if last_check and last_check["steady"]
                           else float(duration)),
              "steady": last_check,
              "wall_time_s": wall_before + _time.perf_counter() - start},
        **frames,
    )
    if ckpt is not None:
        remove_checkpoint(ckpt)
    return run


def checkpoint_files(ckpt: Path) -> tuple[Path, Path, Path]:
    """The engine checkpoint, the record so far (``.record.npz``) and the metadata
    (``.json``: settings, wall and simulated time, SHA-256 of the other two)."""
    ckpt = Path(ckpt)
    return ckpt, Path(str(ckpt) + ".record.npz"), Path(str(ckpt) + ".json")


def _new_files(ckpt: Path) -> tuple[Path, Path]:
    """Where the next engine checkpoint and record are written before they are renamed."""
    engine, record, _ = checkpoint_files(ckpt)
    return engine.with_name(engine.name + ".new"), record.with_name(record.name + ".new.npz")


def remove_checkpoint(ckpt: str | Path) -> None:
    """Remove a checkpoint's files (engine, record, metadata and unfinished writes)."""
    for p in (*checkpoint_files(Path(ckpt)), *_new_files(Path(ckpt))):
        p.unlink(missing_ok=True)


def checkpoint_state(ckpt: str | Path) -> Optional[dict[str, Any]]:
    """The metadata of a checkpoint (``settings``, ``wall_time_s``, ``sim_time_s``,
    ``sha256``), or None if there is none; a damaged metadata file raises
    :class:`CheckpointError` naming it."""
    meta = checkpoint_files(Path(ckpt))[2]
    if not meta.exists():
        return None
    try:
        state = json.loads(meta.read_text(encoding="utf-8"))
        if not isinstance(state, dict) or not {"settings", "sha256", "sim_time_s",
                                               "wall_time_s", "checksum"} <= set(state):
            raise ValueError("missing keys")
        body = {k: v for k, v in state.items() if k != "checksum"}
        if _meta_checksum(body) != state["checksum"]:
            raise ValueError("its checksum does not match its content (altered)")
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise CheckpointError(f"damaged checkpoint file {meta}: {exc}; start afresh "
                              "(fresh=True, demfem run --fresh)") from None
    return state


def _resume(sim, rec: Recorder, ckpt: Path, settings: Mapping[str, Any]) -> float:
    """Restore ``sim`` and ``rec`` from the checkpoint ``ckpt``; returns the wall time used
    so far. Refuses other settings and damaged files."""
    engine, record, meta = checkpoint_files(ckpt)
    state = checkpoint_state(ckpt)
    if state is None:
        raise CheckpointError(f"damaged checkpoint {ckpt}: its metadata {meta} is missing; "
                              "start afresh (fresh=True, demfem run --fresh)")
    diff = settings_differences(state["settings"], settings)
    if diff:
        raise SettingsMismatchError(
            f"the checkpoint {ckpt} belongs to a run with other settings ("
            + "; ".join(diff) + "): run with the same settings to resume it, or start afresh "
            "(fresh=True, demfem run --fresh)")
    sums = state["sha256"]
    # finish an interrupted commit: the metadata already names the new files' checksums
    for final, new, key in ((engine, _new_files(ckpt)[0], "engine"),
                            (record, _new_files(ckpt)[1], "record")):
        if new.exists():
            if sha256_file(new) == sums.get(key):
                os.replace(new, final)
            else:
                new.unlink()
    for path, key in ((engine, "engine"), (record, "record")):
        if not path.exists():
            raise CheckpointError(f"damaged checkpoint: {path} is missing; start afresh "
                                  "(fresh=True, demfem run --fresh)")
        if sha256_file(path) != sums.get(key):
            raise CheckpointError(f"damaged checkpoint file {path}: its SHA-256 differs from "
                                  f"the one recorded in {meta} (truncated or altered); start "
                                  "afresh (fresh=True, demfem run --fresh)")
    try:
        sim.load_checkpoint(engine)
    except Exception as exc:  # the engine's own format errors
        raise CheckpointError(f"damaged checkpoint file {engine}: {exc}") from None
    try:
        rec.load_partial(record)
    except (OSError, KeyError, ValueError) as exc:
        raise CheckpointError(f"damaged checkpoint file {record}: {exc}") from None
    if not math.isclose(float(rec.frames["times"][-1]), float(sim.time), rel_tol=0.0,
                        abs_tol=0.5 * float(sim.dt)):
        raise CheckpointError(f"damaged checkpoint {ckpt}: the record ends at "
                              f"t = {float(rec.frames['times'][-1]):.6g} s but the engine "
                              f"state is at t = {float(sim.time):.6g} s")
    return float(state["wall_time_s"])


def _write_checkpoint(sim, rec: Recorder, files: tuple[Path, Path, Path],
                      wall_time: float, settings: Mapping[str, Any]) -> None:
    """Engine state, record so far, settings and wall time used, committed like a journal:
    the new engine state and record are written in full under temporary names, then the
    metadata with their SHA-256 replaces the old one atomically (the commit), then the two
    are renamed. A crash before the commit leaves the old checkpoint valid; one after it is
    finished by the next resume (:func:`_resume`), which finds the new files by checksum."""
    from demfem.io.strict_json import write_json_atomic

    ckpt, record_file, meta = files
    ckpt.parent.mkdir(parents=True, exist_ok=True)
    new_engine, new_record = _new_files(ckpt)
    sim.save_checkpoint(new_engine)
    rec.save_partial(new_record)
    body = {"format": 2, "settings": dict(settings), "wall_time_s": wall_time,
            "sim_time_s": float(sim.time),
            "sha256": {"engine": sha256_file(new_engine), "record": sha256_file(new_record)}}
    write_json_atomic(meta, {**body, "checksum": _meta_checksum(body)})
    os.replace(new_engine, ckpt)
    os.replace(new_record, record_file)


def _meta_checksum(body: Mapping[str, Any]) -> str:
    """SHA-256 of a checkpoint metadata's content (canonical strict JSON, sorted keys)."""
    import hashlib

    return hashlib.sha256(json_dumps(body, sort_keys=True).encode("utf-8")).hexdigest()


def _belt_plane(scene) -> Optional[tuple[np.ndarray, np.ndarray]]:
    """(point, unit normal) of the scene's belt plane, or None if it has none."""
    for w in scene.walls:
        if w.get("kind") == "plane" and "belt" in str(w.get("name", "")):
            n = np.asarray(w["normal"], float)
            return np.asarray(w["point"], float), n / np.linalg.norm(n)
    return None


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
                    model=None if params.get("model") is None else str(params["model"]),
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
