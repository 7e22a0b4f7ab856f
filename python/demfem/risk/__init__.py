"""Breakage probability of glass cartridges from surface stresses (SI units: Pa, m², s).

* :mod:`~demfem.risk.weibull` — weakest-link failure probability of a stressed surface
  (principle of independent action on the in-plane principal stresses, tension only),
  effective area and size scaling (ASTM C1239 / C1683).
* :mod:`~demfem.risk.surface` — :class:`SurfaceStrength`, the Weibull parameters of one surface.
* :mod:`~demfem.risk.defaults` — inner (pristine) and outer (handled) surface defaults and
  slow-crack-growth exponents, each with its source and range (planning assumptions).
* :mod:`~demfem.risk.fatigue` — slow crack growth: equivalent static stress of a pulse.
* :mod:`~demfem.risk.threshold` — deterministic strength threshold.
* :mod:`~demfem.risk.cartridge_risk` — collisions → cartridge → broken cartridges per hour.

Pure numpy/scipy; nothing here needs the Rust core. See ``docs/risk.md``.
"""
from __future__ import annotations

from demfem.risk.cartridge_risk import cartridge_failure_probability, expected_broken_per_hour
from demfem.risk.defaults import (
    INNER_SURFACE,
    OUTER_SURFACE,
    RANGES,
    SCG_BOROSILICATE,
    SCG_SODA_LIME,
)
from demfem.risk.fatigue import (
    SlowCrackGrowth,
    constant_pulse_equivalent_stress,
    equivalent_static_stress,
    half_sine_equivalent_stress,
    stress_rate_test_reference_time,
)
from demfem.risk.surface import SurfaceStrength
from demfem.risk.threshold import exceeds_threshold, utilisation
from demfem.risk.weibull import (
    effective_area,
    failure_probability,
    risk_of_rupture,
    scale_strength,
    weibull_strength_at_area,
)

__all__ = [
    "INNER_SURFACE",
    "OUTER_SURFACE",
    "RANGES",
    "SCG_BOROSILICATE",
    "SCG_SODA_LIME",
    "SlowCrackGrowth",
    "SurfaceStrength",
    "cartridge_failure_probability",
    "constant_pulse_equivalent_stress",
    "effective_area",
    "equivalent_static_stress",
    "exceeds_threshold",
    "expected_broken_per_hour",
    "failure_probability",
    "half_sine_equivalent_stress",
    "risk_of_rupture",
    "scale_strength",
    "stress_rate_test_reference_time",
    "utilisation",
    "weibull_strength_at_area",
]
