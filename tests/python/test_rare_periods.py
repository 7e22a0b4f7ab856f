"""The check that says whether one gate period (a jam) dominates the hourly number
(demfem.risk.rare_periods) and how assess reports it."""
from __future__ import annotations

import math

import numpy as np
import pytest

from demfem.errors import InvalidParameterError
from demfem.risk.rare_periods import DOMINANCE_RATIO, period_dominance


def _ordinary(n_periods: int, period: float, seed: int = 1):
    """Events spread over n periods with hazards of an ordinary period's scatter (CV ~ 0.2
    per period: 400 events a period of log-normal hazards)."""
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, n_periods * period, 400 * n_periods))
    h = rng.lognormal(-20.0, 1.0, t.size)
    return t, h


def test_ordinary_periods_do_not_dominate_and_the_unseen_bound_is_the_binomial_zero_count():
    t, h = _ordinary(7, 2.0)
    d = period_dominance(t, h, (0.0, 14.0), 2.0)
    assert not d.dominated and d.dominant == ()
    assert d.n_periods == 7 and d.totals.shape == (7,)
    assert d.totals.sum() == pytest.approx(h.sum(), rel=1e-12)
    assert 1.0 < d.largest_over_median < 2.0
    # P(no dominant period in 7 | fraction q) = (1 - q)^7 = 0.05 at the bound
    assert (1.0 - d.unseen_bound) ** 7 == pytest.approx(0.05, rel=1e-12)
    assert d.unseen_bound == pytest.approx(0.3482, abs=1e-4)
    assert period_dominance(t, h, (0.0, 14.0), 2.0, confidence=0.8).unseen_bound < \
        d.unseen_bound


def test_a_jam_period_dominates_with_its_share_and_place_in_time():
    t, h = _ordinary(10, 2.0)
    jam = 70.0 * np.median([h[(t >= 2 * k) & (t < 2 * k + 2)].sum() for k in range(10)])
    t2, h2 = np.append(t, 13.1), np.append(h, jam)
    d = period_dominance(t2, h2, (0.0, 20.0), 2.0)
    assert d.dominated and d.dominant == (6,)
    assert d.largest_index == 6 and d.largest_window_s == (12.0, 14.0)
    assert d.largest_over_median > 60.0
    assert d.largest_share == pytest.approx(d.largest / d.totals.sum(), rel=1e-12)
    assert d.largest_share > 0.8
    assert math.isnan(d.unseen_bound)
    doc = d.to_dict()
    assert doc["dominated"] and doc["dominant_periods"] == [6] and doc["unseen_bound"] is None
    # events after the last whole period are outside the check
    d3 = period_dominance(np.append(t2, 20.5), np.append(h2, 1e3 * jam), (0.0, 21.0), 2.0)
    assert d3.totals.sum() == pytest.approx(d.totals.sum(), rel=1e-12)
    assert DOMINANCE_RATIO == 5.0


@pytest.mark.parametrize("kwargs, field", [
    (dict(period=0.0), "period"),
    (dict(period=-2.0), "period"),
    (dict(window=(0.0, 3.0)), "window"),
    (dict(ratio=0.5), "ratio"),
    (dict(confidence=1.0), "confidence"),
    (dict(times=np.array([0.1, np.nan])), "times"),
    (dict(weights=np.array([1.0, -1.0])), "weights"),
    (dict(weights=np.array([1.0, 2.0, 3.0])), "weights"),
])
def test_bad_input_names_the_field(kwargs, field):
    args = dict(times=np.array([0.1, 2.5]), weights=np.array([1.0, 2.0]), window=(0.0, 4.0),
                period=2.0)
    args.update(kwargs)
    with pytest.raises(InvalidParameterError, match=field):
        period_dominance(args.pop("times"), args.pop("weights"), args.pop("window"),
                         args.pop("period"), **args)


def test_assess_names_the_dominant_period_and_its_event():
    """The risk stage's check on an event table: a gate-wall squeeze in one of 8 periods is
    named with its wall, force and time, and the same check without it says how rare such
    periods must be."""
    from demfem.assess.events import EVENT_DTYPE
    from demfem.assess.risk_product import _period_check

    t, h = _ordinary(8, 2.0, seed=3)
    ev = np.zeros(t.size + 1, EVENT_DTYPE)
    ev["time"][:-1], ev["j"][:-1], ev["wall"][:-1] = t, 1, -1
    ev["time"][-1], ev["j"][-1], ev["partner"][-1], ev["wall"][-1], ev["i"][-1] = \
        9.3, -1, 1, 2, 17
    hazard = np.append(h, 100.0 * h.sum() / 8)
    stress = {"force_N": np.append(np.full(t.size, 3.0), 99.4)}
    inside = np.ones(ev.size, bool)
    names = ["left_side_wall", "right_side_wall", "lower_side_wall", "gate"]
    doc = _period_check(ev, hazard, inside, (0.0, 16.0), 2.0, names, stress)
    assert doc["dominated"] and doc["largest_window_s"] == [8.0, 10.0]
    assert doc["largest_event"]["with"] == "lower side wall"
    assert doc["largest_event"]["force_N"] == 99.4
    assert "t = 8–10 s" in doc["text"] and "cartridge 17 against lower side wall at 99.4 N" \
        in doc["text"]
    assert f"{doc['largest_share']:.0%}" in doc["text"]
    quiet = _period_check(ev[:-1], h, inside[:-1], (0.0, 16.0), 2.0, names,
                          {"force_N": stress["force_N"][:-1]})
    assert not quiet["dominated"] and "at most 31% of the periods" in quiet["text"]
    assert _period_check(ev, hazard, inside, (0.0, 16.0), None, names, stress) == \
        {"status": "no gate period"}
    assert _period_check(ev, hazard, inside, (0.0, 3.0), 2.0, names,
                         stress)["status"].startswith("not checked")
