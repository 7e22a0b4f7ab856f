"""Independent reference computations of the contact laws, for the tests only.

``demfem.contact`` computes every law through the Rust core (the one implementation). The
functions here compute the same quantities a different way, in Python with scipy, so that
the tests check the core against something other than itself:

* closed forms written out from the paper (eqs. 2–4, 6, 9, 13) and from Johnson's *Contact
  Mechanics* §11.4 (Hertz maximum force, overlap and contact time);
* the root of eq. 12 and of the series law δ = (F/k_H)^{2/3} + F/k_R by Brent's method
  (the core uses Newton's method and a normalised cubic);
* the Tsuji restitution by an adaptive Runge–Kutta integration (DOP853, rtol 1e-12, with
  event location; the core uses fixed-form RK4) and ζ(e) by Brent's method on it;
* a dimensional damped Hertz impact integrated by DOP853 (the core has none: its restitution
  is calibrated in scaled units, and this checks that the calibration holds in metres and
  seconds at any speed).

Nothing here imports ``demfem._core`` or calls ``demfem.contact``'s laws. SI units.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq
from scipy.special import beta

from demfem.contact import ContactBody, ImpactResult

EPS = float(np.finfo(float).eps)


def _inv(x: float) -> float:
    return 0.0 if math.isinf(x) else 1.0 / x


def _series(*xs: float) -> float:
    """1 / Σ 1/x, with inf terms dropping out (all inf: inf)."""
    s = sum(_inv(x) for x in xs)
    return math.inf if s == 0.0 else 1.0 / s


# ---------------------------------------------------------------- closed forms (eqs. 2–15)
def effective_modulus(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2 (eq. 4), Pa; ``inf`` drops out."""
    return 1.0 / ((1.0 - nu1**2) * _inv(E1) + (1.0 - nu2**2) * _inv(E2))


def effective_radius(R1: float, R2: float) -> float:
    """1/R* = 1/R1 + 1/R2 (eq. 3), m."""
    return _series(R1, R2)


def effective_mass(m1: float, m2: float) -> float:
    """1/m* = 1/m1 + 1/m2 (eq. 9), kg."""
    return _series(m1, m2)


def reissner_stiffness(E: float, nu: float, t: float, R: float) -> float:
    """k_R = 4/√(3(1 − ν²)) E t²/R (eq. 6), N/m."""
    return 4.0 / math.sqrt(3.0 * (1.0 - nu**2)) * E * t**2 / R


@dataclass(frozen=True)
class PairConstants:
    """Effective quantities of a pair: R* (m), E* (Pa), m* (kg), k_H (N/m^1.5) and the two
    shells in series k_R (N/m, inf without a shell)."""

    r_star: float
    e_star: float
    m_star: float
    k_h: float
    k_r: float


def pair_constants(a: ContactBody, b: ContactBody) -> PairConstants:
    """The pair's constants from the closed forms (eqs. 2–4, 6, 9)."""
    r = effective_radius(a.radius, b.radius)
    e = effective_modulus(a.E, a.nu, b.E, b.nu)
    m = effective_mass(a.mass, b.mass)

    def k_shell(x: ContactBody) -> float:
        if x.shell_thickness is None or x.shell_radius is None:
            return math.inf
        return reissner_stiffness(x.E, x.nu, x.shell_thickness, x.shell_radius)

    k_r = _series(k_shell(a), k_shell(b))
    return PairConstants(r, e, m, 4.0 / 3.0 * math.sqrt(r) * e, k_r)


def hertz_max_force(k_h: float, m_star: float, v: float) -> float:
    """m* v² = (4/5) F^{5/3}/k_H^{2/3} (eq. 12 with k_R → ∞): F = k_H^{2/5} (5/4 m* v²)^{3/5}, N."""
    return k_h**0.4 * (1.25 * m_star * v * v) ** 0.6


def hertz_max_overlap(k_h: float, m_star: float, v: float) -> float:
    """δ_max = (5 m* v² / (4 k_H))^{2/5}, m: the kinetic energy stored as (2/5) k_H δ^{5/2}."""
    return (1.25 * m_star * v * v / k_h) ** 0.4


def linear_max_force(k: float, m_star: float, v: float) -> float:
    """F = √(k m*) v (eq. 14), N."""
    return math.sqrt(k * m_star) * v


def k_linear(r_star: float, e_star: float, m_star: float, v: float) -> float:
    """4/3 (15/16)^{1/5} R*^{2/5} E*^{4/5} m*^{1/5} v^{2/5} (eq. 13), N/m."""
    return 4.0 / 3.0 * (15.0 / 16.0) ** 0.2 * r_star**0.4 * e_star**0.8 * m_star**0.2 * v**0.4


def hertz_duration_factor_beta() -> float:
    """2 ∫₀¹ (1 − x^{5/2})^{-1/2} dx = (4/5) B(2/5, 1/2), by the Beta function."""
    return float(0.8 * beta(0.4, 0.5))


def hertz_duration_factor_quad() -> float:
    """The same integral by quadrature; x = 1 − s² removes the end singularity:
    ∫₀¹ 2s (1 − (1 − s²)^{5/2})^{-1/2} ds, a smooth integrand (→ 2/√(5/2) at s = 0)."""
    def g(s: float) -> float:
        if s == 0.0:
            return 2.0 / math.sqrt(2.5)
        return 2.0 * s / math.sqrt(-math.expm1(2.5 * math.log1p(-s * s)))

    val, _ = quad(g, 0.0, 1.0, epsabs=1e-15, epsrel=1e-13, limit=200)
    return 2.0 * val


