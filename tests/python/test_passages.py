"""Passages (a cartridge from insertion to exit) as the unit of risk: the bookkeeping of a
re-fed table, checked on hand-made logs whose answers are known."""
import math

import numpy as np
import pytest

from demfem.assess.events import EVENT_DTYPE
from demfem.assess.passages import passage_of_events, passages, table_flow
from demfem.assess.risk_stage import passage_risk
from demfem.errors import InvalidParameterError


def _log():
    # 3 spheres on the table at 0; sphere 0 leaves at 1.0 s and is put back at 1.5 s, leaves
    # again at 3.0 s and is put back at 3.2 s; sphere 2 leaves at 2.5 s and stays off
    return passages(3, [1.0, 2.5, 3.0], [0, 2, 0], [1.5, 3.2], [0, 0], end_time=4.0)


def test_a_refed_id_carries_one_passage_per_stay():
    t = _log()
    assert t["particle"].tolist() == [0, 0, 0, 1, 2]
    assert t["start"].tolist() == [0.0, 1.5, 3.2, 0.0, 0.0]
    assert np.isnan(t["end"][2]) and np.isnan(t["end"][3])
    assert t["end"][[0, 1, 4]].tolist() == [1.0, 3.0, 2.5]
    assert t["exited"].tolist() == [True, True, False, False, True]


def test_events_go_to_the_passage_on_the_table_then():
    t = _log()
    k = passage_of_events(t, np.array([0, 0, 0, 0, 2, 2, -1, 1]),
                          np.array([0.5, 1.2, 2.0, 3.5, 2.4, 2.6, 1.0, 3.9]))
    # 1.2 s: sphere 0 was off the table (between its exit and its re-insertion)
    assert k.tolist() == [0, -1, 1, 2, 4, -1, -1, 3]


def test_flow_little_law_and_discharge():
    t = _log()
    f = table_flow(t, (1.0, 4.0))
    # exposures in [1, 4]: p0 0, p1 1.5, p2 0.8, p3 3, p4 1.5
    assert f["exposure_s"].tolist() == pytest.approx([0.0, 1.5, 0.8, 3.0, 1.5])
    assert f["mean_on_table"] == pytest.approx(6.8 / 3.0)
    assert f["exits"] == 3  # 1.0 (at the window's edge), 2.5, 3.0
    assert f["discharge_per_hour"] == pytest.approx(3600.0)
    assert f["residence_time_s"] == pytest.approx((6.8 / 3.0) / 1.0)
    assert f["passages_in_window"] == 4


def test_the_hourly_figures_agree():
    t = _log()
    ev = np.zeros(4, EVENT_DTYPE)
    ev["i"] = [0, 0, 1, 2]
    ev["j"] = [1, -1, 2, -1]
    ev["time"] = [1.7, 3.5, 2.0, 2.2]
    p = np.array([1e-7, 2e-7, 3e-8, 5e-7])
    r = passage_risk(ev, p, t, (1.0, 4.0))
    w = 3.0
    # passage 1 (sphere 0, 1.5-3.0): event 0; passage 2: event 1; passage 3 (sphere 1): events
    # 0 and 2; passage 4 (sphere 2): events 2 and 3
    expect = [0.0, 1e-7, 2e-7, 1e-7 + 3e-8 - 1e-7 * 3e-8, 3e-8 + 5e-7 - 3e-8 * 5e-7]
    assert r["p_window"].tolist() == pytest.approx(expect, rel=1e-12, abs=1e-30)
    assert r["broken_per_hour_table"] == pytest.approx(3600 * sum(expect) / w, rel=1e-12)
    assert r["broken_per_hour_small_p"] == pytest.approx(r["broken_per_hour_table"], rel=1e-6)
    assert r["p_passage"] == pytest.approx(r["broken_per_hour_table"] / 3600.0, rel=1e-12)
    assert r["unassigned_events"] == 0 and r["throughput_source"] == "table"
    # a user's throughput: both figures, the headline at the user's
    u = passage_risk(ev, p, t, (1.0, 4.0), throughput_per_hour=7200.0)
    assert u["broken_per_hour_table"] == r["broken_per_hour_table"]
    assert u["broken_per_hour"] == pytest.approx(2 * r["broken_per_hour_table"], rel=1e-12)
    assert u["throughput_source"] == "user"


@pytest.mark.parametrize("args, match", [
    ((3, [1.0], [5]), "sphere ids"),
    ((3, [1.0, 2.0], [0, 0]), "while off the table"),
    ((3, [1.0], [0], [0.5], [0]), "while on the"),
    ((3, [math.nan], [0]), "finite"),
    ((3, [1.0], [0.5]), "integers"),
])
def test_inconsistent_logs_are_refused(args, match):
    with pytest.raises(InvalidParameterError, match=match):
        passages(*args)


def test_surface_probability_refuses_nan_stress_and_negative_area():
    from demfem.assess.risk_stage import surface_probability
    from demfem.risk import OUTER_SURFACE

    with pytest.raises(InvalidParameterError, match="stress"):
        surface_probability(OUTER_SURFACE, np.array([1e6, np.nan]), np.array([1e-6, 1e-6]))
    with pytest.raises(InvalidParameterError, match="area"):
        surface_probability(OUTER_SURFACE, np.array([1e6]), np.array([-1e-6]))
    p = surface_probability(OUTER_SURFACE, np.array([0.0, 70e6]), np.array([1e-6, 1e-4]))
    assert p[0] == 0.0 and p[1] == pytest.approx(1 - math.exp(-1.0), rel=1e-12)
