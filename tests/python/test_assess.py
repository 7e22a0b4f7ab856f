"""`demfem assess`: stress model, impact law, risk, resumable stages, report and CLI.

Closed forms checked: the Hertz–Reissner duration reduces to the Hertz duration without a
shell; the shell's membrane force under a point load tends to −P R/(16 ℓ²); the per-event
Weibull and slow-crack-growth formulas equal demfem.risk's functions.
"""
import csv
import dataclasses
import json
import math
import os
import re

import numpy as np
import pytest

from demfem.assess import STAGES, StressModel, assess, closed_form_model
from demfem.stress.shell import (closed_form_coefficients, patch_centre_coefficients,
                                       point_load_surface_stresses)
from demfem.assess.events import EVENT_DTYPE
from demfem.assess.figures import FIGURES
from demfem.assess.impact import ImpactLaw, cartridge_body, flat_partner, impact_duration
from demfem.assess.passages import passages
from demfem.assess.risk_stage import (equivalent_stress, event_probabilities, passage_risk,
                                      surface_probability)
from demfem.stress.stage import collision_stresses
from demfem.cli import main
from demfem.contact import ContactBody, hertz_contact_duration, max_contact_force
from demfem.errors import InvalidParameterError, SettingsMismatchError
from demfem.risk import INNER_SURFACE, OUTER_SURFACE, SCG_BOROSILICATE
from demfem.scenes.table import AccumulationTable

SMALL = AccumulationTable(width=0.1, length=0.1, tilted_wall_length=0.05, n_spheres=30)


# ---- stress model ----------------------------------------------------------------------------

def test_sigma_scales_linearly_with_force():
    m = StressModel.default()
    f = np.array([0.5, 1.0, 2.0, 40.0])
    assert np.allclose(m.sigma_inner(2 * f), 2 * m.sigma_inner(f), rtol=1e-14)
    assert np.allclose(m.sigma_inner(f), m.beta_inner * f / m.thickness**2, rtol=1e-14)
    assert np.allclose(m.sigma_outer(f), m.beta_outer * f / m.thickness**2, rtol=1e-14)
    # inner in tension, outer nearly unloaded: the paper's Fig. 13 sign pattern
    assert m.beta_inner > 1.0 and abs(m.beta_outer) < 0.1 * m.beta_inner


def test_fit_recovers_the_coefficients():
    rng = np.random.default_rng(3)
    t = 1.1e-3
    f = rng.uniform(1.0, 80.0, 40)
    exact = StressModel.fit(f, 1.37 * f / t**2, -0.21 * f / t**2, thickness=t)
    assert exact.beta_inner == pytest.approx(1.37, rel=1e-12)
    assert exact.beta_outer == pytest.approx(-0.21, rel=1e-12)
    noisy = StressModel.fit(f, 1.37 * f / t**2 * (1 + 0.02 * rng.standard_normal(40)),
                            0.3 * f / t**2 * (1 + 0.02 * rng.standard_normal(40)))
    assert noisy.beta_inner == pytest.approx(1.37, rel=0.02)
    assert noisy.beta_outer == pytest.approx(0.3, rel=0.02)
    assert noisy.residuals(f, 1.37 * f / t**2, 0.3 * f / t**2)["rms_inner_relative"] < 0.02
    with pytest.raises(InvalidParameterError, match="forces"):
        StressModel.fit([], [], [])


def test_save_load_round_trip_and_the_shipped_default(tmp_path):
    m = StressModel.fit([1.0, 2.0], [1e6, 2e6], [0.0, 0.0], source="synthetic")
    p = m.save(tmp_path / "model.json")
    back = StressModel.load(p)
    assert back == m
    json.loads(p.read_text())  # strict JSON
    default = StressModel.default()
    assert "Reissner" in default.source
    # the shipped file is what closed_form_model computes
    again = closed_form_model()
    for name in ("beta_inner", "beta_outer", "area_factor_inner", "area_factor_outer"):
        assert getattr(default, name) == pytest.approx(getattr(again, name), rel=1e-9)
    (tmp_path / "bad.json").write_text('{"beta_inner": 1}')
    with pytest.raises(InvalidParameterError, match="missing keys"):
        StressModel.load(tmp_path / "bad.json")


