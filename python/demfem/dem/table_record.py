"""What a table run records as it goes: samples of the state at fixed times, every contact
onset (sphere–sphere and sphere–wall), the whole-contact events when asked for, and the
removals; saved to and restored from a partial record for a checkpoint
(:func:`demfem.dem.table_run.run_table`).

SI units: s, m, m/s, N, N s.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping, Optional

import numpy as np

from demfem.analysis.collisions import ONSET_DTYPE, WALL_ONSET_DTYPE
from demfem.analysis.contact_events import contact_event_table
from demfem.io.atomic import atomic_path
from demfem.scenes.table import AccumulationTable

__all__ = ["Recorder", "ARRAYS", "event_columns", "kept_events"]

#: The sampled arrays of a run (see :class:`demfem.dem.table_run.TableRun`).
ARRAYS = ("times", "positions", "velocities", "coordination", "forces", "opening",
          "riding_up", "max_overlap", "kinetic_energy")


class Recorder:
    """Accumulates samples and onsets; can be saved to / restored from a partial record."""

    def __init__(self, n: int) -> None:
        self.n = n
        self.frames: dict[str, list[np.ndarray]] = {k: [] for k in ARRAYS}
        self.onset_parts: list[dict[str, np.ndarray]] = []
        self.wall_parts: list[dict[str, np.ndarray]] = []
        self.event_parts: list[dict[str, np.ndarray]] = []
        self.removal_times = np.full(n, np.nan)
        # every exit and every re-insertion, (time s, sphere id): the passages
        # (demfem.assess.passages); the engine's removal list restarts empty after a resume
        self.removal_log: list[np.ndarray] = []
        self.insertion_log: list[np.ndarray] = []
        self._removals_seen = 0

    def note_insertions(self, time: float, index: np.ndarray) -> None:
        """Record that spheres ``index`` were put back on the table at ``time`` (s)."""
        index = np.asarray(index, np.int64)
        if index.size:
            self.insertion_log.append(np.column_stack([np.full(index.size, float(time)),
                                                       index.astype(float)]))

    def logs(self) -> dict[str, np.ndarray]:
        """The removal and insertion logs as arrays: ``removal_log_time`` (s),
        ``removal_log_index``, ``insertion_log_time`` (s), ``insertion_log_index``."""
        out = {}
        for name, parts in (("removal", self.removal_log), ("insertion", self.insertion_log)):
            a = np.concatenate(parts) if parts else np.zeros((0, 2))
            out[f"{name}_log_time"] = a[:, 0].copy()
            out[f"{name}_log_index"] = a[:, 1].astype(np.int64)
        return out

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

    def collect_events(self, sim, contact_events: bool = False,
                       event_filter: Optional[tuple[float, float]] = None) -> None:
        """Move the engine's onset log, removals and (``contact_events``) whole-contact
        events into the record (and clear the logs); ``event_filter`` = (min_speed, min_force):
        only the events with an onset speed (m/s) or a peak force (N) at least that."""
        if contact_events:
            self.event_parts.append(kept_events(event_columns(sim.events()), event_filter))
        o = sim.onsets()
        wall = np.asarray(o["partner_is_wall"], bool)
        for keep, parts in ((~wall, self.onset_parts), (wall, self.wall_parts)):
            parts.append({
                "i": np.asarray(o["particle"], np.int64)[keep],
                "j": np.asarray(o["partner"], np.int64)[keep],
                "time": np.asarray(o["time"], float)[keep],
                "normal_speed": np.asarray(o["normal_speed"], float)[keep],
                "tangential_speed": np.asarray(o["tangential_speed"], float)[keep],
            })
        point = np.asarray(o["partner_position"], float).reshape(-1, 3)[wall]
        self.wall_parts[-1]["point"] = point
        sim.clear_records()
        times, index = sim.removals()
        index = np.asarray(index, np.int64)
        times = np.asarray(times, float)
        new = np.isnan(self.removal_times[index])
        self.removal_times[index[new]] = times[new]
        fresh = slice(self._removals_seen, None)
        if index[fresh].size:
            self.removal_log.append(np.column_stack([times[fresh], index[fresh].astype(float)]))
        self._removals_seen = int(index.size)

    def impact_times(self, rule) -> np.ndarray:
        """Times (s) of the recorded onsets that ``rule`` (a
        :class:`demfem.dem.steady.SteadyRule`) counts as impacts."""
        sphere, wall = self.raw_onsets(), self.raw_onsets(walls=True)
        both = {"time": np.concatenate([sphere["time"], wall["time"]]),
                "normal_speed": np.concatenate([sphere["normal_speed"], wall["normal_speed"]]),
                "partner": np.concatenate([sphere["j"], wall["j"]]),
                "partner_is_wall": np.concatenate([np.zeros(len(sphere["time"]), bool),
                                                   np.ones(len(wall["time"]), bool)])}
        return rule.impacts(both)

    def stacked(self) -> dict[str, np.ndarray]:
        return {k: np.stack(v) if v else np.zeros(0) for k, v in self.frames.items()}

    def raw_onsets(self, walls: bool = False) -> dict[str, np.ndarray]:
        names: tuple[str, ...] = ("i", "j", "time", "normal_speed", "tangential_speed")
        parts = self.wall_parts if walls else self.onset_parts
        if walls:
            names += ("point",)
        if not parts:
            empty = {k: np.zeros(0, np.int64 if k in "ij" else float) for k in names}
            if walls:
                empty["point"] = np.zeros((0, 3))
            return empty
        return {k: np.concatenate([p[k] for p in parts]) for k in names}

    def wall_onset_table(self, times: np.ndarray, coordination: np.ndarray) -> np.ndarray:
        raw = self.raw_onsets(walls=True)
        table = np.zeros(len(raw["time"]), WALL_ONSET_DTYPE)
        table["i"], table["wall"], table["time"] = raw["i"], raw["j"], raw["time"]
        table["normal_speed"] = raw["normal_speed"]
        table["tangential_speed"] = raw["tangential_speed"]
        table["impact_angle"] = np.arctan2(raw["tangential_speed"], raw["normal_speed"])
        table["x"], table["y"], table["z"] = raw["point"].T if len(table) else ([], [], [])
        if len(table):
            frame = _nearest_frame(times, raw["time"])
            table["coordination_i"] = _coordination_at(coordination, frame, raw["i"])
        return table[np.argsort(table["time"], kind="stable")]

    def onset_table(self, times: np.ndarray, coordination: np.ndarray) -> np.ndarray:
        raw = self.raw_onsets()
        table = np.zeros(len(raw["time"]), ONSET_DTYPE)
        for k in ("i", "j", "time", "normal_speed", "tangential_speed"):
            table[k] = raw[k]
        table["impact_angle"] = np.arctan2(raw["tangential_speed"], raw["normal_speed"])
        if len(table):
            frame = _nearest_frame(times, raw["time"])
            table["coordination_i"] = _coordination_at(coordination, frame, raw["i"])
            table["coordination_j"] = _coordination_at(coordination, frame, raw["j"])
        return table[np.argsort(table["time"], kind="stable")]

    def raw_events(self, open_now: Optional[dict[str, np.ndarray]] = None
                   ) -> dict[str, np.ndarray]:
        """The recorded event columns, and those of ``open_now`` (the contacts open at the
        end), concatenated."""
        parts = self.event_parts + ([open_now] if open_now is not None else [])
        if not parts:
            return event_columns(None)
        return {k: np.concatenate([p[k] for p in parts]) for k in _EVENT_COLUMNS}

    def event_table(self, times: np.ndarray, coordination: np.ndarray, radii: np.ndarray,
                    open_now: dict[str, np.ndarray]) -> np.ndarray:
        table = contact_event_table(self.raw_events(open_now), radii)
        if len(table):
            frame = _nearest_frame(times, table["time"])
            table["coordination_i"] = _coordination_at(coordination, frame, table["i"])
            sphere = ~table["partner_is_wall"]
            table["coordination_j"][sphere] = _coordination_at(coordination, frame[sphere],
                                                               table["j"][sphere])
        return table

    def save_partial(self, path: Path) -> None:
        arrays: dict[str, Any] = {f"frame_{k}": v for k, v in self.stacked().items()}
        arrays.update({f"event_{k}": v for k, v in self.raw_events().items()})
        arrays.update({f"onset_{k}": v for k, v in self.raw_onsets().items()})
        arrays.update({f"wall_onset_{k}": v for k, v in self.raw_onsets(walls=True).items()})
        arrays["removal_times"] = self.removal_times
        arrays.update(self.logs())
        with atomic_path(path, suffix=".npz") as tmp:
            with open(tmp, "wb") as fh:
                np.savez(fh, **arrays)

    def load_partial(self, path: Path) -> None:
        with np.load(path, allow_pickle=False) as data:
            for k in ARRAYS:
                self.frames[k] = list(data[f"frame_{k}"])
            self.onset_parts = [{k: data[f"onset_{k}"] for k in
                                 ("i", "j", "time", "normal_speed", "tangential_speed")}]
            if "wall_onset_time" in data.files:
                self.wall_parts = [{k: data[f"wall_onset_{k}"] for k in
                                    ("i", "j", "time", "normal_speed", "tangential_speed",
                                     "point")}]
            if "event_time" in data.files:
                self.event_parts = [{k: data[f"event_{k}"] for k in _EVENT_COLUMNS}]
            self.removal_times = np.array(data["removal_times"], float)
            self._removals_seen = 0  # the restored engine's removal list starts empty
            self.removal_log, self.insertion_log = [], []
            for name in ("removal", "insertion"):
                if f"{name}_log_time" in data.files:
                    log = np.column_stack([np.array(data[f"{name}_log_time"], float),
                                           np.array(data[f"{name}_log_index"], float)])
                    getattr(self, f"{name}_log").append(log)


#: The engine's event columns (:meth:`demfem._core.DemSimulation.events`).
_EVENT_COLUMNS = ("time", "duration", "particle", "partner", "partner_is_wall", "normal_speed",
                  "tangential_speed", "position", "partner_position", "peak_normal_force",
                  "normal_impulse", "peak_tangential_force", "max_overlap", "complete")


def kept_events(columns: dict[str, np.ndarray], keep: Optional[tuple[float, float]]
          ) -> dict[str, np.ndarray]:
    """The events of ``columns`` with onset speed ≥ keep[0] or peak force ≥ keep[1]."""
    if keep is None:
        return columns
    sel = (columns["normal_speed"] >= keep[0]) | (columns["peak_normal_force"] >= keep[1])
    return {k: v[sel] for k, v in columns.items()}


def event_columns(raw: Optional[Mapping[str, Any]]) -> dict[str, np.ndarray]:
    """The engine's event dict as plain arrays (an empty table for ``None``)."""
    kinds = {"particle": np.int64, "partner": np.int64, "partner_is_wall": bool,
             "complete": bool}
    out = {}
    for k in _EVENT_COLUMNS:
        value = np.zeros(0) if raw is None else raw[k]
        a = np.asarray(value, kinds.get(k, float))
        out[k] = a.reshape(-1, 3) if k in ("position", "partner_position") else a
    return out


def _coordination_at(coordination: np.ndarray, frame: np.ndarray,
                     sphere: np.ndarray) -> np.ndarray:
    """Coordination of each ``sphere`` at its ``frame`` as int64; −1 where it had left."""
    z = coordination[frame, sphere]
    return np.where(np.isfinite(z), z, -1).astype(np.int64)


def _nearest_frame(frame_times: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Index of the sample nearest each time in ``t``."""
    k = np.clip(np.searchsorted(frame_times, t), 1, len(frame_times) - 1)
    left_nearer = (t - frame_times[k - 1]) <= (frame_times[k] - t)
    return np.where(left_nearer, k - 1, k)
