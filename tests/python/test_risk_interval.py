"""demfem.risk.interval: block intervals of a weighted point-process rate, checked by simulated
coverage on processes of known rate whose events are correlated within a gate period.

``python tests/python/test_risk_interval.py [N_SIMS]`` prints the method comparison of
docs/uncertainty.md (default 2000 simulations per scenario)."""
from __future__ import annotations

import json
import math
import sys
import time

import numpy as np
import pytest
from scipy import integrate, stats

from demfem.errors import InvalidParameterError
from demfem.risk.interval import (METHODS, block_totals, hourly_interval_from_events,
                                  interval_from_blocks, rate_interval)
from demfem.dem.steady import period_rates, relative_error

PERIOD = 2.0


def simulate(rng, n_periods, mu=300.0, k_gamma=4.0, sigma=1.0, period=PERIOD):
    """Events of a stationary process of known rate, correlated within each period: the
    period's intensity is mu × G (G gamma, mean 1, CV 1/√k), the events bunch early in the
    period (phase Beta(2, 5), like impacts after the gate opens), weights log-normal.
    Returns times (s), weights and the true rate Σw per second."""
    g = rng.gamma(k_gamma, 1.0 / k_gamma, n_periods)
    n = rng.poisson(mu * g)
    b = np.repeat(np.arange(n_periods), n)
    t = (b + rng.beta(2.0, 5.0, b.size)) * period
    w = rng.lognormal(0.0, sigma, b.size)
    return t, w, mu * math.exp(sigma**2 / 2.0) / period


def coverage(n_sims, n_periods, block, seed, **kw):
    rng = np.random.default_rng(seed)
    hits = 0
    for _ in range(n_sims):
        t, w, truth = simulate(rng, n_periods, **kw)
        r = rate_interval(t, w, (0.0, n_periods * PERIOD), block)
        hits += r.lower <= truth <= r.upper
    return hits / n_sims


# --- block totals and the formula --------------------------------------------------------

def test_block_totals_match_steady_period_rates():
    rng = np.random.default_rng(0)
    t = rng.uniform(-1.0, 21.0, 5000)
    w = rng.exponential(1.0, 5000)
    got = block_totals(t, np.vstack([np.ones_like(w), w]), 2.0, PERIOD, 9)
    assert np.array_equal(got[0], period_rates(t, 2.0, PERIOD, 9))
    assert np.allclose(got[1], period_rates(t, 2.0, PERIOD, 9, weights=w))


def test_log_t_interval_by_hand():
    # four periods of 2 s with block totals 3, 5, 4, 8 (one event each)
    t = np.array([0.5, 2.5, 4.5, 6.5])
    w = np.array([3.0, 5.0, 4.0, 8.0])
    r = rate_interval(t, w, (0.0, 8.0), PERIOD, scale=3600.0)
    m, s = 5.0, np.std(w, ddof=1)
    rel = s / (2.0 * m)
    q = stats.t.ppf(0.975, 3)
    assert r.estimate == pytest.approx(3600.0 * m / PERIOD)
    assert r.lower == pytest.approx(r.estimate * math.exp(-q * rel))
    assert r.upper == pytest.approx(r.estimate * math.exp(q * rel))
    assert r.relative_standard_error == pytest.approx(relative_error(w))
    assert r.factor == pytest.approx(math.exp(q * rel))
    assert r.n_blocks == 4 and r.status == "ok" and r.method == "log-t" and r.n_events == 4
    assert r.lag1_autocorrelation == pytest.approx(
        np.sum((w[1:] - m) * (w[:-1] - m)) / np.sum((w - m) ** 2))


def test_partial_period_is_left_out():
    t = np.array([0.5, 2.5, 4.1])           # the last event lies in an incomplete third period
    r = rate_interval(t, np.ones(3), (0.0, 5.0), PERIOD)
    assert r.n_blocks == 2 and r.window_s == (0.0, 4.0)
    assert r.estimate == pytest.approx(2 / 4.0)


# --- coverage by simulation --------------------------------------------------------------

def test_coverage_of_the_95_interval_with_correlated_periods():
    """400 simulations of 10 periods: the log-t interval over whole periods covers the true
    rate 93-97 % of the time; blocks of a tenth of a period, which take the correlated events
    of one period as independent, cover far less."""
    start = time.perf_counter()
    cov = coverage(400, 10, PERIOD, seed=0)
    cov_short = coverage(400, 10, PERIOD / 10.0, seed=0)
    print(f"coverage, whole-period blocks {cov:.3f}, tenth-period blocks {cov_short:.3f}")
    assert 0.93 <= cov <= 0.97
    assert cov_short < 0.88
    assert time.perf_counter() - start < 20.0


