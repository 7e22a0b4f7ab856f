"""Hertz contact patches of the resolved contact FEM (:mod:`demfem.stress.resolved_fem`).

:class:`HertzPatch` is the pressure of one contact on the loaded body's surface, with an
optional sliding traction q = μ p along the tube's axis; :func:`sphere_on_flat_patch`,
:func:`crossed_cylinders_patch` (90° only) and :func:`parallel_cylinders_patch` (a line contact
of finite length) build it for two bodies of the same glass. Also the closed forms the FEM is
checked against on a half-space: the surface radial stress of the Hertz circle (Johnson 1985)
and the peak tension at the trailing edge of a sliding one (Hamilton 1983).

Units: SI (m, N, Pa).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.special import ellipe, ellipk

from demfem.errors import InvalidParameterError, check_positive, check_range

__all__ = [
    "HertzPatch",
    "effective_modulus_same",
    "check_material",
    "sphere_on_flat_patch",
    "crossed_cylinders_patch",
    "elliptical_semi_axes",
    "parallel_cylinders_patch",
    "hertz_surface_radial_stress",
    "hamilton_max_tension",
]


def effective_modulus_same(E: float, nu: float) -> float:
    """E* = E / (2 (1 − ν²)), Pa: the contact modulus of two bodies of the same glass."""
    E = check_positive("E", E)
    nu = check_range("nu", nu, -1.0, 0.5)
    return E / (2.0 * (1.0 - nu * nu))


def check_material(E: float, nu: float) -> tuple[float, float]:
    """(E, ν) checked: Young's modulus E > 0 (Pa) and Poisson's ratio −1 < ν < 0.5."""
    return check_positive("E", E), check_range("nu", nu, -1.0, 0.5)


@dataclass(frozen=True)
class HertzPatch:
    """The Hertz pressure of one contact, in the surface coordinates (s, z) of the loaded body
    (s across, along the circumference of a tube or x on a block; z along the tube's axis).

    ``kind == "ellipse"``: p = p0 √(1 − (s/a_s)² − (z/a_z)²) (a circle when a_s = a_z);
    ``kind == "line"``: p = p0 √(1 − (s/a_s)²) for |z| ≤ a_z (a_z = half the contact length).
    ``friction`` μ: a sliding traction q = μ p along +z. ``normal_force`` (N) is the whole
    contact's force, ``peak_pressure`` p0 (Pa), semi-axes in m.
    """

    kind: Literal["ellipse", "line"]
    normal_force: float
    semi_axis_s: float
    semi_axis_z: float
    peak_pressure: float
    friction: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in ("ellipse", "line"):
            raise InvalidParameterError(f"invalid kind = {self.kind!r}: must be 'ellipse' or "
                                        "'line'")
        check_positive("normal_force", self.normal_force)
        check_positive("semi_axis_s", self.semi_axis_s)
        check_positive("semi_axis_z", self.semi_axis_z)
        check_positive("peak_pressure", self.peak_pressure)
        check_range("friction", self.friction, 0.0, 1.0, lo_open=False, hi_open=False)

    @property
    def contact_radius(self) -> float:
        """The smaller semi-axis (the half-width b of a line contact), m."""
        return min(self.semi_axis_s, self.semi_axis_z) if self.kind == "ellipse" \
            else self.semi_axis_s

    def pressure(self, s: np.ndarray, z: np.ndarray) -> np.ndarray:
        """p(s, z), Pa (0 outside the contact)."""
        if self.kind == "ellipse":
            q = 1.0 - (s / self.semi_axis_s) ** 2 - (z / self.semi_axis_z) ** 2
        else:
            q = np.where(np.abs(z) <= self.semi_axis_z, 1.0 - (s / self.semi_axis_s) ** 2, -1.0)
        return self.peak_pressure * np.sqrt(np.maximum(q, 0.0))

    def with_friction(self, friction: float) -> "HertzPatch":
        """The same pressure with a sliding traction μ p along +z."""
        return HertzPatch(self.kind, self.normal_force, self.semi_axis_s, self.semi_axis_z,
                          self.peak_pressure, friction)


def sphere_on_flat_patch(normal_force: float, radius: float, E: float, nu: float,
                         friction: float = 0.0) -> HertzPatch:
    """Hertz circle of a glass sphere of ``radius`` (m) on a flat of the same glass:
    a = (3 F R / (4 E*))^(1/3), p0 = 3 F / (2 π a²)."""
    F = check_positive("normal_force", normal_force)
    R = check_positive("radius", radius)
    Es = effective_modulus_same(E, nu)
    a = (3.0 * F * R / (4.0 * Es)) ** (1.0 / 3.0)
    return HertzPatch("ellipse", F, a, a, 3.0 * F / (2.0 * math.pi * a * a), friction)


def crossed_cylinders_patch(normal_force: float, radius: float, E: float, nu: float,
                            crossing_angle_deg: float = 90.0,
                            friction: float = 0.0) -> HertzPatch:
    """Hertz ellipse of two equal glass cylinders (``radius`` m) whose axes cross at
    ``crossing_angle_deg``. The relative curvatures are A, B = (1 ∓ |cos θ|)/(2R) (Johnson
    1985 § 4.2); at 90° A = B = 1/(2R): the circle of a sphere of radius R on a flat.

    Only 90° is accepted: at other angles the ellipse's axes lie at θ/2 to the tube's axis and
    the quarter model's symmetry planes no longer hold.
    """
    th = check_range("crossing_angle_deg", crossing_angle_deg, 0.0, 180.0)
    if abs(th - 90.0) > 1e-9:
        raise InvalidParameterError(
            f"invalid crossing_angle_deg = {crossing_angle_deg!r}: the resolved quarter model "
            "takes 90 only (the ellipse of other angles is not symmetric about the tube's axis)")
    return sphere_on_flat_patch(normal_force, radius, E, nu, friction)


def elliptical_semi_axes(normal_force: float, A: float, B: float, E_star: float
                         ) -> tuple[float, float, float]:
    """(a, b, p0) of the Hertz ellipse for relative curvatures A ≤ B (1/m), a along the
    direction of A (Johnson 1985 eq. 3.29): B/A = ((a/b)² E(e) − K(e)) / (K(e) − E(e)),
    a³ = 3 P (K − E) / (2 π e² E* A)."""
    from scipy.optimize import brentq

    P = check_positive("normal_force", normal_force)
    A = check_positive("A", A)
    B = check_positive("B", B)
    if B < A:
        raise InvalidParameterError(f"invalid B = {B!r}: must be >= A = {A!r}")
    if B / A < 1.0 + 1e-9:
        a = (3.0 * P / (8.0 * E_star * A)) ** (1.0 / 3.0)
        return a, a, 3.0 * P / (2.0 * math.pi * a * a)

    def ratio(m: float) -> float:  # m = e²
        k, e = ellipk(m), ellipe(m)
        return float(((1.0 / (1.0 - m)) * e - k) / (k - e)) - B / A

    m = brentq(ratio, 1e-12, 1.0 - 1e-15)
    k, e = ellipk(m), ellipe(m)
    a = (3.0 * P * (k - e) / (2.0 * math.pi * m * E_star * A)) ** (1.0 / 3.0)
    b = a * math.sqrt(1.0 - m)
    return a, b, 3.0 * P / (2.0 * math.pi * a * b)


def parallel_cylinders_patch(normal_force: float, contact_length: float, radius: float,
                             E: float, nu: float, friction: float = 0.0) -> HertzPatch:
    """Hertz line contact of two equal parallel glass cylinders (``radius`` m) touching over
    ``contact_length`` (m): F' = F/L, R* = R/2, b = √(4 F' R* / (π E*)), p0 = 2 F' / (π b)."""
    F = check_positive("normal_force", normal_force)
    L = check_positive("contact_length", contact_length)
    R = check_positive("radius", radius)
    Es = effective_modulus_same(E, nu)
    fl = F / L
    b = math.sqrt(4.0 * fl * (0.5 * R) / (math.pi * Es))
    return HertzPatch("line", F, b, 0.5 * L, 2.0 * fl / (math.pi * b), friction)


def hertz_surface_radial_stress(r_over_a: np.ndarray, nu: float) -> np.ndarray:
    """σ_r / p0 on the surface of a half-space under the Hertz circle (Johnson 1985 eq. 3.45):
    inside (1−2ν)/3 (a/r)² (1 − (1 − r²/a²)^{3/2}) − √(1 − r²/a²), outside (1−2ν)/3 (a/r)²."""
    x = np.asarray(r_over_a, dtype=float)
    c = (1.0 - 2.0 * nu) / 3.0
    with np.errstate(divide="ignore", invalid="ignore"):
        q = np.sqrt(np.clip(1.0 - x * x, 0.0, None))
        inside = c / (x * x) * (1.0 - q ** 3) - q
        out = np.where(x < 1.0, inside, c / (x * x))
    return np.where(x == 0.0, -(1.0 + 2.0 * nu) / 2.0, out)


def hamilton_max_tension(nu: float, friction: float) -> float:
    """σ_max / p0 at the trailing edge of a sliding Hertz circle (Hamilton 1983):
    (1 − 2ν)/3 + (4 + ν) π μ / 8."""
    return (1.0 - 2.0 * nu) / 3.0 + (4.0 + nu) * math.pi * friction / 8.0