def test_closed_form_shell_solution():
    nu = 0.22
    field = point_load_surface_stresses(np.array([1e-3]), nu)
    # membrane part at the load: N = -P R/(16 l^2) -> sigma t^2/P = -sqrt(12(1-nu^2))/16
    membrane = 0.5 * (field["inner_r"] + field["outer_r"])
    assert membrane[0] == pytest.approx(-math.sqrt(12 * (1 - nu**2)) / 16, rel=1e-3)
    inner, outer = patch_centre_coefficients(10.0, nu)
    assert inner > 0 > outer  # inner tension, outer compression under the load
    # the beta grows as the contact patch shrinks (log singularity of the point load)
    small = closed_form_coefficients(1.1e-3, 5.25e-3, nu, 3e-5)
    large = closed_form_coefficients(1.1e-3, 5.25e-3, nu, 1.5e-4)
    assert small.beta_inner > large.beta_inner
    assert small.beta_inner - large.beta_inner == pytest.approx(
        3 * (1 + nu) / (2 * math.pi) * math.log(5.0), rel=1e-9)


# ---- impact law and stresses -----------------------------------------------------------------

def test_impact_duration_reduces_to_hertz_and_table_interpolates():
    body = cartridge_body(45e9)
    solid = ContactBody(body.mass, body.radius, body.E, body.nu)
    assert impact_duration(solid, solid, 0.05) == pytest.approx(
        hertz_contact_duration(solid, solid, 0.05), rel=1e-8)
    law = ImpactLaw(body, body)
    v = np.array([3e-3, 0.0123, 0.071, 0.4])
    direct = [max_contact_force(body, body, x, "hertz_reissner") for x in v]
    assert np.allclose(law.force(v), direct, rtol=1e-5)
    assert np.allclose(law.duration(v), [impact_duration(body, body, x) for x in v], rtol=1e-5)
    wall = ImpactLaw(body, flat_partner(45e9, body.nu))
    assert wall.force(np.array([0.05]))[0] > law.force(np.array([0.05]))[0]  # m* doubles


def test_collision_stresses_use_the_calibrated_law():
    m = StressModel.default()
    s = collision_stresses(np.array([0.01, 0.05]), np.array([0, 1]), 45e9, model=m)
    body = cartridge_body(45e9)
    assert s["force_N"][0] == pytest.approx(max_contact_force(body, body, 0.01), rel=1e-5)
    assert s["force_N"][1] == pytest.approx(
        max_contact_force(body, flat_partner(45e9, body.nu), 0.05), rel=1e-5)
    assert np.allclose(s["sigma_inner_Pa"], m.sigma_inner(s["force_N"]))
    assert np.all(s["area_inner_m2"] > 0) and np.all(s["duration_s"] > 0)


# ---- risk ------------------------------------------------------------------------------------

def _synthetic_events(speeds, times=None):
    ev = np.zeros(len(speeds), EVENT_DTYPE)
    ev["i"] = np.arange(len(speeds)) % 4
    ev["j"] = (np.arange(len(speeds)) + 1) % 4
    ev["normal_speed"] = speeds
    ev["time"] = np.linspace(0.5, 1.0, len(speeds)) if times is None else times
    return ev


def _risk(speeds):
    ev = _synthetic_events(speeds)
    st = collision_stresses(ev["normal_speed"], ev["partner"], 45e9, model=StressModel.default())
    p = event_probabilities(st)
    return ev, st, p, passage_risk(ev, p["p_event"], passages(4, [], []), (0.5, 1.0), 6000)


def test_risk_rises_with_impact_speed():
    v = np.array([0.01, 0.02, 0.05, 0.1, 0.3])
    _, _, p1, c1 = _risk(v)
    _, _, p2, c2 = _risk(2 * v)
    assert np.all(np.diff(p1["p_event"]) > 0)
    assert np.all(p2["p_event"] > p1["p_event"])
    assert c2["broken_per_hour"] > c1["broken_per_hour"] > 0
    # small P: the hourly number is 3600 x the summed hazard rate of the population
    assert c1["broken_per_hour"] == pytest.approx(c1["broken_per_hour_small_p"], rel=1e-6)
    # no cartridge left in the window: P per passage at the throughput given
    assert c1["exits"] == 0 and c1["throughput_source"] == "user"
    assert c1["p_passage"] == pytest.approx(c1["broken_per_hour_table"] / 6000, rel=1e-12)
    assert c1["broken_per_hour"] == pytest.approx(c1["broken_per_hour_table"], rel=1e-12)
    assert c1["mean_on_table"] == pytest.approx(4.0)


