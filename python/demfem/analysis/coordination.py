"""Coordination number: how many neighbours touch each sphere (paper Figs. 6, 8, 9).

A square packing has 4 in-plane neighbours per interior sphere, a hexagonal packing 6; the
paper reads the oscillation of the mean coordination between these values as the table's
rearrangement with the gate's period.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
from scipy.spatial import cKDTree

from demfem.analysis._checks import as_pairs
from demfem.errors import InvalidParameterError, ShapeError

__all__ = [
    "contact_pairs_from_positions",
    "coordination_from_positions",
    "coordination_number",
    "coordination_series",
    "mean_coordination",
    "tag_mask",
]


def contact_pairs_from_positions(positions: np.ndarray, radii: np.ndarray,
                                 gap_tolerance: float = 0.0) -> np.ndarray:
    """Pairs of spheres in contact, from their centres.

    Two spheres i < j count as touching if ``|x_i - x_j| <= r_i + r_j + gap_tolerance``;
    a small positive tolerance (m) counts spheres that are a hair apart, e.g. in a start
    packing with a gap or in a recording sampled between contacts.

    Args:
        positions: (N, 3) or (N, 2) centres, m; rows with a non-finite value (removed spheres)
            take part in no pair.
        radii: (N,) radii, m.
        gap_tolerance: largest surface gap still counted as contact, m (>= 0).

    Returns:
        (n_c, 2) int64 array, i < j in each row, rows sorted.
    """
    pos = np.asarray(positions, float)
    rad = np.asarray(radii, float)
    if pos.ndim != 2 or pos.shape[1] not in (2, 3) or rad.shape != (len(pos),):
        raise ShapeError(f"shape mismatch for positions/radii: expected (N, 3) and (N,), got "
                         f"{pos.shape} and {rad.shape}")
    tol = float(gap_tolerance)
    if not (np.isfinite(tol) and tol >= 0):
        raise InvalidParameterError(f"invalid gap_tolerance = {gap_tolerance!r}: must be "
                                    "finite and in [0, inf)")
    present = np.flatnonzero(np.all(np.isfinite(pos), axis=1))
    if len(present) < 2:
        return np.zeros((0, 2), np.int64)
    tree = cKDTree(pos[present])
    candidates = tree.query_pairs(2.0 * rad[present].max() + tol, output_type="ndarray")
    if len(candidates) == 0:
        return np.zeros((0, 2), np.int64)
    i, j = present[candidates[:, 0]], present[candidates[:, 1]]
    touching = np.linalg.norm(pos[i] - pos[j], axis=1) <= rad[i] + rad[j] + tol
    pairs = np.sort(np.column_stack([i, j])[touching], axis=1)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


def coordination_number(pairs: np.ndarray, n_particles: int) -> np.ndarray:
    """Number of contacts of each particle.

    Args:
        pairs: (n_c, 2) int indices of the particles of each contact; each contact once, in
            either order ((i, j) and (j, i) together count once).
        n_particles: N.

    Returns:
        (N,) int64 coordination numbers.
    """
    pairs = as_pairs(pairs, n_particles)
    if len(pairs):
        pairs = np.unique(np.sort(pairs, axis=1), axis=0)
    return np.bincount(pairs.ravel(), minlength=n_particles).astype(np.int64)


def coordination_series(pairs_per_frame: Sequence[np.ndarray], n_particles: int) -> np.ndarray:
    """Coordination of every particle in every frame: (n_frames, N) int64, from one (n_c, 2)
    contact list per frame."""
    return np.array([coordination_number(p, n_particles) for p in pairs_per_frame],
                    dtype=np.int64).reshape(len(pairs_per_frame), n_particles)


def coordination_from_positions(positions: np.ndarray, radii: np.ndarray,
                                gap_tolerance: float = 0.0) -> np.ndarray:
    """Coordination of every sphere from its centres, for one frame (N, 3) -> (N,) or a
    recording (n_frames, N, 3) -> (n_frames, N); contacts as in
    :func:`contact_pairs_from_positions` (surface gap <= ``gap_tolerance``, m). Spheres with
    NaN rows (removed) get 0; leave them out of means with ``present``."""
    pos = np.asarray(positions, float)
    if pos.ndim == 2:
        return coordination_number(contact_pairs_from_positions(pos, radii, gap_tolerance),
                                   len(pos))
    if pos.ndim != 3:
        raise ShapeError(f"shape mismatch for positions: expected (N, 3) or (n_frames, N, 3), "
                         f"got {pos.shape}")
    return coordination_series(
        [contact_pairs_from_positions(frame, radii, gap_tolerance) for frame in pos],
        pos.shape[1])


def tag_mask(tags: np.ndarray, *codes: int) -> np.ndarray:
    """(N,) bool: particles whose tag is one of ``codes``."""
    return np.isin(np.asarray(tags), np.asarray(codes, dtype=np.asarray(tags).dtype))


def mean_coordination(coordination: np.ndarray, select: np.ndarray | None = None,
                      present: np.ndarray | None = None) -> np.ndarray | float:
    """Mean coordination over all particles or a selection, per frame.

    Args:
        coordination: (N,) or (n_frames, N) coordination numbers.
        select: (N,) bool mask or index array of the particles to average (e.g.
            ``tag_mask(tags, Tag.FIRST_LINE)``); all particles by default.
        present: (N,) or (n_frames, N) bool, False for particles that have left the table;
            they are left out of the mean. All present by default.

    Returns:
        A float for (N,) input, else (n_frames,); NaN where no selected particle is present.
    """
    z = np.asarray(coordination, float)
    single = z.ndim == 1
    z = np.atleast_2d(z)
    n = z.shape[1]
    weight = np.ones_like(z, dtype=bool)
    if select is not None:
        sel = np.asarray(select)
        mask = np.zeros(n, bool)
        if sel.dtype == np.bool_:
            if sel.shape != (n,):
                raise ShapeError(f"shape mismatch for select: expected ({n},), got {sel.shape}")
            mask = sel
        else:
            mask[sel] = True
        weight &= mask[None, :]
    if present is not None:
        pres = np.asarray(present, bool)
        if pres.shape[-1] != n:
            raise ShapeError(f"shape mismatch for present: expected (..., {n}), got "
                             f"{pres.shape}")
        weight &= np.atleast_2d(pres)
    count = weight.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count > 0, np.where(weight, z, 0.0).sum(axis=1) / np.maximum(count, 1), np.nan)
    return float(mean[0]) if single else mean
