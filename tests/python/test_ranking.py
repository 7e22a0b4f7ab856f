"""demfem.assess.ranking: set-ups ranked by broken_per_hour over paired replicas, each with its
interval and whether its difference to the best is real (Holm-corrected paired tests),
checked on synthetic heavy-tailed replicas with a known real and a known null difference;
the sweep wiring (issue 41).

``python tests/python/test_ranking.py [N_SWEEPS]`` prints the error and power table quoted
in demfem/assess/ranking.py and docs/replicas.md (default 400 sweeps per cell)."""
from __future__ import annotations

import json
import sys

import numpy as np
import pytest

from demfem.assess.ranking import (TESTS, holm, paired_test, rank_setups, ranked_sweep)
from demfem.assess.replica_stats import simulate_replicas
from demfem.errors import InvalidParameterError



def synthetic(rng, factors, replicas, periods=7, background=0.05):
    """Set-ups whose true hourly numbers are in the ratios ``factors``: each replica the
    heavy-tailed per-period hazards of :func:`simulate_replicas` (a period's CV about 2,
    as on the default table) plus a small steady background (the soft impacts)."""
    out = {}
    for k, f in enumerate(factors):
        hz, _ = simulate_replicas(rng, replicas, periods)
        out[f"s{k}"] = [{"seed": s, "expected_broken": f * (hz[s].sum() + background),
                         "hours": float(periods)} for s in range(replicas)]
    return out


def error_and_power(replicas, n_sweeps, factor=3.0, method=None, seed=0):
    """(family-wise error with three equal set-ups, power to flag a set-up ``factor`` times
    worse against both others, rate of a false flag between the two equal ones then)."""
    rng = np.random.default_rng(seed)
    fwer = power = false = 0
    for _ in range(n_sweeps):
        fwer += any(p["significant"] for p in
                    rank_setups(synthetic(rng, [1, 1, 1], replicas), method=method).pairs)
        sig = {frozenset((p["a"], p["b"])): p["significant"] for p in
               rank_setups(synthetic(rng, [1, 1, factor], replicas), method=method).pairs}
        power += sig[frozenset(("s0", "s2"))] and sig[frozenset(("s1", "s2"))]
        false += sig[frozenset(("s0", "s1"))]
    return fwer / n_sweeps, power / n_sweeps, false / n_sweeps


def test_holm():
    adj = holm([0.01, 0.04, 0.03, 0.5])
    assert np.allclose(adj, [0.04, 0.09, 0.09, 0.5])
    with pytest.raises(InvalidParameterError):
        holm([0.2, 1.5])


def test_paired_test_basics():
    y = np.array([1.0, 2.0, 0.5, 3.0, 1.2, 0.8])
    h = np.ones(6)
    same = paired_test(y, h, y, h)
    assert same["method"] == "log-t" and same["p_value"] == 1.0 and same["ratio"] == 1.0
    far = paired_test(10 * y * np.linspace(0.9, 1.1, 6), h, y, h)
    assert far["p_value"] < 1e-4 and far["ratio_lower"] < far["ratio"] < far["ratio_upper"]
    # sign flips: 6 pairs all one way is the most extreme of 2^6 swaps (two-sided: 2/64)
    sf = paired_test(y + 10.0, h, y, h, method="sign-flip")
    assert sf["p_value"] == pytest.approx(2 / 64) and sf["smallest_p"] == pytest.approx(2 / 64)
    # a set-up without any hazard has no log rate: sign flips
    assert paired_test(np.zeros(6), h, y, h)["method"] == "sign-flip"
    with pytest.raises(InvalidParameterError):
        paired_test(y, h, y, h, method="wilcoxon")
    with pytest.raises(InvalidParameterError):
        paired_test(y[:1], h[:1], y[:1], h[:1])


@pytest.mark.parametrize("method", TESTS)
def test_a_single_comparison_flags_real_and_not_null_differences(method):
    """Two set-ups, 10 paired replicas: a null difference flagged at most at the stated 5 %
    (within the simulation's noise), a real 3× difference flagged most of the time."""
    rng = np.random.default_rng(11)
    n = 300
    null = sum(paired_test(*_arrays(synthetic(rng, [1, 1], 10)), method=method)["p_value"]
               < 0.05 for _ in range(n)) / n
    real = sum(paired_test(*_arrays(synthetic(rng, [1, 3], 10)), method=method)["p_value"]
               < 0.05 for _ in range(n)) / n
    assert null <= 0.05 + 3 * np.sqrt(0.05 * 0.95 / n), null
    assert real >= 0.7, real


