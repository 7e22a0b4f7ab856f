"""The steady state of a running table: the rule that compares the collision rate over whole
gate periods, the table run that stops once it holds (and resumes to the same stop), the
assessment's rule and window, and the steadiness report of the risk stage."""
import numpy as np
import pytest

from demfem.assess.risk_stage import steady_state
from demfem.assess.run import steady_rule
from demfem.errors import InvalidParameterError
from demfem.scenes import AccumulationTable
from demfem.dem.table_run import run_table
from demfem.dem.steady import SteadyRule, period_rates, relative_error

TINY = dict(width=0.1, length=0.1, tilted_wall_length=0.08, opening_width=0.03,
            gate_amplitude=0.01, gate_period=0.2, belt_velocity=0.5, young_modulus=1e7,
            n_spheres=30, refeed=True)


def test_the_rule_counts_whole_periods_from_the_warmup_and_their_standard_error():
    rule = SteadyRule(period=2.0, min_periods=4, warmup=2.0, tolerance=0.10)
    # the default table's impacts per 2 s period over 2-20 s (re-fed, docs/assess.md)
    counts = [36108, 35276, 59122, 52449, 40333, 31574, 40900, 43278, 41456]
    t = np.concatenate([2.0 + 2.0 * k + np.linspace(0.0, 2.0, c, endpoint=False)
                        for k, c in enumerate(counts)])
    # two agreeing periods are no test: fewer than min_periods never stop the run
    assert not rule.due(6.0, 1e-6) and not rule.check(6.0, t)["steady"]
    assert rule.due(10.0, 1e-6) and not rule.due(10.5, 1e-6)
    errors = [rule.check(2.0 + 2.0 * n, t)["relative_error"] for n in range(3, 8)]
    np.testing.assert_allclose(errors, [0.1796, 0.1303, 0.1062, 0.1046, 0.0890], atol=1e-4)
    steady_at = [2.0 + 2.0 * n for n in range(4, 10) if rule.check(2.0 + 2.0 * n, t)["steady"]]
    assert steady_at[0] == 16.0
    c = rule.check(16.0, t)
    assert c["window_s"] == [2.0, 16.0] and c["counts"] == counts[:7]
    assert relative_error([5.0]) == float("inf") and relative_error([1.0, 1.0]) == 0.0
    assert list(period_rates([0.1, 0.2, 1.5], 0.0, 1.0, 2)) == [2.0, 1.0]
    for bad in (dict(period=0.0), dict(period=1.0, min_periods=1),
                dict(period=1.0, tolerance=-0.1), dict(period=1.0, warmup=float("nan"))):
        with pytest.raises(InvalidParameterError):
            SteadyRule(**bad)


def test_impacts_leave_out_the_belt_and_slow_onsets():
    rule = SteadyRule(period=1.0, min_speed=5e-3, excluded_walls=(0,))
    onsets = {"time": np.array([0.1, 0.2, 0.3, 0.4]), "partner": np.array([3, 0, 0, 5]),
              "partner_is_wall": np.array([False, True, False, True]),
              "normal_speed": np.array([0.1, 0.1, 0.1, 1e-3])}
    # the belt's contact (wall 0) and the slow gate touch are not impacts; sphere 0 is
    np.testing.assert_array_equal(rule.impacts(onsets), [0.1, 0.3])


def test_a_table_run_stops_once_steady_and_resumes_to_the_same_stop(tmp_path):
    loose = SteadyRule(period=0.2, min_periods=2, warmup=0.2, tolerance=10.0, min_speed=0.0)
    run = run_table(AccumulationTable(**TINY), 2.0, sample_interval=0.02, steady=loose)
    # the end of the second whole period past the warm-up: t = 0.6 s
    assert run.info["steady"]["steady"] and run.info["duration"] == pytest.approx(0.6)
    assert run.times[-1] == pytest.approx(0.6, abs=2 * run.info["dt"])
    strict = SteadyRule(period=0.2, min_periods=2, warmup=0.2, tolerance=1e-9, min_speed=0.0)
    never = run_table(AccumulationTable(**TINY), 0.8, sample_interval=0.02, steady=strict)
    assert never.info["duration"] == 0.8 and not never.info["steady"]["steady"]

    class Stop(Exception):
        pass

    def stop(sim_time, steps):
        if sim_time > 0.3:
            raise Stop

    ck = tmp_path / "run.ck"
    with pytest.raises(Stop):
        run_table(AccumulationTable(**TINY), 2.0, sample_interval=0.02, steady=loose,
                  checkpoint=ck, checkpoint_every=1e-9, progress=stop)
    resumed = run_table(AccumulationTable(**TINY), 2.0, sample_interval=0.02, steady=loose,
                        checkpoint=ck)
    assert resumed.info["duration"] == run.info["duration"]
    np.testing.assert_array_equal(resumed.positions, run.positions)
    # another rule is another run: its checkpoint is refused
    with pytest.raises(Stop):
        run_table(AccumulationTable(**TINY), 2.0, sample_interval=0.02, steady=loose,
                  checkpoint=ck, checkpoint_every=1e-9, progress=stop)
    from demfem.errors import SettingsMismatchError
    with pytest.raises(SettingsMismatchError, match="steady"):
        run_table(AccumulationTable(**TINY), 2.0, sample_interval=0.02, steady=strict,
                  checkpoint=ck)


def test_the_assessment_rule_follows_the_gate_and_leaves_out_the_belt():
    table = AccumulationTable()
    rule = steady_rule(table)
    assert rule.period == 2.0 and rule.min_periods == 4 and rule.tolerance == 0.10
    assert rule.excluded_walls == (0,)  # the belt is the first wall of the default table
    full = steady_rule(table, full=True)
    assert full.min_periods == 8 and full.tolerance == 0.05
    import dataclasses
    still = steady_rule(dataclasses.replace(table, gate_amplitude=0.0))
    assert still.period == 1.0


def test_the_risk_stage_reports_per_period_steadiness():
    ev = np.zeros(1000, dtype=[("time", "f8"), ("i", "i8"), ("j", "i8")])
    ev["time"] = np.r_[np.linspace(2.0, 3.99, 400), np.linspace(4.0, 5.99, 300),
                       np.linspace(6.0, 7.99, 300)]
    ev["j"] = -1
    p = np.full(1000, 1e-9)
    st = steady_state(ev, p, (2.0, 8.0), period=2.0, tolerance=0.11)
    assert st["criterion"] == "periods" and st["period_events"] == [400, 300, 300]
    # s = 57.7, mean 333.3: s / (sqrt(3) mean) = 0.1
    assert st["relative_error"] == pytest.approx(0.1, rel=1e-6) and st["steady"]
    assert st["hazard_relative_error"] == pytest.approx(0.1, rel=1e-6)
    assert not steady_state(ev, p, (2.0, 8.0), period=2.0, tolerance=0.09)["steady"]
    # a window shorter than two periods: the halves' Poisson test
    assert steady_state(ev, p, (2.0, 3.0), period=2.0)["criterion"] == "poisson_z"
