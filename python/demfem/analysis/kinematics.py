"""Speeds of spheres and groups of spheres (paper Figs. 7, 8b, 9b, 9d), and the robust
'middle' average of Fig. 9d."""
from __future__ import annotations

import numpy as np

from demfem.analysis._checks import as_fraction, as_vectors
from demfem.errors import ShapeError

__all__ = ["speed", "tagged_speed", "middle_mean", "spheres_riding_up"]


def speed(velocities: np.ndarray) -> np.ndarray:
    """Speed |v| in m/s of each velocity (..., 3) in m/s; shape (...). NaN stays NaN."""
    return np.linalg.norm(as_vectors(velocities, "velocities"), axis=-1)


def tagged_speed(velocities: np.ndarray, tags: np.ndarray, tag: int) -> np.ndarray:
    """Mean speed in m/s of the spheres carrying ``tag``, per frame.

    Args:
        velocities: (n_frames, N, 3) velocities, m/s; NaN rows are spheres that have left.
        tags: (N,) tag codes.
        tag: the code to follow (for a single tagged sphere, its own speed).

    Returns:
        (n_frames,) mean speed, m/s; NaN in frames where none of them is on the table.
    """
    v = as_vectors(velocities, "velocities")
    tags = np.asarray(tags)
    if v.ndim != 3 or tags.shape != (v.shape[1],):
        raise ShapeError(f"shape mismatch for velocities/tags: expected (n_frames, N, 3) and "
                         f"(N,), got {v.shape} and {tags.shape}")
    s = speed(v[:, tags == tag, :])
    count = np.isfinite(s).sum(axis=1)
    total = np.where(np.isfinite(s), s, 0.0).sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / np.maximum(count, 1), np.nan)


def _middle_mean_1d(values: np.ndarray, drop: float) -> float:
    finite = np.sort(values[np.isfinite(values)])
    n = len(finite)
    cut = int(np.floor(drop * n))
    kept = finite[cut:n - cut]
    return float(kept.mean()) if len(kept) else np.nan


def middle_mean(values: np.ndarray, drop: float = 0.1, axis: int = -1) -> np.ndarray | float:
    """'Middle' mean: the mean after dropping the extremes (paper Fig. 9d).

    Along ``axis``, the finite values are sorted and ``floor(drop * n)`` of them are dropped at
    each end (n = number of finite values; NaN marks spheres that have left and is ignored);
    the rest are averaged. ``drop = 0`` is the plain mean; as ``drop`` nears 0.5 it tends to
    the median. The paper does not say how many values it dropped; 10 % at each end is our
    default.

    Args:
        values: array of any shape, in any unit (the result has the same unit).
        drop: fraction dropped at each end, in [0, 0.5).
        axis: axis to average over.

    Returns:
        The middle mean, with ``axis`` removed; NaN where nothing is left.
    """
    drop = as_fraction("drop", drop, 0.5)
    arr = np.asarray(values, float)
    if arr.ndim == 0:
        raise ShapeError("shape mismatch for values: expected at least one axis, got a scalar")
    result = np.apply_along_axis(_middle_mean_1d, axis, arr, drop)
    return float(result) if result.ndim == 0 else result


def spheres_riding_up(positions: np.ndarray, radii: np.ndarray, floor_z: float = 0.0,
                      tolerance: float = 0.002) -> np.ndarray | int:
    """Number of spheres per frame whose centre is more than ``tolerance`` (m) above the
    height of a sphere resting on the belt (``floor_z + radius``): spheres riding on their
    neighbours, which an upright cartridge cannot do (DESIGN section 4, effect "planar").

    Args:
        positions: (N, 3) or (n_frames, N, 3) centres, m; NaN rows are not counted.
        radii: (N,) radii, m.
        floor_z: belt height, m.
        tolerance: height above resting still counted as on the belt, m.

    Returns:
        int for one frame, else (n_frames,) int64.
    """
    pos = as_vectors(positions, "positions")
    rad = np.asarray(radii, float)
    if pos.shape[-2] != rad.shape[0]:
        raise ShapeError(f"shape mismatch for positions/radii: {pos.shape} and {rad.shape}")
    with np.errstate(invalid="ignore"):
        up = pos[..., 2] > floor_z + rad + tolerance
    count = up.sum(axis=-1)
    return int(count) if np.ndim(count) == 0 else count.astype(np.int64)
