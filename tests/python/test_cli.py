"""The calibrate command writes its table and figure."""
import numpy as np

from demfem.cli import main


def test_calibrate_writes_table_and_png(tmp_path, capsys):
    assert main(["calibrate", "--n", "5", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "equivalent sphere" in out and "hertz_reissner" in out
    data = np.loadtxt(tmp_path / "calibration.csv", delimiter=",", skiprows=1)
    assert data.shape == (5, 6)
    # Fig. 3: the series law lies below both single laws at every E
    assert np.all(data[:, 3] < data[:, 1]) and np.all(data[:, 3] < data[:, 2])
    png = (tmp_path / "calibration_force_vs_E.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"


def test_calibrate_reports_bad_input(tmp_path, capsys):
    assert main(["calibrate", "--v-rel", "-1", "--out", str(tmp_path)]) == 2
    assert "v_rel" in capsys.readouterr().err


def test_core_stub_matches_the_extension():
    """The hand-written _core.pyi must describe the compiled module exactly."""
    import subprocess
    import sys

    r = subprocess.run([sys.executable, "-m", "mypy.stubtest", "demfem._core"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr


def test_package_type_checks():
    """The package is typed (py.typed); mypy must accept it."""
    import subprocess
    import sys

    # by package name, not path: an installed package's path is site-packages, which mypy
    # would then scan as a source root
    r = subprocess.run([sys.executable, "-m", "mypy", "--ignore-missing-imports", "-p", "demfem"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr


# ---- one option style, user errors without a traceback ------------------------------------

import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402

import pytest  # noqa: E402

from demfem.cli import build_parser, package_version  # noqa: E402

TINY = dict(width=0.1, length=0.1, tilted_wall_length=0.08, opening_width=0.03,
            gate_amplitude=0.01, gate_period=0.2, belt_velocity=0.5, young_modulus=1e7,
            n_spheres=30)


@pytest.fixture()
def tiny_scene(tmp_path):
    from demfem.scenes.table import AccumulationTable

    return str(AccumulationTable(**TINY).to_toml(tmp_path / "tiny.toml"))


def test_options_are_named_alike():
    p = build_parser()
    assert p.parse_args(["equivalence", "--t-end", "3"]).duration == 3.0  # hidden alias
    assert p.parse_args(["equivalence", "--duration", "3"]).duration == 3.0
    for cmd in (["run"], ["fig5"], ["equivalence"]):
        a = p.parse_args(cmd + ["--young-modulus", "1e8"])
        b = p.parse_args(cmd + ["--E", "1e8"])
        assert a.young_modulus == b.young_modulus and float(a.young_modulus) == 1e8
    assert p.parse_args(["run", "scene.toml", "--overwrite"]).fresh
    assert p.parse_args(["run", "--fresh"]).scene is None


def test_version(capsys):
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"demfem {package_version()}"


@pytest.mark.parametrize("argv", [["run", "--duration", "abc"], ["run", "--bogus"],
                                  ["nonsense"], ["calibrate", "--n", "x"]])
def test_bad_arguments_exit_2_with_one_line_and_no_traceback(argv):
    r = subprocess.run([sys.executable, "-m", "demfem.cli", *argv], capture_output=True,
                       text=True)
    assert r.returncode == 2
    assert "Traceback" not in r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("demfem: error: ")


def test_a_users_scene_runs_and_the_same_run_is_reused(tmp_path, tiny_scene, capsys):
    out = tmp_path / "out"
    argv = ["run", tiny_scene, "--duration", "0.04", "--sample-interval", "0.02", "--out",
            str(out)]
    assert main(argv) == 0
    summary = json.loads((out / "summary.json").read_text())  # strict JSON: parses
    assert summary["table"]["n_spheres"] == 30
    assert "first_line_force_mean_N" in summary["table"]
    record = json.loads((out / "run.json").read_text())
    assert "n_spheres = 30" in record["settings"]["scene_toml"]
    capsys.readouterr()
    assert main(argv) == 0
    assert "its record is reused" in capsys.readouterr().out


def test_another_run_in_the_folder_is_refused_then_replaced(tmp_path, tiny_scene, capsys):
    out = tmp_path / "out"
    base = ["run", tiny_scene, "--sample-interval", "0.02", "--out", str(out)]
    assert main(base + ["--duration", "0.06"]) == 0
    frames = len(list((out / "vtk").glob("table_*.vtp")))
    (out / ".summary.json.x1.tmp").write_text("stale")
    capsys.readouterr()
    assert main(base + ["--duration", "0.04"]) == 2
    err = capsys.readouterr().err
    assert "duration_s: 0.06 -> 0.04" in err and "--fresh" in err and "Traceback" not in err
    assert not (out / ".summary.json.x1.tmp").exists()  # stale temporaries cleaned
    assert main(base + ["--duration", "0.04", "--fresh"]) == 0
    assert len(list((out / "vtk").glob("table_*.vtp"))) < frames  # no old frames left
    assert json.loads((out / "run.json").read_text())["settings"]["duration_s"] == 0.04


def test_a_damaged_run_file_fails_with_exit_1_and_says_how_to_start_afresh(
        tmp_path, tiny_scene, capsys):
    out = tmp_path / "out"
    argv = ["run", tiny_scene, "--duration", "0.04", "--sample-interval", "0.02", "--out",
            str(out)]
    assert main(argv) == 0
    data = bytearray((out / "table_run.npz").read_bytes())
    data[len(data) // 2] ^= 0x01
    (out / "table_run.npz").write_bytes(bytes(data))
    capsys.readouterr()
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert "table_run.npz" in err and "--fresh" in err
    assert main(argv + ["--fresh"]) == 0


def test_a_failed_run_exits_1_naming_the_cause(tmp_path, tiny_scene, capsys):
    assert main(["run", tiny_scene, "--E", "1e3", "--duration", "0.2", "--out",
                 str(tmp_path / "soft")]) == 1
    err = capsys.readouterr().err
    assert err.startswith("demfem: error: ") and "Young's modulus too low" in err
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    assert main(["run", tiny_scene, "--duration", "0.02", "--out", str(blocker)]) == 1
    assert "a_file" in capsys.readouterr().err
