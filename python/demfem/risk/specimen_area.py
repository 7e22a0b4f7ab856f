"""Effective area of standard glass strength tests from their closed-form stress fields (SI: m, Pa).

A strength test reports one stress per specimen, the nominal failure stress σ_nom (the peak
tension of the test's stress field at the failure load). With a two-parameter Weibull surface
flaw population the specimen's failure probability is

    P = 1 − exp(−(A_eff / A_0) (σ_nom / σ_0)^m),    A_eff = ∫ Σ_i ⟨σ_i(x) / σ_nom⟩^m dA,

so the specimens' characteristic strength σ_θ converts to the material's σ_0 on a reference
area A_0 as σ_0 = σ_θ (A_eff / A_0)^{1/m} (ASTM C1683). The sum over i is the criterion of
:func:`demfem.risk.weibull.effective_area`: ``"max_principal"`` keeps the largest in-plane
principal stress (what ``demfem assess`` uses: σ1 on each surface), ``"pia"`` adds every
tensile principal stress (principle of independent action). Under equibiaxial tension (inside
the load ring of a ring-on-ring test) PIA counts the area twice.

Tests (each function returns A_eff in m² of one surface, relative to that test's σ_nom):

* **Ring-on-ring** (ASTM C1499): a disc of diameter D on a support ring D_S, loaded by a ring
  D_L (the test of Vitman & Pukh 1963). Kirchhoff plate with overhang (Timoshenko &
  Woinowsky-Krieger 1959, ch. 3; Fessler & Fricker 1984): equibiaxial σ_nom inside the load
  ring, σ_r and σ_θ falling between the rings, hoop tension in the overhang. σ_nom is the
  ASTM C1499 formula (:func:`ring_on_ring_stress`). The load-ring disc gives π D_L²/4
  (``max_principal``) or π D_L²/2 (``pia``); the annulus and the overhang are integrated
  numerically (adaptive Gauss–Kronrod, relative error < 1e-10). ASTM C1683 tabulates
  closed-form expressions for this area; this module integrates the plate field itself.
* **Side (diametral) compression** of a tube or ring between flat platens: a thin ring of
  mean radius R, wall t, loaded length L, line load P = F/L (Timoshenko 1956, Roark ring case
  1): M(φ) = P R (1/π − sin φ / 2), N(φ) = −(P/2) sin φ, φ from the load line;
  σ = ±6M/t² + N/t on the inner/outer surface. σ_nom = 6 F R / (π L t²), the inner surface
  under the platens (:func:`side_compression_stress`). Hoop stress only (a long tube's axial
  ν σ_θ would add ν^m ≈ 1e-5 of the area under PIA); thin-ring theory (t/R ≲ 0.2: the
  curved-beam correction of the inner stress is ≈ t/(3R)).
* **Burst** (internal pressure p over a length L, Lamé thick cylinder): hoop stress uniform
  along the length, σ_nom = p (r_o² + r_i²)/(r_o² − r_i²) at the inner surface
  (:func:`burst_stress`); with closed ends the axial stress p r_i²/(r_o² − r_i²) is a second
  principal stress (counts under PIA only). A_eff(inner) = 2π r_i L (open ends).
"""
from __future__ import annotations

import math
from typing import Any, Callable, Dict, Mapping, Tuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from demfem.errors import InvalidParameterError, check_positive, check_range
from demfem.risk.weibull import CRITERIA

__all__ = [
    "SURFACES",
    "TESTS",
    "burst_effective_area",
    "burst_stress",
    "ring_on_ring_effective_area",
    "ring_on_ring_stress",
    "ring_on_ring_stress_field",
    "side_compression_effective_area",
    "side_compression_stress",
    "side_compression_stress_field",
    "effective_area_of_test",
]

#: Test types understood by :func:`effective_area_of_test`; ``"none"``: the effective area is
#: given directly.
TESTS = ("ring-on-ring", "side-compression", "burst", "none")

#: Glass surfaces of a cartridge.
SURFACES = ("inner", "outer")

