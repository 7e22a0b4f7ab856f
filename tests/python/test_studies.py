"""Studies: recorded table runs, checkpoint/resume, the sweep runner, the figure functions."""
import json
import math

import numpy as np
import pytest

from demfem.cli import main
from demfem.errors import InvalidParameterError
from demfem.scenes import AccumulationTable, Tag
from demfem.dem.table_run import TableRun, run_table, sweep_point, table_from_params
from demfem.studies import figures
from demfem.sweep import run_key

#: A table of 30 spheres that empties a little through a fast gate within 0.4 s at E = 1e7 Pa.
TINY = dict(width=0.1, length=0.1, tilted_wall_length=0.08, opening_width=0.03,
            gate_amplitude=0.01, gate_period=0.2, belt_velocity=0.5, young_modulus=1e7,
            n_spheres=30)


@pytest.fixture(scope="module")
def tiny_run():
    return run_table(AccumulationTable(**TINY), 0.4, sample_interval=0.02)


def test_run_table_records_consistent_shapes(tiny_run):
    run = tiny_run
    f, n = 21, 30
    assert run.n_frames == f and run.n_particles == n
    np.testing.assert_allclose(run.times, 0.02 * np.arange(f), atol=run.info["dt"])
    for name, shape in (("positions", (f, n, 3)), ("velocities", (f, n, 3)),
                        ("forces", (f, n, 3)), ("coordination", (f, n)), ("opening", (f,)),
                        ("riding_up", (f,)), ("max_overlap", (f,))):
        assert getattr(run, name).shape == shape, name
    np.testing.assert_allclose(run.opening, AccumulationTable(**TINY).opening_width_at(run.times))
    assert np.array_equal(run.tags, AccumulationTable(**TINY).build().tags)
    # removed spheres: NaN from the first sample after their removal on, finite before
    removed = np.flatnonzero(np.isfinite(run.removal_times))
    assert len(removed) >= 1
    for i in removed:
        after = run.times >= run.removal_times[i]
        assert np.all(np.isnan(run.positions[after, i])) and np.all(np.isnan(run.velocities[after, i]))
        assert np.all(np.isnan(run.coordination[after, i])) and np.all(np.isnan(run.forces[after, i]))
        assert np.all(np.isfinite(run.positions[~after, i]))
    kept = np.setdiff1d(np.arange(n), removed)
    assert np.all(np.isfinite(run.positions[:, kept])) and np.all(run.coordination[:, kept] >= 0)
    assert run.present.sum(axis=1)[-1] == n - len(removed)


def test_onsets_carry_partner_coordination(tiny_run):
    o = tiny_run.onsets
    assert len(o) > 10
    assert np.all(np.diff(o["time"]) >= 0) and np.all(o["i"] != o["j"])
    assert np.all((o["i"] < 30) & (o["j"] < 30))
    # the coordination of both partners is the one recorded at the nearest sample
    k = np.rint(o["time"] / 0.02).astype(int)
    for row, frame in zip(o[:50], k[:50]):
        for who, z in (("i", row["coordination_i"]), ("j", row["coordination_j"])):
            recorded = tiny_run.coordination[frame, row[who]]
            assert z == (recorded if np.isfinite(recorded) else -1)
    np.testing.assert_allclose(o["impact_angle"], np.arctan2(o["tangential_speed"],
                                                             o["normal_speed"]))


def test_first_line_force_parts(tiny_run):
    total = tiny_run.first_line_force()
    plane = tiny_run.first_line_force("in_plane")
    ok = np.isfinite(total)
    assert ok.sum() > 10 and np.all(plane[ok] <= total[ok] + 1e-15)
    # a sphere resting on the belt carries its weight: the total force is about m g
    weight = AccumulationTable(**TINY).sphere_mass * 9.81
    assert np.nanmedian(total[5:]) == pytest.approx(weight, rel=0.5)
    with pytest.raises(InvalidParameterError, match="part"):
        tiny_run.first_line_force("vertical")


def test_save_load_round_trip(tiny_run, tmp_path):
    path = tiny_run.save(tmp_path / "run.npz")
    back = TableRun.load(path)
    for name in ("times", "positions", "velocities", "coordination", "forces", "opening",
                 "tags", "radii", "removal_times", "riding_up", "max_overlap"):
        np.testing.assert_array_equal(getattr(back, name), getattr(tiny_run, name))
    assert np.array_equal(back.onsets, tiny_run.onsets) and back.onsets.dtype == tiny_run.onsets.dtype
    assert back.parameters == tiny_run.parameters and back.table == AccumulationTable(**TINY)
    assert back.info == json.loads(json.dumps(tiny_run.info))
    np.testing.assert_array_equal(back.first_line_force(), tiny_run.first_line_force())
    with pytest.raises(InvalidParameterError, match="invalid table run file"):
        np.savez(tmp_path / "bad.npz", times=np.zeros(2))
        TableRun.load(tmp_path / "bad.npz")


