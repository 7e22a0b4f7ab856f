"""Contact laws of Boso et al. (eqs. 1–15) and the calibration of the equivalent sphere.

Two colliding cartridges deform in two ways at once: Hertzian indentation at the contact
(eqs. 1–4) and bending/membrane deflection of the thin glass wall, which Reissner's
shallow-shell solution gives as a linear spring (eqs. 5–6). The paper puts the two in series
and, from the energy balance of the impact (eqs. 7–11), gets the maximum contact force as the
root of eq. 12; eqs. 13–15 give an explicit linearised alternative. SI units throughout: m,
kg, s, N, Pa.

The laws are written once, in the Rust core (``demfem._core``, the crate's ``contact``
module), which the DEM uses. This module is their documented Python front: each function
validates its inputs here (errors name the field) and computes through the core. The tests
check the core against closed forms and against independent scipy computations (Brent's
method on eq. 12, adaptive Runge–Kutta integrations of the Tsuji impact) kept in
``tests/python/contact_oracles.py``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, NamedTuple, Optional

import numpy as np

from demfem import _core
from demfem.errors import InvalidParameterError, as_real, check_positive, check_range

if TYPE_CHECKING:
    from demfem.cartridge import Cartridge

__all__ = [
    "effective_modulus",
    "effective_radius",
    "effective_mass",
    "hertz_stiffness",
    "reissner_stiffness",
    "ContactBody",
    "MODELS",
    "max_contact_force",
    "k_linear",
    "k_eq",
    "normal_force",
    "hertz_max_overlap",
    "hertz_contact_duration",
    "rayleigh_time_step",
    "tsuji_restitution",
    "tsuji_damping_for_restitution",
    "ImpactResult",
]

Model = Literal["hertz", "reissner", "hertz_reissner", "linearized"]
MODELS: tuple[str, ...] = ("hertz", "reissner", "hertz_reissner", "linearized")


def _check_nu(field: str, nu: float) -> float:
    return check_range(field, nu, -1.0, 0.5)


def _check_positive_or_inf(field: str, value: float) -> float:
    """``value`` as a float if it is > 0 and finite, or +inf; else an error naming ``field``."""
    x = as_real(field, value)
    if math.isinf(x) and x > 0:
        return x
    return check_positive(field, value)


def effective_modulus(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """E* from 1/E* = (1−ν1²)/E1 + (1−ν2²)/E2 (eq. 4), Pa. ``E2 = inf``: rigid partner.

    Computed by the Rust core (``demfem._core.effective_modulus``)."""
    E1 = check_positive("E1", E1)
    nu1 = _check_nu("nu1", nu1)
    nu2 = _check_nu("nu2", nu2)
    E2 = _check_positive_or_inf("E2", E2)
    return _core.effective_modulus(E1, nu1, E2, nu2)


def effective_radius(R1: float, R2: float) -> float:
    """R* from 1/R* = 1/R1 + 1/R2 (eq. 3), m. ``R2 = inf``: a plane.

    Computed by the Rust core (``demfem._core.effective_radius``)."""
    R1 = check_positive("R1", R1)
    R2 = _check_positive_or_inf("R2", R2)
    return _core.effective_radius(R1, R2)


def effective_mass(m1: float, m2: float) -> float:
    """m* from 1/m* = 1/m1 + 1/m2 (eq. 9), kg. ``m2 = inf``: an immovable partner.

    Computed by the Rust core (``demfem._core.effective_mass``)."""
    m1 = check_positive("m1", m1)
    m2 = _check_positive_or_inf("m2", m2)
    return _core.effective_mass(m1, m2)


def hertz_stiffness(R1: float, R2: float, E1: float, nu1: float, E2: float, nu2: float) -> float:
    """Hertz stiffness k_H = 4/3 √R* E* (eqs. 2–4), N/m^{3/2}; F = k_H d^{3/2} (eq. 1).

    Radii in m (``inf`` for a plane), moduli in Pa (``inf`` for a rigid partner). Computed by
    the Rust core (``demfem._core.hertz_stiffness`` of R* and E*).
    """
    return _core.hertz_stiffness(effective_radius(R1, R2), effective_modulus(E1, nu1, E2, nu2))


def reissner_stiffness(E: float, nu: float, t: float, R: float) -> float:
    """Reissner point-load stiffness of a thin shallow shell (eq. 6), N/m:

    k_R = 4 / √(3 (1 − ν²)) · E t² / R,

    with E in Pa, wall thickness ``t`` (m) and mid-surface radius of curvature ``R`` (m),
    0 < t < R; F = k_R d_R (eq. 5). Computed by the Rust core
    (``demfem._core.reissner_stiffness``).
    """
    E = check_positive("E", E)
    nu = _check_nu("nu", nu)
    t = check_positive("t", t)
    R = check_positive("R", R)
    if t >= R:
        raise InvalidParameterError(f"invalid t = {t!r}: must be < R = {R!r} (a thin shell)")
    return _core.reissner_stiffness(E, nu, t, R)


@dataclass(frozen=True)
class ContactBody:
    """One partner of an impact, as the paper's 'equivalent empty sphere'.

    Parameters
    ----------
    mass:
        Mass, kg (``inf`` for an immovable wall).
    radius:
        Radius of curvature at the contact for Hertz, m (``inf`` for a plane).
    E, nu:
        Young's modulus (Pa, ``inf`` for a rigid body) and Poisson's ratio.
    shell_thickness:
        Wall thickness for Reissner's formula, m; ``None`` for a solid body (no shell term).
    shell_radius:
        Mid-surface radius of the shell for Reissner's formula, m; required with a thickness.
    """

    mass: float
    radius: float
    E: float
    nu: float
    shell_thickness: Optional[float] = None
    shell_radius: Optional[float] = None

    def __post_init__(self) -> None:
        for name in ("mass", "radius", "E"):
            v = as_real(name, getattr(self, name))
            if not (math.isinf(v) and v > 0):
                check_positive(name, v)
            object.__setattr__(self, name, v)
        object.__setattr__(self, "nu", _check_nu("nu", self.nu))
        if (self.shell_thickness is None) != (self.shell_radius is None):
            raise InvalidParameterError(
                "invalid shell: shell_thickness and shell_radius must be given together "
                f"(got shell_thickness={self.shell_thickness!r}, shell_radius={self.shell_radius!r})"
            )
        if self.shell_thickness is not None and self.shell_radius is not None:
            t = check_positive("shell_thickness", self.shell_thickness)
            R = check_positive("shell_radius", self.shell_radius)
            if t >= R:
                raise InvalidParameterError(
                    f"invalid shell_thickness = {t!r}: must be < shell_radius = {R!r}"
                )
            if math.isinf(self.E):
                raise InvalidParameterError("invalid E = inf: a rigid body cannot be a shell")

    @classmethod
    def from_cartridge(cls, cartridge: "Cartridge") -> "ContactBody":
        """The paper's equivalent body of a cartridge.

        * mass: the cartridge's mass;
        * radius (Hertz): the equivalent sphere's radius — the sphere the DEM simulates,
          which has the cartridge's mass and material (paper, Fig. 2a and Table S1);
        * shell: Reissner's formula is for a shell of radius of curvature R loaded by a point
          force; the wall that deflects when two cartridges collide is the cylindrical body,
          whose curvature radius is its **mid-surface radius** (OD − t)/2 = 5.25 mm, not the
          8.1 mm equivalent-sphere radius, which is a mass-preserving construct with no wall.
          (A cylinder is more compliant than a sphere of the same R, because one of its
          directions is flat; the FEM collision of two real cartridges measures that error.)
        """
        sphere = cartridge.equivalent_sphere()
        mat = cartridge.material
        return cls(
            mass=cartridge.mass,
            radius=sphere.radius,
            E=mat.E,
            nu=mat.nu,
            shell_thickness=cartridge.wall_thickness,
            shell_radius=cartridge.body_mid_radius,
        )

    @classmethod
    def rigid_wall(cls) -> "ContactBody":
        """An immovable, rigid, flat wall."""
        return cls(mass=math.inf, radius=math.inf, E=math.inf, nu=0.0)

    @property
    def k_reissner(self) -> float:
        """Reissner stiffness of this body's shell (eq. 6), N/m; ``inf`` without a shell."""
        if self.shell_thickness is None or self.shell_radius is None:
            return math.inf
        return reissner_stiffness(self.E, self.nu, self.shell_thickness, self.shell_radius)


