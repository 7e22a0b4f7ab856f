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
