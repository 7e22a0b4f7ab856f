"""Peaks over threshold: a generalized Pareto (GPD) tail for a positive per-event quantity
(the peak force of an impact, N), and the hazard per unit time of impacts harder than any seen
in the window. Method, diagnostic and checks: ``docs/uncertainty.md``.

Above a threshold u, P(X > x | X > u) = (1 + ξ (x − u)/σ)^(−1/ξ) (``scipy.stats.genpareto``,
c = ξ) and values arrive at λ_u = n_u / W per second. :func:`fit_gpd`: maximum likelihood over
(ξ, ln σ), ξ > −1, covariance from the observed information (regular for ξ > −0.5 only, NaN
below; Smith 1985). :func:`choose_threshold`: the lowest candidate whose shape estimate agrees
with every higher candidate's that has ≥ 200 exceedances, |ξ_j − ξ_i| ≤ z √(se_j² − se_i²),
z = 2.5 (nested estimates have independent increments: Wadsworth & Tawn 2012).
:func:`expected_beyond`: λ_u ∫_L^∞ h(x) g(x) dx = λ_u ζ_L ∫_0^∞ h(L + σ_L (e^{ξs} − 1)/ξ)
e^{−s} ds (ζ_L = P(X > L | X > u), σ_L = σ + ξ (L − u)) on a Simpson grid of s, vectorised
over parameter draws; +inf where the integrand does not decay (h ~ x^k, k ξ ≥ 1) unless the
values are capped. Intervals: percentiles over draws of (ξ, σ) from the fit's normal law and
of λ_u from a gamma law.

SI units: the values' own (N for forces), s, rates per second.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Callable, Optional, Sequence

import numpy as np
from numpy.typing import NDArray
from scipy import optimize

from demfem.errors import InvalidParameterError, check_count, check_positive, check_range
from demfem.risk._validate import as_array, check_same_shape

__all__ = ["TailModel", "ThresholdChoice", "TailContribution", "TailCorrectedRate",
           "fit_gpd", "fit_tail", "mean_excess", "choose_threshold", "expected_beyond",
           "tail_corrected_rate"]

#: Fewest exceedances a fit accepts by default.
MIN_EXCEEDANCES = 50

Hazard = Callable[[NDArray[np.float64]], NDArray[np.float64]]


def _nll(xi: float, sigma: float, y: NDArray[np.float64]) -> float:
    """Negative GPD log-likelihood of excesses y ≥ 0 (inf outside the support or ξ ≤ −1)."""
    if not (sigma > 0) or xi <= -1.0:
        return math.inf
    n = y.shape[0]
    if abs(xi) < 1e-9:
        return n * math.log(sigma) + float(y.sum()) / sigma
    z = xi * y / sigma
    if z.min() <= -1.0:
        return math.inf
    return n * math.log(sigma) + (1.0 + 1.0 / xi) * float(np.log1p(z).sum())


def _pwm_start(y: NDArray[np.float64]) -> tuple[float, float]:
    """Probability-weighted-moment estimate (Hosking & Wallis 1987) of (ξ, σ)."""
    ys = np.sort(y)
    n = ys.shape[0]
    a0 = float(ys.mean())
    a1 = float(np.sum(ys * (n - 1 - np.arange(n)) / (n - 1))) / n   # E[Y (1 − F)]
    if not a0 > 2.0 * a1 > 0.0:
        return 0.0, a0                                              # exponential
    return (float(np.clip(2.0 - a0 / (a0 - 2.0 * a1), -0.45, 0.9)),
            2.0 * a0 * a1 / (a0 - 2.0 * a1))


def fit_gpd(excesses: Sequence[float] | NDArray[np.float64]
            ) -> tuple[float, float, NDArray[np.float64]]:
    """Maximum-likelihood GPD fit of excesses over a threshold (≥ 0; units of the values).

    Returns (ξ, σ, covariance of (ξ, σ) as a 2 × 2 array: the inverse of the observed
    information; NaN when ξ ≤ −0.5 or the Hessian is not positive definite).
    """
    y = as_array("excesses", excesses, 0.0, math.inf, lo_open=False, ndim=1)
    if y.shape[0] < 3 or not np.any(y > 0):
        raise InvalidParameterError(f"invalid excesses: {y.shape[0]} values with "
                                    f"{int(np.sum(y > 0))} positive; at least 3 needed")
    xi0, s0 = _pwm_start(y)
    n = y.shape[0]
    best = None
    # from the PWM estimate; from an exponential start only if that fails
    for start in ((xi0, math.log(s0)), (0.0, math.log(float(y.mean())))):
        with np.errstate(invalid="ignore", over="ignore"):
            res = optimize.minimize(lambda p: _nll(p[0], math.exp(p[1]), y) / n,
                                    np.array(start), method="Nelder-Mead",
                                    options={"xatol": 1e-9, "fatol": 1e-13, "maxiter": 4000})
        if best is None or res.fun < best.fun:
            best = res
        if math.isfinite(best.fun) and best.success:
            break
    assert best is not None
    xi, sigma = float(best.x[0]), float(math.exp(best.x[1]))
    cov = np.full((2, 2), math.nan)
    if xi > -0.5:
        hx, hs = 1e-4 * max(1.0, abs(xi)), 1e-4 * sigma
        f = lambda a, b: _nll(xi + a * hx, sigma + b * hs, y)   # noqa: E731
        f0 = f(0, 0)
        h11 = (f(1, 0) - 2 * f0 + f(-1, 0)) / hx**2
        h22 = (f(0, 1) - 2 * f0 + f(0, -1)) / hs**2
        h12 = (f(1, 1) - f(1, -1) - f(-1, 1) + f(-1, -1)) / (4 * hx * hs)
        hess = np.array([[h11, h12], [h12, h22]])
        if np.all(np.isfinite(hess)) and h11 > 0 and np.linalg.det(hess) > 0:
            cov = np.linalg.inv(hess)
    return xi, sigma, cov


@dataclass(frozen=True, eq=False)
class TailModel:
    """A fitted generalized Pareto tail (module docstring).

    Attributes:
        threshold: u (units of the values). shape: ξ. scale: σ (units of the values).
        covariance: 2 × 2 covariance of (ξ, σ) (NaN when not regular, ξ ≤ −0.5).
        n_exceedances: values above u; n_values: all values; duration_s: observed time W, s.
        rate_relative_se: relative standard error of λ_u (Poisson: 1/√n_u).
        max_value: the largest value observed.
    """

    threshold: float
    shape: float
    scale: float
    covariance: NDArray[np.float64]
    n_exceedances: int
    n_values: int
    duration_s: float
    rate_relative_se: float
    max_value: float

    @property
    def rate_above(self) -> float:
        """λ_u: values above the threshold per second."""
        return self.n_exceedances / self.duration_s

    @property
    def shape_se(self) -> float:
        """Standard error of ξ (NaN when not regular)."""
        return float(np.sqrt(self.covariance[0, 0]))

    @property
    def scale_se(self) -> float:
        """Standard error of σ (NaN when not regular)."""
        return float(np.sqrt(self.covariance[1, 1]))

    def _level(self, level: Any) -> NDArray[np.float64]:
        return as_array("level", level, self.threshold, math.inf, lo_open=False)

    def exceedance_rate(self, level: Any) -> Any:
        """Values above ``level`` (≥ u) per second: λ_u (1 + ξ (level − u)/σ)^(−1/ξ)
        (a float for a scalar level, else an array of its shape)."""
        x = self._level(level)
        return _like(x, self.rate_above * _survival(self.shape, self.scale, x - self.threshold))

    def return_level(self, rate: Any) -> Any:
        """The level exceeded ``rate`` times per second (0 < rate ≤ λ_u), e.g. once an hour:
        ``rate = 1/3600`` (a float for a scalar rate, else an array of its shape)."""
        r = as_array("rate", rate, 0.0, self.rate_above, hi_open=False)
        q = r / self.rate_above
        xi, s = self.shape, self.scale
        if abs(xi) < 1e-9:
            return _like(r, self.threshold - s * np.log(q))
        return _like(r, self.threshold + s * np.expm1(-xi * np.log(q)) / xi)

    def parameter_draws(self, n: int, seed: int = 0) -> tuple[NDArray[np.float64], ...]:
        """``n`` draws of (ξ, σ, λ_u) from the fit's sampling distribution: (ξ, σ) normal
        with the fit's covariance (draws with σ ≤ 0 or ξ ≤ −1 replaced), λ_u gamma with mean
        λ_u and the relative standard error ``rate_relative_se``."""
        if not np.all(np.isfinite(self.covariance)):
            raise InvalidParameterError(
                f"invalid shape = {self.shape:g}: the fit is not regular (needs shape > -0.5) "
                "so it has no standard errors to draw from")
        rng = np.random.default_rng(seed)
        mean = np.array([self.shape, self.scale])
        out = np.empty((0, 2))
        while out.shape[0] < n:
            d = rng.multivariate_normal(mean, self.covariance, size=2 * n)
            out = np.vstack([out, d[(d[:, 1] > 0) & (d[:, 0] > -1.0)]])
        r = self.rate_relative_se
        lam = (self.rate_above * rng.gamma(1.0 / r**2, r**2, size=n) if r > 0
               else np.full(n, self.rate_above))
        return out[:n, 0], out[:n, 1], lam


def _like(arg: NDArray[np.float64], out: NDArray[np.float64]) -> Any:
    """``out`` as a float when ``arg`` is 0-d."""
    return float(out) if np.ndim(arg) == 0 else out


def _survival(xi: Any, sigma: Any, excess: Any) -> NDArray[np.float64]:
    """P(Y > excess) of GPD(ξ, σ), vectorised (0 beyond a finite end point)."""
    xi = np.asarray(xi, float)
    z = np.asarray(excess, float) / np.asarray(sigma, float)
    small = np.abs(xi) < 1e-9
    xs = np.where(small, 1.0, xi)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        arg = 1.0 + xs * z
        pw = np.where(arg > 0, np.exp(-np.log(np.where(arg > 0, arg, 1.0)) / xs), 0.0)
    return np.where(small, np.exp(-z), pw)


def mean_excess(values: Sequence[float] | NDArray[np.float64],
                thresholds: Sequence[float] | NDArray[np.float64]) -> NDArray[np.float64]:
    """Mean excess e(u) = mean(X − u | X > u) at each threshold (NaN where nothing exceeds)."""
    x = np.sort(as_array("values", values, 0.0, math.inf, lo_open=False, ndim=1))
    u = np.asarray(thresholds, float)
    csum = np.concatenate([[0.0], np.cumsum(x[::-1])])           # sums of the k largest
    k = x.shape[0] - np.searchsorted(x, u, side="right")
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(k > 0, csum[k] / np.where(k > 0, k, 1) - u, math.nan)


@dataclass(frozen=True)
class ThresholdChoice:
    """The threshold diagnostic of :func:`choose_threshold` (arrays over the candidates, lowest
    first): ``candidates`` (units of the values), ``n_exceedances``, ``shape``, ``shape_se``,
    ``modified_scale`` (σ − ξ u), ``mean_excess``; ``index`` of the chosen candidate,
    ``threshold`` = candidates[index], and ``rule`` in words."""

    candidates: NDArray[np.float64]
    n_exceedances: NDArray[np.int64]
    shape: NDArray[np.float64]
    shape_se: NDArray[np.float64]
    modified_scale: NDArray[np.float64]
    mean_excess: NDArray[np.float64]
    index: int
    threshold: float
    rule: str


def choose_threshold(values: Sequence[float] | NDArray[np.float64], *,
                     min_exceedances: int = MIN_EXCEEDANCES,
                     max_exceedances: Optional[int] = None, n_candidates: int = 20,
                     z: float = 2.5, min_compare: int = 200) -> ThresholdChoice:
    """The lowest threshold above which the GPD shape estimate is stable (module docstring).

    Args:
        values: (n,) positive per-event values (NaN, inf or negative refused).
        min_exceedances: fewest values above the highest candidate (≥ 10).
        max_exceedances: most values above the lowest candidate (default: min(n/2, 20 000)).
        n_candidates: candidates, geometrically spaced in their number of exceedances (≥ 3).
        z: how many standard errors of the difference the shapes may differ by (> 0).
        min_compare: fewest exceedances of a higher candidate compared against (≥ 10; at
            most a quarter of the lowest candidate's): with fewer, the shape estimate is
            skewed and its normal standard error unreliable.

    Raises:
        InvalidParameterError: bad values or fewer than ``min_exceedances`` of them.
    """
    x = np.sort(as_array("values", values, 0.0, math.inf, lo_open=False, ndim=1))
    n = x.shape[0]
    k_min = check_count("min_exceedances", min_exceedances, 10)
    nc = check_count("n_candidates", n_candidates, 3)
    zz = check_positive("z", z)
    k_cmp = check_count("min_compare", min_compare, 10)
    k_max = min(n // 2, 20000) if max_exceedances is None else check_count(
        "max_exceedances", max_exceedances, k_min)
    if k_max < k_min:
        raise InvalidParameterError(
            f"invalid values: {n} values leave at most {k_max} above the lowest candidate "
            f"threshold, fewer than min_exceedances = {k_min}; need at least {2 * k_min} values")
    ks = np.unique(np.round(np.geomspace(k_max, k_min, nc)).astype(np.int64))[::-1]
    rows: list[tuple[float, int, float, float, float]] = []     # u, n_u, ξ, σ, se(ξ)
    for k in ks:
        u = float(x[n - k - 1])
        y = x[x > u] - u
        if y.shape[0] < k_min or (rows and u <= rows[-1][0]):
            continue
        a, s, cov = fit_gpd(y)
        rows.append((u, y.shape[0], a, s, math.sqrt(cov[0, 0]) if np.isfinite(cov[0, 0])
                     else math.inf))
    if not rows:
        raise InvalidParameterError(
            f"invalid values: ties leave no candidate threshold with at least "
            f"min_exceedances = {k_min} values above it")
    c, n_exc, xi_a, sigma, se_a = (np.array(col) for col in zip(*rows))
    index = len(c) - 1
    k_cmp = min(k_cmp, max(k_min, int(n_exc[0]) // 4))
    for i in range(len(c)):
        j = np.flatnonzero(n_exc[i + 1:] >= k_cmp) + i + 1          # comparators above i
        with np.errstate(invalid="ignore"):      # inf − inf: a non-regular candidate fails
            se_diff = np.sqrt(np.nan_to_num(np.maximum(se_a[j] ** 2 - se_a[i] ** 2, 0.0)))
        if np.all(np.abs(xi_a[j] - xi_a[i]) <= zz * se_diff):
            index = i
            break
    return ThresholdChoice(
        candidates=c, n_exceedances=n_exc.astype(np.int64), shape=xi_a, shape_se=se_a,
        modified_scale=sigma - xi_a * c, mean_excess=mean_excess(x, c), index=index,
        threshold=float(c[index]),
        rule=(f"lowest candidate whose shape differs from every higher candidate's with at "
              f"least {k_cmp} exceedances by at most {zz:g} standard errors of the "
              f"difference; {len(c)} candidates with {int(n_exc[-1])}-{int(n_exc[0])} "
              "exceedances"))


def fit_tail(values: Sequence[float] | NDArray[np.float64], duration: float, *,
             threshold: Optional[float] = None, min_exceedances: int = MIN_EXCEEDANCES,
             rate_relative_se: Optional[float] = None) -> TailModel:
    """Fit the GPD tail of per-event ``values`` observed over ``duration`` seconds.

    Args:
        values: (n,) values ≥ 0 (e.g. peak forces, N).
        duration: observed time W, s (> 0).
        threshold: u (units of the values); None: :func:`choose_threshold`.
        min_exceedances: fewest values above u (≥ 10).
        rate_relative_se: relative standard error of λ_u (None: Poisson, 1/√n_u).

    Raises:
        InvalidParameterError: NaN, inf or negative values; a threshold that leaves fewer
            than ``min_exceedances`` values above it (the message names both).
    """
    x = as_array("values", values, 0.0, math.inf, lo_open=False, ndim=1)
    w = check_positive("duration", duration)
    k_min = check_count("min_exceedances", min_exceedances, 10)
    if threshold is None:
        u = choose_threshold(x, min_exceedances=k_min).threshold
    else:
        u = check_range("threshold", threshold, 0.0, math.inf, lo_open=False)
    y = x[x > u] - u
    if y.shape[0] < k_min:
        raise InvalidParameterError(
            f"invalid threshold = {u:g}: leaves {y.shape[0]} values above it, at least "
            f"min_exceedances = {k_min} needed")
    xi, sigma, cov = fit_gpd(y)
    r = (1.0 / math.sqrt(y.shape[0]) if rate_relative_se is None
         else check_range("rate_relative_se", rate_relative_se, 0.0, math.inf, lo_open=False))
    return TailModel(threshold=u, shape=xi, scale=sigma, covariance=cov,
                     n_exceedances=int(y.shape[0]), n_values=int(x.shape[0]), duration_s=w,
                     rate_relative_se=r, max_value=float(x.max()))


def _beyond(xi: NDArray[np.float64], sigma: NDArray[np.float64], lam: NDArray[np.float64],
            u: float, level: float, hazard: Hazard, n_grid: int,
            upper: Optional[float] = None, s_max: float = 60.0) -> NDArray[np.float64]:
    """λ ∫_level^upper h(x) g(x) dx for each parameter draw (module docstring), vectorised
    (``upper`` None: ∞)."""
    xi = np.asarray(xi, float)[:, None]
    sigma = np.asarray(sigma, float)[:, None]
    zeta = _survival(xi[:, 0], sigma[:, 0], level - u)[:, None]           # P(X > L | X > u)
    sig_l = np.maximum(sigma + xi * (level - u), 1e-300)                    # scale beyond L
    small = np.abs(xi) < 1e-9
    xs = np.where(small, 1.0, xi)
    s_end = np.full(xi.shape, s_max)
    if upper is not None:                        # s at which x reaches the cap
        with np.errstate(divide="ignore", invalid="ignore"):
            arg = 1.0 + xs * (upper - level) / sig_l
            s_up = np.where(small, (upper - level) / sig_l,
                            np.where(arg > 0, np.log(np.where(arg > 0, arg, 1.0)) / xs,
                                     math.inf))
        s_end = np.minimum(s_end, s_up)
    capped = s_end < s_max
    s = np.linspace(0.0, 1.0, n_grid)[None, :] * s_end
    with np.errstate(over="ignore", invalid="ignore"):
        growth = np.where(small, s, np.expm1(xi * s) / xs)
        x = level + sig_l * growth
        h = np.asarray(hazard(x.ravel()), float).reshape(x.shape)
    if np.any(h < 0) or np.any(np.isnan(h) & np.isfinite(x)):
        raise InvalidParameterError("invalid hazard: the callable returned negative or NaN "
                                    "values; it must map values to hazards >= 0")
    with np.errstate(over="ignore", invalid="ignore"):
        f = h * np.exp(-s)
        ds = s_end[:, 0] / (n_grid - 1)
        wts = np.full(n_grid, 2.0)                                         # Simpson weights
        wts[1::2] = 4.0
        wts[0] = wts[-1] = 1.0
        integral = (f * wts).sum(axis=1) * ds / 3.0
        # remainder past s_max: the integrand's own exponential decay over the last step
        ratio = f[:, -1] / f[:, -2]
        decay = -np.log(np.where(ratio > 0, ratio, 1.0)) / ds
        rest = np.where(f[:, -1] > 0, np.where(decay > 1e-3, f[:, -1] / decay, math.inf), 0.0)
        rest = np.where(capped[:, 0], 0.0, rest)
        out = np.asarray(lam, float) * zeta[:, 0] * (integral + rest)
    return np.where(zeta[:, 0] > 0, out, 0.0)


@dataclass(frozen=True)
class TailContribution:
    """Expected hazard per second of the events above ``level`` (units of h per s), from
    the tail model: ``estimate`` at the fit, ``lower``/``upper`` its ``confidence`` interval
    over parameter draws (+inf when enough draws have an infinite expectation),
    ``rate_beyond`` the events per second above ``level``."""

    estimate: float
    lower: float
    upper: float
    confidence: float
    level: float
    rate_beyond: float


def _quantiles(draws: NDArray[np.float64], confidence: float) -> tuple[float, float]:
    """Equal-tailed percentile interval of draws that may hold +inf (kept as +inf)."""
    big = np.finfo(float).max
    d = np.where(np.isnan(draws) | np.isposinf(draws), big, draws)
    a = (1.0 - confidence) / 2.0
    q = np.quantile(d, [a, 1.0 - a], method="inverted_cdf")
    return tuple(math.inf if v >= big else float(v) for v in q)  # type: ignore[return-value]


def _check_n_grid(n_grid: int) -> int:
    g = check_count("n_grid", n_grid, 101)
    return g if g % 2 == 1 else g + 1


def _contribution(model: TailModel, hazard: Hazard, level: float, upper: Optional[float],
                  confidence: float, n_draws: int, seed: int, n_grid: int
                  ) -> tuple[float, float, float, Optional[NDArray[np.float64]]]:
    """Estimate, interval and draws (None when the fit is not regular) of the expected hazard
    per second above ``level``."""
    est = float(_beyond(np.array([model.shape]), np.array([model.scale]),
                        np.array([model.rate_above]), model.threshold, level, hazard, n_grid,
                        upper)[0])
    if not np.all(np.isfinite(model.covariance)):
        return est, math.nan, math.nan, None
    xi, sg, lam = model.parameter_draws(n_draws, seed)
    d = _beyond(xi, sg, lam, model.threshold, level, hazard, n_grid, upper)
    lo, hi = _quantiles(d, confidence)
    return est, lo, hi, d


def expected_beyond(model: TailModel, hazard: Hazard, *, level: Optional[float] = None,
                    upper: Optional[float] = None, confidence: float = 0.95,
                    n_draws: int = 2000, seed: int = 0,
                    n_grid: int = 2001) -> TailContribution:
    """Expected hazard per second from events above ``level`` (default: the largest value
    observed): λ_u ∫_level^∞ h(x) g(x) dx with its interval (module docstring).

    Args:
        model: the fitted tail (:func:`fit_tail`).
        hazard: vectorised monotone map value → per-event hazard ≥ 0 (any array shape in,
            same shape out), e.g. force (N) → −ln(1 − P).
        level: lower end of the integral, ≥ u (units of the values).
        upper: a physical cap on the values (> level), e.g. the force of the fastest impact
            the table can produce; None: the GPD's own end (∞ for ξ ≥ 0).
        confidence: in (0, 1). n_draws: parameter draws (≥ 100). seed: their seed.
        n_grid: points of the integration grid (odd, ≥ 101).
    """
    lv = model.max_value if level is None else check_range(
        "level", level, model.threshold, math.inf, lo_open=False)
    conf = check_range("confidence", confidence, 0.0, 1.0)
    nd = check_count("n_draws", n_draws, 100)
    ng = _check_n_grid(n_grid)
    cap = None if upper is None else check_range("upper", upper, lv, math.inf)
    est, lo, hi, _ = _contribution(model, hazard, lv, cap, conf, nd, seed, ng)
    return TailContribution(est, lo, hi, conf, lv, model.exceedance_rate(lv))


@dataclass(frozen=True)
class TailCorrectedRate:
    """Hazard per second with the events above ``level`` replaced by the tail model's
    expectation (:func:`tail_corrected_rate`; units of the weights per s):
    ``estimate``, ``lower``, ``upper`` at ``confidence``; ``body`` (empirical, values ≤
    level), ``tail`` (model, above level), ``empirical_tail`` (what the events above level
    counted), ``empirical`` (body + empirical tail), ``level``, ``model``."""

    estimate: float
    lower: float
    upper: float
    confidence: float
    body: float
    tail: float
    empirical_tail: float
    empirical: float
    level: float
    model: TailModel


def tail_corrected_rate(values: Sequence[float] | NDArray[np.float64],
                        weights: Sequence[float] | NDArray[np.float64], duration: float,
                        hazard: Hazard, *, model: Optional[TailModel] = None,
                        level: Optional[float] = None, upper: Optional[float] = None,
                        times: Optional[Sequence[float] | NDArray[np.float64]] = None,
                        window: Optional[tuple[float, float]] = None,
                        period: Optional[float] = None, confidence: float = 0.95,
                        n_draws: int = 2000, seed: int = 0,
                        n_grid: int = 2001) -> TailCorrectedRate:
    """Σ weights / W with the events whose value exceeds ``level`` replaced by the model's
    expected contribution above ``level``, and its interval.

    Args:
        values: (n,) per-event values ≥ 0 (peak force, N). weights: (n,) their hazards ≥ 0.
        duration: observed time W, s. hazard: value → hazard callable for the model's part.
        model: the tail (default: :func:`fit_tail` on ``values`` with the chosen threshold).
        level: where the model takes over, ≥ u (default: u).
        upper: physical cap on the values for the model's part (:func:`expected_beyond`).
        times, window, period: optional event times (s), window (t_0, t_1) and block length
            (s); with them the body's uncertainty comes from its block totals (Student-t on
            the log scale, :mod:`demfem.risk.interval`) and λ_u's from the counts above u per
            block; without, from independent events (compound Poisson), which ignores their
            correlation in time.
        confidence, n_draws, seed, n_grid: as :func:`expected_beyond`.

    The interval: percentiles of body draws (log-t, or log-normal with the compound-Poisson
    error) plus tail draws (parameter draws), taken as independent.
    """
    x = as_array("values", values, 0.0, math.inf, lo_open=False, ndim=1)
    w = as_array("weights", weights, 0.0, math.inf, lo_open=False, ndim=1)
    check_same_shape(values=x, weights=w)
    dur = check_positive("duration", duration)
    conf = check_range("confidence", confidence, 0.0, 1.0)
    nd = check_count("n_draws", n_draws, 100)
    if model is None:
        model = fit_tail(x, dur)
    lv = model.threshold if level is None else check_range(
        "level", level, model.threshold, math.inf, lo_open=False)
    cap = None if upper is None else check_range("upper", upper, lv, math.inf)
    body_w = np.where(x <= lv, w, 0.0)
    body, emp_tail = float(body_w.sum()) / dur, float(w[x > lv].sum()) / dur
    if times is None:                                  # independent events: compound Poisson
        body_r = math.sqrt(float(np.sum(body_w**2))) / float(body_w.sum()) if body > 0 else 0.0
        dof = math.inf
    else:                  # block totals of the body's hazard and of the counts above u
        y = _block_totals_of(x, times, window, period,
                             np.vstack([body_w, (x > model.threshold).astype(float)]))
        dof = y.shape[1] - 1
        with np.errstate(invalid="ignore", divide="ignore"):
            r = y.std(axis=1, ddof=1) / math.sqrt(y.shape[1]) / y.mean(axis=1)
        body_r = float(r[0]) if np.isfinite(r[0]) else 0.0
        if np.isfinite(r[1]):
            model = replace(model, rate_relative_se=float(r[1]))
    tail, _, _, tail_d = _contribution(model, hazard, lv, cap, conf, nd, seed,
                                       _check_n_grid(n_grid))
    rng = np.random.default_rng(seed + 1)
    noise = rng.standard_t(dof, nd) if math.isfinite(dof) else rng.standard_normal(nd)
    lo, hi = ((math.nan, math.nan) if tail_d is None
              else _quantiles(body * np.exp(body_r * noise) + tail_d, conf))
    return TailCorrectedRate(estimate=body + tail, lower=lo, upper=hi, confidence=conf,
                             body=body, tail=tail, empirical_tail=emp_tail,
                             empirical=body + emp_tail, level=lv, model=model)


def _block_totals_of(x: NDArray[np.float64], times: Any, window: Any, period: Any,
                     series: NDArray[np.float64]) -> NDArray[np.float64]:
    """Block totals (n_series, n_blocks ≥ 2) over the whole periods of ``window``."""
    from demfem.risk.interval import block_totals

    if window is None or period is None:
        raise InvalidParameterError("invalid times: window and period must be given with them")
    t = as_array("times", times, ndim=1, unit="s")
    check_same_shape(values=x, times=t)
    t0 = check_range("window start", window[0])
    block = check_positive("period", period)
    nb = int(math.floor((check_range("window end", window[1], t0, math.inf) - t0) / block
                        + 1e-9))
    if nb < 2:
        raise InvalidParameterError(f"invalid window = {tuple(window)}: holds {nb} whole "
                                    f"period(s) of {block:g} s, at least 2 needed")
    return block_totals(t, series, t0, block, nb)
