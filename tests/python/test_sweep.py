"""Sweeps: grid expansion, keys, skip-on-relaunch, Dask LocalCluster, CLI."""
import json

import pytest

from demfem.calibration import sweep_point
from demfem.cli import main
from demfem.errors import InvalidParameterError
from demfem.sweep import grid_points, parse_grid_option, run_key, sweep


def test_grid_is_cartesian_product():
    pts = grid_points({"A": [0.01, 0.02], "T": [1, 2, 3]})
    assert len(pts) == 6 and {"A": 0.02, "T": 3} in pts
    assert len({run_key(p) for p in pts}) == 6
    assert run_key({"A": 1, "T": 2}) == run_key({"T": 2, "A": 1})


def test_serial_sweep_skips_finished_runs(tmp_path):
    grid = {"E": [1e8, 1e9], "v_rel": [0.1, 0.2]}
    first = sweep(grid, "demfem.calibration:sweep_point", tmp_path, scheduler="serial")
    assert first.ran == 4 and first.skipped == 0
    rec = first.records[0]
    assert rec["result"] == sweep_point(rec["params"])
    # a larger grid re-launched: only the new points run
    grid["v_rel"].append(0.3)
    second = sweep(grid, "demfem.calibration:sweep_point", tmp_path, scheduler="serial")
    assert second.ran == 2 and second.skipped == 4
    lines = second.table_path.read_text().strip().splitlines()
    assert len(lines) == 1 + 6 and lines[0].startswith("E,v_rel,F_hertz_N")


def test_local_cluster_sweep(tmp_path):
    res = sweep({"E": [1e7, 1e10]}, "demfem.calibration:sweep_point", tmp_path, n_workers=2)
    assert res.ran == 2
    f = [r["result"]["F_hertz_reissner_N"] for r in res.records]
    assert f[0] < f[1]


def test_bad_sweeps_are_reported(tmp_path):
    with pytest.raises(InvalidParameterError, match="runner"):
        sweep({"E": [1e9]}, "no_such_module:f", tmp_path, scheduler="serial")
    with pytest.raises(InvalidParameterError, match="grid"):
        sweep({"E": []}, "demfem.calibration:sweep_point", tmp_path, scheduler="serial")
    with pytest.raises(InvalidParameterError, match="allowed"):
        sweep({"G": [1]}, "demfem.calibration:sweep_point", tmp_path, scheduler="serial")
    with pytest.raises(InvalidParameterError, match="--grid"):
        parse_grid_option(["E:1,2"])


def test_cli_sweep(tmp_path, capsys):
    code = main(["sweep", "--runner", "demfem.calibration:sweep_point", "--grid", "E=1e8,1e9",
                 "--grid", "v_rel=0.2", "--out", str(tmp_path), "--scheduler", "serial"])
    assert code == 0
    assert "ran 2, skipped 0" in capsys.readouterr().out
    runs = sorted((tmp_path / "runs").glob("*.json"))
    assert len(runs) == 2 and json.loads(runs[0].read_text())["params"]["v_rel"] == 0.2
