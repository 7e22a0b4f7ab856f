"""Contact laws of Boso et al. (eqs. 1–15) and the calibration of the equivalent sphere.

Two colliding cartridges deform in two ways at once: Hertzian indentation at the contact
(eqs. 1–4) and bending/membrane deflection of the thin glass wall, which Reissner's
shallow-shell solution gives as a linear spring (eqs. 5–6). The paper puts the two in series
and, from the energy balance of the impact (eqs. 7–11), gets the maximum contact force as the
root of eq. 12; eqs. 13–15 give an explicit linearised alternative. SI units throughout: m,
kg, s, N, Pa.

The same normal laws live in the Rust core (``demfem._core``), which the DEM uses; the test
suite checks that both agree to 1e-12 relative and that both obey the closed forms.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, Optional

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

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
    "damped_hertz_impact",
    "ImpactResult",
]

Model = Literal["hertz", "reissner", "hertz_reissner", "linearized"]
MODELS: tuple[str, ...] = ("hertz", "reissner", "hertz_reissner", "linearized")


def _check_nu(field: str, nu: float) -> float:
    return check_range(field, nu, -1.0, 0.5)


def effective_modulus(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """E* from 1/E* = (1−ν1²)/E1 + (1−ν2²)/E2 (eq. 4), Pa. ``E2 = inf``: rigid partner."""
    E1 = check_positive("E1", E1)
    nu1 = _check_nu("nu1", nu1)
    nu2 = _check_nu("nu2", nu2)
    E2 = float(E2)
    if math.isinf(E2) and E2 > 0:
        c2 = 0.0
    else:
        c2 = (1.0 - nu2**2) / check_positive("E2", E2)
    return 1.0 / ((1.0 - nu1**2) / E1 + c2)


def effective_radius(R1: float, R2: float) -> float:
    """R* from 1/R* = 1/R1 + 1/R2 (eq. 3), m. ``R2 = inf``: a plane."""
    R1 = check_positive("R1", R1)
    R2 = float(R2)
    if math.isinf(R2) and R2 > 0:
        return R1
    return 1.0 / (1.0 / R1 + 1.0 / check_positive("R2", R2))


def effective_mass(m1: float, m2: float) -> float:
    """m* from 1/m* = 1/m1 + 1/m2 (eq. 9), kg. ``m2 = inf``: an immovable partner."""
    m1 = check_positive("m1", m1)
    m2 = float(m2)
    if math.isinf(m2) and m2 > 0:
        return m1
    return 1.0 / (1.0 / m1 + 1.0 / check_positive("m2", m2))


def hertz_stiffness(R1: float, R2: float, E1: float, nu1: float, E2: float, nu2: float) -> float:
    """Hertz stiffness k_H = 4/3 √R* E* (eqs. 2–4), N/m^{3/2}; F = k_H d^{3/2} (eq. 1).

    Radii in m (``inf`` for a plane), moduli in Pa (``inf`` for a rigid partner).
    """
    return 4.0 / 3.0 * math.sqrt(effective_radius(R1, R2)) * effective_modulus(E1, nu1, E2, nu2)


def reissner_stiffness(E: float, nu: float, t: float, R: float) -> float:
    """Reissner point-load stiffness of a thin shallow shell (eq. 6), N/m:

    k_R = 4 / √(3 (1 − ν²)) · E t² / R,

    with E in Pa, wall thickness ``t`` (m) and mid-surface radius of curvature ``R`` (m),
    0 < t < R; F = k_R d_R (eq. 5).
    """
    E = check_positive("E", E)
    nu = _check_nu("nu", nu)
    t = check_positive("t", t)
    R = check_positive("R", R)
    if t >= R:
        raise InvalidParameterError(f"invalid t = {t!r}: must be < R = {R!r} (a thin shell)")
    return 4.0 / math.sqrt(3.0 * (1.0 - nu**2)) * E * t**2 / R


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


def _pair(a: ContactBody, b: ContactBody) -> tuple[float, float, float]:
    """(k_H, k_R of both shells in series, m*) of a pair; ``inf`` entries (a plane, a rigid
    or an immovable wall) drop out of the harmonic sums of eqs. 3, 4 and 9."""
    for what, x, y in (("radius", a.radius, b.radius), ("mass", a.mass, b.mass), ("E", a.E, b.E)):
        if math.isinf(x) and math.isinf(y):
            raise InvalidParameterError(
                f"invalid pair: both bodies have {what} = inf (no finite contact partner)")
    inv = lambda x: 0.0 if math.isinf(x) else 1.0 / x  # noqa: E731
    r_star = 1.0 / (inv(a.radius) + inv(b.radius))
    e_star = 1.0 / ((1.0 - a.nu**2) * inv(a.E) + (1.0 - b.nu**2) * inv(b.E))
    m_star = 1.0 / (inv(a.mass) + inv(b.mass))
    k_r = 1.0 / (inv(a.k_reissner) + inv(b.k_reissner)) if (
        math.isfinite(a.k_reissner) or math.isfinite(b.k_reissner)) else math.inf
    return 4.0 / 3.0 * math.sqrt(r_star) * e_star, k_r, m_star


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
    It gives the Hertz maximum overlap and a force √(4/5) times the Hertz maximum force."""
    v = _check_v(v_rel)
    k_h, _, m_star = _pair(a, b)
    # k_H = 4/3 √R* E*  ⇒  R*^{2/5} E*^{4/5} = (3 k_H / 4)^{4/5}
    return 4.0 / 3.0 * (15.0 / 16.0) ** 0.2 * (0.75 * k_h) ** 0.8 * m_star**0.2 * v**0.4


