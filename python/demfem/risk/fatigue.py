"""Slow crack growth (static fatigue) of glass: equivalent static stress of a stress history.

In humid air a surface flaw grows sub-critically at a rate that follows a power law in the
stress intensity factor, v = da/dt = v_0 (K_I / K_Ic)^n (Evans 1974; Wiederhorn & Bolz 1970).
With K_I = Y σ √a, integrating from the initial to the critical flaw size shows that, as long as
the stress at failure is small compared with the inert strength, a flaw fails under σ(t) exactly
when ∫ ⟨σ⟩^n dt reaches a constant of that flaw. Two histories with equal ∫ ⟨σ⟩^n dt are then
equally damaging, and a history of any shape can be replaced by the constant stress acting over
a reference time t_ref:

    σ_eq = [ (1 / t_ref) ∫ ⟨σ(t)⟩^n dt ]^{1/n},   ⟨x⟩ = max(x, 0)   (Pa).

Use σ_eq in :func:`demfem.risk.weibull.failure_probability` with Weibull parameters measured in
a test of the same effective duration t_ref. For a constant-stress-rate test that fails at t_f,
∫σ^n dt = σ_f^n t_f / (n + 1), so t_ref = t_f / (n + 1) (:func:`stress_rate_test_reference_time`).
The exponent must exceed 2 (the crack-length integral diverges otherwise).

Multiaxial use: apply σ_eq to each principal stress history separately (an approximation when
the principal directions rotate during the pulse).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Union

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import gammaln

from demfem.errors import InvalidParameterError, check_positive, check_range
from demfem.risk._validate import RiskShapeError, as_array

__all__ = [
    "SlowCrackGrowth",
    "constant_pulse_equivalent_stress",
    "equivalent_static_stress",
    "half_sine_equivalent_stress",
    "half_sine_sn_factor",
    "stress_rate_test_reference_time",
]

FloatOrArray = Union[float, NDArray[np.float64]]


def _check_n(n: float) -> float:
    return check_range("crack_growth_exponent", n, 2.0, math.inf)


def _segment_integrals(a: NDArray[np.float64], b: NDArray[np.float64], h: NDArray[np.float64],
                       n: float) -> NDArray[np.float64]:
    """∫ ⟨σ⟩^n dt over linear segments from a to b of duration h (a, b normalised to ≤ 1).

    Exact for piecewise-linear histories, including segments that cross zero:
    h (⟨b⟩^{n+1} − ⟨a⟩^{n+1}) / ((n+1)(b − a)); near-constant segments use the series
    h m^n [1 + n(n−1)/6 x² + n(n−1)(n−2)(n−3)/120 x⁴], m = (a+b)/2, x = (b−a)/(2m).
    """
    d = b - a
    mid = 0.5 * (a + b)
    scale = np.maximum(np.abs(a), np.abs(b))
    near = np.abs(d) <= 2e-4 * scale
    out = np.zeros(np.broadcast(a, b).shape)
    far = ~near & (d != 0.0)
    ap, bp = np.maximum(a, 0.0), np.maximum(b, 0.0)
    hb = np.broadcast_to(h, out.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        out[far] = hb[far] * (bp[far] ** (n + 1) - ap[far] ** (n + 1)) / ((n + 1) * d[far])
        pos = near & (mid > 0.0)
        x = d[pos] / (2.0 * mid[pos])
        series = 1.0 + n * (n - 1) / 6.0 * x**2 + n * (n - 1) * (n - 2) * (n - 3) / 120.0 * x**4
        out[pos] = hb[pos] * mid[pos] ** n * series
    return out


def equivalent_static_stress(
    stress: ArrayLike,
    time: ArrayLike,
    crack_growth_exponent: float,
    reference_time: float,
) -> FloatOrArray:
    """Equivalent static stress σ_eq = [(1/t_ref) ∫ ⟨σ(t)⟩^n dt]^{1/n} of sampled histories, Pa.

    Parameters
    ----------
    stress:
        Stress samples, Pa: shape (T,) for one history or (T, N) for N histories (time along
        axis 0); finite. Compressive values contribute nothing.
    time:
        Sample times, s, shape (T,), T ≥ 2, finite and strictly increasing.
    crack_growth_exponent:
        n of the power-law crack velocity, dimensionless; in (2, ∞).
    reference_time:
        t_ref, s; finite and > 0.

    Returns
    -------
    float or ndarray
        σ_eq (≥ 0) per history. The history is taken as piecewise linear between samples and
        integrated exactly; histories with no tension give 0.
    """
    n = _check_n(crack_growth_exponent)
    t_ref = check_positive("reference_time", reference_time)
    t = as_array("time", time, ndim=1, unit="s")
    s = as_array("stress", stress, unit="Pa")
    if s.ndim not in (1, 2):
        raise RiskShapeError(f"invalid stress: shape {s.shape}, must be (T,) or (T, N)")
    if t.size < 2:
        raise RiskShapeError(f"invalid time: {t.size} sample(s), need at least 2")
    if s.shape[0] != t.size:
        raise RiskShapeError(
            f"invalid stress: {s.shape[0]} samples along axis 0 do not match time shape {t.shape}"
        )
    dt = np.diff(t)
    if np.any(dt <= 0.0):
        i = int(np.argmax(dt <= 0.0))
        raise InvalidParameterError(
            f"invalid time[{i + 1}] = {t[i + 1]!r}: must be finite and strictly greater than "
            f"time[{i}] = {t[i]!r} (s)"
        )
    s2 = s.reshape(s.shape[0], -1)
    smax = np.max(np.maximum(s2, 0.0), axis=0)
    safe = np.where(smax > 0.0, smax, 1.0)
    u = s2 / safe
    integral = _segment_integrals(u[:-1], u[1:], dt[:, None], n).sum(axis=0)
    result = np.where(smax > 0.0, smax * (integral / t_ref) ** (1.0 / n), 0.0)
    return float(result[0]) if s.ndim == 1 else result


def constant_pulse_equivalent_stress(
    stress: ArrayLike, duration: float, crack_growth_exponent: float, reference_time: float
) -> FloatOrArray:
    """σ_eq of a constant stress held for ``duration`` (s): ⟨σ⟩ (τ / t_ref)^{1/n}, Pa."""
    n = _check_n(crack_growth_exponent)
    tau = check_positive("duration", duration)
    t_ref = check_positive("reference_time", reference_time)
    s = as_array("stress", stress, unit="Pa")
    out = np.maximum(s, 0.0) * (tau / t_ref) ** (1.0 / n)
    return float(out) if out.ndim == 0 else out


def half_sine_sn_factor(crack_growth_exponent: float) -> float:
    """(1/τ) ∫_0^τ sin^n(π t/τ) dt = Γ((n+1)/2) / (√π Γ(n/2 + 1)), dimensionless."""
    n = _check_n(crack_growth_exponent)
    return math.exp(gammaln(0.5 * (n + 1.0)) - gammaln(0.5 * n + 1.0) - 0.5 * math.log(math.pi))


def half_sine_equivalent_stress(
    peak_stress: ArrayLike, duration: float, crack_growth_exponent: float, reference_time: float
) -> FloatOrArray:
    """σ_eq of a half-sine impact pulse σ(t) = σ_p sin(π t / τ), 0 ≤ t ≤ τ, in closed form, Pa.

    σ_eq = ⟨σ_p⟩ [ (τ / t_ref) Γ((n+1)/2) / (√π Γ(n/2 + 1)) ]^{1/n}.

    ``peak_stress``: σ_p, Pa, finite (a negative peak is compressive throughout and gives 0);
    ``duration``: τ, s, > 0; ``crack_growth_exponent``: n in (2, ∞); ``reference_time``:
    t_ref, s, > 0.
    """
    n = _check_n(crack_growth_exponent)
    tau = check_positive("duration", duration)
    t_ref = check_positive("reference_time", reference_time)
    s = as_array("peak_stress", peak_stress, unit="Pa")
    factor = (tau / t_ref * half_sine_sn_factor(n)) ** (1.0 / n)
    out = np.maximum(s, 0.0) * factor
    return float(out) if out.ndim == 0 else out


def stress_rate_test_reference_time(time_to_failure: float, crack_growth_exponent: float) -> float:
    """Effective static duration t_f / (n + 1) of a constant-stress-rate strength test that
    failed after ``time_to_failure`` (s): the t_ref that goes with strengths measured that
    way (e.g. ASTM C1499 / EN 1288 ring-on-ring at a fixed stress rate)."""
    t_f = check_positive("time_to_failure", time_to_failure)
    n = _check_n(crack_growth_exponent)
    return t_f / (n + 1.0)


@dataclass(frozen=True)
class SlowCrackGrowth:
    """Power-law slow-crack-growth parameters, validated on construction.

    Parameters
    ----------
    crack_growth_exponent:
        n in v = v_0 (K_I/K_Ic)^n, dimensionless; in (2, ∞).
    reference_time:
        t_ref, s; finite and > 0: the effective static duration of the strength test behind
        the Weibull parameters that σ_eq is fed to.
    source:
        Where n comes from, or "planning assumption" and a range.
    """

    crack_growth_exponent: float
    reference_time: float
    source: str = "unspecified"

    def __post_init__(self) -> None:
        object.__setattr__(self, "crack_growth_exponent", _check_n(self.crack_growth_exponent))
        object.__setattr__(
            self, "reference_time", check_positive("reference_time", self.reference_time)
        )

    def equivalent_static_stress(self, stress: ArrayLike, time: ArrayLike) -> FloatOrArray:
        """:func:`equivalent_static_stress` with these parameters, Pa."""
        return equivalent_static_stress(
            stress, time, self.crack_growth_exponent, self.reference_time
        )

    def half_sine(self, peak_stress: ArrayLike, duration: float) -> FloatOrArray:
        """:func:`half_sine_equivalent_stress` with these parameters, Pa."""
        return half_sine_equivalent_stress(
            peak_stress, duration, self.crack_growth_exponent, self.reference_time
        )
