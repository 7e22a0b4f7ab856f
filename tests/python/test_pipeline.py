"""`demfem run`: calibration, the DEM of the default table and its analysis, in one call.

The short run is checked against closed forms: a sphere dropped on a belt of speed V ends up
rolling at 2/7 V (its angular momentum about the contact line is conserved: m v r = I w with
I = 2/5 m r^2 and v + w r = V), after sliding for (2/7 V) / (mu g); and a sphere alone on the
belt carries its weight, so the first line's mean net contact force is m g.
"""
import csv
import json
from pathlib import Path

import numpy as np
import pytest

from demfem.cli import main
from demfem.errors import InvalidParameterError, SimulationInterrupted
from demfem.jobs import sha256_file
from demfem.pipeline import NEXT_STEPS, run_pipeline
from demfem.scenes.table import AccumulationTable, Tag
from demfem.dem.table_run import TableRun


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    lines = []
    result = run_pipeline(out, duration=0.05, sample_interval=0.01, log=lines.append)
    return out, result, "\n".join(lines)


def test_a_sphere_on_the_belt_rolls_at_two_sevenths_of_the_belt_speed(short_run):
    out, _, _ = short_run
    run = TableRun.load(out / "table_run.npz")
    table = AccumulationTable()
    v_roll = 2.0 / 7.0 * table.belt_velocity
    t_slide = v_roll / (table.friction * table.gravity)
    assert t_slide < 0.04
    k = int(np.argmin(np.abs(run.times - 0.04)))
    rect = run.velocities[k, run.tags == Tag.RECTANGULAR_CENTRE]
    assert np.allclose(rect[:, 0], v_roll, rtol=2e-3)
    assert np.allclose(rect[:, 1:], 0.0, atol=1e-3 * v_roll)


def test_the_first_line_carries_its_weight_before_the_pack_reaches_it(short_run):
    out, _, _ = short_run
    run = TableRun.load(out / "table_run.npz")
    table = AccumulationTable()
    k = int(np.argmin(np.abs(run.times - 0.04)))
    assert run.first_line_force()[k] == pytest.approx(table.sphere_mass * table.gravity,
                                                      rel=1e-2)