class _Pair(NamedTuple):
    """The effective quantities of a pair of bodies (eqs. 2–4, 6, 9)."""

    k_h: float  # Hertz stiffness, N/m^{3/2}
    k_r: float  # Reissner stiffness of both shells in series, N/m (inf: no shell)
    m_star: float  # effective mass, kg
    r_star: float  # effective radius, m
    e_star: float  # effective modulus, Pa


def _pair(a: ContactBody, b: ContactBody) -> _Pair:
    """The effective quantities of a pair, from the core; ``inf`` entries (a plane, a rigid
    or an immovable wall) drop out of the harmonic sums of eqs. 3, 4 and 9."""
    for what, x, y in (("radius", a.radius, b.radius), ("mass", a.mass, b.mass), ("E", a.E, b.E)):
        if math.isinf(x) and math.isinf(y):
            raise InvalidParameterError(
                f"invalid pair: both bodies have {what} = inf (no finite contact partner)")
    # the core takes the finite partner first (the second may be inf)
    r1, r2 = (a, b) if math.isfinite(a.radius) else (b, a)
    e1, e2 = (a, b) if math.isfinite(a.E) else (b, a)
    m1, m2 = (a, b) if math.isfinite(a.mass) else (b, a)
    r_star = _core.effective_radius(r1.radius, r2.radius)
    e_star = _core.effective_modulus(e1.E, e1.nu, e2.E, e2.nu)
    m_star = _core.effective_mass(m1.mass, m2.mass)
    k_r = _core.series_stiffness(a.k_reissner, b.k_reissner)
    return _Pair(_core.hertz_stiffness(r_star, e_star), k_r, m_star, r_star, e_star)