def _h_moment(xi, sigma, u, k):
    """E[(u + Y)^k], Y ~ GPD(xi, sigma), as ∫ (u + Q(e^-s))^k e^-s ds over s = -ln P(Y > y)
    (Q the quantile of the survival; a plain quad over y misses the far tail)."""
    f = lambda s: (u + stats.genpareto.isf(math.exp(-s), xi, scale=sigma)) ** k \
        * math.exp(-s)  # noqa: E731
    return sum(integrate.quad(f, a, b, limit=200)[0]
               for a, b in ((0, 10), (10, 50), (50, 200), (200, 700)))


def block_scenario(rng, n_sims, n_blocks, kind, mu=300.0, k_gamma=4.0):
    """(n_sims, n_blocks) block totals and the true mean block total. ``kind``: ``"lognormal"``
    (σ = 1) or ``("force", ξ)``: hazard h = F^6.6 of a force F = 0.5 + GPD(ξ, 0.6) (the
    exponent of the default table's hazard in its peak force)."""
    g = rng.gamma(k_gamma, 1.0 / k_gamma, (n_sims, n_blocks))
    n = rng.poisson(mu * g)
    idx = np.repeat(np.arange(n_sims * n_blocks), n.ravel())
    if kind == "lognormal":
        w, mean_w = rng.lognormal(0.0, 1.0, idx.size), math.exp(0.5)
    else:
        xi = kind[1]
        f = 0.5 + stats.genpareto.rvs(xi, scale=0.6, size=idx.size, random_state=rng)
        w, mean_w = f**6.6, _h_moment(xi, 0.6, 0.5, 6.6)
    y = np.bincount(idx, weights=w, minlength=n_sims * n_blocks).reshape(n_sims, n_blocks)
    return y, mu * mean_w


def _reference_intervals(y, alpha=0.05, n_boot=2000, seed=0):
    """Symmetric Student-t and BCa (jackknife acceleration) intervals of the mean block total,
    for the comparison only."""
    n = y.shape[1]
    m, se = y.mean(1), y.std(1, ddof=1) / math.sqrt(n)
    q = stats.t.ppf(1 - alpha / 2, n - 1)
    out = {"t (symmetric)": (np.maximum(m - q * se, 0.0), m + q * se)}
    rng = np.random.default_rng(seed)
    c = rng.multinomial(n, np.full(n, 1.0 / n), size=n_boot)
    d = y @ c.T / n
    z0 = stats.norm.ppf(np.clip((d < m[:, None]).mean(1), 1e-6, 1 - 1e-6))
    jack = (y.sum(1)[:, None] - y) / (n - 1)
    dj = jack.mean(1)[:, None] - jack
    a = (dj**3).sum(1) / (6 * ((dj**2).sum(1)) ** 1.5)
    bounds = []
    for zq in (stats.norm.ppf(alpha / 2), stats.norm.ppf(1 - alpha / 2)):
        p = stats.norm.cdf(z0 + (z0 + zq) / (1 - a * (z0 + zq)))
        bounds.append(np.array([np.quantile(d[i], p[i]) for i in range(len(m))]))
    out["BCa"] = tuple(bounds)
    return out


def method_table(n_sims, seed=1, scenarios=None, reference=False):
    """Coverage of each method's 95 % interval of the mean block total over simulated
    scenarios (block_scenario). Returns {scenario: {method: coverage}}."""
    scenarios = scenarios or [(7, "lognormal"), (4, "lognormal"), (7, ("force", 0.0)),
                              (7, ("force", 0.1)), (30, ("force", 0.1))]
    rng = np.random.default_rng(seed)
    table = {}
    for n_blocks, kind in scenarios:
        y, truth = block_scenario(rng, n_sims, n_blocks, kind)
        row = {}
        for method in METHODS:
            r = interval_from_blocks(y, 1.0, method=method, seed=seed)
            row[method] = float(np.mean((r["lower"] <= truth) & (truth <= r["upper"])))
        if reference:
            for name, (lo, hi) in _reference_intervals(y).items():
                row[name] = float(np.mean((lo <= truth) & (truth <= hi)))
        name = kind if isinstance(kind, str) else f"F^6.6, xi={kind[1]}"
        table[f"{n_blocks} blocks, {name}"] = row
    return table


def test_log_t_covers_better_than_the_bootstrap_with_few_blocks():
    """7 periods: the percentile bootstrap undercovers (the plug-in variance and normal-like
    quantiles); log-t is near 95 % for log-normal weights and as good as the bootstrap-t on
    the log scale (which is far wider) for a heavy hazard."""
    table = method_table(400, scenarios=[(7, "lognormal"), (7, ("force", 0.0))])
    for name, row in table.items():
        print(name, {k: round(v, 3) for k, v in row.items()})
    ln, heavy = table["7 blocks, lognormal"], table["7 blocks, F^6.6, xi=0.0"]
    assert 0.93 <= ln["log-t"] <= 0.97
    assert ln["percentile"] < ln["log-t"] - 0.04
    assert heavy["percentile"] < heavy["log-t"] - 0.05
    assert abs(heavy["studentized-log"] - heavy["log-t"]) < 0.03
    assert heavy["log-t"] > 0.85


