"""Packing order in the table plane: bond-orientational order parameters psi_4 and psi_6.

For a sphere i with neighbours j, psi_m(i) = (1/n_i) sum_j exp(i m theta_ij), where theta_ij is
the angle of the bond i -> j in the table plane (x, y). |psi_4| = 1 for a sphere inside a
square packing and |psi_6| = 1 inside a hexagonal one; each is 0 in the other lattice. This
tells the square start packing of the rectangular section (Fig. 4) from the hexagonal order the
paper sees the table pass through with the gate's period.
"""
from __future__ import annotations

import numpy as np

from demfem.analysis._checks import as_pairs
from demfem.analysis.coordination import contact_pairs_from_positions
from demfem.errors import InvalidParameterError, ShapeError

__all__ = ["bond_order", "bond_order_psi4", "bond_order_psi6", "mean_bond_order"]


def bond_order(positions: np.ndarray, m: int, pairs: np.ndarray | None = None,
               cutoff: float | None = None) -> np.ndarray:
    """Bond-orientational order psi_m of each sphere in the x-y plane (one frame).

    Neighbours are given either as a contact list ``pairs`` (e.g. the engine's contacts, or
    :func:`~demfem.analysis.coordination.contact_pairs_from_positions`) or by a ``cutoff``:
    spheres whose centres are at most ``cutoff`` apart in the plane (m; about 1.2 diameters
    takes the first shell of both lattices).

    Args:
        positions: (N, 2) or (N, 3) centres, m (z is ignored); NaN rows have no neighbours.
        m: symmetry order (4 for square, 6 for hexagonal), >= 1.
        pairs: (n_c, 2) neighbour pairs, each once.
        cutoff: neighbour distance, m, if ``pairs`` is not given.

    Returns:
        (N,) complex psi_m; NaN for spheres without neighbours.
    """
    pos = np.asarray(positions, float)
    if pos.ndim != 2 or pos.shape[1] not in (2, 3):
        raise ShapeError(f"shape mismatch for positions: expected (N, 2) or (N, 3), "
                         f"got {pos.shape}")
    if int(m) != m or m < 1:
        raise InvalidParameterError(f"invalid m = {m!r}: must be a whole number >= 1")
    n = len(pos)
    xy = pos[:, :2]
    if (pairs is None) == (cutoff is None):
        raise InvalidParameterError("invalid neighbours: give exactly one of pairs and cutoff")
    if pairs is None:
        assert cutoff is not None  # exactly one of the two was given, checked above
        if not (np.isfinite(cutoff) and cutoff > 0):
            raise InvalidParameterError(f"invalid cutoff = {cutoff!r}: must be finite and in "
                                        "(0, inf)")
        # Points of zero radius touching within the cutoff: the same neighbour search.
        pairs = contact_pairs_from_positions(xy, np.zeros(n), gap_tolerance=cutoff)
    pairs = as_pairs(pairs, n)
    pairs = np.unique(np.sort(pairs, axis=1), axis=0) if len(pairs) else pairs
    i, j = pairs[:, 0], pairs[:, 1]
    d = xy[j] - xy[i]
    bond = np.exp(1j * m * np.arctan2(d[:, 1], d[:, 0]))
    # The bond j -> i points the opposite way: its factor is exp(i m pi) = (-1)^m times.
    back = bond * (-1.0) ** m
    total = (np.bincount(i, bond.real, n) + np.bincount(j, back.real, n)
             + 1j * (np.bincount(i, bond.imag, n) + np.bincount(j, back.imag, n)))
    count = np.bincount(pairs.ravel(), minlength=n)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / np.maximum(count, 1), np.nan + 1j * np.nan)


def bond_order_psi4(positions: np.ndarray, pairs: np.ndarray | None = None,
                    cutoff: float | None = None) -> np.ndarray:
    """Square order psi_4 of each sphere (see :func:`bond_order`); (N,) complex."""
    return bond_order(positions, 4, pairs=pairs, cutoff=cutoff)


def bond_order_psi6(positions: np.ndarray, pairs: np.ndarray | None = None,
                    cutoff: float | None = None) -> np.ndarray:
    """Hexagonal order psi_6 of each sphere (see :func:`bond_order`); (N,) complex."""
    return bond_order(positions, 6, pairs=pairs, cutoff=cutoff)


def mean_bond_order(psi: np.ndarray, select: np.ndarray | None = None) -> float:
    """Mean of |psi_i| over the spheres that have neighbours (optionally only ``select``, a
    bool mask or index array): 1 for a perfect lattice of that symmetry whatever its
    orientation; NaN if no selected sphere has neighbours."""
    magnitude = np.abs(np.asarray(psi))
    if select is not None:
        magnitude = magnitude[np.asarray(select)]
    magnitude = magnitude[np.isfinite(magnitude)]
    return float(magnitude.mean()) if len(magnitude) else float("nan")