#: Smallest non-zero relative impact speed, m/s: below it m* v_rel^2 can underflow to zero
#: (a ZeroDivisionError otherwise) and overlaps would be below 1e-20 m, far under any
#: physical length.
V_REL_MIN = 1e-12


def _check_v(v_rel: float, allow_zero: bool = True) -> float:
    v = check_range("v_rel", v_rel, 0.0, math.inf, lo_open=False)
    if (v == 0.0 and not allow_zero) or 0.0 < v < V_REL_MIN:
        raise InvalidParameterError(
            f"invalid v_rel = {v_rel!r}: must be {'0 or ' if allow_zero else ''}in "
            f"[{V_REL_MIN:g}, inf) m/s")
    return v


def k_linear(a: ContactBody, b: ContactBody, v_rel: float) -> float:
    """Linearised Hertz stiffness (eq. 13), N/m:
    k_lin = 4/3 (15/16)^{1/5} R*^{2/5} E*^{4/5} m*^{1/5} v_rel^{2/5}.
    It is the secant stiffness F/δ at the maximum of a Hertz impact; an impact on a spring of
    this stiffness reaches √(4/5) times the Hertz maximum force (and overlap).
    Computed by the Rust core (``demfem._core.linearized_hertz_stiffness``)."""
    v = _check_v(v_rel)
    p = _pair(a, b)
    return _core.linearized_hertz_stiffness(p.r_star, p.e_star, p.m_star, v)


def k_eq(a: ContactBody, b: ContactBody, v_rel: float) -> float:
    """Equivalent stiffness 1/k_eq = 1/k_R1 + 1/k_R2 + 1/k_lin (eq. 15), N/m.
    Computed by the Rust core (``demfem._core.series_stiffness``)."""
    p = _pair(a, b)
    return _core.series_stiffness(p.k_r, k_linear(a, b, v_rel))


