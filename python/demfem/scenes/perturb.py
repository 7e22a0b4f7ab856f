"""Perturbed starts: the same scene with its spheres moved by a small seeded random amount,
so that independent replicas of a table in operation follow different trajectories.

The DEM is deterministic (bitwise the same on any number of threads), so two runs of one
scene are one run twice. A replica needs another start: :func:`perturbed_start` moves every
sphere of a :class:`~demfem.scenes.description.SceneDescription` within the plane of the belt
(x, y; the height is kept, so a sphere on the belt stays on it) by a point drawn uniformly in
a disc of radius ``fraction`` × the start's **clearance**, the largest move that can never
make two spheres touch or a sphere touch a wall: half the narrowest gap between two spheres,
and the narrowest gap between a sphere and a wall or the removal plane
(:func:`start_clearance`). On the built-in table (packing gap 1 % of the 16.17 mm diameter)
the clearance is 81 µm and the default moves are at most half of it, 40 µm: far below
anything the table's geometry resolves, while the granular flow, which is chaotic, turns
them into different collision histories within a fraction of the 2 s warm-up.

The draws come from ``numpy.random.default_rng(seed)`` in sphere order, so a seed gives the
same moves on any machine and two set-ups with the same spheres get the same moves (common
random starts for paired comparisons). SI units: m.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.spatial import cKDTree

from demfem.errors import InvalidParameterError, check_count, check_range

__all__ = ["start_clearance", "perturbed_start", "DEFAULT_FRACTION"]

#: Default largest move as a fraction of the start's clearance.
DEFAULT_FRACTION = 0.5


def start_clearance(description) -> float:
    """The largest distance (m) every sphere of ``description`` can move at t = 0 without
    touching another sphere, a wall or the removal plane: the smallest of half of every gap
    between two spheres and every gap between a sphere and a wall's plane (the walls of the
    table are convex, as :meth:`SceneDescription.check_start_positions` assumes) or the
    removal plane. 0 when something touches already."""
    pos = np.asarray(description.positions, float)
    rad = np.asarray(description.radii, float)
    if len(pos) == 0:
        return math.inf
    best = math.inf
    if len(pos) > 1:
        tree = cKDTree(pos)
        dist, idx = tree.query(pos, k=2)
        gap = dist[:, 1] - rad - rad[idx[:, 1]]
        # the nearest centre is not always the nearest surface for unequal radii: check every
        # pair within the largest possible touching distance of the nearest gap
        reach = 2.0 * float(rad.max()) + max(float(gap.min()), 0.0)
        pairs = tree.query_pairs(reach, output_type="ndarray")
        if len(pairs):
            d = np.linalg.norm(pos[pairs[:, 0]] - pos[pairs[:, 1]], axis=1)
            gap = np.concatenate([gap, d - rad[pairs[:, 0]] - rad[pairs[:, 1]]])
        best = min(best, 0.5 * float(gap.min()))
    for w in description.walls:
        point = w["point"] if w["kind"] == "plane" else w["vertices"][0]
        normal = np.asarray(w["normal"], float)
        if abs(normal[2]) > 1.0 - 1e-12:
            continue  # the belt (or a ceiling): the moves are parallel to it
        signed = (pos - np.asarray(point, float)) @ normal
        # only the in-plane part of the normal sees an in-plane move
        scale = math.hypot(normal[0], normal[1])
        best = min(best, float(np.min((signed - rad) / scale)))
    removal = description.removal
    if removal:
        normal = np.asarray(removal["normal"], float)
        ahead = (np.asarray(removal["point"], float) - pos) @ normal
        scale = math.hypot(normal[0], normal[1])
        if scale > 0:
            best = min(best, float(np.min(ahead / scale)))
    return max(best, 0.0)


def perturbed_start(description, seed: int, fraction: float = DEFAULT_FRACTION):
    """``description`` with every sphere moved in the x–y plane by a uniform random point of
    the disc of radius ``fraction`` × :func:`start_clearance` (m), drawn from
    ``numpy.random.default_rng(seed)`` (see the module text); the heights, radii and
    everything else are kept. The result is checked
    (:meth:`~demfem.scenes.description.SceneDescription.check_start_positions`).

    Args:
        description: the scene's :class:`SceneDescription`.
        seed: whole number ≥ 0.
        fraction: the largest move over the clearance, in (0, 1).

    Raises:
        InvalidParameterError: a bad seed or fraction, or a start with no clearance (spheres
            or walls touching at t = 0, e.g. ``packing_gap = 0``), naming what to change.
    """
    seed = check_count("seed", seed, 0)
    fraction = check_range("fraction", fraction, 0.0, 1.0)
    room = start_clearance(description)
    if not room > 0.0:
        raise InvalidParameterError(
            f"invalid seed = {seed}: a perturbed start needs room between the spheres and from "
            "the walls at t = 0, and this scene's start has none (its spheres or walls touch; "
            "give the table a packing_gap > 0)")
    rng = np.random.default_rng(seed)
    n = len(description.positions)
    radius = fraction * min(room, 1.0) * np.sqrt(rng.random(n))
    angle = 2.0 * math.pi * rng.random(n)
    pos = np.array(description.positions, float, copy=True)
    pos[:, 0] += radius * np.cos(angle)
    pos[:, 1] += radius * np.sin(angle)
    moved = dataclasses.replace(description, positions=pos)
    moved.check_start_positions()
    return moved