#: Geometry keys (SI units) each test needs, and the optional ones with their defaults.
GEOMETRY: Dict[str, Tuple[Tuple[str, ...], Dict[str, Any]]] = {
    "ring-on-ring": (("load_ring_diameter_m", "support_ring_diameter_m", "specimen_diameter_m"),
                     {"poisson_ratio": 0.2}),
    "side-compression": (("outer_diameter_m", "wall_thickness_m", "length_m"), {}),
    "burst": (("outer_diameter_m", "wall_thickness_m", "length_m"), {"closed_ends": False}),
    "none": (("effective_area_m2",), {}),
}

_QUAD_TOL = 1e-12


def _check_criterion(criterion: str) -> str:
    if criterion not in CRITERIA:
        raise InvalidParameterError(f"invalid criterion = {criterion!r}: must be one of "
                                    f"{', '.join(map(repr, CRITERIA))}")
    return criterion


def _check_surface(surface: str) -> str:
    if surface not in SURFACES:
        raise InvalidParameterError(f"invalid surface = {surface!r}: must be 'inner' or 'outer'")
    return surface


def _integral(f: Callable[[float], float], lo: float, hi: float) -> float:
    """∫_lo^hi f, adaptive Gauss–Kronrod to a relative 1e-12 (0 for an empty interval)."""
    from scipy.integrate import quad

    if not hi > lo:
        return 0.0
    value, _ = quad(f, lo, hi, epsabs=0.0, epsrel=_QUAD_TOL, limit=200)
    return float(value)


# --- ring-on-ring (ASTM C1499) ---------------------------------------------------------------

def _ring_geometry(load_ring_diameter: float, support_ring_diameter: float,
                   specimen_diameter: float, poisson_ratio: float) -> Tuple[float, ...]:
    d_l = check_positive("load_ring_diameter", load_ring_diameter)
    d_s = check_positive("support_ring_diameter", support_ring_diameter)
    d = check_positive("specimen_diameter", specimen_diameter)
    nu = check_range("poisson_ratio", poisson_ratio, -1.0, 0.5, hi_open=False)
    if not d_l < d_s:
        raise InvalidParameterError(f"invalid load_ring_diameter = {d_l!r}: must be smaller "
                                    f"than support_ring_diameter = {d_s!r} (m)")
    if not d_s <= d:
        raise InvalidParameterError(f"invalid specimen_diameter = {d!r}: must be at least "
                                    f"support_ring_diameter = {d_s!r} (m)")
    return d_l / 2.0, d_s / 2.0, d / 2.0, nu


def _ring_bracket(b: float, a: float, big_r: float, nu: float) -> float:
    """(1+ν) ln(a/b) + (1−ν)(a² − b²)/(2R²): σ_nom = 3F/(2π h²) × this."""
    return (1.0 + nu) * math.log(a / b) + (1.0 - nu) * (a * a - b * b) / (2.0 * big_r ** 2)


def ring_on_ring_stress(force: float, thickness: float, load_ring_diameter: float,
                        support_ring_diameter: float, specimen_diameter: float,
                        poisson_ratio: float = 0.2) -> float:
    """ASTM C1499 equibiaxial stress (Pa) inside the load ring of a ring-on-ring test:
    σ = 3F/(2π h²) [(1−ν)(D_S² − D_L²)/(2D²) + (1+ν) ln(D_S/D_L)], for the load ``force`` (N)
    on a disc of ``thickness`` h (m); diameters in m."""
    b, a, big_r, nu = _ring_geometry(load_ring_diameter, support_ring_diameter,
                                     specimen_diameter, poisson_ratio)
    f = check_positive("force", force)
    h = check_positive("thickness", thickness)
    return 3.0 * f / (2.0 * math.pi * h * h) * _ring_bracket(b, a, big_r, nu)


