"""Deterministic strength threshold: the simple alternative to the Weibull model (Pa).

The paper (Boso et al. 2021) judges the likelihood of crack initiation by the maximum principal
tensile stress alone. :func:`exceeds_threshold` reproduces that reading: a loading "breaks" a
cartridge when its peak tensile stress exceeds a fixed design strength; :func:`utilisation`
gives the margin as a ratio.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from demfem.errors import check_positive
from demfem.risk._validate import as_array

__all__ = ["exceeds_threshold", "utilisation"]


def utilisation(stress: ArrayLike, threshold: float) -> float:
    """max⟨σ⟩ / σ_threshold, dimensionless (0 when nothing is in tension).

    ``stress``: stresses, Pa, any shape, finite; ``threshold``: Pa, finite and > 0.
    """
    limit = check_positive("threshold", threshold)
    s = as_array("stress", stress, unit="Pa")
    if s.size == 0:
        return 0.0
    return float(max(np.max(s), 0.0) / limit)


def exceeds_threshold(stress: ArrayLike, threshold: float) -> bool:
    """True when any tensile stress (Pa) is strictly above ``threshold`` (Pa, > 0)."""
    return utilisation(stress, threshold) > 1.0
