"""One collision's loads from the calibrated contact law: peak force, contact radius and
contact duration against the normal impact speed.

The two partners are :class:`demfem.contact.ContactBody` objects: a cartridge is its
equivalent body (:meth:`ContactBody.from_cartridge`: the cartridge's mass, the equivalent
sphere's radius for Hertz, the body's wall for Reissner); a wall, the belt or the gate is a
flat, immovable half-space of the wall's glass (``mass = radius = inf``, the wall's E and ν,
no shell). The peak force is that of the calibrated Hertz–Reissner law
(:func:`demfem.contact.max_contact_force`, eq. 12 of the paper); the Hertz contact radius at
that force is a = (3 F R* / (4 E*))^{1/3}; the contact duration of the same law is

    τ = 2 ∫_0^{F_max} (dδ/dF) dF / √(v² − 2 U(F)/m*),
    δ(F) = (F/k_H)^{2/3} + F/k_R,   U(F) = (2/5) F^{5/3} / k_H^{2/3} + F² / (2 k_R),

which reduces to the Hertz duration 2.9432 δ_max / v (:func:`demfem.contact.
hertz_contact_duration`) without a shell and to π √(m*/k_R) without Hertz.

For speed, :class:`ImpactLaw` tabulates F(v) and τ(v) on a log grid once per partner type and
interpolates log-log (relative error < 1e-6 on the default grid, checked by the tests).

SI units: m/s, N, m, s, Pa, kg.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Optional

import numpy as np
from scipy.integrate import quad

from demfem.cartridge import Cartridge
from demfem.contact import ContactBody, max_contact_force
from demfem.errors import InvalidParameterError, check_positive, check_range

__all__ = ["PARTNERS", "cartridge_body", "flat_partner", "pair_constants", "impact_duration",
           "contact_radius", "ImpactLaw"]

#: Partner types of an impact event, by code (see :mod:`demfem.assess.events`).
PARTNERS = ("sphere", "wall")


def cartridge_body(young_modulus: float, poisson_ratio: Optional[float] = None,
                   cartridge: Optional[Cartridge] = None) -> ContactBody:
    """The equivalent body of ``cartridge`` (default: the 3 mL default) made of its glass
    with Young's modulus ``young_modulus`` (Pa) and, if given, ``poisson_ratio``."""
    cartridge = cartridge or Cartridge()
    E = check_positive("young_modulus", young_modulus)
    mat = cartridge.material.with_modulus(E)
    if poisson_ratio is not None:
        mat = replace(mat, nu=check_range("poisson_ratio", poisson_ratio, -1.0, 0.5))
    return ContactBody.from_cartridge(replace(cartridge, material=mat))


def flat_partner(young_modulus: float, poisson_ratio: float) -> ContactBody:
    """An immovable flat half-space of Young's modulus (Pa) and Poisson's ratio: a wall,
    the belt or the gate."""
    return ContactBody(mass=math.inf, radius=math.inf,
                       E=check_positive("young_modulus", young_modulus),
                       nu=check_range("poisson_ratio", poisson_ratio, -1.0, 0.5))


def pair_constants(a: ContactBody, b: ContactBody) -> dict[str, float]:
    """Constants of a pair: ``r_star`` (m), ``e_star`` (Pa), ``m_star`` (kg), ``k_h``
    (N/m^{3/2}) and ``k_r`` (N/m; inf without a shell), as in eqs. 3, 4, 9 of the paper."""
    inv = lambda x: 0.0 if math.isinf(x) else 1.0 / x  # noqa: E731
    if math.isinf(a.mass) and math.isinf(b.mass):
        raise InvalidParameterError("invalid pair: both bodies have mass = inf")
    r_star = 1.0 / (inv(a.radius) + inv(b.radius))
    e_star = 1.0 / ((1.0 - a.nu**2) * inv(a.E) + (1.0 - b.nu**2) * inv(b.E))
    m_star = 1.0 / (inv(a.mass) + inv(b.mass))
    sk = inv(a.k_reissner) + inv(b.k_reissner)
    k_r = 1.0 / sk if sk > 0 else math.inf
    return {"r_star": r_star, "e_star": e_star, "m_star": m_star,
            "k_h": 4.0 / 3.0 * math.sqrt(r_star) * e_star, "k_r": k_r}