# --- splits ------------------------------------------------------------------------------

def _split_data(seed=2, n_periods=8):
    rng = np.random.default_rng(seed)
    t, w, _ = simulate(rng, n_periods)
    place = rng.choice(np.array(["gate", "lower side", "cartridge"]), t.size)
    inner = w * rng.uniform(0.0, 0.2, t.size)
    return t, w, place, inner


@pytest.mark.parametrize("method", METHODS)
def test_splits_add_up_and_match_separate_calls(method):
    t, w, place, inner = _split_data()
    window = (0.0, 16.0)
    r = rate_interval(t, {"inner": inner, "outer": w - inner}, window, PERIOD,
                      groups={"place": place}, method=method, scale=3600.0)
    total = rate_interval(t, w, window, PERIOD, method=method, scale=3600.0)
    assert r.estimate == pytest.approx(total.estimate)
    assert (r.lower, r.upper) == pytest.approx((total.lower, total.upper))
    for grouping in ("place", "component"):
        parts = r.splits[grouping]
        assert sum(p.estimate for p in parts.values()) == pytest.approx(r.estimate)
        assert sum(p.share for p in parts.values()) == pytest.approx(1.0)
        for p in parts.values():
            assert 0.0 <= p.share_lower <= p.share <= p.share_upper <= 1.0
            assert p.lower <= p.estimate <= p.upper
    # a split is the interval of its own weights, from the same blocks (and the same draws)
    alone = rate_interval(t, np.where(place == "gate", w, 0.0), window, PERIOD,
                          method=method, scale=3600.0)
    gate = r.splits["place"]["gate"]
    assert (gate.estimate, gate.lower, gate.upper) == pytest.approx(
        (alone.estimate, alone.lower, alone.upper))


def test_share_interval_covers():
    """The share's Student-t interval (ratio estimator) covers the true share of a group."""
    rng = np.random.default_rng(5)
    # the label's probability follows the gate's phase: 0.3 (1 + 0.5 cos 2π phase); the true
    # share is its mean over the events' phases (Beta(2, 5))
    truth = 0.3 * (1.0 + 0.5 * integrate.quad(
        lambda x: math.cos(2.0 * math.pi * x) * stats.beta.pdf(x, 2.0, 5.0), 0.0, 1.0)[0])
    hits = 0
    for _ in range(300):
        t, w, _ = simulate(rng, 8)
        phase = t / PERIOD - np.floor(t / PERIOD)
        lab = rng.random(t.size) < 0.3 * (1.0 + 0.5 * np.cos(2.0 * math.pi * phase))
        r = rate_interval(t, w, (0.0, 16.0), PERIOD, groups=lab)
        s = r.splits["group"]["True"]
        hits += s.share_lower <= truth <= s.share_upper
    print(f"share coverage {hits / 300:.3f}")
    assert 0.90 <= hits / 300 <= 0.98


def test_bootstrap_is_seeded_and_vectorised():
    rng = np.random.default_rng(3)
    n = 1_000_000
    t = rng.uniform(0.0, 40.0, n)
    w = rng.exponential(1.0, n)
    start = time.perf_counter()
    a = rate_interval(t, w, (0.0, 40.0), PERIOD, method="percentile", n_boot=2000, seed=7,
                      groups=rng.integers(0, 4, n))
    elapsed = time.perf_counter() - start
    b = rate_interval(t[:10], w[:10], (0.0, 40.0), PERIOD, method="percentile", seed=7)
    c = rate_interval(t[:10], w[:10], (0.0, 40.0), PERIOD, method="percentile", seed=7)
    assert (b.lower, b.upper) == (c.lower, c.upper)
    assert a.n_blocks == 20 and a.lower < a.estimate < a.upper
    assert elapsed < 5.0


# --- degenerate cases and bad input ------------------------------------------------------

def test_fewer_than_two_periods_is_not_estimable():
    r = rate_interval([0.5, 1.5, 2.5], [1.0, 2.0, 3.0], (0.0, 3.0), PERIOD)
    assert r.status == "too few blocks" and not r.estimable
    assert math.isnan(r.lower) and math.isnan(r.upper)
    assert r.estimate == pytest.approx(6.0 / 3.0)            # over the whole window
    d = r.to_dict()
    assert d["lower"] is None and d["upper"] is None
    json.dumps(d, allow_nan=False)


