"""The collision-onset table: one row per contact that starts, with how hard and at what angle
the partners met and how crowded each was (the DEM input the paper's FEM cases are chosen
from: relative speeds and impact directions at the onset of collisions)."""
from __future__ import annotations

from typing import Sequence

import numpy as np

from demfem.analysis._checks import as_fraction, as_vectors
from demfem.errors import InvalidParameterError, ShapeError

__all__ = [
    "ONSET_DTYPE",
    "WALL_ONSET_DTYPE",
    "collision_onset_table",
    "onset_histogram",
    "onset_quantiles",
]

#: Fields of the onset table. Speeds in m/s, time in s, angle in rad.
ONSET_DTYPE = np.dtype([
    ("i", "i8"), ("j", "i8"),
    ("time", "f8"),
    ("normal_speed", "f8"),
    ("tangential_speed", "f8"),
    ("impact_angle", "f8"),
    ("coordination_i", "i8"), ("coordination_j", "i8"),
])

#: Fields of the sphere-wall onset table: sphere i, wall index (into the run's
#: ``info["wall_names"]``), time (s), normal and tangential speed relative to the wall's
#: surface (m/s), impact angle (rad), contact point on the wall (m), coordination of i.
WALL_ONSET_DTYPE = np.dtype([
    ("i", "i8"), ("wall", "i8"),
    ("time", "f8"),
    ("normal_speed", "f8"),
    ("tangential_speed", "f8"),
    ("impact_angle", "f8"),
    ("x", "f8"), ("y", "f8"), ("z", "f8"),
    ("coordination_i", "i8"),
])

_NUMERIC_FIELDS = ("time", "normal_speed", "tangential_speed", "impact_angle",
                   "coordination_i", "coordination_j")


def collision_onset_table(pairs: np.ndarray, times: np.ndarray,
                          relative_velocities: np.ndarray, normals: np.ndarray,
                          coordination: np.ndarray) -> np.ndarray:
    """Build the onset table from an engine's onset log.

    Conventions: ``v_rel = v_i - v_j`` (velocities of the centres; the contact-point velocity
    from spins is left out because it does not change the approach speed), ``n`` the unit
    vector from the centre of i to the centre of j. Then

    * normal speed ``v_n = v_rel . n`` (> 0 while the pair approaches, as it does at onset),
    * tangential speed ``v_t = |v_rel - (v_rel . n) n|``,
    * impact angle ``atan2(v_t, v_n)``: 0 for a head-on impact, pi/2 for a grazing one.

    Args:
        pairs: (n, 2) int particle indices (i, j) of each onset.
        times: (n,) onset times, s.
        relative_velocities: (n, 3) v_i - v_j at onset, m/s.
        normals: (n, 3) centre-to-centre directions i -> j; normalised here.
        coordination: (n, 2) int coordination of i and of j at onset (counting this contact
            or not, as the engine logs it; say which when you publish).

    Returns:
        Structured array of :data:`ONSET_DTYPE`, in time order.
    """
    pairs = np.asarray(pairs)
    n = len(pairs)
    times = np.asarray(times, float)
    v = as_vectors(relative_velocities, "relative_velocities")
    normal = as_vectors(normals, "normals")
    z = np.asarray(coordination)
    if (pairs.shape != (n, 2) or times.shape != (n,) or v.shape != (n, 3)
            or normal.shape != (n, 3) or z.shape != (n, 2)):
        raise ShapeError(
            f"shape mismatch for the onset log: pairs {pairs.shape}, times {times.shape}, "
            f"relative_velocities {v.shape}, normals {normal.shape}, coordination {z.shape}; "
            f"expected (n, 2), (n,), (n, 3), (n, 3), (n, 2)")
    if n and not (np.issubdtype(pairs.dtype, np.integer) and np.issubdtype(z.dtype, np.integer)):
        raise InvalidParameterError("invalid pairs/coordination: must be integers")
    length = np.linalg.norm(normal, axis=1)
    if np.any(~np.isfinite(length) | (length <= 0)):
        k = int(np.flatnonzero(~np.isfinite(length) | (length <= 0))[0])
        raise InvalidParameterError(f"invalid normals[{k}] = {normal[k].tolist()}: must be a "
                                    "finite non-zero vector")
    if not (np.all(np.isfinite(times)) and np.all(np.isfinite(v))):
        raise InvalidParameterError("invalid times/relative_velocities: must be finite")
    unit = normal / length[:, None]
    v_n = np.einsum("ij,ij->i", v, unit)
    v_t = np.linalg.norm(v - v_n[:, None] * unit, axis=1)
    table = np.zeros(n, ONSET_DTYPE)
    table["i"], table["j"] = pairs[:, 0], pairs[:, 1]
    table["time"] = times
    table["normal_speed"] = v_n
    table["tangential_speed"] = v_t
    table["impact_angle"] = np.arctan2(v_t, v_n)
    table["coordination_i"], table["coordination_j"] = z[:, 0], z[:, 1]
    return table[np.argsort(times, kind="stable")]


def _field(table: np.ndarray, field: str) -> np.ndarray:
    if field not in _NUMERIC_FIELDS:
        raise InvalidParameterError(f"invalid field = {field!r}: must be one of "
                                    + ", ".join(_NUMERIC_FIELDS))
    return np.asarray(table[field], float)


def onset_histogram(table: np.ndarray, field: str,
                    bins: int | Sequence[float] = 20,
                    value_range: tuple[float, float] | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Histogram of one field of the onset table (e.g. "normal_speed" in m/s,
    "impact_angle" in rad): (counts (n_bins,), edges (n_bins + 1,)), as :func:`numpy.histogram`.
    """
    return np.histogram(_field(table, field), bins=bins, range=value_range)


def onset_quantiles(table: np.ndarray, field: str,
                    q: Sequence[float] = (0.5, 0.9, 0.95, 0.99)) -> np.ndarray:
    """Quantiles of one field of the onset table, in the field's unit; NaN for an empty table.
    """
    probabilities = np.array([as_fraction("q", x, 1.0 + 1e-12) for x in q])
    values = _field(table, field)
    if len(values) == 0:
        return np.full(len(probabilities), np.nan)
    return np.quantile(values, probabilities)