def test_per_event_probabilities_match_demfem_risk():
    ev, st, p, _ = _risk(np.array([0.02, 0.2, 0.5]))
    for k in range(3):
        s_in = SCG_BOROSILICATE.half_sine(st["sigma_inner_Pa"][k], st["duration_s"][k])
        assert p["sigma_eq_inner_Pa"][k] == pytest.approx(s_in, rel=1e-12)
        assert p["p_inner"][k] == pytest.approx(INNER_SURFACE.failure_probability(
            [s_in], [st["area_inner_m2"][k]]), rel=1e-9)
        s_out = SCG_BOROSILICATE.half_sine(st["sigma_outer_Pa"][k], st["duration_s"][k])
        assert p["p_outer"][k] == pytest.approx(OUTER_SURFACE.failure_probability(
            [s_out], [st["area_outer_m2"][k]]), rel=1e-9)
    assert np.all(equivalent_stress(np.array([1e6]), np.array([1e-4]), None) == 1e6)
    assert surface_probability(INNER_SURFACE, np.array([-1e6, 0.0]), np.array([1e-6, 1e-6])
                               ).tolist() == [0.0, 0.0]


def test_wall_and_gate_impacts_are_events_and_the_belt_is_not():
    """Sphere-wall onsets become wall events (partner 1, j = -1, the wall's index, the
    contact point), filtered by the same minimum speed; onsets on the belt (a cartridge
    standing on its base) are counted but are not events."""
    from types import SimpleNamespace

    from demfem.analysis.collisions import ONSET_DTYPE, WALL_ONSET_DTYPE
    from demfem.assess.events import impact_events

    w = np.zeros(4, WALL_ONSET_DTYPE)
    w["i"], w["wall"], w["time"] = [3, 4, 5, 6], [0, 5, 4, 5], [0.1, 0.2, 0.3, 0.4]
    w["normal_speed"] = [0.5, 0.08, 0.001, 0.02]
    w["x"], w["y"] = [0.1, 0.2, 0.3, 0.4], [0.01, 0.02, 0.03, 0.04]
    run = SimpleNamespace(onsets=np.zeros(0, ONSET_DTYPE), wall_onsets=w,
                          info={"wall_names": ["belt", "back", "lower_side", "upper_side",
                                               "tilted", "gate"]})
    ev, summary = impact_events(run, min_speed=5e-3)
    assert list(ev["i"]) == [4, 6] and set(ev["j"]) == {-1} and set(ev["partner"]) == {1}
    assert list(ev["wall"]) == [5, 5] and list(ev["x"]) == [0.2, 0.4]
    assert summary["n_wall_events"] == 2 and summary["wall_events"]["gate"] == 2
    assert summary["n_belt_contacts"] == 1 and summary["n_dropped"] == 1
    assert summary["n_onsets"] == 4


# ---- the job ---------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def small_job(tmp_path_factory):
    out = tmp_path_factory.mktemp("assess_full")
    lines = []
    risk = assess(SMALL, out=out, duration=0.12, sample_interval=0.01, log=lines.append,
                  csv=True)
    return out, risk, lines


def test_interrupted_assess_resumes_to_the_same_numbers(small_job, tmp_path):
    full_out, full, _ = small_job
    lines = []
    stopped = assess(SMALL, out=tmp_path, duration=0.12, sample_interval=0.01,
                     log=lines.append, stop_after="dem", csv=True)
    assert stopped == {"stopped_after": "dem"}
    book = json.loads((tmp_path / "stages.json").read_text())
    assert set(book["completed"]) == {"calibration", "dem"}
    lines = []
    resumed = assess(SMALL, out=tmp_path, duration=0.12, sample_interval=0.01,
                     log=lines.append, csv=True)
    text = "\n".join(lines)
    assert "1/6 calibration" in text and text.count("(done before: reused)") == 2
    assert json.loads((tmp_path / "risk.json").read_text())["summary"] == \
        json.loads((full_out / "risk.json").read_text())["summary"]
    assert resumed["summary"] == full["summary"]
    assert (tmp_path / "events.csv").read_text() == (full_out / "events.csv").read_text()
    # a rerun skips every stage
    lines = []
    assess(SMALL, out=tmp_path, duration=0.12, sample_interval=0.01, log=lines.append,
           csv=True)
    assert "\n".join(lines).count("(done before: reused)") == len(STAGES)
    # other settings: refused, naming the difference; --fresh replaces
    with pytest.raises(SettingsMismatchError, match="throughput_per_hour"):
        assess(SMALL, out=tmp_path, duration=0.12, sample_interval=0.01, throughput=100.0,
               log=lines.append, csv=True)
    other = assess(SMALL, out=tmp_path, duration=0.12, sample_interval=0.01, throughput=100.0,
                   fresh=True, log=lambda _: None, csv=True)
    assert other["summary"]["throughput_per_hour"] == 100.0


