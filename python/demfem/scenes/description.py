"""The engine-neutral scene of a table: the tag codes of Fig. 4, the wall-motion convention
shared by the engines, plots and tests, and :class:`SceneDescription` (positions, radii,
masses, tags, walls, effects, materials; saved to and loaded from ``.npz``).

SI units: m, kg, s, Pa.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from enum import IntEnum
from pathlib import Path
from typing import Any, Mapping

import numpy as np
from scipy.spatial import cKDTree

from demfem.errors import DemfemIOError, InvalidParameterError
from demfem.io.atomic import atomic_path

__all__ = ["SceneDescription", "Tag", "TAG_NAMES", "wall_displacement", "wall_velocity"]


class Tag(IntEnum):
    """Integer codes of the tagged spheres of Fig. 4 (``SceneDescription.tags``)."""

    NONE = 0
    TRIANGULAR_CENTRE = 1
    RECTANGULAR_CENTRE = 2
    UPPER_VERTEX = 3
    LOWER_VERTEX = 4
    FIRST_LINE = 5


#: Readable names of the tag codes, e.g. for legends and file point data.
TAG_NAMES: dict[int, str] = {
    Tag.NONE: "untagged",
    Tag.TRIANGULAR_CENTRE: "triangular centre",
    Tag.RECTANGULAR_CENTRE: "rectangular centre",
    Tag.UPPER_VERTEX: "upper vertex",
    Tag.LOWER_VERTEX: "lower vertex",
    Tag.FIRST_LINE: "first line",
}


# --------------------------------------------------------------------------------------------
# Wall motion convention: one place, used by engines, plots and tests alike.
# --------------------------------------------------------------------------------------------

def wall_displacement(motion: Mapping[str, Any], t: float) -> np.ndarray:
    """Displacement (3,) in m of a wall at time ``t`` (s) from its reference position.

    ``{"kind": "fixed"}`` never moves. ``{"kind": "harmonic", "direction", "amplitude",
    "period", "phase"}`` moves rigidly by
    ``direction * amplitude * sin(2 pi t / period + phase)`` (direction a unit vector,
    amplitude in m, period in s, phase in rad). The reference position is the one at which the
    sine is zero, i.e. the wall's vertices as stored in the description.
    """
    if motion["kind"] == "fixed":
        return np.zeros(3)
    phase = 2.0 * math.pi * t / motion["period"] + motion["phase"]
    return np.asarray(motion["direction"], float) * motion["amplitude"] * math.sin(phase)


def wall_velocity(motion: Mapping[str, Any], t: float) -> np.ndarray:
    """Velocity (3,) in m/s of a wall at time ``t`` (s); the time derivative of
    :func:`wall_displacement`."""
    if motion["kind"] == "fixed":
        return np.zeros(3)
    omega = 2.0 * math.pi / motion["period"]
    phase = omega * t + motion["phase"]
    return np.asarray(motion["direction"], float) * motion["amplitude"] * omega * math.cos(phase)


# --------------------------------------------------------------------------------------------
# The engine-neutral description
# --------------------------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class SceneDescription:
    """Everything an engine needs to run a scene, as numpy arrays and plain data (SI units).

    Attributes:
        positions: (N, 3) sphere centres at t = 0, m.
        radii: (N,) sphere radii, m.
        masses: (N,) sphere masses, kg.
        tags: (N,) int32 tag codes (:class:`Tag`).
        tag_names: tag code -> readable name.
        walls: list of dicts, each with
            ``name``; ``kind`` "plane" (``point`` (3,), ``normal`` (3,) unit, pointing into the
            space the spheres occupy) or "polygon" (``vertices`` (k, 3) planar and convex,
            ``normal`` (3,) unit, the side the spheres are on); ``motion`` (see
            :func:`wall_displacement`); ``surface_velocity`` (3,) m/s, the velocity of the
            wall's surface that enters the contact law while the geometry stays put (the belt);
            ``material`` (key of ``materials``); ``top_view`` (2, 2) the wall's trace in the
            table plane at its reference position, for drawing (planes are infinite for
            contact; the trace shows the physical wall's extent), or ``None`` for the belt.
        effects: names of the physics the scene needs; an engine must refuse to run a scene
            whose effects it does not implement, and must not add others.
        materials: material name -> {"young_modulus" Pa, "poisson_ratio", "density" kg/m^3,
            "friction", "restitution", "rolling_resistance"}.
        particle_material: key of ``materials`` for the spheres.
        gravity: (3,) m/s^2.
        removal: {"kind": "half_space", "point" (3,), "normal" (3,)}: a sphere whose centre c
            has (c - point) . normal > 0 has left the table and is removed.
        refeed: ``None``, or {"sites" (k, 3), "velocity" (3,)}: a removed sphere is re-inserted,
            at rest relative to ``velocity``, at the first site (in order) where it overlaps
            nothing; if no site is free it waits for the next step.
        planar: True if the "planar" effect is on (centres kept at z = radius).
        parameters: the scene's own parameters, for the record.
    """

    positions: np.ndarray
    radii: np.ndarray
    masses: np.ndarray
    tags: np.ndarray
    tag_names: dict[int, str]
    walls: list[dict[str, Any]]
    effects: tuple[str, ...]
    materials: dict[str, dict[str, float]]
    particle_material: str
    gravity: np.ndarray
    removal: dict[str, Any]
    refeed: dict[str, Any] | None
    planar: bool
    parameters: dict[str, Any] = field(default_factory=dict)

    @property
    def n_particles(self) -> int:
        """Number of spheres at t = 0."""
        return int(self.positions.shape[0])

    def wall(self, name: str) -> dict[str, Any]:
        """The wall called ``name``."""
        for w in self.walls:
            if w["name"] == name:
                return w
        names = ", ".join(w["name"] for w in self.walls)
        raise InvalidParameterError(f"invalid wall name = {name!r}: must be one of {names}")

    # Keys of wall, motion, removal and refeed dicts that hold vectors: stored as lists in the
    # file, restored as arrays.
    _VECTOR_KEYS = ("point", "normal", "vertices", "surface_velocity", "top_view", "direction",
                    "sites", "velocity")

    def save(self, path: str | Path) -> Path:
        """Save to a ``.npz`` file (arrays as arrays, the rest as one JSON document; no
        pickle), written atomically; :meth:`load` reads it back."""

        def plain(value: Any) -> Any:
            if isinstance(value, np.ndarray):
                return value.tolist()
            if isinstance(value, (np.floating, np.integer)):
                return value.item()
            if isinstance(value, dict):
                return {str(k): plain(v) for k, v in value.items()}
            if isinstance(value, (list, tuple)):
                return [plain(v) for v in value]
            return value

        document = {
            "tag_names": plain(self.tag_names), "walls": plain(self.walls),
            "effects": list(self.effects), "materials": plain(self.materials),
            "particle_material": self.particle_material, "removal": plain(self.removal),
            "refeed": plain(self.refeed), "planar": self.planar,
            "parameters": plain(self.parameters),
        }
        with atomic_path(path, suffix=".npz") as tmp:
            with open(tmp, "wb") as handle:  # a handle: np.savez would append ".npz" to a name
                np.savez(handle, positions=self.positions, radii=self.radii,
                         masses=self.masses, tags=self.tags, gravity=self.gravity,
                         document=np.array(json.dumps(document)))
        return Path(path)

    @classmethod
    def load(cls, path: str | Path) -> "SceneDescription":
        """Read a description written by :meth:`save`."""

        def arrays(value: Any) -> Any:
            if isinstance(value, dict):
                return {k: (np.asarray(v, float) if k in cls._VECTOR_KEYS and v is not None
                            else arrays(v)) for k, v in value.items()}
            if isinstance(value, list):
                return [arrays(v) for v in value]
            return value

        try:
            with np.load(path, allow_pickle=False) as data:
                document = json.loads(str(data["document"]))
                fields = {k: data[k] for k in ("positions", "radii", "masses", "tags",
                                               "gravity")}
        except OSError as exc:
            raise DemfemIOError(f"i/o error on {path}: {exc}") from None
        except (KeyError, ValueError) as exc:
            raise InvalidParameterError(
                f"invalid scene description file {path}: {exc}") from None
        return cls(
            tag_names={int(k): v for k, v in document["tag_names"].items()},
            walls=arrays(document["walls"]),
            effects=tuple(document["effects"]),
            materials=document["materials"],
            particle_material=document["particle_material"],
            removal=arrays(document["removal"]),
            refeed=arrays(document["refeed"]),
            planar=bool(document["planar"]),
            parameters=document["parameters"],
            **fields,
        )

    def check_start_positions(self) -> None:
        """Raise :class:`InvalidParameterError` if two spheres overlap or a sphere is not
        inside every wall at t = 0.

        "Inside" uses each wall's plane (a polygon's supporting plane): the signed distance of
        the centre must be at least the radius. That is exact because the table is convex.
        """
        pos, rad = self.positions, self.radii
        if not np.all(np.isfinite(pos)):
            bad = int(np.flatnonzero(~np.all(np.isfinite(pos), axis=1))[0])
            raise InvalidParameterError(
                f"invalid positions[{bad}] = {pos[bad].tolist()}: must be finite")
        tree = cKDTree(pos)
        pairs = tree.query_pairs(2.0 * float(rad.max()), output_type="ndarray")
        if len(pairs):
            dist = np.linalg.norm(pos[pairs[:, 0]] - pos[pairs[:, 1]], axis=1)
            overlap = rad[pairs[:, 0]] + rad[pairs[:, 1]] - dist
            k = int(np.argmax(overlap))
            if overlap[k] > 0.0:
                i, j = pairs[k]
                raise InvalidParameterError(
                    f"invalid positions: spheres {i} and {j} overlap by {overlap[k]:.3g} m; "
                    "start positions must not overlap")
        for w in self.walls:
            point = w["point"] if w["kind"] == "plane" else w["vertices"][0]
            signed = (pos - point) @ np.asarray(w["normal"])
            k = int(np.argmin(signed - rad))
            if signed[k] < rad[k] * (1.0 - 1e-9):
                raise InvalidParameterError(
                    f"invalid positions[{k}] = {pos[k].tolist()}: the sphere crosses wall "
                    f"{w['name']!r} (centre {signed[k]:.4g} m from it, radius {rad[k]:.4g} m); "
                    "start positions must lie inside every wall")
        ahead = (pos - self.removal["point"]) @ np.asarray(self.removal["normal"])
        if np.any(ahead > 0):
            k = int(np.argmax(ahead))
            raise InvalidParameterError(
                f"invalid positions[{k}] = {pos[k].tolist()}: the sphere starts in the removal "
                "region; start positions must be on the table")


# --------------------------------------------------------------------------------------------
# The scene's parameters
# --------------------------------------------------------------------------------------------

def _is_bool(value: Any) -> bool:
    return isinstance(value, (bool, np.bool_))
