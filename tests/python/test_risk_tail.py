"""demfem.risk.tail: peaks over threshold, checked against known generalized Pareto truths and
closed forms.

``python tests/python/test_risk_tail.py [N_SIMS] [XI]`` prints the coverage study of
docs/uncertainty.md: the block interval of the empirical rate against the tail-corrected rate
on a heavy per-event hazard (default 300 simulations, ξ = 0.1)."""
from __future__ import annotations

import math
import sys
import time

import numpy as np
import pytest
from scipy import integrate, stats

from demfem.errors import InvalidParameterError
from demfem.risk.tail import (TailModel, choose_threshold, expected_beyond, fit_gpd, fit_tail,
                              mean_excess, tail_corrected_rate)


def model_of(xi, sigma, u=1.0, n_exc=1000, duration=10.0, max_value=5.0, se=0.02):
    """A TailModel with given parameters (a small diagonal covariance)."""
    return TailModel(threshold=u, shape=xi, scale=sigma,
                     covariance=np.diag([se**2, (se * sigma) ** 2]), n_exceedances=n_exc,
                     n_values=10 * n_exc, duration_s=duration,
                     rate_relative_se=1.0 / math.sqrt(n_exc), max_value=max_value)


def power_beyond_closed_form(xi, sigma, u, level, k, rate):
    """rate × E[F^k; F > level | F > u] for F − u ~ GPD(ξ, σ), integer k, k ξ < 1: the excess
    over ``level`` is GPD(ξ, σ + ξ (level − u)) with E[Z^j] = σ_L^j j! / Π_{i≤j} (1 − i ξ)."""
    zeta = math.exp(-(level - u) / sigma) if xi == 0 else (1 + xi * (level - u) / sigma) ** (
        -1 / xi)
    s_l = sigma + xi * (level - u)
    moments = [s_l**j * math.factorial(j) / math.prod(1 - i * xi for i in range(1, j + 1))
               for j in range(k + 1)]
    return rate * zeta * sum(math.comb(k, j) * level ** (k - j) * moments[j]
                             for j in range(k + 1))


def mixture(rng, n=20000, u0=2.0, zeta=0.1, xi=0.3, sigma=1.0):
    """Exponential bulk below u0 (truncated) with a GPD(ξ, σ) tail above u0 of weight zeta."""
    n_tail = rng.binomial(n, zeta)
    bulk = rng.exponential(1.0, 4 * n)
    bulk = bulk[bulk < u0][: n - n_tail]
    return np.concatenate([bulk, u0 + stats.genpareto.rvs(xi, scale=sigma, size=n_tail,
                                                          random_state=rng)])


# --- the fit -----------------------------------------------------------------------------

@pytest.mark.parametrize("xi, sigma", [(0.2, 2.0), (0.0, 1.0), (-0.2, 0.5), (0.4, 3.0)])
def test_fit_recovers_shape_and_scale(xi, sigma):
    rng = np.random.default_rng(11)
    y = stats.genpareto.rvs(xi, scale=sigma, size=5000, random_state=rng)
    a, s, cov = fit_gpd(y)
    se = np.sqrt(np.diag(cov))
    assert abs(a - xi) < 3 * se[0] and abs(s - sigma) < 3 * se[1]
    # the observed information agrees with the expected one (Smith 1985)
    assert se[0] == pytest.approx((1 + xi) / math.sqrt(5000), rel=0.15)
    assert se[1] == pytest.approx(sigma * math.sqrt(2 * (1 + xi) / 5000), rel=0.15)
    c, _, scale = stats.genpareto.fit(y, floc=0)
    assert (a, s) == pytest.approx((c, scale), abs=2e-3)


def test_standard_errors_match_the_spread_of_the_estimates():
    rng = np.random.default_rng(12)
    fits = [fit_gpd(stats.genpareto.rvs(0.15, scale=1.0, size=1000, random_state=rng))
            for _ in range(150)]
    xi = np.array([f[0] for f in fits])
    se = np.array([math.sqrt(f[2][0, 0]) for f in fits])
    assert np.std(xi) == pytest.approx(np.mean(se), rel=0.2)