def test_no_events_gives_zero_and_the_rule_of_three_bound():
    t = np.array([0.5, 3.0, 5.0])
    r = rate_interval(t, np.zeros(3), (0.0, 10.0), PERIOD, scale=3600.0)
    assert r.status == "no events" and r.estimate == 0.0 and r.lower == 0.0
    assert r.upper == math.inf and r.n_events == 0
    r = rate_interval(t, np.zeros(3), (0.0, 10.0), PERIOD, scale=3600.0, max_weight=1e-6)
    # no event in 10 s: at most -ln(0.025) = 3.69 events per 10 s (two-sided 95 %)
    assert r.upper == pytest.approx(3600.0 * 1e-6 * -math.log(0.025) / 10.0)
    empty = rate_interval([], None, (0.0, 10.0), PERIOD)
    assert empty.status == "no events" and empty.upper == math.inf
    json.dumps(empty.to_dict(), allow_nan=False)


@pytest.mark.parametrize("kwargs, field", [
    ({"event_times": [0.0, np.nan]}, "event_times"),
    ({"event_weights": [1.0, -1.0]}, "event_weights"),
    ({"event_weights": [1.0, np.inf]}, "event_weights"),
    ({"event_weights": [1.0]}, "event_weights"),
    ({"window": (4.0, 4.0)}, "window end"),
    ({"period": 0.0}, "period"),
    ({"confidence": 1.0}, "confidence"),
    ({"method": "bca"}, "method"),
    ({"n_boot": 10}, "n_boot"),
    ({"scale": -1.0}, "scale"),
    ({"max_weight": 0.0}, "max_weight"),
    ({"groups": ["a"]}, "groups"),
    ({"groups": {"place": ["a", "b", "c"]}}, "groups['place']"),
])
def test_bad_input_names_the_field(kwargs, field):
    args = {"event_times": [0.5, 2.5], "event_weights": [1.0, 2.0], "window": (0.0, 4.0),
            "period": PERIOD}
    args.update(kwargs)
    with pytest.raises(InvalidParameterError, match=field.replace("[", r"\[")):
        rate_interval(args.pop("event_times"), args.pop("event_weights"), args.pop("window"),
                      args.pop("period"), **args)


# --- the assess event table --------------------------------------------------------------

def test_hourly_interval_from_events():
    from demfem.assess.events import EVENT_DTYPE

    rng = np.random.default_rng(4)
    n = 4000
    ev = np.zeros(n, EVENT_DTYPE)
    ev["time"] = rng.uniform(2.0, 18.0, n)
    wall = rng.random(n) < 0.2
    ev["partner"] = wall.astype(int)
    ev["j"] = np.where(wall, -1, 1)
    ev["wall"] = np.where(wall, rng.integers(0, 2, n), -1)
    p_in = rng.uniform(0.0, 1e-9, n)
    p_out = rng.uniform(0.0, 1e-8, n)
    p = -np.expm1(np.log1p(-p_in) + np.log1p(-p_out))
    r = hourly_interval_from_events(ev, p, (2.0, 18.0), PERIOD, wall_names=["gate", "lower"],
                                    p_surfaces={"inner": p_in, "outer": p_out})
    h = -np.log1p(-p) * np.where(wall, 1.0, 2.0)
    assert r.estimate == pytest.approx(3600.0 * h.sum() / 16.0, rel=1e-9)
    assert set(r.splits["with"]) == {"gate", "lower", "cartridge"}
    assert set(r.splits["partner"]) == {"sphere", "wall"}
    assert r.splits["with"]["cartridge"].estimate == pytest.approx(
        r.splits["partner"]["sphere"].estimate)
    assert r.splits["component"]["inner"].estimate + r.splits["component"][
        "outer"].estimate == pytest.approx(r.estimate)
    assert r.lower < r.estimate < r.upper
    json.dumps(r.to_dict(), allow_nan=False)
    plain = hourly_interval_from_events(ev, p, (2.0, 18.0), PERIOD)
    assert plain.estimate == pytest.approx(r.estimate, rel=1e-9)
    assert set(plain.splits["with"]) == {"wall", "cartridge"}


if __name__ == "__main__":
    sims = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
    print(f"coverage of the nominal 95 % interval, {sims} simulations per scenario")
    for name, row in method_table(sims, reference=True).items():
        print(f"{name:28s}", "  ".join(f"{k} {v:.3f}" for k, v in row.items()))
    print(f"whole-period blocks, 10 periods: {coverage(sims, 10, PERIOD, seed=0):.3f}; "
          f"tenth-period blocks: {coverage(sims, 10, PERIOD / 10, seed=0):.3f}")