def contact_radius(force: Any, r_star: float, e_star: float) -> np.ndarray:
    """Hertz contact radius a = (3 F R* / (4 E*))^{1/3} (m) at force F (N)."""
    f = np.maximum(np.asarray(force, float), 0.0)
    return np.cbrt(3.0 * f * check_positive("r_star", r_star)
                   / (4.0 * check_positive("e_star", e_star)))


def impact_duration(a: ContactBody, b: ContactBody, v_rel: float) -> float:
    """Contact duration (s) of an undamped impact at ``v_rel`` (m/s) under the Hertz–Reissner
    law (module docstring), by quadrature with F = F_max (1 − s²)."""
    v = check_positive("v_rel", v_rel)
    p = pair_constants(a, b)
    f_max = max_contact_force(a, b, v, "hertz_reissner")
    kh23 = p["k_h"] ** (2.0 / 3.0)
    inv_kr = 0.0 if math.isinf(p["k_r"]) else 1.0 / p["k_r"]
    w = 0.5 * p["m_star"] * v * v

    def energy(f: float) -> float:
        return 0.4 * f ** (5.0 / 3.0) / kh23 + 0.5 * f * f * inv_kr

    def integrand(s: float) -> float:
        f = f_max * (1.0 - s * s)
        if f <= 0.0:
            return 0.0
        ddelta = (2.0 / 3.0) * f ** (-1.0 / 3.0) / kh23 + inv_kr
        rest = max((w - energy(f)) / w, 0.0)
        # v² − 2U/m* = v² rest; dF = 2 F_max s ds; rest ~ s² near s = 0
        return ddelta * 2.0 * f_max * s / (v * math.sqrt(rest)) if rest > 0 else (
            ddelta * 2.0 * f_max / v / math.sqrt(max(_slope(energy, f_max, w), 1e-300)))

    value, _ = quad(integrand, 0.0, 1.0, limit=200, epsabs=0.0, epsrel=1e-10)
    return 2.0 * value


def _slope(energy, f_max: float, w: float) -> float:
    """lim_{s→0} (1 − U(F)/W)/s² at F = F_max (1 − s²): 2 F_max U'(F_max) / W."""
    h = 1e-6 * f_max
    du = (energy(f_max) - energy(f_max - h)) / h
    return 2.0 * f_max * du / w


@dataclass
class ImpactLaw:
    """Peak force and duration of impacts of ``body`` against ``partner`` under the
    calibrated Hertz–Reissner law, tabulated on ``n`` log-spaced speeds in [v_min, v_max]
    (m/s) and interpolated log-log. Speeds outside the grid are computed directly."""

    body: ContactBody
    partner: ContactBody
    v_min: float = 1e-4
    v_max: float = 10.0
    n: int = 241

    def __post_init__(self) -> None:
        self.v_min = check_positive("v_min", self.v_min)
        self.v_max = check_range("v_max", self.v_max, self.v_min, math.inf)
        self.constants = pair_constants(self.body, self.partner)
        self._v = np.geomspace(self.v_min, self.v_max, self.n)
        self._lf = np.log([max_contact_force(self.body, self.partner, float(v),
                                             "hertz_reissner") for v in self._v])
        self._lt = np.log([impact_duration(self.body, self.partner, float(v))
                           for v in self._v])

    def _eval(self, v: np.ndarray, table: np.ndarray, direct) -> np.ndarray:
        v = np.asarray(v, float)
        if np.any(~np.isfinite(v)) or np.any(v <= 0):
            raise InvalidParameterError("invalid normal_speed: must be finite and > 0 m/s")
        out = np.exp(np.interp(np.log(v), np.log(self._v), table))
        outside = (v < self.v_min) | (v > self.v_max)
        for k in np.flatnonzero(outside):
            out.flat[k] = direct(float(v.flat[k]))
        return out

    def force(self, v: np.ndarray) -> np.ndarray:
        """Peak normal force (N) at normal impact speeds ``v`` (m/s, > 0)."""
        return self._eval(v, self._lf, lambda x: max_contact_force(
            self.body, self.partner, x, "hertz_reissner"))

    def duration(self, v: np.ndarray) -> np.ndarray:
        """Contact duration (s) at normal impact speeds ``v`` (m/s, > 0)."""
        return self._eval(v, self._lt, lambda x: impact_duration(self.body, self.partner, x))

    def contact_radius(self, force: Any) -> np.ndarray:
        """Hertz contact radius (m) at ``force`` (N) for this pair."""
        return contact_radius(force, self.constants["r_star"], self.constants["e_star"])