def rayleigh_time_step(radius: float, E: float, nu: float, density: float) -> float:
    """π R √(ρ/G) / (0.1631 ν + 0.8766), G = E/(2(1 + ν)), s (Li, Xu & Thornton 2005)."""
    G = E / (2.0 * (1.0 + nu))
    return math.pi * radius * math.sqrt(density / G) / (0.1631 * nu + 0.8766)


# ------------------------------------------------------------- roots by Brent's method
def hertz_reissner_max_force(k_h: float, k_r: float, m_star: float, v: float) -> float:
    """Root F of eq. 12, m* v² = F²/k_R + (4/5) F^{5/3}/k_H^{2/3}, by Brent's method on the
    bracket [0, min(F_hertz, F_reissner)] (each law alone reaches m* v² earlier), N."""
    w = m_star * v * v
    hi = min(hertz_max_force(k_h, m_star, v), linear_max_force(k_r, m_star, v))
    kh23 = k_h ** (2.0 / 3.0)

    def residual(x: float) -> float:  # scaled by m* v² so it is O(1) for any E, v
        f = x * hi
        return (f * f / k_r + 0.8 * f ** (5.0 / 3.0) / kh23) / w - 1.0

    if residual(1.0) <= 0.0:
        return hi
    x = brentq(residual, 0.0, 1.0, xtol=1e-300, rtol=4.0 * EPS, maxiter=500)
    return float(x * hi)


def hertz_reissner_force(overlap: np.ndarray, k_h: float, k_r: float) -> np.ndarray:
    """F solving δ = (F/k_H)^{2/3} + F/k_R at each overlap δ > 0 (0 elsewhere), by Brent's
    method on [0, min(k_H δ^{3/2}, k_R δ)], N."""
    d = np.asarray(overlap, dtype=float)
    out = np.zeros(d.size)
    for i, di in enumerate(d.reshape(-1)):
        if di <= 0:
            continue
        hi = min(k_h * di**1.5, k_r * di)

        def g(x: float, di: float = di, hi: float = hi) -> float:
            return ((x * hi / k_h) ** (2.0 / 3.0) + x * hi / k_r) / di - 1.0

        out[i] = hi * brentq(g, 0.0, 1.0, xtol=1e-300, rtol=4.0 * EPS, maxiter=500)
    return out.reshape(d.shape)


# ------------------------------------------------- Tsuji restitution by adaptive DOP853
def _overlap_exit(_t: float, y: np.ndarray) -> float:
    """solve_ivp event: the overlap y[0] returns to zero (the bodies separate)."""
    return y[0]


_overlap_exit.terminal = True  # type: ignore[attr-defined]
_overlap_exit.direction = -1  # type: ignore[attr-defined]


def tsuji_restitution(zeta: float, clamp: bool = False, rtol: float = 1e-12,
                      max_step: float = 0.05) -> float:
    """Restitution of X'' = −X^{3/2} − ζ X^{1/4} X' from X = 0, X' = 1 (the Tsuji-damped
    Hertz impact in scaled units), with the force clamped at ≥ 0 when ``clamp``; adaptive
    DOP853 with event location of the separation."""
    def rhs(_t: float, y: np.ndarray) -> list[float]:
        x, v = max(y[0], 0.0), y[1]
        f = x**1.5 + zeta * x**0.25 * v
        if clamp:
            f = max(f, 0.0)
        return [v, -f]

    events = [_overlap_exit]
    if clamp:
        def zero_force(_t: float, y: np.ndarray) -> float:
            x = max(y[0], 0.0)
            return x**1.5 + zeta * x**0.25 * y[1] if y[1] < 0 else 1.0

        zero_force.terminal = True  # type: ignore[attr-defined]
        zero_force.direction = -1  # type: ignore[attr-defined]
        events.append(zero_force)
    sol = solve_ivp(rhs, (0.0, 1e3), [0.0, 1.0], method="DOP853", rtol=rtol,
                    atol=rtol * 1e-2, events=events, max_step=max_step)
    for ev in sol.y_events:
        if len(ev):
            return float(max(-ev[0][1], 0.0))
    return 0.0  # the overlap never returned to zero: fully damped


def tsuji_damping_for_restitution(e: float, clamp: bool = False) -> float:
    """ζ with :func:`tsuji_restitution` (ζ) = e, by Brent's method (e decreases with ζ)."""
    if e == 1.0:
        return 0.0
    hi = 1.0
    while tsuji_restitution(hi, clamp) > e:
        hi *= 2.0
    return float(brentq(lambda z: tsuji_restitution(z, clamp) - e, 0.0, hi, xtol=1e-14,
                        rtol=4.0 * EPS))


def damped_hertz_impact(a: ContactBody, b: ContactBody, v_rel: float, zeta: float = 0.0,
                        clamp: bool = False, n_out: int = 400) -> ImpactResult:
    """One head-on Hertz impact in metres and seconds, with Tsuji damping
    F = k_H δ^{3/2} + ζ √(m* k_H) δ^{1/4} δ̇ (clamped at ≥ 0 when ``clamp``), integrated by
    DOP853 from δ = 0, δ̇ = ``v_rel`` until the bodies separate. The pair's k_H and m* come
    from :func:`pair_constants`. Returns the histories and the realised restitution."""
    p = pair_constants(a, b)
    k_h, m_star, v = p.k_h, p.m_star, float(v_rel)
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
    # time scale from the closed forms (only to size the integration window and steps)
    tc = hertz_duration_factor_beta() * hertz_max_overlap(k_h, m_star, v) / v
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
