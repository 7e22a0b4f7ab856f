"""Weibull parameters of one glass surface (SI units: Pa, m²).

A cartridge has two surfaces with different flaw populations: the inner surface, formed from
the melt and never touched by tools or neighbours (pristine, strong), and the outer surface,
abraded by forming rolls, transport and glass-to-glass contact (handled, weaker). Each gets its
own :class:`SurfaceStrength`; the documented defaults are in :mod:`demfem.risk.defaults`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

from numpy.typing import ArrayLike

from demfem.errors import check_positive
from demfem.risk.weibull import effective_area, failure_probability, weibull_strength_at_area

__all__ = ["SurfaceStrength"]


@dataclass(frozen=True)
class SurfaceStrength:
    """Two-parameter Weibull strength of a glass surface, validated on construction.

    Parameters
    ----------
    weibull_modulus:
        m, dimensionless; finite and > 0.
    characteristic_strength:
        σ_0, Pa; finite and > 0: 63.2 % failure probability of ``reference_area`` under uniform
        tension.
    reference_area:
        A_0, m²; finite and > 0.
    source:
        Where the values come from, or the words "planning assumption" and a range.
    """

    weibull_modulus: float
    characteristic_strength: float
    reference_area: float
    source: str = "unspecified"

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "weibull_modulus", check_positive("weibull_modulus", self.weibull_modulus)
        )
        object.__setattr__(
            self,
            "characteristic_strength",
            check_positive("characteristic_strength", self.characteristic_strength),
        )
        object.__setattr__(
            self, "reference_area", check_positive("reference_area", self.reference_area)
        )

    def failure_probability(
        self,
        stress: Optional[ArrayLike],
        area: ArrayLike,
        *,
        principal_stresses: Optional[ArrayLike] = None,
        criterion: str = "pia",
    ) -> float:
        """:func:`demfem.risk.weibull.failure_probability` with these parameters."""
        return failure_probability(
            stress,
            area,
            self.weibull_modulus,
            self.characteristic_strength,
            self.reference_area,
            principal_stresses=principal_stresses,
            criterion=criterion,
        )

    def effective_area(
        self,
        stress: Optional[ArrayLike],
        area: ArrayLike,
        *,
        principal_stresses: Optional[ArrayLike] = None,
        criterion: str = "pia",
    ) -> float:
        """:func:`demfem.risk.weibull.effective_area` with this Weibull modulus, m²."""
        return effective_area(
            stress, area, self.weibull_modulus,
            principal_stresses=principal_stresses, criterion=criterion,
        )

    def strength_at_area(self, area: float, probability: float = 1.0 - math.exp(-1.0)) -> float:
        """Uniform stress (Pa) breaking ``area`` (m²) with ``probability``
        (:func:`demfem.risk.weibull.weibull_strength_at_area`)."""
        return weibull_strength_at_area(
            area, self.weibull_modulus, self.characteristic_strength, self.reference_area,
            probability,
        )
