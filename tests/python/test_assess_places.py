"""Where on the cartridge: the place weights of the sphere table's events
(:mod:`demfem.assess.places`), the expectation over places in the risk, and the job's outputs
by place (risk.json, events.parquet, the report, the console, cartridge_places.vtp)."""
from __future__ import annotations

import dataclasses
import json
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from demfem.assess.events import EVENT_DTYPE
from demfem.assess.places import (PLACE_WEIGHTS, PLACES, event_place_weights, load_place_weights,
                                  pair_place_weights, weights_from_full_shape)
from demfem.assess.risk_stage import (event_hazard, event_probabilities, hazard_components,
                                      surface_probability, equivalent_stress)
from demfem.errors import InvalidParameterError
from demfem.risk import INNER_SURFACE, OUTER_SURFACE, SCG_BOROSILICATE
from demfem.stress.model import LOCATIONS
from demfem.stress.stage import PLACE_FIELDS, collision_stresses

ROOT = Path(__file__).resolve().parents[2]


def test_the_shipped_weights_are_the_full_shape_tables_counts():
    doc = json.loads((ROOT / "docs" / "data" / "full_shape_table.json").read_text())
    made = weights_from_full_shape(doc)
    assert made["weights"] == PLACE_WEIGHTS["weights"]
    assert PLACES == LOCATIONS
    # pairs: each cartridge of a pair at its own place (docs/cartridge-places.md's counts)
    rev = doc["revolution"]["pair_place_pairs"]
    rim = 2 * rev["rim-rim"] + rev["body-rim"]
    total = 2 * sum(rev.values())
    assert PLACE_WEIGHTS["weights"]["cartridge"][1] == pytest.approx(rim / total, rel=1e-12)
    assert made["neck_or_flange_onsets"] == 0
    for row in PLACE_WEIGHTS["weights"].values():
        assert sum(row) == pytest.approx(1.0, abs=1e-12)


def test_bad_weights_files_and_counts_are_refused(tmp_path):
    bad = tmp_path / "w.json"
    bad.write_text(json.dumps({"places": list(PLACES), "weights": {"cartridge": [0.5, 0.6, 0],
                                                                  "wall": [1, 0, 0]}}))
    with pytest.raises(InvalidParameterError, match="cartridge"):
        load_place_weights(bad)
    bad.write_text(json.dumps({"places": ["rim", "body", "shoulder"], "weights": {}}))
    with pytest.raises(InvalidParameterError, match="places"):
        load_place_weights(bad)
    with pytest.raises(InvalidParameterError, match="pair of places"):
        weights_from_full_shape({"revolution": {"pair_place_pairs": {"rim-lid": 3},
                                                "place_by_partner": {}}})


def _events(partners, walls):
    ev = np.zeros(len(partners), EVENT_DTYPE)
    ev["partner"] = partners
    ev["wall"] = walls
    ev["j"] = np.where(np.asarray(partners) == 0, 1, -1)
    return ev


def test_event_weights_by_partner_and_wall_name():
    names = ["back", "lower_side", "upper_side", "tilted", "gate"]
    ev = _events([0, 1, 1, 1, 1], [-1, 1, 4, 0, 9])
    w = event_place_weights(ev, names)
    table = PLACE_WEIGHTS["weights"]
    assert np.array_equal(w[0], table["cartridge"])
    assert np.array_equal(w[1], table["lower_side"])
    assert np.array_equal(w[2], table["gate"])
    # a wall the full-shape table did not log (the back wall) and an unknown index: pooled
    assert np.array_equal(w[3], table["wall"]) and np.array_equal(w[4], table["wall"])
    assert np.array_equal(event_place_weights(ev, names, "rim"), np.tile([0, 1, 0], (5, 1)))
    assert pair_place_weights(3, "shoulder").tolist() == [[0, 0, 1]] * 3
    with pytest.raises(InvalidParameterError, match="place"):
        event_place_weights(ev, names, "neck")


