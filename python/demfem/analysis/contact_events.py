"""The whole-contact event table: one row per contact from its first step to its last, with
what the DEM measured while it lasted (the engine's ``record_events``; see
:meth:`demfem._core.DemSimulation.events`).

Where the onset table (:data:`demfem.analysis.collisions.ONSET_DTYPE`) says how hard two
bodies met, this one also says what the contact did: its duration, the largest normal and
tangential force, the normal impulse ∫F_n dt and the deepest overlap, summed over the steps in
contact. In a packed table these differ from a binary impact's: a cartridge pushed on by the
queue behind it presses longer and harder than its onset speed says.

Rocky-style summaries (per particle, per wall, per pair of groups) are one ``np.bincount`` or
mask away; :func:`events_per_partner` gives the per-wall / sphere one.

SI units: s, m, m/s, N, N s.
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence

import numpy as np

__all__ = ["CONTACT_EVENT_DTYPE", "contact_event_table", "events_per_partner"]

#: Fields: sphere i; partner j (a sphere's index, or the wall's index into the run's
#: ``info["wall_names"]`` when ``partner_is_wall``); time of the first step in contact (s);
#: duration (s); normal and tangential relative speed at onset (m/s); contact point at onset
#: (m: on the wall, or on the surface of i towards j); peak normal force (N); normal impulse
#: (N s); peak tangential force (N); largest overlap (m); ``complete`` (False: still open at
#: the end of the run, or cut short by a removal); coordination of i and j at the nearest
#: sample (-1 for a wall or a sphere that had left).
CONTACT_EVENT_DTYPE = np.dtype([
    ("i", "i8"), ("j", "i8"), ("partner_is_wall", "?"),
    ("time", "f8"), ("duration", "f8"),
    ("normal_speed", "f8"), ("tangential_speed", "f8"),
    ("x", "f8"), ("y", "f8"), ("z", "f8"),
    ("peak_normal_force", "f8"), ("normal_impulse", "f8"), ("peak_tangential_force", "f8"),
    ("max_overlap", "f8"), ("complete", "?"),
    ("coordination_i", "i8"), ("coordination_j", "i8"),
])

#: Columns of the engine's event dict that the table copies as they are.
_COPIED = ("time", "duration", "normal_speed", "tangential_speed", "peak_normal_force",
           "normal_impulse", "peak_tangential_force", "max_overlap", "complete")


def contact_event_table(raw: Mapping[str, Any], radii: np.ndarray) -> np.ndarray:
    """The event table (:data:`CONTACT_EVENT_DTYPE`, in time order) from the engine's event
    columns ``raw`` (``sim.events()``, or several concatenated) and the spheres' ``radii``
    (m). Coordination is left at -1 (the caller that has the samples fills it)."""
    n = len(np.asarray(raw["time"]))
    table = np.zeros(n, CONTACT_EVENT_DTYPE)
    if n == 0:
        return table
    i = np.asarray(raw["particle"], np.int64)
    j = np.asarray(raw["partner"], np.int64)
    wall = np.asarray(raw["partner_is_wall"], bool)
    table["i"], table["j"], table["partner_is_wall"] = i, j, wall
    for k in _COPIED:
        table[k] = np.asarray(raw[k])
    ci = np.asarray(raw["position"], float).reshape(-1, 3)
    cj = np.asarray(raw["partner_position"], float).reshape(-1, 3)
    d = cj - ci
    norm = np.linalg.norm(d, axis=1)
    unit = np.where(norm[:, None] > 0, d / np.where(norm > 0, norm, 1.0)[:, None], 0.0)
    point = np.where(wall[:, None], cj, ci + np.asarray(radii, float)[i][:, None] * unit)
    table["x"], table["y"], table["z"] = point.T
    table["coordination_i"] = table["coordination_j"] = -1
    return table[np.argsort(table["time"], kind="stable")]


def events_per_partner(events: np.ndarray, wall_names: Sequence[str]) -> dict[str, dict[str, float]]:
    """Per partner (``"sphere"`` and each wall by name): the number of events, their summed
    normal impulse (N s), their largest peak normal force (N) and their mean duration (s)."""
    out: dict[str, dict[str, float]] = {}
    groups = [("sphere", ~events["partner_is_wall"])]
    groups += [(str(name), events["partner_is_wall"] & (events["j"] == k))
               for k, name in enumerate(wall_names)]
    for name, sel in groups:
        e = events[sel]
        out[name] = {"n_events": int(len(e)),
                     "normal_impulse_N_s": float(e["normal_impulse"].sum()),
                     "peak_normal_force_N": float(e["peak_normal_force"].max()) if len(e) else 0.0,
                     "mean_duration_s": float(e["duration"].mean()) if len(e) else 0.0}
    return out