class _Stop(Exception):
    pass


def test_checkpoint_resume_matches_uninterrupted_run(tiny_run, tmp_path):
    ckpt = tmp_path / "run.ckpt"

    def stop_at_a_quarter(sim_time, steps):
        if sim_time > 0.1:
            raise _Stop

    with pytest.raises(_Stop):
        run_table(AccumulationTable(**TINY), 0.4, sample_interval=0.02, checkpoint=ckpt,
                  checkpoint_every=1e-9, progress=stop_at_a_quarter)
    assert ckpt.exists()
    resumed = run_table(AccumulationTable(**TINY), 0.4, sample_interval=0.02, checkpoint=ckpt)
    assert not ckpt.exists()  # cleaned up once finished
    for name in ("times", "positions", "velocities", "coordination", "forces",
                 "removal_times"):
        np.testing.assert_array_equal(getattr(resumed, name), getattr(tiny_run, name))
    assert np.array_equal(resumed.onsets, tiny_run.onsets)
    assert resumed.info["steps"] == tiny_run.info["steps"]


def test_mismatched_checkpoint_pair_is_refused_and_fresh_starts_afresh(tiny_run, tmp_path):
    """An engine state and a record that do not belong together (a record file replaced by
    an older one) are refused, naming the file, rather than spliced; fresh=True starts
    again and reaches the uninterrupted run."""
    import shutil

    from demfem.errors import CheckpointError

    ckpt = tmp_path / "run.ckpt"
    record = tmp_path / "run.ckpt.record.npz"

    def stop_after(limit):
        def progress(sim_time, steps):
            if sim_time > limit:
                raise _Stop
        return progress

    for limit in (0.05, 0.15):
        with pytest.raises(_Stop):
            run_table(AccumulationTable(**TINY), 0.4, sample_interval=0.02, checkpoint=ckpt,
                      checkpoint_every=1e-9, progress=stop_after(limit))
        if limit == 0.05:
            shutil.copy(record, tmp_path / "old.npz")
    shutil.copy(tmp_path / "old.npz", record)  # engine at ~0.16 s, record up to ~0.06 s
    with pytest.raises(CheckpointError, match="run.ckpt.record.npz"):
        run_table(AccumulationTable(**TINY), 0.4, sample_interval=0.02, checkpoint=ckpt)
    resumed = run_table(AccumulationTable(**TINY), 0.4, sample_interval=0.02, checkpoint=ckpt,
                        fresh=True)
    np.testing.assert_array_equal(resumed.positions, tiny_run.positions)
    assert resumed.n_frames == tiny_run.n_frames


def test_a_crash_after_the_checkpoint_commit_is_finished_on_resume(tiny_run, tmp_path):
    """The metadata (with the new files' SHA-256) is the commit: new files left under their
    temporary names by a crash after it are renamed into place by the next resume."""
    import os

    ckpt = tmp_path / "run.ckpt"

    def stop(sim_time, steps):
        if sim_time > 0.1:
            raise _Stop

    with pytest.raises(_Stop):
        run_table(AccumulationTable(**TINY), 0.4, sample_interval=0.02, checkpoint=ckpt,
                  checkpoint_every=1e-9, progress=stop)
    os.replace(ckpt, tmp_path / "run.ckpt.new")
    os.replace(tmp_path / "run.ckpt.record.npz", tmp_path / "run.ckpt.record.npz.new.npz")
    seen = []
    resumed = run_table(AccumulationTable(**TINY), 0.4, sample_interval=0.02, checkpoint=ckpt,
                        progress=lambda t, n: seen.append(t))
    assert min(seen) > 0.1
    np.testing.assert_array_equal(resumed.positions, tiny_run.positions)
    assert not list(tmp_path.iterdir())  # everything removed at the end


def test_run_table_rejects_bad_arguments():
    table = AccumulationTable(**TINY)
    with pytest.raises(InvalidParameterError, match="duration"):
        run_table(table, -1.0)
    with pytest.raises(InvalidParameterError, match="sample_interval"):
        run_table(table, 0.1, sample_interval=0.2)
    with pytest.raises(InvalidParameterError, match="threads"):
        run_table(table, 0.1, threads=0)