def test_bad_place_weights_name_the_field():
    f = np.array([5.0, 20.0])
    kw = dict(measured_force=f, measured_impulse=f * 1e-4)
    z, code = np.zeros(2), np.zeros(2, np.int64)
    with pytest.raises(InvalidParameterError, match="place_weights"):
        collision_stresses(z, code, 45e9, place_weights=np.ones((2, 2)), **kw)
    with pytest.raises(InvalidParameterError, match="place_weights"):
        collision_stresses(z, code, 45e9, place_weights=np.full((2, 3), 0.5), **kw)
    with pytest.raises(InvalidParameterError, match="place_weights"):
        collision_stresses(z, code, 45e9, place_weights=np.array([[np.nan, 1, 0]] * 2), **kw)


def _stresses(place_weights=None):
    f = np.array([0.5, 5.0, 20.0, 45.0, 3.0, 12.0])
    code = np.array([0, 0, 0, 0, 1, 1])
    return collision_stresses(np.zeros(6), code, 45e9, measured_force=f,
                              measured_impulse=f * 5e-5,
                              measured_tangential=np.array([0, 0.5, 2, 9, 0.3, 1]),
                              friction=0.2, flaw_depth=29e-6, place_weights=place_weights)


def test_every_event_on_the_body_is_the_model_without_places_bitwise():
    plain = _stresses()
    body = _stresses(pair_place_weights(6, "body"))
    for k in plain:
        assert np.array_equal(plain[k], body[k]), k
    assert np.array_equal(body["sigma_outer_Pa_by_place"][:, 0], plain["sigma_outer_Pa"])
    p0, p1 = event_probabilities(plain), event_probabilities(body)
    for k in ("p_inner", "p_outer", "p_event"):
        assert np.array_equal(p0[k], p1[k]), k


def test_the_risk_is_the_expectation_over_places():
    ev = _events([0, 0, 0, 0, 1, 1], [-1] * 4 + [1, 4])
    w = event_place_weights(ev, ["back", "lower_side", "upper_side", "tilted", "gate"])
    st = _stresses(w)
    for k in PLACE_FIELDS:
        assert st[f"{k}_by_place"].shape == (6, 3)
    # point contacts (the pairs) differ by place; line contacts (walls) take the body's
    so = st["sigma_outer_Pa_by_place"]
    assert np.all(so[:4, 1] > so[:4, 0]) and np.all(st["sigma_inner_Pa_by_place"][:4, 2]
                                                      < st["sigma_inner_Pa_by_place"][:4, 0])
    assert np.array_equal(so[4:, 1], so[4:, 0])
    # the one-value fields are the worst place's (largest outer sigma1 among those possible)
    rows = np.arange(6)
    possible = np.where(w > 0, st["sigma_outer_Pa_by_place"], -np.inf)
    assert np.array_equal(st["place_index"], np.argmax(possible, axis=1))
    assert np.array_equal(st["sigma_outer_Pa"], st["sigma_outer_Pa_by_place"][rows,
                                                                               st["place_index"]])
    p = event_probabilities(st)
    # independently: P at each place from demfem.risk's surfaces, then weighted
    tau = st["duration_s"][:, None]
    pi = surface_probability(INNER_SURFACE, equivalent_stress(st["sigma_inner_Pa_by_place"],
                                                              tau, SCG_BOROSILICATE),
                             st["area_inner_m2_by_place"])
    po = surface_probability(OUTER_SURFACE, equivalent_stress(st["sigma_outer_Pa_by_place"],
                                                              tau, SCG_BOROSILICATE),
                             st["area_outer_m2_by_place"])
    expected = (w * -np.expm1(np.log1p(-pi) + np.log1p(-po))).sum(axis=1)  # 1-(1-pi)(1-po)
    assert np.allclose(p["p_event"], expected, rtol=1e-12, atol=0)
    assert np.allclose(p["p_event_by_place"].sum(axis=1), p["p_event"], rtol=1e-14, atol=0)
    # the hazard splits exactly, by place and surface
    parts = hazard_components(ev, p)
    assert set(parts) == {f"{pl} {s}" for pl in PLACES for s in ("outer", "inner")}
    total = sum(parts.values())
    assert np.allclose(total, event_hazard(ev, p["p_event"]), rtol=1e-12, atol=0)
    surf = hazard_components(ev, p, by_place=False)
    assert np.allclose(surf["outer"], sum(v for k, v in parts.items() if "outer" in k),
                       rtol=1e-12, atol=0)