def max_contact_force(a: ContactBody, b: ContactBody, v_rel: float, model: Model = "hertz_reissner") -> float:
    """Maximum normal force (N) of an impact at relative speed ``v_rel`` (m/s).

    ``model``:

    * ``"hertz"`` — shells rigid: m* v² = (4/5) F^{5/3} / k_H^{2/3} (eq. 12 with k_R → ∞),
      F = k_H^{2/5} (5/4 m* v²)^{3/5};
    * ``"reissner"`` — contact rigid: m* v² = F²/k_R1 + F²/k_R2 (eq. 12 without Hertz);
    * ``"hertz_reissner"`` — both in series: the root of eq. 12,
      m* v² = F²/k_R1 + F²/k_R2 + (4/5) F^{5/3}/k_H^{2/3}, found by the core by Newton's
      method in x = F^{1/3} from above, starting at min(F_hertz, F_reissner)^{1/3} (each law
      alone reaches m* v² at a smaller x, and the right side is convex and increasing in x),
      to round-off; without a shell it is the Hertz force;
    * ``"linearized"`` — F = √(k_eq m*) v (eqs. 13–15).

    Computed by the Rust core (``demfem._core.max_impact_force``).
    """
    v = _check_v(v_rel)
    if model not in MODELS:
        raise InvalidParameterError(f"invalid model = {model!r}: must be one of {MODELS}")
    p = _pair(a, b)
    if v == 0.0:
        return 0.0
    if model == "hertz":
        return _core.max_impact_force(p.m_star, v, "hertz", k_h=p.k_h)
    if model == "reissner":
        if not math.isfinite(p.k_r):
            raise InvalidParameterError("invalid model = 'reissner': neither body has a shell")
        return _core.max_impact_force(p.m_star, v, "linear", k=p.k_r)
    if model == "linearized":
        return _core.max_impact_force(p.m_star, v, "linear", k=k_eq(a, b, v))
    if not math.isfinite(p.k_r):  # no shell: eq. 12 is Hertz alone
        return _core.max_impact_force(p.m_star, v, "hertz", k_h=p.k_h)
    return _core.max_impact_force(p.m_star, v, "hertz_reissner", k_h=p.k_h, k_r=p.k_r)


def normal_force(overlap: np.ndarray, model: Literal["hertz", "linear", "hertz_reissner"],
                 k_h: float = math.nan, k_r: float = math.nan, k: float = math.nan) -> np.ndarray:
    """Elastic normal force (N) at each overlap (m), in the shape of ``overlap``; zero where
    overlap <= 0.

    * ``"hertz"``: F = k_H d^{3/2} (eq. 1), ``k_h`` in N/m^{3/2};
    * ``"linear"``: F = k d, ``k`` in N/m (eq. 5 for a shell, eq. 15 linearised);
    * ``"hertz_reissner"``: d = (F/k_H)^{2/3} + F/k_R, the series law behind eq. 12 (``k_r``
      in N/m), solved by the core in normalised form (u³ + u² = s, see docs/method.md).

    Computed by the Rust core (``demfem._core.normal_force``, which the DEM uses).
    """
    d = np.asarray(overlap, dtype=float)
    if not np.all(np.isfinite(d)):
        raise InvalidParameterError("invalid overlap: must be finite (NaN or inf given)")
    if model == "hertz":
        kw = {"k_h": check_positive("k_h", k_h)}
    elif model == "linear":
        kw = {"k": check_positive("k", k)}
    elif model == "hertz_reissner":
        kw = {"k_h": check_positive("k_h", k_h), "k_r": check_positive("k_r", k_r)}
    else:
        raise InvalidParameterError(
            f"invalid model = {model!r}: must be one of ('hertz', 'linear', 'hertz_reissner')")
    f, _ = _core.normal_force(np.ascontiguousarray(d.reshape(-1)), model, **kw)
    return f.reshape(d.shape)


def hertz_max_overlap(a: ContactBody, b: ContactBody, v_rel: float) -> float:
    """Maximum overlap of an undamped Hertz impact, (5 m* v² / (4 k_H))^{2/5}, m.
    Computed by the Rust core (``demfem._core.hertz_max_overlap``)."""
    p = _pair(a, b)
    v = _check_v(v_rel)
    return _core.hertz_max_overlap(p.k_h, p.m_star, v)


