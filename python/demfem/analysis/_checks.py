"""Shape checks shared by the analyses (one place for the error messages)."""
from __future__ import annotations

import numpy as np

from demfem.errors import InvalidParameterError, ShapeError


def as_pairs(pairs: np.ndarray, n_particles: int, name: str = "pairs") -> np.ndarray:
    """``pairs`` as an (n_c, 2) int64 array of distinct particle indices in [0, n_particles)."""
    arr = np.asarray(pairs)
    if arr.size == 0:
        return np.zeros((0, 2), np.int64)
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ShapeError(f"shape mismatch for {name}: expected (n_c, 2), got {arr.shape}")
    if not np.issubdtype(arr.dtype, np.integer):
        raise InvalidParameterError(f"invalid {name} of dtype {arr.dtype}: must be integers")
    arr = arr.astype(np.int64)
    if arr.min() < 0 or arr.max() >= n_particles:
        raise InvalidParameterError(
            f"invalid {name}: indices must be in [0, {n_particles - 1}], "
            f"got [{arr.min()}, {arr.max()}]")
    if np.any(arr[:, 0] == arr[:, 1]):
        k = int(np.flatnonzero(arr[:, 0] == arr[:, 1])[0])
        raise InvalidParameterError(f"invalid {name}[{k}] = {arr[k].tolist()}: a particle "
                                    "cannot touch itself")
    return arr


def as_vectors(values: np.ndarray, name: str) -> np.ndarray:
    """``values`` as a float array whose last axis has length 3."""
    arr = np.asarray(values, float)
    if arr.ndim < 1 or arr.shape[-1] != 3:
        raise ShapeError(f"shape mismatch for {name}: expected (..., 3), got {arr.shape}")
    return arr


def as_fraction(name: str, value: float, hi: float) -> float:
    """``value`` as a float in [0, hi)."""
    x = float(value)
    if not (np.isfinite(x) and 0.0 <= x < hi):
        raise InvalidParameterError(f"invalid {name} = {value!r}: must be finite and in "
                                    f"[0, {hi:g})")
    return x