def test_fit_tail_rate_and_levels():
    rng = np.random.default_rng(13)
    x = 1.0 + stats.genpareto.rvs(0.1, scale=0.5, size=3000, random_state=rng)
    m = fit_tail(x, 60.0, threshold=1.0)
    assert m.n_exceedances == 3000 and m.rate_above == pytest.approx(50.0)
    assert m.rate_relative_se == pytest.approx(1 / math.sqrt(3000))
    assert m.max_value == x.max()
    assert m.exceedance_rate(1.0) == pytest.approx(50.0)
    levels = np.array([1.5, 3.0, 8.0])
    assert m.return_level(m.exceedance_rate(levels)) == pytest.approx(levels)
    # against scipy's survival function with the fitted parameters
    assert m.exceedance_rate(3.0) == pytest.approx(
        50.0 * stats.genpareto.sf(2.0, m.shape, scale=m.scale))
    once_an_hour = m.return_level(1 / 3600)
    assert m.exceedance_rate(once_an_hour) == pytest.approx(1 / 3600)


# --- threshold diagnostic ----------------------------------------------------------------

def test_mean_excess():
    x = np.array([1.0, 2.0, 3.0, 10.0])
    assert mean_excess(x, [0.0, 2.0, 10.0]) == pytest.approx([4.0, 4.5, np.nan], nan_ok=True)
    rng = np.random.default_rng(14)
    y = stats.genpareto.rvs(0.2, scale=1.0, size=200000, random_state=rng)
    # e(u) = (σ + ξ u)/(1 − ξ) for a GPD
    assert mean_excess(y, [1.0])[0] == pytest.approx((1.0 + 0.2) / 0.8, rel=0.03)


@pytest.mark.parametrize("xi", [0.3, -0.1])
def test_threshold_diagnostic_finds_the_true_threshold(xi):
    """Exponential bulk below u0 = 2, GPD tail above: the chosen threshold lies near 2 (a
    little below is nearly GPD too), and the shape fitted there is the tail's."""
    choices = [choose_threshold(mixture(np.random.default_rng(100 + s), xi=xi))
               for s in range(5)]
    chosen = [c.threshold for c in choices]
    z = [(c.shape[c.index] - xi) / c.shape_se[c.index] for c in choices]
    print("chosen thresholds", np.round(chosen, 2), "shape error / se", np.round(z, 2))
    assert 1.4 <= np.median(chosen) <= 2.4
    assert all(1.3 <= c <= 3.6 for c in chosen)
    assert all(abs(v) < 3.0 for v in z)


def test_threshold_diagnostic_on_a_pure_gpd_keeps_a_low_threshold():
    x = stats.genpareto.rvs(0.2, size=20000, random_state=np.random.default_rng(15))
    ch = choose_threshold(x)
    assert ch.index <= 3 and ch.threshold < 2.0
    assert len(ch.candidates) == len(ch.shape) == len(ch.mean_excess)
    assert np.all(np.diff(ch.candidates) > 0) and np.all(np.diff(ch.n_exceedances) < 0)
    # above the threshold, the modified scale σ − ξu stays near the true σ = 1
    assert np.median(ch.modified_scale[ch.index:]) == pytest.approx(1.0, rel=0.15)
    assert "standard errors" in ch.rule


# --- beyond the largest value ------------------------------------------------------------

@pytest.mark.parametrize("xi, k", [(0.2, 2), (0.2, 3), (0.0, 4), (-0.3, 3), (0.3, 3)])
def test_expected_beyond_matches_the_closed_form(xi, k):
    m = model_of(xi, 1.5, u=1.0, n_exc=1000, duration=500.0, max_value=5.0)
    c = 2e-9
    got = expected_beyond(m, lambda f: c * f**k, n_draws=200)
    want = power_beyond_closed_form(xi, 1.5, 1.0, 5.0, k, 2.0) * c
    assert got.estimate == pytest.approx(want, rel=1e-7)
    assert got.lower < got.estimate < got.upper
    assert got.level == 5.0 and got.rate_beyond == pytest.approx(m.exceedance_rate(5.0))


def test_expected_beyond_with_a_cap_and_a_non_integer_power():
    m = model_of(0.25, 1.2, u=1.0, n_exc=300, duration=100.0, max_value=4.0)
    h = lambda f: f**2.7                                                   # noqa: E731
    pdf = lambda f: stats.genpareto.pdf(f - 1.0, 0.25, scale=1.2)          # noqa: E731
    for upper, tail_end in ((None, np.inf), (12.0, 12.0)):
        want = 3.0 * integrate.quad(lambda f: h(f) * pdf(f), 4.0, tail_end, limit=200)[0]
        got = expected_beyond(m, h, upper=upper, n_draws=200).estimate
        assert got == pytest.approx(want, rel=1e-7)


