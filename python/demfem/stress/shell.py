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
point load (refit β from the FEM, :meth:`demfem.stress.StressModel.fit`). The Hertzian
contact's own surface tension at the edge of the contact circle, (1 − 2ν) p_0 / 3 (the
ring-crack stress), confined to a depth of order the contact radius, is not in this model:
:func:`demfem.stress.contact_stresses` superposes it.

**The Hertz patch.** The load of a contact is not uniform over the patch but Hertzian,
p ∝ √(1 − r²/c²). Near the load (r ≪ ℓ) the shell is a thin plate, whose moment field under
an axisymmetric load follows from the point solution exactly: with s = r/c, the load's
normalised radial density 3 s √(1 − s²), and

    h(s) = ∫_{s'>s} 3 s' √(1 − s'²) ln(s'/s) ds' = ln((1 + w)/s) − w − w³/3,  w = √(1 − s²)
    (0 for s ≥ 1),   h̄(s) = (2/s²) ∫_0^s s' h(s') ds'   (= 1/(5 s²) for s ≥ 1),

the patch's moments are (M_r + M_θ) = (M_r + M_θ)_point − (1 + ν)(P/2π) h(s) and
(M_θ − M_r) = (M_θ − M_r)_point + (1 − ν)(P/2π)(h(s) − h̄(s)) (the Laplacian of the deflection
averages ln|x − x'| over the load; D(1 − ν)(Λ − Λ̄) gives the difference of the moments).
Outside the patch this is the point field plus (1 − ν) P ⟨ρ²⟩/(8π r²) on M_r (minus on M_θ),
⟨ρ²⟩ = 2c²/5; at the centre M_0 = (1 + ν) P/(4π) [ln(ℓ/c) + 4/3 − γ] — the uniform patch's
constant ln 2 + 1/2 − γ becomes 4/3 − γ (:data:`HERTZ_PATCH_CONSTANT`), since the mean of
ln(c/ρ) over the Hertz pressure is 4/3 − ln 2 instead of 1/2. :func:`hertz_patch_surface_stresses`
evaluates this field; the membrane forces are the point solution's (finite at the load).

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
           "patch_centre_coefficients", "closed_form_coefficients", "PATCH_CONSTANT",
           "HERTZ_PATCH_CONSTANT", "hertz_patch_centre_coefficients",
           "hertz_patch_surface_stresses", "point_load_deflection", "point_load_resultants"]

_EULER_GAMMA = 0.5772156649015329

#: ln 2 + 1/2 − γ (Euler's γ): the constant of the patch-load moment (Timoshenko § 58).
PATCH_CONSTANT = math.log(2.0) + 0.5 - _EULER_GAMMA

#: 4/3 − γ: the same constant for a Hertzian pressure p ∝ √(1 − r²/c²) (module docstring).
HERTZ_PATCH_CONSTANT = 4.0 / 3.0 - _EULER_GAMMA


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


def point_load_deflection(r: np.ndarray, force: float, shell_radius: float, thickness: float,
                          young_modulus: float, nu: float) -> np.ndarray:
    """Deflection w (m, inward) of the shallow shell under a point ``force`` P (N) at the
    distances ``r`` (m, ≥ 0): w = −(P ℓ²/(2π D)) kei(r/ℓ), so w(0) = P ℓ²/(8D) = P/k_R with
    Reissner's stiffness k_R = 4 E t²/(R √(3(1 − ν²))) (module docstring)."""
    r = np.asarray(r, float)
    if np.any(~np.isfinite(r)) or np.any(r < 0):
        raise InvalidParameterError("invalid r: must be finite and >= 0 m")
    P = check_positive("force", force)
    E = check_positive("young_modulus", young_modulus)
    ell = characteristic_length(shell_radius, thickness, nu)
    D = E * thickness**3 / (12.0 * (1.0 - nu * nu))
    return -P * ell * ell / (2.0 * math.pi * D) * kei(r / ell)


def _point_load_resultants(x: np.ndarray, nu: float) -> tuple[np.ndarray, ...]:
    """(M_r/P, M_θ/P, N_r t/P, N_θ t/P) of the point-load solution at r = x ℓ (x > 0)."""
    # Kelvin functions: K = ker + i kei solves K'' + K'/x - i K = 0
    kei1, ker1 = keip(x), kerp(x)
    kei2 = ker(x) - kei1 / x
    ker2 = -kei(x) - ker1 / x
    m_r = (kei2 + nu * kei1 / x) / (2.0 * math.pi)     # M_r / P
    m_t = (kei1 / x + nu * kei2) / (2.0 * math.pi)     # M_theta / P
    c = math.sqrt(12.0 * (1.0 - nu * nu)) / (2.0 * math.pi)
    n_r = -c * (ker1 + 1.0 / x) / x                    # N_r t / P
    n_t = -c * (ker2 - 1.0 / x**2)                     # N_theta t / P
    return m_r, m_t, n_r, n_t


def _surface(m_r: np.ndarray, m_t: np.ndarray, n_r: np.ndarray,
             n_t: np.ndarray) -> dict[str, np.ndarray]:
    out = {"inner_r": n_r + 6.0 * m_r, "inner_theta": n_t + 6.0 * m_t,
           "outer_r": n_r - 6.0 * m_r, "outer_theta": n_t - 6.0 * m_t}
    out["inner_s1"] = np.maximum(out["inner_r"], out["inner_theta"])
    out["outer_s1"] = np.maximum(out["outer_r"], out["outer_theta"])
    return out