def ring_on_ring_stress_field(radius: ArrayLike, load_ring_diameter: float,
                              support_ring_diameter: float, specimen_diameter: float,
                              poisson_ratio: float = 0.2
                              ) -> Tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Radial and hoop stress on the tensile face of a ring-on-ring disc at ``radius`` (m,
    0 ≤ r ≤ D/2), each divided by σ_nom (:func:`ring_on_ring_stress`): dimensionless
    (σ_r/σ_nom, σ_θ/σ_nom). 1 inside the load ring; Kirchhoff plate theory (moments
    M = σ h²/6, simply supported on the support ring, free edge at D/2)."""
    b, a, big_r, nu = _ring_geometry(load_ring_diameter, support_ring_diameter,
                                     specimen_diameter, poisson_ratio)
    r = np.asarray(radius, dtype=np.float64)
    if np.any(~np.isfinite(r)) or np.any(r < 0.0) or np.any(r > big_r * (1 + 1e-12)):
        raise InvalidParameterError(f"invalid radius: must be finite and in [0, "
                                    f"{big_r:g}] m (the specimen radius)")
    s = _ring_bracket(b, a, big_r, nu)
    rr = np.maximum(r, b)  # the inner branch is never used below b
    log_term = (1.0 + nu) * np.log(a / np.minimum(rr, a))
    k_out = (1.0 - nu) * (a * a - b * b) / (2.0 * big_r ** 2)
    annulus_r = log_term + (1.0 - nu) * (0.5 * b * b / rr ** 2 - 0.5) + k_out
    annulus_t = log_term + (1.0 - nu) * (0.5 - 0.5 * b * b / rr ** 2) + k_out
    c = (1.0 - nu) * (a * a - b * b) / 2.0
    over_r = c * (1.0 / big_r ** 2 - 1.0 / rr ** 2)
    over_t = c * (1.0 / big_r ** 2 + 1.0 / rr ** 2)
    sr = np.where(r <= b, s, np.where(r <= a, annulus_r, over_r)) / s
    st = np.where(r <= b, s, np.where(r <= a, annulus_t, over_t)) / s
    return sr, st


def ring_on_ring_effective_area(weibull_modulus: float, load_ring_diameter: float,
                                support_ring_diameter: float, specimen_diameter: float,
                                poisson_ratio: float = 0.2, *,
                                criterion: str = "max_principal") -> float:
    """Effective area (m²) of the tensile face of a ring-on-ring (ASTM C1499) disc.

    Parameters
    ----------
    weibull_modulus:
        m, > 0.
    load_ring_diameter, support_ring_diameter, specimen_diameter:
        D_L < D_S ≤ D, m.
    poisson_ratio:
        ν of the glass, in (−1, 0.5] (0.2 for borosilicate 3.3).
    criterion:
        ``"max_principal"`` (σ_θ ≥ σ_r everywhere: the hoop stress) or ``"pia"``.

    Returns
    -------
    float
        A_eff = ∫ Σ ⟨σ_i/σ_nom⟩^m dA over the disc: π D_L²/4 (× 2 under PIA) inside the load
        ring plus the annulus and the overhang. Tends to that disc as m → ∞.
    """
    m = check_positive("weibull_modulus", weibull_modulus)
    _check_criterion(criterion)
    b, a, big_r, nu = _ring_geometry(load_ring_diameter, support_ring_diameter,
                                     specimen_diameter, poisson_ratio)
    args = (2.0 * b, 2.0 * a, 2.0 * big_r, nu)

    def hoop(r: float) -> float:
        return 2.0 * math.pi * r * float(ring_on_ring_stress_field(r, *args)[1]) ** m

    def radial(r: float) -> float:
        sr = float(ring_on_ring_stress_field(r, *args)[0])
        return 2.0 * math.pi * r * sr ** m if sr > 0.0 else 0.0

    n_components = 2.0 if criterion == "pia" else 1.0
    area = n_components * math.pi * b * b + _integral(hoop, b, a) + _integral(hoop, a, big_r)
    if criterion == "pia":
        # σ_r falls from 1 at the load ring and may turn compressive before the support
        from scipy.optimize import brentq

        sr_a = float(ring_on_ring_stress_field(a, *args)[0])
        end = a if sr_a >= 0.0 else brentq(
            lambda r: float(ring_on_ring_stress_field(r, *args)[0]), b, a, xtol=1e-15 * a)
        area += _integral(radial, b, end)
    return float(area)


# --- side compression of a tube (thin ring between flat platens) -----------------------------

def _tube(outer_diameter: float, wall_thickness: float, length: float) -> Tuple[float, float,
                                                                                   float]:
    d_o = check_positive("outer_diameter", outer_diameter)
    t = check_positive("wall_thickness", wall_thickness)
    length_m = check_positive("length", length)
    if not 2.0 * t < d_o:
        raise InvalidParameterError(f"invalid wall_thickness = {t!r}: must be less than half "
                                    f"the outer_diameter = {d_o!r} (m)")
    return d_o / 2.0, t, length_m


def side_compression_stress(force: float, outer_diameter: float, wall_thickness: float,
                            length: float) -> float:
    """Nominal failure stress (Pa) of a tube crushed between flat platens: σ = 6 F R/(π L t²),
    the thin-ring bending tension of the inner surface under the load line, for the ``force``
    (N) over the loaded ``length`` L (m), mean radius R = (D_o − t)/2 (m), wall t (m)."""
    r_o, t, length_m = _tube(outer_diameter, wall_thickness, length)
    f = check_positive("force", force)
    return 6.0 * f * (r_o - t / 2.0) / (math.pi * length_m * t * t)


def side_compression_stress_field(angle: ArrayLike, outer_diameter: float,
                                  wall_thickness: float, surface: str = "inner"
                                  ) -> NDArray[np.float64]:
    """Hoop stress of ``surface`` at ``angle`` (rad, from the load line) of a thin ring under
    diametral compression, divided by σ_nom (:func:`side_compression_stress`):
    ±(1 − (π/2) sin φ) − (π t/(12 R)) sin φ (bending, + on the inner surface, and the hoop
    compression N = −(P/2) sin φ). 1 on the inner surface under the load line."""
    r_o, t, _ = _tube(outer_diameter, wall_thickness, 1.0)
    _check_surface(surface)
    phi = np.asarray(angle, dtype=np.float64)
    if np.any(~np.isfinite(phi)):
        raise InvalidParameterError("invalid angle: must be finite (rad)")
    s = np.abs(np.sin(phi))
    bending = 1.0 - 0.5 * math.pi * s
    membrane = math.pi * t / (12.0 * (r_o - t / 2.0)) * s
    return (bending if surface == "inner" else -bending) - membrane


def side_compression_effective_area(weibull_modulus: float, outer_diameter: float,
                                    wall_thickness: float, length: float, *,
                                    surface: str = "inner",
                                    criterion: str = "max_principal") -> float:
    """Effective area (m²) of the ``surface`` ("inner" or "outer") of a tube of
    ``outer_diameter`` and ``wall_thickness`` crushed between flat platens over ``length``
    (all m), relative to σ_nom = 6 F R/(π L t²) (:func:`side_compression_stress`).

    A_eff = L R_s ∫_0^{2π} ⟨σ(φ)/σ_nom⟩^m dφ with R_s the surface's radius: the inner surface
    is in tension under both load lines (peak 1), the outer at the sides (peak ≈ 0.57).
    Hoop stress only, so ``criterion`` does not change the result (see the module notes).
    """
    m = check_positive("weibull_modulus", weibull_modulus)
    _check_criterion(criterion)
    _check_surface(surface)
    r_o, t, length_m = _tube(outer_diameter, wall_thickness, length)
    radius = r_o - t if surface == "inner" else r_o
    mu = math.pi * t / (12.0 * (r_o - t / 2.0))

    def f(phi: float) -> float:
        s = float(side_compression_stress_field(phi, 2.0 * r_o, t, surface))
        return s ** m if s > 0.0 else 0.0

    # by symmetry 4 × the quarter [0, π/2]; tension where the sign of σ(φ) is positive
    if surface == "inner":
        lo, hi = 0.0, math.asin(min(1.0, 1.0 / (0.5 * math.pi + mu)))
    else:
        lo, hi = math.asin(min(1.0, 1.0 / (0.5 * math.pi - mu))), 0.5 * math.pi
    return 4.0 * length_m * radius * _integral(f, lo, hi)


# --- burst (internal pressure) -----------------------------------------------------------------

def burst_stress(pressure: float, outer_diameter: float, wall_thickness: float) -> float:
    """Lamé hoop stress (Pa) of the inner surface of a tube under internal ``pressure`` (Pa):
    σ = p (r_o² + r_i²)/(r_o² − r_i²); diameters and wall in m."""
    r_o, t, _ = _tube(outer_diameter, wall_thickness, 1.0)
    p = check_positive("pressure", pressure)
    r_i = r_o - t
    return p * (r_o ** 2 + r_i ** 2) / (r_o ** 2 - r_i ** 2)


def burst_effective_area(weibull_modulus: float, outer_diameter: float, wall_thickness: float,
                         length: float, *, surface: str = "inner", closed_ends: bool = False,
                         criterion: str = "max_principal") -> float:
    """Effective area (m²) of the ``surface`` of a tube pressurised over ``length`` (m),
    relative to the inner hoop stress (:func:`burst_stress`).

    Inner: 2π r_i L [1 + (r_i²/(r_o² + r_i²))^m with closed ends under PIA]; outer:
    2π r_o L [(2 r_i²/(r_o² + r_i²))^m + (r_i²/(r_o² + r_i²))^m with closed ends under PIA].
    """
    m = check_positive("weibull_modulus", weibull_modulus)
    _check_criterion(criterion)
    _check_surface(surface)
    if not isinstance(closed_ends, (bool, np.bool_)):
        raise InvalidParameterError(f"invalid closed_ends = {closed_ends!r}: must be true or "
                                    "false")
    r_o, t, length_m = _tube(outer_diameter, wall_thickness, length)
    r_i = r_o - t
    k = r_o ** 2 + r_i ** 2
    axial = (r_i ** 2 / k) ** m if (closed_ends and criterion == "pia") else 0.0
    if surface == "inner":
        return 2.0 * math.pi * r_i * length_m * (1.0 + axial)
    return 2.0 * math.pi * r_o * length_m * ((2.0 * r_i ** 2 / k) ** m + axial)


# --- dispatch ----------------------------------------------------------------------------------

def effective_area_of_test(test: str, weibull_modulus: float, geometry: Mapping[str, Any], *,
                        surface: str = "inner", criterion: str = "max_principal") -> float:
    """Effective area (m²) of ``surface`` in a ``test`` (one of :data:`TESTS`) with the
    ``geometry`` (SI keys, see :data:`GEOMETRY`: e.g. ``load_ring_diameter_m``; ``"none"``
    takes ``effective_area_m2`` directly). Unknown tests and missing or unknown keys raise
    :class:`~demfem.errors.InvalidParameterError` naming them."""
    if test not in TESTS:
        raise InvalidParameterError(f"invalid test = {test!r}: must be one of "
                                    f"{', '.join(map(repr, TESTS))}")
    _check_surface(surface)
    _check_criterion(criterion)
    required, optional = GEOMETRY[test]
    given = dict(geometry)
    missing = [k for k in required if given.get(k) is None]
    if missing:
        raise InvalidParameterError(f"invalid geometry for test {test!r}: missing "
                                    f"{', '.join(missing)}")
    unknown = sorted(set(given) - set(required) - set(optional))
    if unknown:
        raise InvalidParameterError(f"invalid geometry for test {test!r}: unknown "
                                    f"{', '.join(unknown)}; allowed: "
                                    f"{', '.join(required + tuple(optional))}")
    g = {**optional, **{k: v for k, v in given.items() if v is not None}}
    m = weibull_modulus
    if test == "ring-on-ring":
        check_positive("weibull_modulus", m)
        return ring_on_ring_effective_area(
            m, g["load_ring_diameter_m"], g["support_ring_diameter_m"],
            g["specimen_diameter_m"], g["poisson_ratio"], criterion=criterion)
    if test == "side-compression":
        return side_compression_effective_area(
            m, g["outer_diameter_m"], g["wall_thickness_m"], g["length_m"], surface=surface,
            criterion=criterion)
    if test == "burst":
        return burst_effective_area(
            m, g["outer_diameter_m"], g["wall_thickness_m"], g["length_m"], surface=surface,
            closed_ends=g["closed_ends"], criterion=criterion)
    check_positive("weibull_modulus", m)
    return check_positive("effective_area_m2", g["effective_area_m2"])