def test_expected_beyond_is_infinite_where_the_integral_diverges():
    m = model_of(0.5, 1.0)
    assert expected_beyond(m, lambda f: f**2, n_draws=200).estimate == math.inf
    capped = expected_beyond(m, lambda f: f**2, upper=50.0, n_draws=200)
    assert math.isfinite(capped.estimate) and math.isfinite(capped.upper)
    # half the draws have ξ > 0.5 and an infinite expectation: the upper bound is +inf
    assert expected_beyond(m, lambda f: f**2, n_draws=200).upper == math.inf


def test_interval_of_the_beyond_contribution_covers():
    """Fit 1000 exceedances, predict the hazard beyond the largest: the 95 % interval holds
    the true value in about 95 % of 120 simulations."""
    rng = np.random.default_rng(16)
    xi, sigma, k = 0.1, 1.0, 3
    hits = 0
    start = time.perf_counter()
    for _ in range(120):
        x = 1.0 + stats.genpareto.rvs(xi, scale=sigma, size=1000, random_state=rng)
        m = fit_tail(x, 100.0, threshold=1.0)
        got = expected_beyond(m, lambda f: f**k, n_draws=400, n_grid=201,
                              seed=int(rng.integers(1 << 30)))
        truth = power_beyond_closed_form(xi, sigma, 1.0, m.max_value, k, 10.0)
        hits += got.lower <= truth <= got.upper
    print(f"beyond-max coverage {hits / 120:.3f}")
    assert 0.88 <= hits / 120 <= 0.99
    assert time.perf_counter() - start < 20.0


# --- the tail-corrected rate -------------------------------------------------------------

def test_tail_corrected_rate():
    rng = np.random.default_rng(17)
    duration = 20.0
    f = 0.5 + stats.genpareto.rvs(0.05, scale=0.6, size=8000, random_state=rng)
    t = rng.uniform(0.0, duration, f.size)
    h = lambda x: 1e-12 * x**4                                             # noqa: E731
    r = tail_corrected_rate(f, h(f), duration, h, times=t, window=(0.0, duration), period=2.0,
                            n_draws=500)
    assert r.level == r.model.threshold
    assert r.body == pytest.approx(h(f[f <= r.level]).sum() / duration)
    assert r.empirical == pytest.approx(h(f).sum() / duration)
    assert r.estimate == pytest.approx(r.body + r.tail)
    truth = 8000 / duration * 1e-12 * integrate.quad(
        lambda x: x**4 * stats.genpareto.pdf(x - 0.5, 0.05, scale=0.6), 0.5, np.inf)[0]
    assert r.lower <= truth <= r.upper and r.lower <= r.empirical <= r.upper
    # a level above the threshold: the model replaces only the events above it
    hi = tail_corrected_rate(f, h(f), duration, h, model=r.model, level=3.0, n_draws=500)
    assert hi.body == pytest.approx(h(f[f <= 3.0]).sum() / duration)
    assert hi.estimate == pytest.approx(hi.body + hi.tail)
    assert hi.lower < hi.estimate < hi.upper


# --- bad input ---------------------------------------------------------------------------

def test_bad_input_names_the_field_and_the_limit():
    good = np.linspace(0.1, 10.0, 500)
    with pytest.raises(InvalidParameterError, match=r"values\[3\] = .*nan"):
        fit_tail(np.r_[good[:3], np.nan, good[3:]], 10.0)
    with pytest.raises(InvalidParameterError, match=r"values\[0\] = .*-1"):
        choose_threshold(np.r_[-1.0, good])
    with pytest.raises(InvalidParameterError, match="threshold = 9.9.*leaves 6 values.*50"):
        fit_tail(good, 10.0, threshold=9.9)
    with pytest.raises(InvalidParameterError, match="min_exceedances = 50"):
        choose_threshold(good[:60])
    with pytest.raises(InvalidParameterError, match="duration"):
        fit_tail(good, 0.0)
    m = fit_tail(good, 10.0, threshold=2.0)
    with pytest.raises(InvalidParameterError, match="level"):
        expected_beyond(m, lambda f: f, level=1.0)
    with pytest.raises(InvalidParameterError, match="level"):
        m.exceedance_rate(1.0)
    with pytest.raises(InvalidParameterError, match="rate"):
        m.return_level(2 * m.rate_above)
    with pytest.raises(InvalidParameterError, match="hazard"):
        expected_beyond(m, lambda f: -f, n_draws=100)
    with pytest.raises(InvalidParameterError, match="weights"):
        tail_corrected_rate(good, good[:-1], 10.0, lambda f: f)
    with pytest.raises(InvalidParameterError, match="window"):
        tail_corrected_rate(good, good, 10.0, lambda f: f, times=good)