def test_sweep_point_returns_summary_and_saves_the_run(tmp_path):
    params = {**TINY, "duration": 0.1, "sample_interval": 0.02, "run_dir": str(tmp_path)}
    result = sweep_point(params)
    for key in ("first_line_force_mean_N", "first_line_force_peak_N",
                "first_line_force_q95_N", "mean_coordination", "n_removed", "n_riding_up_end",
                "max_overlap_m", "wall_time_s", "run_file"):
        assert key in result, key
    assert result["first_line_force_peak_N"] >= result["first_line_force_q95_N"] >= 0
    assert result["run_file"] == str(tmp_path / f"{run_key(params)}.npz")
    run = TableRun.load(result["run_file"])
    assert run.n_frames == 6 and math.isclose(result["first_line_force_mean_N"],
                                              float(np.nanmean(run.first_line_force())))
    with pytest.raises(InvalidParameterError, match="duration"):
        sweep_point(TINY)
    with pytest.raises(InvalidParameterError, match="unknown key 'belt_speed'"):
        sweep_point({**TINY, "duration": 0.1, "belt_speed": 0.2})


def test_narrowest_opening_keeps_the_smallest_gap():
    base = {k: v for k, v in TINY.items() if k != "opening_width"}
    table = table_from_params({**base, "gate_amplitude": 0.015, "narrowest_opening": 0.01})
    assert math.isclose(table.opening_width, 0.025) and math.isclose(table.min_opening_width, 0.01)
    with pytest.raises(InvalidParameterError, match="narrowest_opening or opening_width"):
        table_from_params({**TINY, "narrowest_opening": 0.01})


#: Small table for the figure functions: Fig. 6-9 set-ups need an opening up to 6 cm.
SMALL_FIG = dict(width=0.1, length=0.1, tilted_wall_length=0.05, n_spheres=30)


def _opts(tmp_path, moduli=(1e7,), duration=0.2):
    return figures.StudyOptions(out=tmp_path, duration=duration, moduli=moduli,
                                sample_interval=0.02, scheduler="serial", log=lambda s: None,
                                table=SMALL_FIG)


def test_fig6_and_fig7_share_runs_and_write_figures(tmp_path):
    found6 = figures.fig6(_opts(tmp_path, moduli=(1e7, 3e7)))
    assert (tmp_path / "fig6_coordination.png").stat().st_size > 0
    assert set(found6["groups"]) == {"all spheres", "first line", "rectangular centre"}
    assert found6["mean_abs_difference_to_smallest_E"]["1e+07"] == 0.0
    runs = sorted((tmp_path / "runs").glob("*.npz"))
    assert len(runs) == 2
    mtimes = [p.stat().st_mtime_ns for p in runs]
    found7 = figures.fig7(_opts(tmp_path, moduli=(1e7, 3e7)))
    assert [p.stat().st_mtime_ns for p in runs] == mtimes  # reused, not run again
    assert (tmp_path / "fig7_rectangular_centre_speed.png").stat().st_size > 0
    assert found7["1e+07"]["peak_speed_mm_s"] >= found7["1e+07"]["mean_speed_mm_s"] >= 0


def test_fig8_9_writes_snapshots_animation_and_paraview_series(tmp_path):
    found = figures.fig8_9(_opts(tmp_path), snapshot_times=(0.1, 5.0), vtk_interval=0.1)
    for name in ("fig8_triangular_centre.png", "fig9_speed_and_coordination.png",
                 "movie1_table.gif", "fig9_snapshot_0.1s.png", "fig9_snapshot_0.2s.png",
                 "vtk/table.pvd", "vtk/table_00000.vtp", "vtk/table_00010.vtp"):
        assert (tmp_path / name).stat().st_size > 0, name
    assert found["duration_s"] == pytest.approx(0.2, abs=1e-3)
    assert "table_00005.vtp" in (tmp_path / "vtk/table.pvd").read_text()


def test_coordination_findings_measure_a_known_oscillation():
    t = np.arange(0, 20, 0.05)
    z = 5 + np.sin(2 * np.pi * t / 2.0)
    f = figures.coordination_findings(t, z, 2.0, discard_before=2.0)
    assert f["period_acf_s"] == pytest.approx(2.0, rel=0.02)
    assert f["period_fft_s"] == pytest.approx(2.0, rel=0.05)
    assert f["q05"] == pytest.approx(4.0, abs=0.05) and f["q95"] == pytest.approx(6.0, abs=0.05)


def test_speed_windows_average_a_known_ramp():
    t = np.arange(0, 20.0 + 1e-9, 0.05)
    v = 0.01 * t  # m/s
    v[t >= 15.0] = np.nan  # the sphere has left
    w = figures.speed_windows(t, v, 10.0)
    assert len(w) == 2
    # window [0, 10): t = 0 ... 9.95, mean 4.975 s -> 49.75 mm/s, peak 99.5 mm/s
    assert w[0]["mean_mm_s"] == pytest.approx(49.75) and w[0]["peak_mm_s"] == pytest.approx(99.5)
    assert w[0]["finite_fraction"] == 1.0
    # window [10, 20): finite for t = 10 ... 14.95 only
    assert w[1]["mean_mm_s"] == pytest.approx(124.75) and w[1]["finite_fraction"] == 0.5
    with pytest.raises(InvalidParameterError, match="width"):
        figures.speed_windows(t, v, 0.0)