def k_eq(a: ContactBody, b: ContactBody, v_rel: float) -> float:
    """Equivalent stiffness 1/k_eq = 1/k_R1 + 1/k_R2 + 1/k_lin (eq. 15), N/m."""
    _, k_r, _ = _pair(a, b)
    return 1.0 / (1.0 / k_r + 1.0 / k_linear(a, b, v_rel))


def max_contact_force(a: ContactBody, b: ContactBody, v_rel: float, model: Model = "hertz_reissner") -> float:
    """Maximum normal force (N) of an impact at relative speed ``v_rel`` (m/s).

    ``model``:

    * ``"hertz"`` — shells rigid: m* v² = (4/5) F^{5/3} / k_H^{2/3} (eq. 12 with k_R → ∞);
    * ``"reissner"`` — contact rigid: m* v² = F²/k_R1 + F²/k_R2 (eq. 12 without Hertz);
    * ``"hertz_reissner"`` — both in series: the root of eq. 12,
      m* v² = F²/k_R1 + F²/k_R2 + (4/5) F^{5/3}/k_H^{2/3}, bracketed in
      [0, min(F_hertz, F_reissner)] (the left side grows with F and each single law alone
      reaches m* v² earlier) and solved by Brent's method to machine precision;
    * ``"linearized"`` — F = √(k_eq m*) v (eqs. 13–15).
    """
    v = _check_v(v_rel)
    if model not in MODELS:
        raise InvalidParameterError(f"invalid model = {model!r}: must be one of {MODELS}")
    k_h, k_r, m_star = _pair(a, b)
    if v == 0.0:
        return 0.0
    w = m_star * v * v
    f_hertz = k_h**0.4 * (1.25 * w) ** 0.6
    f_reissner = math.sqrt(k_r * w) if math.isfinite(k_r) else math.inf
    if model == "hertz":
        return f_hertz
    if model == "reissner":
        if not math.isfinite(k_r):
            raise InvalidParameterError("invalid model = 'reissner': neither body has a shell")
        return f_reissner
    if model == "linearized":
        return math.sqrt(k_eq(a, b, v) * m_star) * v
    hi = min(f_hertz, f_reissner)
    kh23 = k_h ** (2.0 / 3.0)

    def residual(x: float) -> float:  # scaled by m* v² so it is O(1) for any E, v
        f = x * hi
        return (f * f / k_r + 0.8 * f ** (5.0 / 3.0) / kh23) / w - 1.0

    if residual(1.0) <= 0.0:  # only when one law is absent or round-off at the bracket end
        return hi
    x = brentq(residual, 0.0, 1.0, xtol=1e-300, rtol=4.0 * np.finfo(float).eps, maxiter=500)
    return float(x * hi)


