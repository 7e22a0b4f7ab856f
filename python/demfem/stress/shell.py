"""Closed-form surface stresses of a thin shell under a radial point (patch) load.

The calibration law of demfem (Hertz–Reissner, :mod:`demfem.contact`) takes the shell
deflection from Reissner's solution for a **shallow spherical shell under a concentrated
radial load** (Reissner 1946; stiffness k_R = 4 E t² / (R √(3(1−ν²)))). The same solution
gives the surface stresses, which is what this module evaluates, so the force and the stress
of a collision come from one and the same mechanical model.

Reissner's equations for a shallow sphere of mid-surface radius R and thickness t, with the
deflection w positive inward (the load direction), decouple into a plate on an elastic
foundation of modulus E t / R² (Timoshenko & Woinowsky-Krieger 1959, §§ 57–58 and the chapter
on shallow shells). With x = r/ℓ and the characteristic length

    ℓ⁴ = D R² / (E t),   D = E t³ / (12 (1 − ν²)),   i.e.  ℓ = √(R t) / (12 (1 − ν²))^{1/4},

the point-load solution is (Kelvin functions ker, kei)

    w   = −(P ℓ² / (2π D)) kei(x)                         (w(0) = P ℓ²/(8D) = P / k_R)
    M_r = (P / 2π) (kei''(x) + ν kei'(x)/x),   M_θ = (P / 2π) (kei'(x)/x + ν kei''(x))
    Φ   = −(P R / 2π) (ker(x) + ln x)   (Airy stress function; the ln x removes the
                                          in-plane singularity: no in-plane point source)
    N_r = Φ'/r,   N_θ = Φ''.

Surface stresses (tension > 0): inner surface (the side away from the load)
σ = N/t + 6 M/t², outer surface (the loaded side) σ = N/t − 6 M/t². Under the load the bending
moment is positive: **the inner surface is in tension and the outer in compression**, as the
paper's FEM shows (Boso et al. 2021, Figs. 12–13). The moment diverges like ln r at a true
point load; under a load spread over a small circle of radius c ≪ ℓ (the Hertz contact patch)
the moment at the centre is (Timoshenko & Woinowsky-Krieger 1959, § 58)

    M_0 = (1 + ν) P / (4π) [ln(ℓ/c) + 0.6159],   0.6159 = ln 2 + 1/2 − γ,

and the membrane force there is finite, N_r = N_θ = −P R / (16 ℓ²) (compressive). Hence

    σ_inner(0) = [ 3(1+ν)/(2π) (ln(ℓ/c) + 0.6159) − √(12(1−ν²))/16 ] P / t².

On the outer surface the bending moment changes sign at a few ℓ from the load, where the
outer surface is in (weak) tension: the largest outer σ1 of the point solution.

Assumptions: linear elastic, thin (t ≪ R) and shallow shell, static (quasi-static impact:
the contact lasts ≫ the shell's lowest local bending period), a sphere of the cylinder's
mid-surface radius standing for the cylindrical body — the same idealisation as the
calibration's Reissner stiffness; a cylinder, flat in one direction, bends more under a
point load (refit β from the FEM, :meth:`demfem.assess.StressModel.fit`). The Hertzian
contact's own surface tension at the edge of the contact circle, (1 − 2ν) p_0 / 3 (the
ring-crack stress), confined to a depth of order the contact radius, is not in this model.

SI units: m, N, Pa; all coefficients β are dimensionless (σ = β P / t²).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import trapezoid
from scipy.special import kei, keip, ker, kerp

from demfem.errors import InvalidParameterError, check_positive, check_range

__all__ = ["ShellClosedForm", "characteristic_length", "point_load_surface_stresses",
           "patch_centre_coefficients", "closed_form_coefficients", "PATCH_CONSTANT"]

#: ln 2 + 1/2 − γ (Euler's γ): the constant of the patch-load moment (Timoshenko § 58).
PATCH_CONSTANT = math.log(2.0) + 0.5 - 0.5772156649015329


def characteristic_length(shell_radius: float, thickness: float, nu: float) -> float:
    """ℓ = √(R t) / (12 (1 − ν²))^{1/4}, m: the bending length of a shallow spherical shell of
    mid-surface radius ``shell_radius`` (m) and ``thickness`` (m)."""
    R = check_positive("shell_radius", shell_radius)
    t = check_positive("thickness", thickness)
    nu = check_range("nu", nu, -1.0, 0.5)
    if t >= R:
        raise InvalidParameterError(f"invalid thickness = {t!r}: must be < shell_radius = "
                                    f"{R!r} m (a thin shell)")
    return math.sqrt(R * t) / (12.0 * (1.0 - nu * nu)) ** 0.25


def point_load_surface_stresses(x: np.ndarray, nu: float) -> dict[str, np.ndarray]:
    """Surface stresses of the shallow-shell point-load solution at r = x ℓ (x > 0), as
    dimensionless coefficients σ t² / P: keys ``inner_r``, ``inner_theta``, ``outer_r``,
    ``outer_theta`` and the max principal stresses ``inner_s1``, ``outer_s1``."""
    x = np.asarray(x, float)
    if np.any(~np.isfinite(x)) or np.any(x <= 0):
        raise InvalidParameterError("invalid x: must be finite and > 0 (r / ell)")
    nu = check_range("nu", nu, -1.0, 0.5)
    # Kelvin functions: K = ker + i kei solves K'' + K'/x - i K = 0
    kei1, ker1 = keip(x), kerp(x)
    kei2 = ker(x) - kei1 / x
    ker2 = -kei(x) - ker1 / x
    m_r = (kei2 + nu * kei1 / x) / (2.0 * math.pi)     # M_r / P
    m_t = (kei1 / x + nu * kei2) / (2.0 * math.pi)     # M_theta / P
    c = math.sqrt(12.0 * (1.0 - nu * nu)) / (2.0 * math.pi)
    n_r = -c * (ker1 + 1.0 / x) / x                    # N_r t / P
    n_t = -c * (ker2 - 1.0 / x**2)                     # N_theta t / P
    out = {"inner_r": n_r + 6.0 * m_r, "inner_theta": n_t + 6.0 * m_t,
           "outer_r": n_r - 6.0 * m_r, "outer_theta": n_t - 6.0 * m_t}
    out["inner_s1"] = np.maximum(out["inner_r"], out["inner_theta"])
    out["outer_s1"] = np.maximum(out["outer_r"], out["outer_theta"])
    return out


def patch_centre_coefficients(ell_over_c: float, nu: float) -> tuple[float, float]:
    """(inner, outer) σ t² / P at the centre of a load spread over a circle of radius c,
    ``ell_over_c`` = ℓ/c ≫ 1: ±3(1+ν)/(2π) (ln(ℓ/c) + 0.6159) − √(12(1−ν²))/16."""
    q = check_range("ell_over_c", ell_over_c, 1.0, math.inf, lo_open=False)
    nu = check_range("nu", nu, -1.0, 0.5)
    bending = 3.0 * (1.0 + nu) / (2.0 * math.pi) * (math.log(q) + PATCH_CONSTANT)
    membrane = -math.sqrt(12.0 * (1.0 - nu * nu)) / 16.0
    return bending + membrane, -bending + membrane


@dataclass(frozen=True)
class ShellClosedForm:
    """The closed-form coefficients of one shell and contact radius (see the module doc).

    Attributes:
        beta_inner: peak inner-surface σ1 t² / F (dimensionless), at the load centre.
        beta_outer: peak outer-surface σ1 t² / F (dimensionless): the tensile ring at
            ``outer_peak_radius`` (the outer surface is compressed under the load).
        area_factor_inner: Weibull effective area of the inner σ1 field / (π c²), for
            Weibull modulus ``m_inner``.
        area_factor_outer: the same for the outer σ1 field and ``m_outer``.
        characteristic_length: ℓ, m.
        contact_radius: c, m.
        outer_peak_radius: radius of the outer tensile peak, m.
        outer_under_load: outer-surface σ t² / F under the load (negative: compression).
    """

    beta_inner: float
    beta_outer: float
    area_factor_inner: float
    area_factor_outer: float
    characteristic_length: float
    contact_radius: float
    outer_peak_radius: float
    outer_under_load: float


def _effective_area(r: np.ndarray, s: np.ndarray, m: float) -> float:
    """∫ ⟨s/s_max⟩^m 2π r dr on the grid r (m), trapezoid rule; m² (axisymmetric field)."""
    smax = float(np.max(s))
    if smax <= 0:
        return 0.0
    f = np.maximum(s / smax, 0.0) ** m * 2.0 * math.pi * r
    return float(trapezoid(f, r))


def closed_form_coefficients(thickness: float, shell_radius: float, nu: float,
                             contact_radius: float, m_inner: float = 10.0,
                             m_outer: float = 6.0) -> ShellClosedForm:
    """β and effective-area factors of a shell (``thickness``, ``shell_radius`` in m, Poisson
    ratio ``nu``) loaded over a circle of ``contact_radius`` c (m, c < ℓ), for the Weibull
    moduli ``m_inner`` and ``m_outer`` of the two surfaces.

    Inner field: the patch value at r < c, the point solution beyond; outer field: the point
    solution for r ≥ c (compressive under the patch). Integrated out to r = 12 ℓ, where the
    field has decayed by more than four orders of magnitude.
    """
    ell = characteristic_length(shell_radius, thickness, nu)
    c = check_positive("contact_radius", contact_radius)
    if c >= ell:
        raise InvalidParameterError(f"invalid contact_radius = {c!r}: must be < the shell's "
                                    f"bending length {ell:.4g} m (a concentrated load)")
    m_inner = check_positive("m_inner", m_inner)
    m_outer = check_positive("m_outer", m_outer)
    inner0, outer0 = patch_centre_coefficients(ell / c, nu)
    x_c = c / ell
    x = np.concatenate([np.linspace(0.0, x_c, 200, endpoint=False),
                        np.geomspace(x_c, 12.0, 4000)])
    r = x * ell
    field = point_load_surface_stresses(np.maximum(x, x_c), nu)
    inner = np.where(x < x_c, inner0, np.minimum(field["inner_s1"], inner0))
    outer = np.where(x < x_c, outer0, field["outer_s1"])
    k = int(np.argmax(outer))
    beta_outer = float(outer[k])
    return ShellClosedForm(
        beta_inner=float(inner0), beta_outer=beta_outer,
        area_factor_inner=_effective_area(r, inner, m_inner) / (math.pi * c * c),
        area_factor_outer=(_effective_area(r, outer, m_outer) / (math.pi * c * c)
                           if beta_outer > 0 else 0.0),
        characteristic_length=ell, contact_radius=c,
        outer_peak_radius=float(r[k]), outer_under_load=float(outer0))