def test_a_short_bounded_tail_has_no_interval():
    """ξ < −0.5: maximum likelihood is not regular; the estimate stands without an interval."""
    rng = np.random.default_rng(18)
    x = 1.0 + stats.genpareto.rvs(-0.8, scale=1.0, size=2000, random_state=rng)
    m = fit_tail(x, 10.0, threshold=1.0)
    assert m.shape < -0.5 and math.isnan(m.shape_se)
    got = expected_beyond(m, lambda f: f**2, level=1.5)
    assert math.isfinite(got.estimate) and math.isnan(got.lower) and math.isnan(got.upper)
    with pytest.raises(InvalidParameterError, match="shape"):
        m.parameter_draws(10)


def coverage_study(n_sims, xi, cap=15.0, n_periods=7, mu=300.0, seed=0):
    """Per period Poisson(mu G) events (G gamma, CV 0.5), force F = 0.5 + GPD(ξ, 0.6) N below
    a physical cap (N), hazard h = F^6.6: how often the 95 % interval holds the true hazard
    rate and its median upper/lower, (a) the block interval of the empirical rate
    (demfem.risk.interval, log-t), (b) the tail-corrected rate (automatic threshold, block
    uncertainties) with the cap, (c) the same without the cap."""
    from demfem.risk.interval import rate_interval

    rng = np.random.default_rng(seed)
    h = lambda f: f**6.6                                                    # noqa: E731
    mass = stats.genpareto.cdf(cap - 0.5, xi, scale=0.6)
    mean_h = integrate.quad(lambda f: h(f) * stats.genpareto.pdf(f - 0.5, xi, scale=0.6),
                            0.5, cap, limit=400, points=[1.0, 3.0, 8.0])[0] / mass
    period, window = 2.0, (0.0, n_periods * 2.0)
    truth = mu * mean_h / period
    found = {"empirical, log-t": [], "tail-corrected, cap": [], "tail-corrected, no cap": []}
    for _ in range(n_sims):
        g = rng.gamma(4.0, 0.25, n_periods)
        n = rng.poisson(mu * g)
        t = (np.repeat(np.arange(n_periods), n) + rng.random(n.sum())) * period
        q = rng.uniform(0.0, mass, t.size)                       # F below the cap
        f = 0.5 + stats.genpareto.ppf(q, xi, scale=0.6)
        emp = rate_interval(t, h(f), window, period)
        kw = dict(times=t, window=window, period=period, n_draws=1000, n_grid=801,
                  seed=int(rng.integers(1 << 30)))
        model = fit_tail(f, window[1])
        for name, r in (("empirical, log-t", emp),
                        ("tail-corrected, cap", tail_corrected_rate(
                            f, h(f), window[1], h, model=model, upper=cap, **kw)),
                        ("tail-corrected, no cap", tail_corrected_rate(
                            f, h(f), window[1], h, model=model, **kw))):
            found[name].append((r.lower <= truth <= r.upper, r.upper / r.lower))
    return {k: (float(np.mean([c for c, _ in v])), float(np.median([w for _, w in v])))
            for k, v in found.items()}


if __name__ == "__main__":
    sims = int(sys.argv[1]) if len(sys.argv) > 1 else 300
    xi_ = float(sys.argv[2]) if len(sys.argv) > 2 else 0.1
    print(f"xi = {xi_}, F capped at 15 N, {sims} simulations of 7 periods: coverage of the "
          "95 % interval, median upper/lower")
    for name, (cov, fac) in coverage_study(sims, xi_).items():
        print(f"  {name:24s} {cov:.3f}  {fac:.2f}")