# ---- the job ---------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def places_job(tmp_path_factory):
    import sys

    sys.path.insert(0, str(Path(__file__).parent))
    from test_assess import SMALL

    from demfem.assess import assess

    out = tmp_path_factory.mktemp("assess_places")
    lines: list[str] = []
    risk = assess(SMALL, out=out, duration=0.12, sample_interval=0.01, log=lines.append)
    return out, risk, lines


def test_the_job_reports_the_hazard_by_place_and_the_numbers_agree(places_job):
    import pandas as pd

    from demfem.assess.headline import place_line

    out, risk, lines = places_job
    s = risk["summary"]
    assert risk["settings"]["place"] == "mix"
    shares = s["place_share"]
    assert set(shares) == set(PLACES) and sum(shares.values()) == pytest.approx(1, abs=1e-12)
    both = s["place_surface_share"]
    for pl in PLACES:
        assert both[f"{pl} outer"] + both[f"{pl} inner"] == pytest.approx(shares[pl], rel=1e-12)
    # events.parquet: each place's term, summing to P_k; the shares from them are risk.json's
    ev = pd.read_parquet(out / "events.parquet")
    terms = ev[[f"p_event_{pl}" for pl in PLACES]].to_numpy()
    assert np.allclose(terms.sum(axis=1), ev["p_event"], rtol=1e-12, atol=0)
    inside = ev["in_window"].to_numpy(bool)
    loads = np.where(ev["j"].to_numpy() >= 0, 2.0, 1.0)
    h = -np.log1p(-ev["p_event"].to_numpy()) * loads
    frac = np.where(ev["p_event"].to_numpy()[:, None] > 0,
                    terms / np.where(ev["p_event"].to_numpy() > 0, ev["p_event"], 1)[:, None], 0)
    from_table = (h[:, None] * frac)[inside].sum(axis=0) / h[inside].sum()
    for j, pl in enumerate(PLACES):
        assert from_table[j] == pytest.approx(shares[pl], rel=1e-6)
    assert set(ev["place"]) <= set(PLACES)
    # one text for the console and the report
    line = place_line(s)
    assert line and any(line in x for x in lines)
    html = (out / "report.html").read_text()
    assert line.replace("'", "&#x27;") in html
    assert "by place on the cartridge" in html
    assert all("place" in r for r in risk["worst_events"])
    # ParaView: the likeliest events at each of their places on one cartridge
    piece = ET.parse(out / "cartridge_places.vtp").getroot().find("PolyData/Piece")
    n_points = int(piece.get("NumberOfPoints"))
    n_terms = int((ev.loc[inside, [f"weight_{pl}" for pl in PLACES]] > 0).to_numpy().sum())
    assert n_points == min(n_terms, n_points) and n_points > 0
    names = [a.get("Name") for a in piece.find("PointData")]
    assert {"p_event_place", "place", "weight", "event"} <= set(names)
    assert re.search(r"rim \(the open end", html)


def test_one_place_for_every_event_and_bad_place(tmp_path):
    import sys

    sys.path.insert(0, str(Path(__file__).parent))
    from test_assess import SMALL

    from demfem.assess import assess

    with pytest.raises(InvalidParameterError, match="place"):
        assess(SMALL, out=tmp_path / "bad", duration=0.1, place="neck")
    assert not (tmp_path / "bad" / "stages.json").exists()
    small = dataclasses.replace(SMALL)
    body = assess(small, out=tmp_path / "body", duration=0.12, sample_interval=0.01,
                  place="body", log=lambda _: None)
    assert body["summary"]["place_share"]["body"] == pytest.approx(1.0)
    assert body["summary"]["place_share"]["rim"] == 0.0