#: The files a finished job removes: the stages' intermediates.
INTERMEDIATES = {"table_run_full.npz", "events.npz", "stress.npz"}


def _job(out, log, **kwargs):
    """The small job of ``small_job`` into ``out``."""
    return assess(SMALL, out=out, duration=0.12, sample_interval=0.01, log=log, csv=True,
                  **kwargs)


def _lines(lines, out):
    """Console lines as a rerun in another folder prints them: without the reuse marks, the
    folder named as OUT and the DEM's wall time left out."""
    return [re.sub(r", wall [0-9.]+ s$", "", line.replace(" (done before: reused)", "")
                   .replace(str(out), "OUT")) for line in lines]


def _digests(out):
    from demfem.jobs import sha256_file

    return {p.name: sha256_file(p) for p in out.iterdir() if p.name != ".demfem.lock"}


def test_a_finished_folder_keeps_its_products_only_and_a_rerun_reuses_them(small_job):
    """The intermediates (the whole DEM record, events.npz, stress.npz) are gone once the job
    has finished; stages.json says so and holds the digests the console lines need. The same
    command again reuses every stage, changes no file, prints the same lines and returns the
    same document; the kept DEM record holds its samples in single precision and refuses to
    give events again; load_assessment reads the folder."""
    from demfem.analysis.contact_events import CONTACT_EVENT_DTYPE
    from demfem.assess.events import impact_events
    from demfem.assess.tables import load_assessment
    from demfem.dem.table_run import TableRun

    out, risk, lines = small_job
    names = {p.name for p in out.iterdir()}
    assert not names & INTERMEDIATES
    assert {"calibration.json", "table_run.npz", "risk.json", "events.parquet",
            "passages.parquet", "events.csv", "passages.csv", "events.vtp", "cartridges.vtp",
            "risk_arrays.npz", "report.html", "stages.json", *FIGURES} <= names
    book = json.loads((out / "stages.json").read_text())
    assert book["finished"] is True
    assert book["dropped"] == {"dem": ["table_run_full.npz"], "events": ["events.npz"],
                               "stress": ["stress.npz"]}
    assert set(book["digests"]) == {"events", "stress"}
    assert book["digests"]["events"] == risk["events"]  # the counts risk.json states
    assert not set(book["files"]) & INTERMEDIATES
    before = _digests(out)
    again = []
    assert _job(out, again.append) == risk
    assert "\n".join(again).count("(done before: reused)") == len(STAGES)
    assert [line.replace(" (done before: reused)", "") for line in again] == lines
    assert _digests(out) == before  # nothing written, nothing removed
    run = TableRun.load(out / "table_run.npz")
    assert run.positions.dtype == np.float32 and run.velocities.dtype == np.float32
    assert run.times.dtype == np.float64 and run.info["events_recorded"]
    assert run.contact_events.dtype == CONTACT_EVENT_DTYPE and len(run.contact_events) == 0
    with pytest.raises(InvalidParameterError, match="events.parquet"):
        impact_events(run)
    a = load_assessment(out)
    assert len(a.events) == risk["events"]["n_events"] and a.summary == risk["summary"]
    assert a.events["p_event"].dtype == np.float64 and a.events["x_m"].dtype == np.float32
    with np.load(out / "risk_arrays.npz") as arrays:
        assert "p_event" not in arrays.files and "map_hazard" in arrays.files


@pytest.mark.parametrize("stop", ["events", "stress"])
def test_a_job_stopped_after_its_events_or_stresses_resumes_to_the_same_numbers(
        small_job, tmp_path, stop):
    """Stopped after the events (or the stresses), the folder keeps every intermediate so far
    and is not finished; resumed, it ends with the uninterrupted job's numbers, tables and
    console lines, and keeps only the products. A cluster load case taken from the folder
    is the same from its events.npz (unfinished) and its events.parquet (finished, speeds in
    single precision)."""
    from demfem.scenes.cluster import cluster_from_run

    full_out, full, full_lines = small_job
    out = tmp_path / "job"
    lines = []
    assert _job(out, lines.append, stop_after=stop) == {"stopped_after": stop}
    names = {p.name for p in out.iterdir()}
    assert {"table_run.npz", "table_run_full.npz", "events.npz"} <= names
    assert ("stress.npz" in names) == (stop == "stress") and "risk.json" not in names
    book = json.loads((out / "stages.json").read_text())
    assert "finished" not in book and set(book["completed"]) == set(
        STAGES[:STAGES.index(stop) + 1])
    from_npz = cluster_from_run(out)
    lines = []
    resumed = _job(out, lines.append)
    assert "\n".join(lines).count("(done before: reused)") == STAGES.index(stop) + 1
    assert resumed == full
    assert _lines(lines, out) == _lines(full_lines, full_out)
    assert not {p.name for p in out.iterdir()} & INTERMEDIATES
    assert (out / "events.csv").read_text() == (full_out / "events.csv").read_text()
    import pyarrow.parquet as pq

    for name in ("events.parquet", "passages.parquet"):
        assert pq.read_table(out / name).to_pandas().equals(
            pq.read_table(full_out / name).to_pandas()), name
    from_parquet = cluster_from_run(out)
    for k in ("v2", "v3", "direction_2_deg", "direction_3_deg"):
        assert getattr(from_parquet, k) == pytest.approx(getattr(from_npz, k), rel=1e-6), k


