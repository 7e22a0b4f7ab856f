"""One output folder, one job (issue 43): the folder's record (command, settings, SHA-256 of
its files, under a checksum of its own), the lock that keeps a second process out, and
what each command does with a folder that is not its own."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from demfem.cli import main
from demfem.errors import (CheckpointError, FolderLockedError, OtherJobError,
                           SettingsMismatchError)
from demfem.jobs import LOCK_FILE, FolderLock, OutputFolder, sha256_file
from demfem.scenes.table import AccumulationTable

TINY = dict(width=0.1, length=0.1, tilted_wall_length=0.08, opening_width=0.03,
            gate_amplitude=0.01, gate_period=0.2, belt_velocity=0.5, young_modulus=1e7,
            n_spheres=30)
SETTINGS = {"duration_s": 0.4, "scene": {"n_spheres": 30}}
OUTPUTS = ("summary.json", "result_*.csv", "vtk/frame_*.vtp", "run.ck*")


def _folder(path, settings=SETTINGS, command="demfem run", **kw) -> OutputFolder:
    return OutputFolder(path, command, settings, outputs=OUTPUTS, record="run.json", **kw)


# ---- the record -------------------------------------------------------------------------------

def test_the_record_names_the_command_the_settings_and_the_files(tmp_path):
    with _folder(tmp_path) as folder:
        (tmp_path / "summary.json").write_text("{}")
        folder.add_files([tmp_path / "summary.json"])
        folder.update(status="complete")
    record = json.loads((tmp_path / "run.json").read_text())
    assert record["command"] == "demfem run" and record["format"] == 2
    assert record["settings"] == SETTINGS and record["status"] == "complete"
    assert record["files"] == {"summary.json": sha256_file(tmp_path / "summary.json")}
    assert record["outputs"] == list(OUTPUTS) and len(record["checksum"]) == 64
    # the same job again: resumes with the record
    with _folder(tmp_path) as again:
        assert again.previous is not None and again.fields["status"] == "complete"
        assert again.intact("summary.json")
        assert again.verify(tmp_path / "summary.json") == tmp_path / "summary.json"


def test_other_settings_are_refused_naming_each_difference_and_fresh_replaces(tmp_path):
    with _folder(tmp_path) as folder:
        (tmp_path / "result_1.csv").write_text("x")
        (tmp_path / "vtk").mkdir()
        (tmp_path / "vtk" / "frame_0.vtp").write_text("x")
        (tmp_path / "mine.txt").write_text("the user's own file")
        folder.add_files([tmp_path / "result_1.csv"])
    other = {"duration_s": 0.3, "scene": {"n_spheres": 31}}
    with pytest.raises(SettingsMismatchError,
                       match=r"duration_s: 0\.4 -> 0\.3; scene\.n_spheres: 30 -> 31") as exc:
        _folder(tmp_path, other)
    assert "--fresh" in str(exc.value)
    with _folder(tmp_path, other, fresh=True) as folder:
        assert folder.previous is None and folder.files == {}
    # the old job's outputs are gone (an emptied sub-folder too), nothing else
    assert not (tmp_path / "result_1.csv").exists() and not (tmp_path / "vtk").exists()
    assert (tmp_path / "mine.txt").exists()
    assert json.loads((tmp_path / "run.json").read_text())["settings"] == other


def test_another_commands_folder_is_refused_naming_that_command(tmp_path):
    with _folder(tmp_path) as folder:
        (tmp_path / "summary.json").write_text("{}")
        folder.add_files([tmp_path / "summary.json"])
    for command in ("demfem assess", "demfem run (mesh table)"):
        with pytest.raises(OtherJobError, match=r"another job, 'demfem run' \(its record "
                                                r"run\.json\).*--fresh"):
            OutputFolder(tmp_path, command, {}, outputs=("summary.json",), record="stages.json"
                         if command == "demfem assess" else "run.json")
    # fresh: the other job's outputs and record go, then the new job's record is written
    with OutputFolder(tmp_path, "demfem assess", {"a": 1}, outputs=("report.html",),
                      record="stages.json", fresh=True):
        pass
    assert not (tmp_path / "summary.json").exists() and not (tmp_path / "run.json").exists()
    assert json.loads((tmp_path / "stages.json").read_text())["command"] == "demfem assess"


def test_outputs_without_a_record_are_refused(tmp_path):
    (tmp_path / "summary.json").write_text("{}")
    with pytest.raises(OtherJobError, match=r"summary\.json.*no record"):
        _folder(tmp_path)
    with _folder(tmp_path, fresh=True):
        pass
    assert not (tmp_path / "summary.json").exists()


@pytest.mark.parametrize("damage", [
    lambda d: d.replace('"duration_s": 0.4', '"duration_s": 0.5'),  # edited by hand
    lambda d: d[: len(d) // 2],                                        # truncated
    lambda d: "[1, 2]",                                                # another JSON value
    lambda d: d.replace('"files": {', '"files": [').replace("}\n,", "],"),
])
def test_a_damaged_record_is_refused_naming_it_and_fresh(tmp_path, damage):
    with _folder(tmp_path):
        pass
    path = tmp_path / "run.json"
    path.write_text(damage(path.read_text()))
    with pytest.raises(CheckpointError, match=r"damaged job record .*run\.json.*--fresh"):
        _folder(tmp_path)
    with _folder(tmp_path, fresh=True):
        pass
    assert json.loads(path.read_text())["settings"] == SETTINGS


def test_a_binary_record_is_refused_naming_it(tmp_path):
    (tmp_path / "stages.json").write_bytes(bytes(range(256)))
    with pytest.raises(CheckpointError, match=r"stages\.json: it is not UTF-8"):
        OutputFolder(tmp_path, "demfem assess", {}, record="stages.json")


def test_a_changed_output_is_refused_by_name(tmp_path):
    with _folder(tmp_path) as folder:
        (tmp_path / "summary.json").write_text('{"force": 1.0}')
        folder.add_files([tmp_path / "summary.json"])
    (tmp_path / "summary.json").write_text('{"force": 2.0}')
    with _folder(tmp_path) as folder:
        assert not folder.intact("summary.json")
        with pytest.raises(CheckpointError, match=r"summary\.json cannot be reused: its "
                                                  r"SHA-256 differs.*--fresh"):
            folder.verify("summary.json")


def test_inputs_join_the_settings_by_their_sha256(tmp_path):
    stl = tmp_path / "walls.stl"
    stl.write_text("solid a\nendsolid a\n")
    out = tmp_path / "out"
    with _folder(out, inputs={"walls": stl}):
        pass
    stl.write_text("solid b\nendsolid b\n")
    with pytest.raises(SettingsMismatchError, match=r"inputs\.walls"):
        _folder(out, inputs={"walls": stl})


def test_a_legacy_record_without_checksum_is_read(tmp_path):
    (tmp_path / "run.json").write_text(json.dumps(
        {"format": 1, "status": "complete", "settings": SETTINGS, "table_run_sha256": "ab"}))
    with _folder(tmp_path) as folder:
        assert folder.previous["command"] == "demfem run"
        assert folder.fields["table_run_sha256"] == "ab"


def test_stale_temporaries_go_only_once_the_folder_is_locked(tmp_path):
    stale = tmp_path / ".summary.json.x1.tmp"
    stale.parent.mkdir(exist_ok=True)
    stale.write_text("half")
    with _folder(tmp_path):
        assert not stale.exists()


# ---- the lock ---------------------------------------------------------------------------------

HOLD = textwrap.dedent("""
    import sys, time
    from demfem.jobs import OutputFolder
    folder = OutputFolder(sys.argv[1], "demfem run", {"duration_s": 0.4}, record="run.json")
    print("locked", flush=True)
    time.sleep(120)