def test_discharge_speeds_follow_mass_conservation():
    # 10 spheres leave in [0, 10) s and 30 in [10, 20): Q = 1 and 3 per s
    removal = np.concatenate([np.linspace(0.5, 9.5, 10), np.linspace(10.1, 19.9, 30),
                              [np.nan, np.nan]])
    w = figures.discharge_speeds(removal, 20.0, 10.0, table_width=0.5, pitch=0.02,
                                 opening_width=0.05, belt_velocity=0.1)
    assert [x["discharge_per_s"] for x in w] == [1.0, 3.0]
    # v = Q p^2 / W = 3 * 4e-4 / 0.5 m/s = 2.4 mm/s (square), x sqrt(3)/2 (hexagonal)
    assert w[1]["bulk_speed_square_mm_s"] == pytest.approx(2.4)
    assert w[1]["bulk_speed_hexagonal_mm_s"] == pytest.approx(2.4 * 3 ** 0.5 / 2)
    assert w[0]["bulk_speed_bound_mm_s"] == pytest.approx(10.0)  # 0.1 * 0.05 / 0.5 m/s
    with pytest.raises(InvalidParameterError, match="pitch"):
        figures.discharge_speeds(removal, 20.0, 10.0, 0.5, 0.0, 0.05, 0.1)


def test_per_modulus_durations_override_and_are_checked():
    opts = figures.StudyOptions(out=".", duration=8.0, moduli=(1e7, 1e8, 4.5e10))
    assert figures._durations(opts, 4.0, {1e7: 60.0}) == {1e7: 60.0, 1e8: 8.0, 4.5e10: 4.0}
    assert figures._durations(opts, None, {4.5e10: 12.0}) == {1e7: 8.0, 1e8: 8.0, 4.5e10: 12.0}
    with pytest.raises(InvalidParameterError, match="durations key E = 1000000000.0"):
        figures._durations(opts, None, {1e9: 5.0})
    with pytest.raises(InvalidParameterError, match=r"durations\[10000000.0\] = -1"):
        figures._durations(opts, None, {1e7: -1.0})


def test_coordination_period_survives_a_draining_trend():
    # the table drains: a fall from 3 to 1 over 60 s under the 2 s gate oscillation
    t = np.arange(0, 60, 0.05)
    z = 3.0 - t / 30.0 + 0.5 * np.sin(2 * np.pi * t / 2.0)
    f = figures.coordination_findings(t, z, 2.0, discard_before=2.0)
    assert f["period_acf_s"] == pytest.approx(2.0, rel=0.02)
    assert f["period_fft_s"] == pytest.approx(2.0, rel=0.02)


def test_moving_average_is_nan_aware_and_exact_on_lines():
    x = np.arange(10.0)
    m = figures.moving_average(x, 3)
    assert np.allclose(m[1:-1], x[1:-1]) and m[0] == 0.5 and m[-1] == 8.5
    y = x.copy()
    y[4] = np.nan
    assert figures.moving_average(y, 3)[4] == 4.0  # mean of 3 and 5
    assert np.isnan(figures.moving_average(np.full(4, np.nan), 3)).all()
    with pytest.raises(InvalidParameterError, match="invalid n"):
        figures.moving_average(x, 0)


def test_study_options_and_cli_errors(capsys):
    with pytest.raises(InvalidParameterError, match="duration"):
        figures.StudyOptions(out=".", duration=0.0, moduli=(1e7,))
    with pytest.raises(InvalidParameterError, match="moduli"):
        figures.StudyOptions(out=".", duration=1.0, moduli=())
    assert main(["fig6", "--E", "ten", "--quick"]) == 2
    assert "invalid --E 'ten'" in capsys.readouterr().err
    assert main(["fig7", "--E-duration", "1e7:60", "--quick"]) == 2
    assert "invalid --E-duration '1e7:60'" in capsys.readouterr().err
    assert main(["fig7", "--E", "1e7", "--E-duration", "1e8=60", "--quick"]) == 2
    assert "invalid durations key E = 100000000.0" in capsys.readouterr().err


@pytest.mark.slow
def test_cli_fig5_quick(tmp_path, capsys):
    assert main(["fig5", "--quick", "--duration", "0.1", "--out", str(tmp_path),
                 "--scheduler", "serial"]) == 0
    out = capsys.readouterr().out
    assert "gentlest set-up:" in out and (tmp_path / "fig5_first_line_force.png").exists()
    lines = (tmp_path / "fig5_ranking.csv").read_text().strip().splitlines()
    # 9 distinct set-ups of the three panels + the paper's choice, ranked in-plane and total
    assert len(lines) == 1 + 2 * 10