def test_a_finished_folder_with_a_damaged_product_is_redone_from_the_dem(small_job, tmp_path):
    """A finished folder cannot rerun a later stage alone (the intermediates are gone): a
    damaged product makes the job redo it from the DEM, to the same numbers."""
    import shutil

    full_out, full, _ = small_job
    out = tmp_path / "job"
    shutil.copytree(full_out, out)
    (out / "events.parquet").write_bytes(b"damaged")
    lines = []
    assert _job(out, lines.append) == full
    text = "\n".join(lines)
    assert "1/6 calibration: equivalent body, contact law and stress model (done before" in text
    assert text.count("(done before: reused)") == 1
    assert not {p.name for p in out.iterdir()} & INTERMEDIATES
    assert (out / "events.csv").read_text() == (full_out / "events.csv").read_text()


def test_outputs_and_report(small_job):
    out, risk, _ = small_job
    doc = json.loads((out / "risk.json").read_text())  # strict JSON: parses
    assert doc["summary"]["n_events_window"] == risk["summary"]["n_events_window"]
    rows = list(csv.DictReader(open(out / "events.csv")))
    assert len(rows) == doc["events"]["n_events"]
    # the minimum speed, or a measured peak force at least that of a 5 mm/s impact (0.27 N)
    assert all(float(r["normal_speed_m_per_s"]) >= 5e-3 or float(r["force_N"]) >= 0.26
               for r in rows)
    assert doc["summary"]["forces_measured"] and doc["events"]["measured"]
    # ParaView: the window's likeliest events at their contact points, every cartridge at its
    # last position with its risk
    import xml.etree.ElementTree as ET

    in_window = sum(r["in_window"] == "1" for r in rows)
    for name, count, field in (("events.vtp", min(in_window, 20_000), "p_event"),
                               ("cartridges.vtp", SMALL.n_spheres, "p_window")):
        piece = ET.parse(out / name).getroot().find("PolyData/Piece")
        assert int(piece.get("NumberOfPoints")) == count, name
        names = [a.get("Name") for a in piece.find("PointData")]
        assert field in names, (name, names)
    walls = [r for r in rows if r["partner"] == "wall"]
    assert walls and all(r["j"] == "-1" and r["wall"] not in ("", "belt") for r in walls)
    assert doc["events"]["n_wall_events"] == len(walls)
    assert 0.0 <= doc["summary"]["wall_share"] <= 1.0
    # every hourly figure is one number: passages.csv, risk.json's three and the report's
    rows_p = list(csv.DictReader(open(out / "passages.csv")))
    assert len(rows_p) >= SMALL.n_spheres
    s = doc["summary"]
    w = doc["window_s"][1] - doc["window_s"][0]
    from_csv = 3600.0 * sum(float(r["p_window"]) for r in rows_p) / w
    assert from_csv == pytest.approx(s["broken_per_hour_table"], rel=1e-7)
    assert s["broken_per_hour_small_p"] == pytest.approx(s["broken_per_hour_table"], rel=1e-6)
    assert s["broken_per_hour"] == s["broken_per_hour_table"]
    assert s["unassigned_events"] == 0
    exposure = sum(float(r["exposure_in_window_s"]) for r in rows_p)
    assert exposure / w == pytest.approx(s["mean_on_table"], rel=1e-7)
    from demfem.assess.headline import fmt
    assert fmt(s["broken_per_hour"]) in (out / "report.html").read_text()
    # the Parquet tables, with units in their schema, are the CSV files' numbers
    import pyarrow.parquet as pq

    from demfem.assess.tables import load_assessment

    a = load_assessment(out)
    assert len(a.events) == len(rows) and len(a.passages) == len(rows_p)
    assert a.summary == s
    assert 3600.0 * a.passages["p_window"].sum() / w == pytest.approx(
        s["broken_per_hour_table"], rel=1e-12)
    assert np.allclose(a.events["force_N"], [float(r["force_N"]) for r in rows], rtol=1e-8)
    schema = pq.read_schema(out / "events.parquet")
    assert schema.field("force_N").metadata[b"unit"] == b"N"
    assert schema.field("time_s").metadata[b"unit"] == b"s"
    html_text = (out / "report.html").read_text()
    imgs = re.findall(r'<img src="data:image/png;base64,([A-Za-z0-9+/=]+)"', html_text)
    assert len(imgs) == len(FIGURES)
    assert all(len(b) > 1000 for b in imgs)
    assert "<table class='summary'>" in html_text and "expected broken per hour" in html_text
    assert "planning assumption" in html_text.lower()
    assert not re.search(r'(src|href)="(http|//)', html_text) and "<script" not in html_text
    st = doc["steady_state"]
    assert st["window_s"] == [0.06, 0.12]
    # the rare-period check needs two whole gate periods; this window has none
    assert doc["period_check"]["status"].startswith("not checked")
    assert st["events_first_half"] + st["events_second_half"] == doc["summary"][
        "n_events_window"]