def normal_force(overlap: np.ndarray, model: Literal["hertz", "linear", "hertz_reissner"],
                 k_h: float = math.nan, k_r: float = math.nan, k: float = math.nan) -> np.ndarray:
    """Elastic normal force (N) at each overlap (m); zero where overlap <= 0.

    * ``"hertz"``: F = k_H d^{3/2} (eq. 1), ``k_h`` in N/m^{3/2};
    * ``"linear"``: F = k d, ``k`` in N/m (eq. 5 for a shell, eq. 15 linearised);
    * ``"hertz_reissner"``: d = (F/k_H)^{2/3} + F/k_R, the series law behind eq. 12, solved
      per entry by Brent's method on the bracket [0, min(k_H d^{3/2}, k_R d)].
    """
    d = np.asarray(overlap, dtype=float)
    if not np.all(np.isfinite(d)):
        raise InvalidParameterError("invalid overlap: must be finite (NaN or inf given)")
    out = np.zeros_like(d)
    pos = d > 0
    if model == "hertz":
        out[pos] = check_positive("k_h", k_h) * d[pos] ** 1.5
    elif model == "linear":
        out[pos] = check_positive("k", k) * d[pos]
    elif model == "hertz_reissner":
        k_h = check_positive("k_h", k_h)
        k_r = check_positive("k_r", k_r)
        flat = out.reshape(-1)
        for i, di in enumerate(d.reshape(-1)):
            if di <= 0:
                continue
            hi = min(k_h * di**1.5, k_r * di)
            g = lambda x, di=di, hi=hi: ((x * hi / k_h) ** (2.0 / 3.0) + x * hi / k_r) / di - 1.0  # noqa: E731
            flat[i] = hi * brentq(g, 0.0, 1.0, xtol=1e-300, rtol=4.0 * np.finfo(float).eps,
                                  maxiter=500)
        out = flat.reshape(d.shape)
    else:
        raise InvalidParameterError(
            f"invalid model = {model!r}: must be one of ('hertz', 'linear', 'hertz_reissner')")
    return out


def hertz_max_overlap(a: ContactBody, b: ContactBody, v_rel: float) -> float:
    """Maximum overlap of an undamped Hertz impact, (5 m* v² / (4 k_H))^{2/5}, m."""
    k_h, _, m_star = _pair(a, b)
    v = _check_v(v_rel)
    return (1.25 * m_star * v * v / k_h) ** 0.4


def hertz_contact_duration(a: ContactBody, b: ContactBody, v_rel: float) -> float:
    """Duration of an undamped Hertz impact, s:
    t_c = 2 (δ_max / v) ∫₀¹ (1 − x^{5/2})^{-1/2} dx = 2.9432… δ_max / v (Johnson §11.4)."""
    v = _check_v(v_rel, allow_zero=False)
    from scipy.special import beta

    factor = 2.0 * 0.4 * beta(0.4, 0.5)
    return factor * hertz_max_overlap(a, b, v) / v


def rayleigh_time_step(radius: float, E: float, nu: float, density: float) -> float:
    """Rayleigh time step π R √(ρ/G) / (0.1631 ν + 0.8766), s, of a sphere of ``radius`` (m),
    Young's modulus ``E`` (Pa), Poisson's ratio ``nu`` and ``density`` (kg/m³)."""
    R = check_positive("radius", radius)
    E = check_positive("E", E)
    nu = _check_nu("nu", nu)
    rho = check_positive("density", density)
    G = E / (2.0 * (1.0 + nu))
    dt = math.pi * R * math.sqrt(rho / G) / (0.1631 * nu + 0.8766) if G > 0 else math.inf
    if not (G > 0 and math.isfinite(dt) and dt > 0):
        # a subnormal E underflows G to 0 (rho / G divided by zero)
        raise InvalidParameterError(
            f"invalid E = {E!r}: must be large enough that G = E/(2(1+nu)) > 0 and the step "
            "pi R sqrt(rho/G)/(0.1631 nu + 0.8766) is finite and > 0")
    return dt


# ---------------------------------------------------------------------------- restitution
#: Largest Tsuji ζ that :func:`tsuji_restitution` integrates (as the core's
#: ``MAX_TSUJI_ZETA``); beyond it the overdamped limit e = 1.25/ζ² (clamped) or 0 is returned
#: (the core's fixed-step integration returned -1 at ζ = 1e20).
MAX_TSUJI_ZETA = 1e3


def _tsuji_rhs(zeta: float, clamp: bool):
    def rhs(_t: float, y: np.ndarray) -> list[float]:
        x, v = max(y[0], 0.0), y[1]
        f = x**1.5 + zeta * x**0.25 * v
        if clamp:
            f = max(f, 0.0)
        return [v, -f]

    return rhs


def _overlap_exit(_t: float, y: np.ndarray) -> float:
    """solve_ivp event: the overlap y[0] returns to zero (the bodies separate)."""
    return y[0]


_overlap_exit.terminal = True  # type: ignore[attr-defined]
_overlap_exit.direction = -1  # type: ignore[attr-defined]


