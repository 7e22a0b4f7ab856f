"""Hertz contact: the size of the contact, its pressure and the stresses it puts on the glass.

Three contact geometries between smooth, frictionless, linear-elastic bodies (Johnson,
*Contact Mechanics*, 1985, ch. 3–4; Hertz 1882):

* **point (circular)** — two spheres, or two equal cylinders crossed at 90°: relative radius
  R* (1/R* = 1/R1 + 1/R2), contact radius a = (3 F R* / (4 E*))^{1/3}, peak pressure
  p0 = 3 F / (2π a²) (Johnson §4.2);
* **elliptical** — general curved bodies, e.g. two cylinders crossed at an angle θ: the
  principal relative curvatures A ≤ B (Johnson §3.5 and §4.2; for cylinders of radii R1, R2
  whose axes make the angle θ, A + B = (1/R1 + 1/R2)/2 and
  B − A = ½ √(1/R1² + 1/R2² + 2 cos 2θ / (R1 R2))) set the ellipse's eccentricity e
  (b/a = √(1 − e²), a along the direction of the smaller curvature A) through

      B/A = [E(e)/(1 − e²) − K(e)] / [K(e) − E(e)]                            (Johnson §3.5)

  with K, E the complete elliptic integrals of modulus e; then
  a³ = 3 F [K(e) − E(e)] / (2π A E* e²), b = a √(1 − e²), p0 = 3 F / (2π a b);
* **line** — parallel cylinders over a length L: half-width b = √(4 F' R* / (π E*)),
  p0 = 2 F' / (π b), F' = F / L (Johnson §4.3).

E* is the contact modulus, 1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2.

Stresses (tension > 0), in units of p0 with lengths in units of the contact radius a:

* :func:`circular_surface_stresses` — the surface field of the circular contact: outside,
  σ_r = −σ_θ = (1 − 2ν) p0 a² / (3 r²), largest at the edge r = a: (1 − 2ν) p0 / 3, the
  ring-crack stress of glass (Johnson §3.4);
* :func:`elliptical_axis_edge_stresses` — the surface tension at the ends of the axes of an
  elliptical contact (Johnson §3.5, after Thomas & Hoersch 1930 and Lundberg & Sjövall 1958);
* :func:`circular_subsurface_stresses` — the whole field beneath a circular contact in
  Hamilton's (1983) explicit form (the normal-load part of his eqs.; Huber 1904);
* :func:`line_sliding_stresses` — the plane-strain field of a sliding line contact (McEwen
  1949; Johnson §7.2), the normal and the tangential parts separately.

SI units for the dimensional functions: N, N/m, m, Pa, 1/m.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from demfem.errors import InvalidParameterError, check_positive, check_range

__all__ = ["contact_modulus", "crossed_cylinder_curvatures", "ellipse_eccentricity_squared",
           "ellipse_size_factors", "elliptical_contact", "point_contact", "line_contact",
           "circular_surface_stresses", "elliptical_axis_edge_stresses",
           "circular_subsurface_stresses", "line_sliding_stresses"]


def contact_modulus(E1: float, nu1: float, E2: float = math.nan, nu2: float = math.nan) -> float:
    """E* (Pa) from 1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2; without the second body, two bodies
    of the first material; ``E2 = inf`` is a rigid partner."""
    E1 = check_positive("E1", E1)
    nu1 = check_range("nu1", nu1, -1.0, 0.5)
    if math.isnan(E2):
        E2, nu2 = E1, nu1
    inv2 = 0.0 if math.isinf(E2) else (1.0 - check_range("nu2", nu2, -1.0, 0.5) ** 2) / \
        check_positive("E2", E2)
    return 1.0 / ((1.0 - nu1 * nu1) / E1 + inv2)


def crossed_cylinder_curvatures(radius_1: float, radius_2: float,
                                crossing_angle_deg: float) -> tuple[float, float]:
    """Principal relative curvatures (A, B), 1/m, A ≤ B, of two cylinders of radii
    ``radius_1``, ``radius_2`` (m; ``inf`` for a flat) whose axes make the angle
    ``crossing_angle_deg`` (degrees, in (0, 90]) (Johnson §3.5 with R' = R, R'' = ∞).
    Two equal cylinders: A = (1 − cos θ)/(2R), B = (1 + cos θ)/(2R); at 90° a circle with
    R* = 1/(2A) = R, the contact of a sphere of radius R on a flat."""
    r1 = check_positive("radius_1", radius_1)
    r2 = check_positive("radius_2", radius_2) if not math.isinf(radius_2) else math.inf
    theta = math.radians(check_range("crossing_angle_deg", crossing_angle_deg, 0.0, 90.0,
                                     hi_open=False))
    k1, k2 = 1.0 / r1, 0.0 if math.isinf(r2) else 1.0 / r2
    total = 0.5 * (k1 + k2)                                                        # A + B
    diff = 0.5 * math.sqrt(max(k1 * k1 + k2 * k2 + 2.0 * k1 * k2 * math.cos(2.0 * theta), 0.0))
    return 0.5 * (total - diff), 0.5 * (total + diff)


def ellipse_eccentricity_squared(curvature_ratio: float) -> float:
    """e² of the Hertz contact ellipse for the curvature ratio B/A ≥ 1 (Johnson §3.5);
    0 for a circle (B/A − 1 < 1e-9). Solved with Brent's method to 1e-15 relative."""
    ratio = check_range("curvature_ratio", curvature_ratio, 1.0, math.inf, lo_open=False)
    if ratio - 1.0 < 1e-9:   # a circle to 1e-9 (e² < 1e-9)
        return 0.0

    def g(m: float) -> float:  # m = e²; scipy's ellipk/ellipe take the parameter m = e²
        k, e = ellipk(m), ellipe(m)
        return math.log((e / (1.0 - m) - k) / (k - e)) - math.log(ratio)

    hi = 1.0 - 1e-16
    if g(hi) < 0:
        raise InvalidParameterError(f"invalid curvature_ratio = {ratio!r}: too elongated a "
                                    "contact for an elliptical Hertz solution (b/a < 1e-8)")
    return brentq(g, 1e-12, hi, xtol=1e-16, rtol=1e-15, maxiter=500)


def ellipse_size_factors(A: float, B: float) -> tuple[float, float, float]:
    """(α, β, e²) of the Hertz ellipse for curvatures A ≤ B (1/m): a = α (F/E*)^{1/3} (α in
    m·(Pa/N)^{1/3}), b = β a, e² = 1 − β²."""
    e2 = ellipse_eccentricity_squared(B / A)
    if e2 == 0.0:  # circle: a³ = 3 F R* / (4 E*), R* = 1 / (2A)
        return (3.0 / (8.0 * A)) ** (1.0 / 3.0), 1.0, 0.0
    k, e = ellipk(e2), ellipe(e2)
    return (3.0 * (k - e) / (2.0 * math.pi * A * e2)) ** (1.0 / 3.0), math.sqrt(1.0 - e2), e2


def elliptical_contact(force: Any, A: float, B: float, e_star: float) -> dict[str, np.ndarray]:
    """Hertz elliptical contact at normal ``force`` (N, array) between bodies of principal
    relative curvatures ``A`` ≤ ``B`` (1/m) and contact modulus ``e_star`` (Pa): semi-axes
    ``a`` ≥ ``b`` (m; a along the direction of A), peak pressure ``p0`` (Pa), ``e2`` = e²."""
    A = check_positive("A", A)
    B = check_range("B", B, A, math.inf, lo_open=False)
    es = check_positive("e_star", e_star)
    alpha, beta, e2 = ellipse_size_factors(A, B)
    f = np.asarray(force, float)
    a = alpha * np.cbrt(f / es)
    b = beta * a
    with np.errstate(divide="ignore", invalid="ignore"):
        p0 = 3.0 * f / (2.0 * math.pi * a * b)
    return {"a": a, "b": b, "p0": p0, "e2": np.full(f.shape, e2)}


def point_contact(force: Any, r_star: float, e_star: float) -> dict[str, np.ndarray]:
    """Circular Hertz contact: radius ``a`` = (3 F R*/(4 E*))^{1/3} (m), ``p0`` =
    3 F/(2π a²) (Pa), approach ``delta`` = a²/R* (m) at ``force`` (N), R* (m), E* (Pa)."""
    r = check_positive("r_star", r_star)
    es = check_positive("e_star", e_star)
    f = np.asarray(force, float)
    a = np.cbrt(3.0 * f * r / (4.0 * es))
    with np.errstate(divide="ignore", invalid="ignore"):
        p0 = 3.0 * f / (2.0 * math.pi * a * a)
    return {"a": a, "p0": p0, "delta": a * a / r}


def line_contact(force_per_length: Any, r_star: float, e_star: float) -> dict[str, np.ndarray]:
    """Hertz line contact: half-width ``b`` = √(4 F' R*/(π E*)) (m) and ``p0`` = 2 F'/(π b)
    (Pa) at ``force_per_length`` F' (N/m), R* (m), E* (Pa)."""
    r = check_positive("r_star", r_star)
    es = check_positive("e_star", e_star)
    fl = np.asarray(force_per_length, float)
    b = np.sqrt(4.0 * fl * r / (math.pi * es))
    with np.errstate(divide="ignore", invalid="ignore"):
        p0 = 2.0 * fl / (math.pi * b)
    return {"b": b, "p0": p0}


def circular_surface_stresses(x: Any, y: Any, nu: float) -> dict[str, np.ndarray]:
    """Surface stresses of the circular Hertz contact, in units of p0, at (x, y) in units of a
    (Johnson §3.4): keys ``xx``, ``yy``, ``xy``, ``zz``.

    r ≥ a: σ_r = −σ_θ = (1 − 2ν)/3 · a²/r²;  r < a: σ_r = (1 − 2ν)/3 · (a²/r²)(1 − (1 −
    r²/a²)^{3/2}) − √(1 − r²/a²), σ_θ = −(1 − 2ν)/3 · (a²/r²)(1 − (1 − r²/a²)^{3/2}) −
    2ν √(1 − r²/a²), σ_z = −√(1 − r²/a²)."""
    nu = check_range("nu", nu, -1.0, 0.5)
    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
    r2 = x * x + y * y
    inside = r2 < 1.0
    s = np.sqrt(np.where(inside, 1.0 - r2, 0.0))
    safe = np.where(r2 > 0, r2, 1.0)
    # (1 − (1 − r²)^{3/2}) / r² → 3/2 as r → 0
    ring = np.where(r2 > 1e-12, (1.0 - s**3) / safe, 1.5 - 0.375 * r2)
    dev = (1.0 - 2.0 * nu) / 3.0 * ring
    s_r = dev - s
    s_t = -dev - 2.0 * nu * s
    c2 = np.where(r2 > 0, x * x / safe, 1.0)
    s2 = np.where(r2 > 0, y * y / safe, 0.0)
    cs = np.where(r2 > 0, x * y / safe, 0.0)
    return {"xx": s_r * c2 + s_t * s2, "yy": s_r * s2 + s_t * c2, "xy": (s_r - s_t) * cs,
            "zz": -s}


def elliptical_axis_edge_stresses(b_over_a: float, nu: float) -> tuple[float, float]:
    """Surface tension at the edge of an elliptical Hertz contact, in units of p0, at the ends
    of the major axis (the stress along that axis) and of the minor axis (along that one), for
    semi-axes ratio b/a ≤ 1 (Johnson §3.5, after Thomas & Hoersch 1930; e² = 1 − b²/a²):

        major-axis end:  (1 − 2ν) (b/a)/e² · [artanh(e)/e − 1]
        minor-axis end:  (1 − 2ν) (b/a)/e² · [1 − (b/a)/e · arctan(e a/b)]

    Both tend to the circular (1 − 2ν)/3 as b/a → 1."""
    beta = check_range("b_over_a", b_over_a, 0.0, 1.0, hi_open=False)
    nu = check_range("nu", nu, -1.0, 0.5)
    e2 = 1.0 - beta * beta
    if e2 < 1e-6:  # series in e²: artanh(e)/e − 1 = e²/3 + e⁴/5, 1 − arctan(t)/t = t²/3 − t⁴/5
        major = (1.0 - 2.0 * nu) * beta * (1.0 / 3.0 + e2 / 5.0)
        minor = (1.0 - 2.0 * nu) * (1.0 / (3.0 * beta) - e2 / (5.0 * beta**3))
        return major, minor
    e = math.sqrt(e2)
    major = (1.0 - 2.0 * nu) * beta / e2 * (math.atanh(e) / e - 1.0)
    minor = (1.0 - 2.0 * nu) * beta / e2 * (1.0 - beta / e * math.atan(e / beta))
    return major, minor


def circular_subsurface_stresses(x: Any, y: Any, z: Any, nu: float) -> dict[str, np.ndarray]:
    """Stresses beneath a circular Hertz contact, in units of p0, at (x, y, z) in units of a
    (z ≥ 0 into the body), from Hamilton's (1983) explicit equations for the normal load
    (equivalent to Huber's 1904 solution): with A = r² + z² − 1, S = √(A² + 4 z²),
    M = √((S + A)/2), N = √((S − A)/2), φ = arctan(1/M),

        σ_xx = (1+ν) z φ + [ (y² − x²)/r² · ((1−ν) N z² − (1−2ν)/3 (N S + 2 A N + 1) − ν M z)
               − N (x² + 2ν y²) − M x² z / S ] / r²,
        σ_yy = the same with x and y exchanged,  σ_zz = −N + M z / S,
        σ_xy = x y (1−2ν)/r⁴ (−N r² + (2/3) N (S + 2A) − z (z N + M) + 2/3)
               + x y z / r⁴ (−M r² / S − z N + M);

    on the axis (r = 0): σ_xx = σ_yy = (1+ν)(z arctan(1/z) − 1) + 1/(2(1 + z²)),
    σ_zz = −1/(1 + z²). Keys ``xx``, ``yy``, ``zz``, ``xy``."""
    nu = check_range("nu", nu, -1.0, 0.5)
    x, y, z = np.broadcast_arrays(*(np.asarray(v, float) for v in (x, y, z)))
    if np.any(z < 0):
        raise InvalidParameterError("invalid z: must be >= 0 (depth into the body, units of a)")
    r2 = x * x + y * y
    axis = r2 < 1e-20
    A = r2 + z * z - 1.0
    S = np.sqrt(A * A + 4.0 * z * z)
    M = np.sqrt(np.maximum(0.5 * (S + A), 0.0))
    N = np.sqrt(np.maximum(0.5 * (S - A), 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        phi = np.arctan2(1.0, M)
        rs = np.where(axis, 1.0, r2)
        Ss = np.where(S > 0, S, 1.0)
        shared = (1.0 - nu) * N * z * z - (1.0 - 2.0 * nu) / 3.0 * (N * S + 2.0 * A * N + 1.0) \
            - nu * M * z
        mz = np.where(S > 0, M * z / Ss, 0.0)
        sxx = (1 + nu) * z * phi + ((y * y - x * x) / rs * shared - N * (x * x + 2 * nu * y * y)
                                    - x * x * mz) / rs
        syy = (1 + nu) * z * phi + ((x * x - y * y) / rs * shared - N * (y * y + 2 * nu * x * x)
                                    - y * y * mz) / rs
        sxy = x * y * (1 - 2 * nu) / rs**2 * (-N * r2 + 2.0 / 3.0 * N * (S + 2 * A)
                                              - z * (z * N + M) + 2.0 / 3.0) \
            + x * y * z / rs**2 * (-r2 * np.where(S > 0, M / Ss, 0.0) - z * N + M)
        szz = -N + mz
        za = np.where(z > 0, z, 1.0)
        on_axis = np.where(z > 0, (1 + nu) * (z * np.arctan(1.0 / za) - 1.0), -(1 + nu)) \
            + 0.5 / (1.0 + z * z)
    sxx = np.where(axis, on_axis, sxx)
    syy = np.where(axis, on_axis, syy)
    sxy = np.where(axis, 0.0, sxy)
    szz = np.where(axis, -1.0 / (1.0 + z * z), szz)
    return {"xx": sxx, "yy": syy, "zz": szz, "xy": sxy}


def line_sliding_stresses(x: Any, z: Any) -> dict[str, np.ndarray]:
    """Plane-strain stresses of a Hertz line contact of half-width b under the pressure
    p0 √(1 − x²/b²) and the tangential traction q = p (in +x; multiply by the friction
    coefficient), at (x, z) in units of b (z ≥ 0 into the body), in units of p0 (McEwen 1949;
    Johnson §7.2): with m² = ½[√((1 − x² + z²)² + 4x²z²) + (1 − x² + z²)],
    n² = ½[√(...) − (1 − x² + z²)], n with the sign of x,

        normal:      σ_x = −[m (1 + (z² + n²)/(m² + n²)) − 2z],  σ_z = −m (1 − (z² + n²)/(m² + n²)),
        tangential:  σ_x = n (2 − (z² − m²)/(m² + n²)) − 2x,     σ_z = −n (z² − m²)/(m² + n²).

    On the surface outside the contact the tangential part is σ_x = −2(x − sgn(x)√(x² − 1)):
    tension 2 at the trailing edge x = −1. Keys ``normal_xx``, ``normal_zz``,
    ``tangential_xx``, ``tangential_zz``."""
    x, z = np.broadcast_arrays(np.asarray(x, float), np.asarray(z, float))
    if np.any(z < 0):
        raise InvalidParameterError("invalid z: must be >= 0 (depth into the body, units of b)")
    k = 1.0 - x * x + z * z
    root = np.sqrt(k * k + 4.0 * x * x * z * z)
    m = np.sqrt(np.maximum(0.5 * (root + k), 0.0))
    n = np.sign(x) * np.sqrt(np.maximum(0.5 * (root - k), 0.0))
    mn = m * m + n * n
    with np.errstate(divide="ignore", invalid="ignore"):
        f_plus = np.where(mn > 0, (z * z + n * n) / mn, 1.0)
        f_minus = np.where(mn > 0, (z * z - m * m) / mn, 0.0)
    return {"normal_xx": -(m * (1.0 + f_plus) - 2.0 * z), "normal_zz": -m * (1.0 - f_plus),
            "tangential_xx": n * (2.0 - f_minus) - 2.0 * x, "tangential_zz": -n * f_minus}