def _chromium():
    import shutil
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    if os.environ.get("DEMFEM_REQUIRE_CHROMIUM"):
        pytest.fail("headless Chromium is required here (DEMFEM_REQUIRE_CHROMIUM) but not found")
    pytest.skip("no headless Chromium (Debian package chromium)")


def test_report_renders_in_headless_chromium(small_job, tmp_path):
    """Chromium loads report.html and every figure decodes: a copy of the report gets a probe
    script (the report itself has none) that writes into the title how many images have a
    non-zero natural size, whether the summary table has rows, and the page height; the
    screenshot is not blank."""
    import subprocess

    out, _, _ = small_job
    page = (out / "report.html").read_text()
    probe = ("<script>window.addEventListener('load', () => {"
             "const im = [...document.images];"
             "const ok = im.filter(i => i.complete && i.naturalWidth > 0).length;"
             "const rows = document.querySelectorAll('table.summary tr').length;"
             "document.title = `probe images=${im.length} decoded=${ok} summary_rows=${rows} "
             "height=${document.body.scrollHeight}`;});</script>")
    probed = tmp_path / "probed.html"
    probed.write_text(page.replace("</body>", probe + "</body>"))
    exe = _chromium()
    flags = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
             "--allow-file-access-from-files", "--virtual-time-budget=10000"]
    dom = subprocess.run([exe, *flags, "--dump-dom", probed.as_uri()], capture_output=True,
                         text=True, timeout=120).stdout
    m = re.search(r"<title>probe images=(\d+) decoded=(\d+) summary_rows=(\d+) "
                  r"height=(\d+)</title>", dom)
    assert m, dom[:500]
    images, decoded, rows, height = map(int, m.groups())
    assert images == len(FIGURES) and decoded == images
    assert rows >= 5 and height > 2000
    shot = tmp_path / "report.png"
    subprocess.run([exe, *flags, f"--screenshot={shot}", "--window-size=1200,2400",
                    (out / "report.html").as_uri()], capture_output=True, timeout=120)
    import matplotlib.image as mpimg

    px = mpimg.imread(shot)
    assert px.shape[0] == 2400 and px.shape[1] == 1200
    assert float(px[..., :3].std()) > 0.02  # text and figures, not a blank page


@pytest.mark.parametrize("kwargs, field", [
    (dict(throughput=-1.0), "throughput"), (dict(duration=float("nan")), "duration"),
    (dict(quick=True, full=True), "quick"),
    (dict(min_speed=-1e-3), "min_speed"), (dict(discard_before=5.0), "discard_before"),
    (dict(stop_after="nope"), "stop_after")])
def test_bad_parameters_name_the_field(tmp_path, kwargs, field):
    with pytest.raises(InvalidParameterError, match=field):
        assess(SMALL, out=tmp_path, **{"duration": 0.1, **kwargs})
    assert not (tmp_path / "stages.json").exists()


