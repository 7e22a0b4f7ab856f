"""kill -9 at any moment loses nothing already written: a `demfem run` or `demfem assess`
killed after its first DEM checkpoint, or a `demfem cluster` FEM run killed after its first
FEM checkpoint, leaves only complete files, and the same call started again resumes and
ends with the numbers of an uninterrupted run (issues 28, 30). While the first process
runs, a second one started into its folder is refused at once naming its PID; the killed
one leaves no lock behind (issue 43)."""
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

RUN = ("import sys; from demfem.pipeline import run_pipeline; "
       "run_pipeline(out=sys.argv[1], duration=0.12, sample_interval=0.02, threads=1, "
       "checkpoint_every=0.3, log=lambda s: None)")
ASSESS = ("import sys; from demfem.assess import assess; "
          "assess(out=sys.argv[1], duration=0.12, checkpoint_every=0.3, log=lambda s: None)")
CLUSTER = ("import sys; from demfem.cartridge import Cartridge; from demfem.materials import "
           "Material; from demfem.scenes import CartridgeCluster; "
           "from demfem.fem.cluster_run import run_cluster; "
           "tube = Cartridge.tube(11.6e-3, 1.1e-3, 10e-3, material=Material(1e8, 0.22, 2230.0)); "
           "c = CartridgeCluster.load_case('max', layers=1, cartridge=tube, springs=True); "
           "run_cluster(c, duration=3e-3, out=sys.argv[1], progress=False, n_snapshots=4, "
           "checkpoint_every=0.3, log=print)")


def _table_numbers(folder: Path) -> dict:
    s = json.loads((folder / "summary.json").read_text())
    return {k: v for k, v in s["table"].items() if not k.startswith("wall") and "wall" not in k}


def _risk_numbers(folder: Path) -> dict:
    r = json.loads((folder / "risk.json").read_text())
    return {k: v for k, v in r.items() if "wall" not in k and k != "settings"}


def _complete(folder: Path) -> None:
    """Every file present is whole: JSON parses, npz loads; no temporary is left visible as
    an output."""
    for p in folder.rglob("*"):
        if not p.is_file() or p.name.endswith(".tmp") or ".tmp" in p.suffixes:
            continue
        if p.suffix == ".json":
            json.loads(p.read_text())
        elif p.suffix == ".npz":
            with np.load(p, allow_pickle=False) as z:
                for k in z.files:
                    z[k]
        elif p.suffix == ".png":
            assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", p


def _kill_after_checkpoint_and_resume(code: str, tmp_path: Path, final: str,
                                      checkpoint: str = "table.ck.json") -> tuple[Path, Path]:
    """Run ``code`` to the end in ``ref``; in ``killed``, SIGKILL it just after its first
    checkpoint (the file ``checkpoint`` appears; ``final`` must not be there yet and every
    file must be whole; a second process started meanwhile is refused naming the first's
    PID), then run it again to the end. Returns (ref, killed)."""
    ref, killed = tmp_path / "ref", tmp_path / "killed"
    subprocess.run([sys.executable, "-c", code, str(ref)], check=True, timeout=600)
    proc = subprocess.Popen([sys.executable, "-c", code, str(killed)])
    meta = killed / checkpoint
    t0 = time.time()
    while not meta.exists() and proc.poll() is None and time.time() - t0 < 300:
        time.sleep(0.05)
    assert proc.poll() is None, "the run ended before its first checkpoint"
    second = subprocess.run([sys.executable, "-c", code, str(killed)], timeout=120,
                            capture_output=True, text=True)
    assert second.returncode != 0 and proc.poll() is None
    assert "FolderLockedError" in second.stderr and f"PID {proc.pid}" in second.stderr
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)
    assert proc.returncode == -signal.SIGKILL
    assert meta.exists() and not (killed / final).exists()
    _complete(killed)
    again = subprocess.run([sys.executable, "-c", code, str(killed)], check=True, timeout=600,
                           capture_output=True, text=True)
    _complete(killed)
    (tmp_path / "resume.log").write_text(again.stdout)
    return ref, killed


def test_kill_9_after_a_checkpoint_then_resume_gives_the_uninterrupted_numbers(tmp_path):
    ref, killed = _kill_after_checkpoint_and_resume(RUN, tmp_path, "summary.json")
    assert _table_numbers(killed) == _table_numbers(ref)


def test_kill_9_of_assess_during_the_dem_then_resume_gives_the_uninterrupted_risk(tmp_path):
    ref, killed = _kill_after_checkpoint_and_resume(ASSESS, tmp_path, "report.html")
    assert _risk_numbers(killed) == _risk_numbers(ref)


def test_kill_9_of_a_cluster_run_then_resume_gives_the_uninterrupted_forces(tmp_path):
    ref, killed = _kill_after_checkpoint_and_resume(CLUSTER, tmp_path, "run.npz",
                                                    checkpoint="checkpoint.npz")
    assert (killed / "forces.csv").read_text() == (ref / "forces.csv").read_text()
    a, b = (json.loads((d / "summary.json").read_text()) for d in (ref, killed))
    for k in ("steps", "force_peaks", "sigma1_body_max_Pa", "energy_balance_error"):
        assert a[k] == b[k], k
    with np.load(ref / "run.npz") as x, np.load(killed / "run.npz") as y:
        for k in ("sigma1", "pressure", "snap_time", "time"):
            assert np.array_equal(x[k], y[k]), k
    assert not (killed / "checkpoint.npz").exists()  # removed once the run is complete
    assert "resuming from the checkpoint at t = " in (tmp_path / "resume.log").read_text()