def test_the_outputs_agree_with_each_other_and_point_to_the_next_steps(short_run):
    out, result, text = short_run
    summary = json.loads((out / "summary.json").read_text())
    # the risk and the cluster FEM are in demfem: the log points to their commands
    assert "not_yet" not in summary and "not in demfem" not in text
    for step in NEXT_STEPS:
        assert step in text
    assert "demfem assess" in text and "demfem cluster" in text
    assert "equivalent sphere" in text and "Fig. 3 analogue" in text
    rows = list(csv.DictReader(open(out / "collisions.csv")))
    assert len(rows) == summary["collisions"]["n_onsets"] > 0
    speeds = np.array([float(r["normal_speed_m_per_s"]) for r in rows])
    assert summary["collisions"]["normal_speed_m_per_s"][-1] == pytest.approx(speeds.max())
    assert summary["collisions"]["normal_speed_m_per_s"][0] == pytest.approx(np.median(speeds))
    # angles in degrees in both files, in [0, 90]: atan2(v_t, v_n) with v_n > 0 at onset
    angles = np.array([float(r["impact_angle_deg"]) for r in rows])
    assert 0.0 <= angles.min() and angles.max() <= 90.0
    assert summary["collisions"]["impact_angle_deg"][-1] == pytest.approx(angles.max())
    cal = np.loadtxt(out / "calibration.csv", delimiter=",", skiprows=1)
    assert np.allclose(cal[:, 1:5].T, summary["calibration"]["max_force_N"], rtol=1e-6)
    assert {str(Path(f).relative_to(out)) for f in summary["files"]} == {
        "calibration.csv", "calibration_force_vs_E.png", "table_run.npz", "collisions.csv",
        "table_time_series.png", "collisions.png", "table_end.png", "vtk/table.pvd"}
    for f in summary["files"]:
        assert Path(f).exists()
    assert "vtk/table.pvd" in text
    assert not (out / "table.ck").exists()  # the checkpoint goes once the run is done
    record = json.loads((out / "run.json").read_text())
    assert record["status"] == "complete" and record["command"] == "demfem run"
    assert record["files"]["table_run.npz"] == sha256_file(out / "table_run.npz")
    assert record["settings"]["duration_s"] == 0.05
    assert record["settings"]["scene_toml"] == AccumulationTable().toml_text()
    for png in ("calibration_force_vs_E.png", "table_time_series.png", "collisions.png",
                "table_end.png"):
        assert (out / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_an_interrupted_job_resumes_and_ends_as_an_uninterrupted_one(short_run, tmp_path):
    _, whole, _ = short_run
    lines = []

    def ctrl_c(sim_time, steps):
        if sim_time > 0.025:
            raise SimulationInterrupted(f"interrupted at t = {sim_time} s after {steps} steps")

    with pytest.raises(SimulationInterrupted):
        run_pipeline(tmp_path, duration=0.05, sample_interval=0.01, log=lines.append,
                     progress=ctrl_c, checkpoint_every=1e-9)
    assert "resumes from its checkpoint at t = 0.02 s" in lines[-1]
    assert not (tmp_path / "summary.json").exists()
    seen = []
    resumed = run_pipeline(tmp_path, duration=0.05, sample_interval=0.01,
                           log=lambda _: None, progress=lambda t, steps: seen.append(t))
    assert min(seen) > 0.025  # resumed after the checkpoint at 0.02 s, not started afresh
    for key in ("first_line_force_mean_N", "first_line_force_peak_N", "mean_coordination",
                "max_overlap_m", "n_onsets", "triangular_centre_mean_speed_m_per_s"):
        assert resumed["table"][key] == whole["table"][key]
    assert resumed["collisions"] == whole["collisions"]


@pytest.mark.parametrize("field,kwargs", [
    ("duration", {"duration": -1.0}),
    ("duration", {"duration": float("nan")}),
    ("sample_interval", {"duration": 0.1, "sample_interval": 0.2}),
    ("discard_before", {"duration": 0.1, "discard_before": 0.5}),
    ("threads", {"duration": 0.1, "threads": 0}),
    ("v_rel", {"duration": 0.1, "v_rel": -0.2}),
    ("young_modulus", {"duration": 0.1, "young_modulus": float("nan")}),
])
def test_bad_input_names_the_field(tmp_path, field, kwargs):
    lines = []
    with pytest.raises(InvalidParameterError, match=field):
        run_pipeline(tmp_path / "out", log=lines.append, **kwargs)
    assert lines == [] and not (tmp_path / "out").exists()  # refused before any work


def test_the_command_reports_bad_input(tmp_path, capsys):
    assert main(["run", "--E", "-1", "--duration", "0.01", "--out", str(tmp_path)]) == 2
    assert "young_modulus" in capsys.readouterr().err


def test_the_calibration_is_of_the_scene_s_cartridge(tmp_path):
    """`demfem run` calibrates the cartridge its scene carries (a `[cartridge]` table), not
    the default one."""
    from demfem.calibration import calibration_report
    from demfem.cartridge import Cartridge

    small = Cartridge(body_outer_diameter=10.0e-3, wall_thickness=0.9e-3)
    text = calibration_report(0.2, small)
    assert "The scene's cartridge (10 mm x 64 mm, wall 0.9 mm)" in text
    assert f"{small.mass * 1e3:10.3f} g" in text and small.mass < Cartridge().mass
    assert calibration_report(0.2).startswith("Default cartridge (3 mL")
    table = AccumulationTable(width=0.1, length=0.1, tilted_wall_length=0.05, n_spheres=30,
                              cartridge=small)
    lines = []
    run_pipeline(tmp_path, duration=0.01, sample_interval=0.005, scene=table, log=lines.append)
    log = "\n".join(lines)
    assert "The scene's cartridge (10 mm x 64 mm, wall 0.9 mm)" in log
    assert f"{small.mass * 1e3:10.3f} g" in log
    # calibration.csv is the small cartridge's force table, not the default's
    from demfem.calibration import force_vs_modulus

    with open(tmp_path / "calibration.csv") as fh:
        row = next(csv.DictReader(fh))
    e = float(row["E_Pa"])
    k = force_vs_modulus(small, [e], 0.2)
    mine = float(k.forces[list(k.models).index("hertz_reissner"), 0])
    d = force_vs_modulus(Cartridge(), [e], 0.2)
    theirs = float(d.forces[list(d.models).index("hertz_reissner"), 0])
    assert float(row["F_hertz_reissner_N"]) == pytest.approx(mine, rel=1e-6)
    assert abs(mine - theirs) > 1e-3 * theirs