def tsuji_restitution(zeta: float, clamp: bool = False) -> float:
    """Restitution coefficient of a Hertz impact with Tsuji damping (dimensionless).

    Force F = k_H δ^{3/2} + ζ √(m* k_H) δ^{1/4} δ̇ (Tsuji, Tanaka & Ishida 1992; the
    calibration e(ζ) is the one analysed by Antypov & Elliott 2011). Scaling δ = s X,
    t = T τ with T² = m*/(k_H s^{1/2}) and s such that the impact speed is 1 turns the
    equation of motion into X'' = −X^{3/2} − ζ X^{1/4} X', so e depends on ζ only. With
    ``clamp=True`` the total force is clamped at ≥ 0 (no attraction near separation), and
    the bodies separate when it vanishes: the realised restitution is then higher.
    Integrated here with an adaptive Runge–Kutta method (DOP853, rtol 1e-12).
    """
    zeta = check_range("zeta", zeta, 0.0, math.inf, lo_open=False)
    if zeta > MAX_TSUJI_ZETA:
        # overdamped limit (as the core): clamped, e = X_m^{5/4}/zeta with
        # X_m = (5/(4 zeta))^{4/5}, i.e. 1.25/zeta^2; unclamped, the bodies stay together
        return 1.25 / (zeta * zeta) if clamp else 0.0
    rhs = _tsuji_rhs(zeta, clamp)

    events = [_overlap_exit]
    if clamp:
        def zero_force(_t: float, y: np.ndarray) -> float:
            x = max(y[0], 0.0)
            return x**1.5 + zeta * x**0.25 * y[1] if y[1] < 0 else 1.0

        zero_force.terminal = True  # type: ignore[attr-defined]
        zero_force.direction = -1  # type: ignore[attr-defined]
        events.append(zero_force)
    sol = solve_ivp(rhs, (0.0, 1e3), [0.0, 1.0], method="DOP853", rtol=1e-12, atol=1e-14,
                    events=events, max_step=0.05)
    for ev in sol.y_events:
        if len(ev):
            return float(max(-ev[0][1], 0.0))
    return 0.0  # the overlap never returned to zero: fully damped


def tsuji_damping_for_restitution(e: float, clamp: bool = False) -> float:
    """Tsuji damping parameter ζ (dimensionless) that realises restitution ``e`` in (0, 1].

    Found by Brent's method on :func:`tsuji_restitution`, which decreases with ζ."""
    e = check_range("restitution", e, 0.0, 1.0, hi_open=False)
    if e == 1.0:
        return 0.0
    hi = 1.0
    while tsuji_restitution(hi, clamp) > e:
        hi *= 2.0
        if hi > 1e6:
            raise InvalidParameterError(f"invalid restitution = {e!r}: not reachable")
    return float(brentq(lambda z: tsuji_restitution(z, clamp) - e, 0.0, hi, xtol=1e-12))


@dataclass(frozen=True)
class ImpactResult:
    """One integrated normal impact: time (s), overlap (m), normal force (N) histories,
    the realised restitution and the maximum force (N)."""

    time: np.ndarray
    overlap: np.ndarray
    force: np.ndarray
    restitution: float
    max_force: float


def damped_hertz_impact(a: ContactBody, b: ContactBody, v_rel: float, restitution: float = 1.0,
                        clamp: bool = False, n_out: int = 400) -> ImpactResult:
    """Integrate one head-on Hertz impact (dimensional units) with Tsuji damping chosen for
    ``restitution``; ``v_rel`` in m/s. Returns the histories and the realised restitution."""
    v = _check_v(v_rel, allow_zero=False)
    k_h, _, m_star = _pair(a, b)
    zeta = tsuji_damping_for_restitution(restitution, clamp)
    c = zeta * math.sqrt(m_star * k_h)

    def force(x: float, xd: float) -> float:
        x = max(x, 0.0)
        f = k_h * x**1.5 + c * x**0.25 * xd
        return max(f, 0.0) if clamp else f

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        return [y[1], -force(y[0], y[1]) / m_star]

    events = [_overlap_exit]
    if clamp:
        def unload(_t: float, y: np.ndarray) -> float:
            return force(y[0], y[1]) if y[1] < 0 else 1.0

        unload.terminal = True  # type: ignore[attr-defined]
        unload.direction = -1  # type: ignore[attr-defined]
        events.append(unload)
    tc = 2.9432751790197716 * (1.25 * m_star * v * v / k_h) ** 0.4 / v
    sol = solve_ivp(rhs, (0.0, 50 * tc), [0.0, v], method="DOP853", rtol=1e-11,
                    atol=1e-16 * max(1.0, v), events=events, dense_output=True,
                    max_step=tc / 200)
    t_end = sol.t[-1]
    ts = np.linspace(0.0, t_end, n_out)
    ys = sol.sol(ts)
    forces = np.array([force(x, xd) for x, xd in ys.T])
    v_out = -sol.y[1, -1]
    return ImpactResult(time=ts, overlap=ys[0], force=forces, restitution=float(v_out / v),
                        max_force=float(forces.max()))