def _arrays(setups):
    a, b = setups["s0"], setups["s1"]
    return ([r["expected_broken"] for r in a], [r["hours"] for r in a],
            [r["expected_broken"] for r in b], [r["hours"] for r in b])


def test_the_ranking_controls_the_family_wise_error_and_finds_the_worse_setup():
    fwer, power, false = error_and_power(10, 250, seed=5)
    bound = 0.05 + 3 * np.sqrt(0.05 * 0.95 / 250)
    assert fwer <= bound and false <= bound, (fwer, false)
    assert power >= 0.55, power


def test_rank_setups_rows(tmp_path):
    rng = np.random.default_rng(2)
    rk = rank_setups(synthetic(rng, [1.0, 30.0, 1.1], 8),
                     params={"s0": {"v": 0.1}, "s1": {"v": 0.2}, "s2": {"v": 0.3}})
    rows = rk.rows
    assert rows[-1]["label"] == "s1" and rows[-1]["significant"] is True
    assert rows[0]["significant"] is None and rows[0]["ratio_to_best"] == 1.0
    assert len(rk.pairs) == 3 and all(0 <= p["p_holm"] <= 1 for p in rk.pairs)
    lo, hi = rows[0]["interval"]["lower"], rows[0]["interval"]["upper"]
    assert lo < rows[0]["estimate"] < hi
    text = rk.text()
    assert "REAL difference" in text and "s1" in text
    json.dumps(rk.to_dict(), allow_nan=False)
    with pytest.raises(InvalidParameterError, match="at least 2"):
        rank_setups({"only": [{"seed": 0, "broken_per_hour": 1.0}]})


def _paired_runner(params):
    """A sweep runner of known numbers: set-up 'b' breaks 20× as often, the replicas differ
    by their seed (common to every set-up)."""
    s = params["seed"]
    base = 1.0 + 0.3 * np.sin(7.0 * s)
    f = {"a": 1.0, "b": 20.0, "c": 1.05}[params["setup"]]
    return {"broken_per_hour": f * base, "expected_broken": f * base * 0.5, "hours": 0.5}


def test_ranked_sweep_pairs_replicas_by_seed(tmp_path):
    rk = ranked_sweep({"setup": ["a", "b", "c"]}, _paired_runner, tmp_path, 6,
                      scheduler="serial")
    assert [r["label"] for r in rk.rows] == ["setup=a", "setup=c", "setup=b"]
    assert all(r["n_replicas"] == 6 and r["seeds"] == list(range(6)) for r in rk.rows)
    assert rk.rows[2]["significant"] is True
    doc = json.loads((tmp_path / "ranking.json").read_text())
    assert doc["rows"][0]["params"] == {"setup": "a"}
    # finished points are reused; 'seed' belongs to --replicas
    again = ranked_sweep({"setup": ["a", "b", "c"]}, _paired_runner, tmp_path, 6,
                         scheduler="serial")
    assert again.rows == rk.rows
    with pytest.raises(InvalidParameterError, match="seed"):
        ranked_sweep({"seed": [1, 2]}, _paired_runner, tmp_path, 2, scheduler="serial")
    with pytest.raises(InvalidParameterError, match="replicas"):
        ranked_sweep({"setup": ["a"]}, _paired_runner, tmp_path, 0, scheduler="serial")


def test_ranked_sweep_of_risk_points_on_a_tiny_table(tmp_path):
    """The risk runner through the sweep: 2 belt speeds × 2 paired replicas of a tiny table,
    every point's assessment kept (resumable) under out/points."""
    grid = {"belt_velocity": [0.1, 0.3], "width": [0.1], "length": [0.1],
            "tilted_wall_length": [0.05], "n_spheres": [30], "duration": [0.05]}
    rk = ranked_sweep(grid, "demfem.assess.sweep_runner:risk_point", tmp_path, 2,
                      scheduler="serial")
    assert len(rk.rows) == 2 and all(r["n_replicas"] == 2 for r in rk.rows)
    assert len(list((tmp_path / "points").glob("*/risk.json"))) == 4
    assert any("fewer than 5 replicas" in n for n in rk.notes)


if __name__ == "__main__":  # the table of docs/replicas.md
    sweeps = int(sys.argv[1]) if len(sys.argv) > 1 else 400
    print("replicas  test       FWER(3 equal)  power(3x vs both)  false flag among equal")
    for r in (4, 6, 8, 10, 16):
        for m in TESTS:
            e, p, f = error_and_power(r, sweeps, method=m, seed=r)
            print(f"{r:8d}  {m:9s}  {e:13.3f}  {p:17.3f}  {f:10.3f}", flush=True)
