"""The target report of benches/dem_anchor_ratio.py (issue 5's targets against one run)."""
import importlib.util
import json
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "benches" / "dem_anchor_ratio.py"


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("dem_anchor_ratio", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_ratio_targets_use_the_median_of_the_repetitions(bench):
    lines = bench.target_report({"yade": [14.0, 16.0, 15.5], "liggghts": [2.9, 3.1, 2.95]},
                                {}, {})
    assert lines[0] == ("target >= 15x yade on 1 thread: 15.50x (median of 3 repetitions, "
                        "14.00-16.00): met")
    assert lines[1] == ("target >= 3x liggghts on 1 thread: 2.95x (median of 3 repetitions, "
                        "2.90-3.10): not met")


def test_absolute_targets_are_also_scaled_by_the_anchors_speed_here(bench):
    # LIGGGHTS at half its reference speed: the 1.5e7 target becomes 7.5e6 on this machine
    lines = bench.target_report({}, {1: 8.0e6, 2: 1.2e7}, {"liggghts": 2.2e6})
    assert lines[0] == ("target >= 1.5e+07 particle-steps/s on 1 thread(s): 8e+06: not met; "
                        "scaled by liggghts's speed here (0.50 of its reference 4.4e+06): "
                        "7.5e+06, met")
    assert lines[1].endswith("1.25e+07, not met")


def test_json_is_written_whole_or_not_at_all(bench, tmp_path):
    path = tmp_path / "runs.json"
    path.write_text("old")
    # what the script writes its runs with: demfem's atomic writer
    bench.write_text_atomic(str(path), json.dumps([{"code": "demfem",
                                                    "particle_steps_per_s": 1.0}]))
    assert json.loads(path.read_text()) == [{"code": "demfem", "particle_steps_per_s": 1.0}]
    assert [p.name for p in tmp_path.iterdir()] == ["runs.json"]


def test_a_missing_anchor_folder_is_named_with_where_to_get_it(bench, tmp_path):
    # the anchors are not in the repository: the error names the folder looked in and the
    # default place beside the repository, instead of a traceback from a bare path
    with pytest.raises(SystemExit) as e:
        bench.check_anchors(str(tmp_path / "nowhere"))
    msg = str(e.value)
    assert str(tmp_path / "nowhere") in msg and "does not exist" in msg
    assert "shared/anchors/dem" in msg and "--anchors" in msg
    (tmp_path / "partial").mkdir()
    (tmp_path / "partial" / "scene.py").write_text("")
    with pytest.raises(SystemExit, match="lacks run_liggghts.py, yade_bench.py, bench_all.py"):
        bench.check_anchors(str(tmp_path / "partial"))
    assert bench.DEFAULT_ANCHORS.endswith("shared/anchors/dem")