def hertz_contact_duration(a: ContactBody, b: ContactBody, v_rel: float) -> float:
    """Duration of an undamped Hertz impact, s:
    t_c = 2 (δ_max / v) ∫₀¹ (1 − x^{5/2})^{-1/2} dx = 2.9432… δ_max / v (Johnson §11.4).
    Computed by the Rust core (``demfem._core.hertz_impact_duration``)."""
    v = _check_v(v_rel, allow_zero=False)
    p = _pair(a, b)
    return _core.hertz_impact_duration(p.k_h, p.m_star, v)


def rayleigh_time_step(radius: float, E: float, nu: float, density: float) -> float:
    """Rayleigh time step π R √(ρ/G) / (0.1631 ν + 0.8766), s, of a sphere of ``radius`` (m),
    Young's modulus ``E`` (Pa), Poisson's ratio ``nu`` and ``density`` (kg/m³), with
    G = E / (2 (1 + ν)). Computed by the Rust core (``demfem._core.rayleigh_time_step``),
    which refuses, naming ``E``, a modulus so small (subnormal) that G underflows to 0."""
    R = check_positive("radius", radius)
    E = check_positive("E", E)
    nu = _check_nu("nu", nu)
    rho = check_positive("density", density)
    return _core.rayleigh_time_step(R, E, nu, rho)


# ---------------------------------------------------------------------------- restitution
#: Largest Tsuji ζ that the core integrates (its ``MAX_TSUJI_ZETA``); beyond it
#: :func:`tsuji_restitution` returns the overdamped limit e = 1.25/ζ² (clamped) or 0.
MAX_TSUJI_ZETA = 1e3


def tsuji_restitution(zeta: float, clamp: bool = False) -> float:
    """Restitution coefficient of a Hertz impact with Tsuji damping (dimensionless).

    Force F = k_H δ^{3/2} + ζ √(m* k_H) δ^{1/4} δ̇ (Tsuji, Tanaka & Ishida 1992; the
    calibration e(ζ) is the one analysed by Antypov & Elliott 2011). Scaling δ = s X,
    t = T τ with T² = m*/(k_H s^{1/2}) and s such that the impact speed is 1 turns the
    equation of motion into X'' = −X^{3/2} − ζ X^{1/4} X', so e depends on ζ only. With
    ``clamp=True`` the total force is clamped at ≥ 0 (no attraction near separation), and
    the bodies separate when it vanishes: the realised restitution is then higher.

    Computed by the Rust core (``demfem._core.tsuji_restitution``): classical RK4 with a step
    that shrinks where X^{1/4} is not smooth (within about 3e-11 of an adaptive DOP853
    integration unclamped, 3e-9 clamped); beyond ζ = :data:`MAX_TSUJI_ZETA` the overdamped
    limit 1.25/ζ² (clamped) or 0 (unclamped).
    """
    zeta = check_range("zeta", zeta, 0.0, math.inf, lo_open=False)
    return _core.tsuji_restitution(zeta, bool(clamp))


def tsuji_damping_for_restitution(e: float, clamp: bool = False) -> float:
    """Tsuji damping parameter ζ (dimensionless) that realises restitution ``e`` in (0, 1].

    Computed by the Rust core (``demfem._core.tsuji_damping_for_restitution``): bisection on
    its :func:`tsuji_restitution`, which decreases with ζ, to 1e-13 relative in ζ."""
    e = check_range("restitution", e, 0.0, 1.0, hi_open=False)
    return _core.tsuji_damping_for_restitution(e, bool(clamp))


@dataclass(frozen=True)
class ImpactResult:
    """One integrated normal impact: time (s), overlap (m), normal force (N) histories,
    the realised restitution and the maximum force (N). (The integration itself, a scipy
    reference for the tests, lives in ``tests/python/contact_oracles.py``.)"""

    time: np.ndarray
    overlap: np.ndarray
    force: np.ndarray
    restitution: float
    max_force: float
