"""Argument checks shared by :mod:`demfem.risk` (private).

Scalars go through :func:`demfem.errors.check_range` / :func:`demfem.errors.check_positive`;
arrays through the helpers here, which raise :class:`demfem.errors.InvalidParameterError` with a
message naming the field, the first offending element and the allowed range.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from demfem.errors import InvalidParameterError, ShapeError

__all__ = ["RiskShapeError", "as_array", "check_same_shape"]


class RiskShapeError(InvalidParameterError, ShapeError):
    """Arrays of :mod:`demfem.risk` whose shapes do not fit together.

    Both an :class:`~demfem.errors.InvalidParameterError` (what the risk API promises) and a
    :class:`~demfem.errors.ShapeError` (the project's class for shape mismatches)."""


def _interval(lo: float, hi: float, lo_open: bool, hi_open: bool) -> str:
    left = "(" if lo_open else "["
    right = ")" if hi_open else "]"
    return f"{left}{lo:g}, {hi:g}{right}"


def as_array(
    field: str,
    value: Any,
    lo: float = -math.inf,
    hi: float = math.inf,
    *,
    lo_open: bool = True,
    hi_open: bool = True,
    ndim: int | None = None,
    unit: str = "",
) -> NDArray[np.float64]:
    """``value`` as a float64 array whose every element is finite and inside the interval.

    ``ndim`` (if given) is the required number of dimensions; a 0-d input is promoted to 1-d
    when ``ndim == 1``. Raises :class:`InvalidParameterError` naming ``field`` otherwise.
    """
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidParameterError(
            f"invalid {field} = {value!r}: must be an array of real numbers"
        ) from None
    if ndim is not None:
        if ndim == 1 and arr.ndim == 0:
            arr = arr.reshape(1)
        if arr.ndim != ndim:
            raise RiskShapeError(
                f"invalid {field}: shape {arr.shape} has {arr.ndim} dimension(s), must have {ndim}"
            )
    lo_ok = arr > lo if lo_open else arr >= lo
    hi_ok = arr < hi if hi_open else arr <= hi
    bad = ~(np.isfinite(arr) & lo_ok & hi_ok)
    if np.any(bad):
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        where = f"[{', '.join(map(str, idx))}]" if arr.ndim else ""
        suffix = f" ({unit})" if unit else ""
        raise InvalidParameterError(
            f"invalid {field}{where} = {arr[idx]!r}: must be finite and in "
            f"{_interval(lo, hi, lo_open, hi_open)}{suffix}"
        )
    return arr


def check_same_shape(**arrays: NDArray[np.float64]) -> None:
    """Raise :class:`RiskShapeError` naming the fields unless all arrays share one shape."""
    items = list(arrays.items())
    first_name, first = items[0]
    for name, arr in items[1:]:
        if arr.shape != first.shape:
            raise RiskShapeError(
                f"invalid {name}: shape {arr.shape} does not match {first_name} shape {first.shape}"
            )