""")


def _holder(folder: Path) -> subprocess.Popen:
    proc = subprocess.Popen([sys.executable, "-c", HOLD, str(folder)], stdout=subprocess.PIPE,
                            text=True)
    assert proc.stdout.readline().strip() == "locked"
    return proc


def test_a_second_process_is_refused_naming_the_pid_and_a_killed_one_leaves_no_lock(tmp_path):
    proc = _holder(tmp_path)
    try:
        t0 = time.monotonic()
        with pytest.raises(FolderLockedError) as exc:
            _folder(tmp_path)
        assert time.monotonic() - t0 < 1.0
        assert f"PID {proc.pid}" in str(exc.value) and str(tmp_path) in str(exc.value)
        assert "demfem run" in str(exc.value)
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
    # kill -9 released it: the kernel drops a dead process's flock
    with _folder(tmp_path, fresh=True):
        assert (tmp_path / LOCK_FILE).exists()


def test_two_commands_at_once_the_second_gets_one_line_naming_the_pid(tmp_path, capsys):
    scene = tmp_path / "tiny.toml"
    AccumulationTable(**TINY).to_toml(scene)
    out = tmp_path / "out"
    proc = _holder(out)
    try:
        for argv in (["run", str(scene), "--duration", "0.04", "--out", str(out)],
                     ["assess", str(scene), "--quick", "--out", str(out)]):
            assert main(argv) == 1
            err = capsys.readouterr().err
            assert err.count("\n") == 1 and err.startswith("demfem: error: ")
            assert f"PID {proc.pid}" in err and "Traceback" not in err
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)


def test_the_same_thread_takes_over_a_lock_its_ended_job_kept(tmp_path):
    first = FolderLock(tmp_path, "demfem run").acquire()  # e.g. held by a traceback's frame
    second = FolderLock(tmp_path, "demfem run").acquire()
    assert second.locked and not first.locked
    second.release()


# ---- the commands -----------------------------------------------------------------------------

def test_assess_into_a_run_folder_is_refused_naming_demfem_run(tmp_path, capsys):
    from demfem.assess import assess
    from demfem.pipeline import run_pipeline

    scene = tmp_path / "tiny.toml"
    AccumulationTable(**TINY).to_toml(scene)
    out = tmp_path / "out"
    run_pipeline(out, duration=0.04, sample_interval=0.02, scene=scene, log=lambda _: None)
    digest = sha256_file(out / "table_run.npz")
    with pytest.raises(OtherJobError, match="'demfem run'"):
        assess(scene, out=out, duration=0.04, log=lambda _: None)
    assert main(["assess", str(scene), "--quick", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "'demfem run'" in err and "--fresh" in err and err.count("\n") == 1
    assert sha256_file(out / "table_run.npz") == digest  # nothing overwritten


def test_a_damaged_stages_json_gives_one_line_naming_it_and_fresh(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "stages.json").write_text('{"format": 1, "settings": {}, "completed": [1, 2]}')
    assert main(["assess", "--quick", "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "stages.json" in err and "--fresh" in err
    assert "Traceback" not in err


def test_a_mesh_table_run_into_a_table_runs_folder_is_refused(tmp_path):
    """What ``run_mesh_table`` opens (issue 43: it replaced a finished table run's
    summary.json): its settings and mesh files make its record; a table run's folder is
    another job's."""
    from demfem.io.stl import write_stl
    from demfem.scenes.infeed import OUTPUT_FILES
    from demfem.scenes.mesh_table import MeshTable

    write_stl(tmp_path / "rail.stl", [[0, 0.3, 0], [1, 0.3, 0], [1, 0.3, 0.05]], [[0, 1, 2]])
    doc = {"scene": "mesh_table", "meshes": [{"file": "rail.stl"}],
           "belts": [{"polygon": [[0, 0], [1, 0], [1, 0.3], [0, 0.3]], "velocity": [0.2, 0]}],
           "infeed": {"rate": 60, "region": [[0, 0], [0.1, 0.3]], "velocity": [0.2, 0]},
           "outlet": {"point": [0.9, 0, 0], "normal": [1, 0, 0]}}
    table = MeshTable.from_dict(doc, base=tmp_path)

    def open_folder(out, t=table, **kw):
        return OutputFolder(out, "demfem run (mesh table)", t.job_settings(1.0),
                            outputs=OUTPUT_FILES, record="run.json", inputs=t.input_files(),
                            **kw)

    table_run = tmp_path / "table_run"
    with _folder(table_run) as folder:
        (table_run / "summary.json").write_text('{"table": 1}')
        folder.add_files([table_run / "summary.json"])
        folder.update(status="complete")
    with pytest.raises(OtherJobError, match=r"another job, 'demfem run' \(its record run\.json\)"
                                            r"; this is 'demfem run \(mesh table\)'"):
        open_folder(table_run)
    assert (table_run / "summary.json").read_text() == '{"table": 1}'
    # its own folder: the same scene resumes; another belt speed, or an edited STL, is refused
    with open_folder(tmp_path / "mesh"):
        pass
    with open_folder(tmp_path / "mesh") as folder:
        assert folder.previous is not None
    doc["belts"][0]["velocity"] = [0.3, 0]
    with pytest.raises(SettingsMismatchError, match=r"belts.*0\.2.*0\.3"):
        open_folder(tmp_path / "mesh", MeshTable.from_dict(doc, base=tmp_path))
    write_stl(tmp_path / "rail.stl", [[0, 0.3, 0], [1, 0.3, 0], [1, 0.3, 0.06]], [[0, 1, 2]])
    with pytest.raises(SettingsMismatchError, match=r"inputs\.meshes\[0\]"):
        open_folder(tmp_path / "mesh")