def test_cli_assess_quick(tmp_path, capsys):
    out = tmp_path / "q"
    assert main(["assess", "--quick", "--out", str(out)]) == 0
    assert (out / "report.html").exists() and (out / "risk.json").exists()
    assert "Expected broken cartridges per hour" in capsys.readouterr().out
    assert main(["assess", "--quick", "--out", str(out), "--throughput", "10"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("demfem: error:") and "throughput_per_hour" in err
    assert main(["assess", "--throughput", "-3", "--out", str(tmp_path / "x")]) == 2
    assert "throughput" in capsys.readouterr().err
    # another stress model is another assessment: refused in the same folder, named
    half = dataclasses.replace(StressModel.default(), beta_inner=0.5 * StressModel.default().beta_inner)
    half.save(tmp_path / "half.json")
    assert main(["assess", "--quick", "--out", str(out), "--stress-model",
                 str(tmp_path / "half.json")]) == 2
    assert "stress_model" in capsys.readouterr().err
    assert main(["assess", "--quick", "--out", str(tmp_path / "h"), "--stress-model",
                 str(tmp_path / "half.json")]) == 0
    lower = json.loads((tmp_path / "h" / "risk.json").read_text())["summary"]
    first = json.loads((out / "risk.json").read_text())["summary"]
    assert lower["broken_per_hour_table"] < first["broken_per_hour_table"]


def test_stress_model_refit_from_a_grid_of_fem_collisions(tmp_path):
    """The FEM refit: a 4 x 1 grid of crossed-tube collisions (45 GPa, 1 layer, 20 mm tubes),
    run serially through the sweep, three for training and one held back; the fitted model
    reproduces its training runs (the scaling σ1 = β F/t² is linear in F), reports its
    held-back error, loads back, and a rerun reuses the FEM runs."""
    from demfem.stress.fem_fit import fit_from_fem

    grid = {"v_rel": [0.1, 0.2, 0.3, 0.4], "tilt_deg": [90.0]}
    lines = []
    rep = fit_from_fem(tmp_path, grid=grid, layers=1, tube_length=20e-3, scheduler="serial",
                       log=lines.append)
    assert rep["n_training"] == 3 and rep["n_held_back"] == 1
    by_speed = sorted(rep["runs"], key=lambda r: r["v_rel"])
    forces = [r["max_force_N"] for r in by_speed]
    assert all(f > 0 for f in forces) and forces == sorted(forces)  # faster, harder
    assert rep["training_error"]["rms_inner_relative"] < 0.3
    assert math.isfinite(rep["held_back_error"]["rms_inner_relative"])
    model = StressModel.load(tmp_path / "stress_model.json")
    assert model.beta_inner == pytest.approx(rep["model"]["beta_inner"])
    assert 0 < model.beta_inner < StressModel.default().beta_inner  # 1 layer: far too stiff
    assert "fitted to 3 FEM collisions" in model.source
    lines.clear()
    fit_from_fem(tmp_path, grid=grid, layers=1, tube_length=20e-3, scheduler="serial",
                 log=lines.append)
    assert "FEM runs done 4/4" in lines[1]  # all reused
    with pytest.raises(InvalidParameterError, match="hold_out_every"):
        fit_from_fem(tmp_path, grid={"v_rel": [0.1], "tilt_deg": [90.0]}, layers=1,
                     scheduler="serial", log=lines.append)
    with pytest.raises(InvalidParameterError, match="tilt_deg"):
        fit_from_fem(tmp_path, grid={"v_rel": [0.1, 0.2]}, scheduler="serial",
                     log=lines.append)


def test_risk_rises_with_belt_speed_on_a_small_table(tmp_path):
    """The same small table (30 spheres, 0.3 s; the engine is deterministic, so the start is
    the fixed seed) at belt speeds 0.1, 0.2, 0.3 m/s: the hardest impact and the expected
    breakage per hour rise with the belt speed (measured 2.3e-14, 1.6e-13, 8.4e-12 per hour)."""
    risk = []
    for v in (0.1, 0.2, 0.3):
        r = assess(dataclasses.replace(SMALL, belt_velocity=v), out=tmp_path / f"v{v}",
                   duration=0.3, sample_interval=0.01, log=lambda s: None)
        risk.append((r["summary"]["max_force_N"], r["summary"]["broken_per_hour"]))
    forces, hourly = zip(*risk)
    assert list(forces) == sorted(forces) and forces[0] < forces[-1]
    assert list(hourly) == sorted(hourly) and hourly[-1] > 10 * hourly[0]


def test_setups_ranked_by_risk_through_demfem_sweep(tmp_path, capsys):
    """`demfem sweep --runner demfem.assess.sweep_runner:risk_point --rank-by
    broken_per_hour`: one assessment per point (a small table here), ranked lowest first;
    an unknown table field and an unknown ranking key are refused, naming them."""
    base = ["sweep", "--runner", "demfem.assess.sweep_runner:risk_point", "--grid",
            "n_spheres=30", "--grid", "width=0.1", "--grid", "length=0.1", "--grid",
            "tilted_wall_length=0.05", "--grid", "duration=0.3", "--scheduler", "serial"]
    assert main([*base, "--grid", "belt_velocity=0.3,0.1", "--rank-by", "broken_per_hour",
                 "--out", str(tmp_path / "a")]) == 0
    out = capsys.readouterr().out
    ranking = out[out.index("ranked by broken_per_hour"):].splitlines()[1:]
    assert "belt_velocity=0.1" in ranking[0] and "belt_velocity=0.3" in ranking[1]
    assert main([*base, "--grid", "belt_speed=0.1", "--out", str(tmp_path / "b")]) == 2
    assert "belt_speed" in capsys.readouterr().err
    assert main([*base, "--grid", "belt_velocity=0.1", "--rank-by", "nope",
                 "--out", str(tmp_path / "a")]) == 2
    assert "nope" in capsys.readouterr().err


def test_a_reduced_modulus_is_flagged_with_its_measured_effect(tmp_path):
    """A DEM at 1e8 Pa: the report warns and cites the measured effect of the softer table,
    and the stresses use the law at the glass's modulus when asked (the DEM's measured forces
    hold at its own modulus only)."""
    soft = dataclasses.replace(SMALL, young_modulus=1e8)
    lines = []
    risk = assess(soft, out=tmp_path, duration=0.05, sample_interval=0.01,
                  stress_young_modulus=45e9, log=lines.append)
    text = " ".join(risk["warnings"])
    assert "reduced Young's modulus" in text and "Spearman 0.92" in text
    assert not risk["summary"]["forces_measured"]
    assert any("calibrated law at the onset speed" in line for line in lines)


def test_contact_stress_stage_matches_demfem_stress_per_partner():
    """The stage's contact model is demfem.stress.contact_stresses with the measured friction
    force (capped at mu F): crossed cartridges, walls along the body."""
    from demfem.cartridge import Cartridge
    from demfem.materials import PAPER_GLASS
    from demfem.stress import contact_stresses

    f = np.array([2.0, 45.0, 10.0])
    q = np.array([0.1, 20.0, np.nan])  # the second above mu F: capped at 0.2 x 45 N
    s = collision_stresses(np.zeros(3), np.array([0, 0, 1]), 45e9,
                           measured_force=f, measured_impulse=f * 1e-4,
                           measured_tangential=q, friction=0.2)
    assert s["tangential_force_N"].tolist() == [0.1, 9.0, 0.0]
    pair = contact_stresses(f[:2], [0.1, 9.0], geometry="crossed", material=PAPER_GLASS,
                            friction_coefficient=0.2)
    wall = contact_stresses(f[2:], 0.0, geometry="wall",
                            contact_length=Cartridge().body_length, material=PAPER_GLASS)
    assert np.allclose(s["sigma_outer_Pa"][:2], pair.outer_sigma1_max, rtol=1e-12)
    assert np.allclose(s["sigma_inner_Pa"][:2], pair.inner_sigma1_max, rtol=1e-12)
    assert np.allclose(s["area_outer_m2"][2:], wall.outer_effective_area, rtol=1e-12)
    # the Hertz edge tension (1 - 2 nu) p0 / 3 of two crossed cartridges without friction
    still = collision_stresses(np.zeros(1), np.zeros(1, np.int64), 45e9,
                               measured_force=np.array([45.0]),
                               measured_impulse=np.array([45e-4]))
    p0 = still["p0_Pa"][0]
    assert still["sigma_outer_contact_Pa"][0] == pytest.approx((1 - 2 * 0.22) * p0 / 3,
                                                               rel=1e-9)
    # the shell-only model on request
    old = collision_stresses(np.zeros(1), np.zeros(1, np.int64), 45e9, model="shell",
                             measured_force=np.array([45.0]),
                             measured_impulse=np.array([45e-4]))
    assert old["sigma_inner_Pa"][0] == pytest.approx(
        StressModel.default().sigma_inner(np.array([45.0]))[0])


def test_the_job_goes_through_its_stages_in_order_and_names_their_files():
    from demfem.assess.job_stages import JOB_STAGES
    from demfem.assess.run import OUTPUT_FILES

    assert tuple(stage.name for stage in JOB_STAGES) == STAGES
    assert {f for stage in JOB_STAGES for f in (*stage.files, *stage.intermediates)} == {
        *OUTPUT_FILES, *FIGURES}
    assert {f for stage in JOB_STAGES for f in stage.intermediates} == INTERMEDIATES
