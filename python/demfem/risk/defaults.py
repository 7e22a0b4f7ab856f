"""Documented default strength and fatigue parameters for Type I borosilicate cartridges.

**Every Weibull value below is a planning assumption, not a measured property of a specific
product.** The strength of a glass container is set by its surface flaws, which depend on the
forming line, annealing, handling history, coatings and test method far more than on the glass
composition; measure (ASTM C1239 fit of ring-on-ring or burst data on the actual containers,
scaled with ASTM C1683) before trusting absolute breakage rates. The defaults only order of
magnitude the risk and make relative comparisons (table settings, speeds) meaningful.

Sources (author, year, title):

* Weibull, W. (1951) "A statistical distribution function of wide applicability", J. Appl.
  Mech. 18, 293–297 — the weakest-link distribution.
* ASTM C1239 "Standard practice for reporting uniaxial strength data and estimating Weibull
  distribution parameters for advanced ceramics" — estimating m and σ_0.
* ASTM C1683 "Standard practice for size scaling of tensile strengths using Weibull statistics
  for advanced ceramics" — effective area and size scaling.
* Nemeth, N.N. et al. (2003) "CARES/Life ceramics analysis and reliability evaluation of
  structures life prediction program", NASA/TM-2003-106316 — PIA and slow crack growth in
  the weakest-link integral.
* Haldimann, M., Luible, A., Overend, M. (2008) "Structural use of glass", IABSE Structural
  Engineering Documents 10 — strength of as-received and weathered/abraded glass (Weibull
  moduli of order 5–8 for damaged surfaces) and the design crack-velocity exponent n = 16 for
  soda-lime glass in ambient conditions.
* Wiederhorn, S.M., Bolz, L.H. (1970) "Stress corrosion and static fatigue of glass", J. Am.
  Ceram. Soc. 53, 543–548 — crack-velocity curves of six glasses in water: soda-lime-silica
  has one of the lowest exponents, borosilicate and silica-rich glasses higher ones.
* Kurkjian, C.R., Gupta, P.K., Brow, R.K., Lower, N. (2003) "The intrinsic strength and
  fatigue of oxide glasses", J. Non-Cryst. Solids 316, 114–124 — pristine glass is several
  GPa strong; any real surface is far below that bound.
* Haines, D., Maurer, F., Rothhaar, U. (2016) "Why do pharmaceutical glass containers break?
  The underestimated power of strength testing and fractography", International Pharmaceutical
  Industry 8(1) — container strength is governed by handling/processing damage; measure it.
* Boso, D. et al. (2021), the paper this package follows — cracks start where the maximum
  principal tensile stress peaks, often on the inner surface opposite the contact.
"""
from __future__ import annotations

from typing import Dict, Tuple

from demfem.risk.fatigue import SlowCrackGrowth
from demfem.risk.surface import SurfaceStrength

__all__ = [
    "INNER_SURFACE",
    "OUTER_SURFACE",
    "SCG_BOROSILICATE",
    "SCG_SODA_LIME",
    "RANGES",
    "REFERENCE_AREA",
    "REFERENCE_TIME",
]

#: A_0 = 1 cm² (m²): the area the characteristic strengths below refer to; planning assumption
#: (typical effective area of ring-on-ring / burst tests on small containers, 1e-5–1e-3 m²).
REFERENCE_AREA = 1.0e-4

#: t_ref = 1 s: effective static duration of the strength test behind σ_0; planning assumption,
#: range 0.5–5 s (t_f / (n + 1) of a constant-stress-rate test failing after t_f ≈ 20–100 s,
#: see :func:`demfem.risk.fatigue.stress_rate_test_reference_time`).
REFERENCE_TIME = 1.0

#: Outer (handled, abraded) surface. Planning assumption: m = 6 (range 5–8), σ_0 = 70 MPa
#: (range 50–100 MPa) at A_0 = 1e-4 m²; from the strength of handled/abraded soda-lime and
#: borosilicate glass (Haldimann et al. 2008) and the dominance of handling damage in container
#: breakage (Haines et al. 2016). Not measured on any specific cartridge.
OUTER_SURFACE = SurfaceStrength(
    weibull_modulus=6.0,
    characteristic_strength=70e6,
    reference_area=REFERENCE_AREA,
    source=(
        "planning assumption: handled/abraded glass, m 5-8, sigma_0 50-100 MPa at 1e-4 m^2 "
        "(Haldimann, Luible & Overend 2008; Haines, Maurer & Rothhaar 2016)"
    ),
)

#: Inner (pristine, formed from the melt, untouched) surface. Planning assumption: m = 10
#: (range 6–15), σ_0 = 300 MPa (range 200–600 MPa) at A_0 = 1e-4 m²: several times the
#: handled surface and far below the intrinsic strength of several GPa (Kurkjian et al. 2003).
#: Not measured on any specific cartridge.
INNER_SURFACE = SurfaceStrength(
    weibull_modulus=10.0,
    characteristic_strength=300e6,
    reference_area=REFERENCE_AREA,
    source=(
        "planning assumption: pristine inner surface, m 6-15, sigma_0 200-600 MPa at 1e-4 m^2 "
        "(bounded above by the intrinsic strength, Kurkjian et al. 2003)"
    ),
)

#: Soda-lime-silica glass in humid air: n = 16 (literature range 16–20), the design value of
#: Haldimann et al. (2008); Wiederhorn & Bolz (1970) measured curves of this order in water.
SCG_SODA_LIME = SlowCrackGrowth(
    crack_growth_exponent=16.0,
    reference_time=REFERENCE_TIME,
    source="n 16-20 (Haldimann, Luible & Overend 2008; Wiederhorn & Bolz 1970); t_ref assumed",
)

#: Borosilicate (Type I) glass in humid air: n = 25, planning assumption inside the range
#: 20–35 of borosilicate and silica-rich glasses (Wiederhorn & Bolz 1970: higher exponents than
#: soda-lime). The cartridge default.
SCG_BOROSILICATE = SlowCrackGrowth(
    crack_growth_exponent=25.0,
    reference_time=REFERENCE_TIME,
    source="planning assumption: n 20-35 for borosilicate (Wiederhorn & Bolz 1970); t_ref assumed",
)

#: Allowed planning ranges (low, high) of each default, SI units, for sensitivity sweeps.
RANGES: Dict[str, Tuple[float, float]] = {
    "outer.weibull_modulus": (5.0, 8.0),
    "outer.characteristic_strength": (50e6, 100e6),
    "inner.weibull_modulus": (6.0, 15.0),
    "inner.characteristic_strength": (200e6, 600e6),
    "reference_area": (1e-5, 1e-3),
    "reference_time": (0.5, 5.0),
    "soda_lime.crack_growth_exponent": (16.0, 20.0),
    "borosilicate.crack_growth_exponent": (20.0, 35.0),
}