def point_load_surface_stresses(x: np.ndarray, nu: float) -> dict[str, np.ndarray]:
    """Surface stresses of the shallow-shell point-load solution at r = x ℓ (x > 0), as
    dimensionless coefficients σ t² / P: keys ``inner_r``, ``inner_theta``, ``outer_r``,
    ``outer_theta`` and the max principal stresses ``inner_s1``, ``outer_s1``."""
    x = np.asarray(x, float)
    if np.any(~np.isfinite(x)) or np.any(x <= 0):
        raise InvalidParameterError("invalid x: must be finite and > 0 (r / ell)")
    nu = check_range("nu", nu, -1.0, 0.5)
    return _surface(*_point_load_resultants(x, nu))


def _hertz_h(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """h(s) and its disc mean h̄(s) of the Hertz patch (module docstring), s = r/c > 0."""
    inside = s < 1.0
    si = np.where(inside, s, 0.5)
    w = np.sqrt(1.0 - si * si)
    h = np.where(inside, np.log((1.0 + w) / si) - w - w**3 / 3.0, 0.0)
    # ∫_0^s s' h ds' = 1/2 − w/2 + (s²/2) ln((1 + w)/s) − (1 − w³)/3 − (1 − w⁵)/15
    integral = 0.5 - 0.5 * w + 0.5 * si * si * np.log((1.0 + w) / si) - (1.0 - w**3) / 3.0 \
        - (1.0 - w**5) / 15.0
    mean = np.where(inside, 2.0 * integral / (si * si), 1.0 / (5.0 * np.where(inside, 1.0, s)**2))
    return h, mean


def hertz_patch_centre_coefficients(ell_over_c: float, nu: float) -> tuple[float, float]:
    """(inner, outer) σ t² / P at the centre of a Hertzian load of radius c, ``ell_over_c`` =
    ℓ/c ≥ 1: ±3(1+ν)/(2π) (ln(ℓ/c) + 4/3 − γ) − √(12(1−ν²))/16."""
    q = check_range("ell_over_c", ell_over_c, 1.0, math.inf, lo_open=False)
    nu = check_range("nu", nu, -1.0, 0.5)
    bending = 3.0 * (1.0 + nu) / (2.0 * math.pi) * (math.log(q) + HERTZ_PATCH_CONSTANT)
    membrane = -math.sqrt(12.0 * (1.0 - nu * nu)) / 16.0
    return bending + membrane, -bending + membrane


def point_load_resultants(x: np.ndarray, nu: float) -> tuple[np.ndarray, ...]:
    """(M_r/P, M_θ/P, N_r t/P, N_θ t/P) of the point-load solution at r = x ℓ (x > 0): the
    stress resultants behind :func:`point_load_surface_stresses`."""
    x = np.asarray(x, float)
    if np.any(~np.isfinite(x)) or np.any(x <= 0):
        raise InvalidParameterError("invalid x: must be finite and > 0 (r / ell)")
    return _point_load_resultants(x, check_range("nu", nu, -1.0, 0.5))


def hertz_patch_surface_stresses(x: np.ndarray, x_c: float, nu: float,
                                 point: tuple[np.ndarray, ...] | None = None
                                 ) -> dict[str, np.ndarray]:
    """Surface stresses of the shallow shell under a Hertzian pressure of radius c = x_c ℓ
    (``x_c`` in (0, 1)) at r = x ℓ (x ≥ 0), as coefficients σ t² / P (module docstring):
    keys as :func:`point_load_surface_stresses`. Exact for the thin-plate near field; beyond
    the patch it is the point solution plus the (1 − ν) P ⟨ρ²⟩/(8π r²) correction.
    ``point``: :func:`point_load_resultants` at these x (all > 0), when already computed."""
    x = np.asarray(x, float)
    if np.any(~np.isfinite(x)) or np.any(x < 0):
        raise InvalidParameterError("invalid x: must be finite and >= 0 (r / ell)")
    x_c = check_range("x_c", x_c, 0.0, 1.0)
    nu = check_range("nu", nu, -1.0, 0.5)
    centre = x < 1e-3 * x_c
    xs = np.where(centre, x_c, x)
    m_r, m_t, n_r, n_t = _point_load_resultants(xs, nu) if point is None else point
    h, hbar = _hertz_h(xs / x_c)
    m_sum = m_r + m_t - (1.0 + nu) * h / (2.0 * math.pi)
    m_diff = (m_t - m_r) + (1.0 - nu) * (h - hbar) / (2.0 * math.pi)
    out = _surface(0.5 * (m_sum - m_diff), 0.5 * (m_sum + m_diff), n_r, n_t)
    if np.any(centre):
        inner0, outer0 = hertz_patch_centre_coefficients(1.0 / x_c, nu)
        for key, value in (("inner", inner0), ("outer", outer0)):
            for comp in ("_r", "_theta", "_s1"):
                out[key + comp] = np.where(centre, value, out[key + comp])
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
