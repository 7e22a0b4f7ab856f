"""`demfem run`: the DEM of a table scene with its calibration and analysis, from one call.

:func:`run_pipeline` runs, in order:

1. **Calibration** of the equivalent sphere of the default 3 mL cartridge: mass, diameter,
   Reissner shell stiffness, Hertz contact time, Rayleigh step, and the Fig. 3 analogue (the
   maximum force of two colliding cartridges against E, for each contact law).
2. **DEM** of the accumulation table (the built-in default: 840 equivalent spheres of that
   cartridge, E = 45 GPa, belt 0.2 m/s into the funnel, gate A = 2 cm, T = 2 s; or a user's
   scene, an :class:`~demfem.scenes.AccumulationTable` or its TOML file), recorded every
   ``sample_interval`` s, with every sphere-sphere contact onset logged. The run checkpoints
   into the output folder and resumes from it when started again with the same settings.
3. **Analysis**: first-line force, coordination numbers, speeds of the tagged spheres,
   collision statistics (impact speeds and angles at contact onset), spheres that left
   through the opening.

The breakage risk of the table is ``demfem assess`` (:func:`demfem.assess.assess`), the FEM
of the seven-cartridge cluster ``demfem cluster``; the run's log points to both.

Outputs in ``out``: ``calibration.csv`` and ``calibration_force_vs_E.png``, ``table_run.npz``
(the whole record, :class:`demfem.dem.table_run.TableRun`), ``collisions.csv`` (one row
per contact onset), ``summary.json``, ``table_time_series.png``, ``collisions.png``,
``table_end.png``, a ParaView series ``vtk/table.pvd`` and ``run.json``, the folder's record
(:class:`demfem.jobs.OutputFolder`: the command, the run's settings — the scene's TOML text
and SHA-256, duration, sample interval, E, ... — and the SHA-256 of ``table_run.npz`` once
the run is complete). Every file is written atomically; JSON files are strict (no NaN:
null).

The folder is locked while the run writes it. A folder that holds another command's job or
a run with other settings is refused (:class:`~demfem.errors.OtherJobError`,
:class:`~demfem.errors.SettingsMismatchError` naming the settings that differ) unless
``fresh=True``, which removes the old job's outputs first; one that holds the same run
resumes it, and reuses a complete one after checking its ``table_run.npz`` against the
recorded SHA-256 (a changed file is refused by name, :class:`~demfem.errors.CheckpointError`).

SI units throughout: m, s, kg, N, Pa.
"""
from __future__ import annotations

import dataclasses
import hashlib
from pathlib import Path
from typing import Any, Callable, Mapping, Optional

import numpy as np

from demfem.errors import (CheckpointError, SimulationInterrupted, check_positive,
                           check_range)

__all__ = ["run_pipeline", "load_scene", "OUTPUT_FILES", "COMMAND", "NEXT_STEPS"]

#: The job's name in its folder's record.
COMMAND = "demfem run"

#: What to run next, printed at the end of the run.
NEXT_STEPS = ("the breakage risk of this table: demfem assess [SCENE.toml]",
              "the FEM of the seven-cartridge cluster (Figs. 10-13): demfem cluster")

#: Files a run writes into its output folder (glob patterns; its checkpoint and the ``vtk/``
#: series included): removed by a fresh start so that no old output stays beside the new
#: ones.
OUTPUT_FILES = ("calibration.csv", "calibration_force_vs_E.png", "table_run.npz",
                "collisions.csv", "collisions.png", "summary.json", "table_time_series.png",
                "table_end.png", "table.ck*", "vtk/table_*.vtp", "vtk/table.pvd")
_CHECKPOINT = "table.ck"
_RUN_RECORD = "run.json"


def load_scene(scene: Any = None):
    """The :class:`~demfem.scenes.AccumulationTable` of ``scene``: None (the built-in
    default), a table, or the path of a TOML scene file (``AccumulationTable.to_toml``)."""
    from demfem.errors import InvalidParameterError
    from demfem.scenes.table import AccumulationTable

    if scene is None:
        return AccumulationTable()
    if isinstance(scene, AccumulationTable):
        return scene
    if isinstance(scene, (str, Path)):
        return AccumulationTable.from_toml(scene)
    raise InvalidParameterError(f"invalid scene = {scene!r}: must be None, an "
                                "AccumulationTable or the path of a TOML scene file")


def _settings(table, duration: float, sample_interval: float, v_rel: float,
              discard: float, model: str) -> dict[str, Any]:
    toml = table.toml_text()
    return {"scene_sha256": hashlib.sha256(toml.encode("utf-8")).hexdigest(),
            "scene_toml": toml, "duration_s": float(duration),
            "sample_interval_s": float(sample_interval),
            "young_modulus_Pa": float(table.young_modulus), "v_rel_m_per_s": float(v_rel),
            "statistics_from_s": float(discard), "model": model}


def _compare(recorded: Mapping[str, Any], now: Mapping[str, Any]) -> list[str]:
    """The differences that refuse a resume, with the scene named as one setting (its TOML
    text is in the record for the user, its SHA-256 is compared)."""
    from demfem.jobs import settings_differences

    diff = settings_differences({k: v for k, v in recorded.items() if k != "scene_toml"},
                                {k: v for k, v in now.items() if k != "scene_toml"})
    return [d if not d.startswith("scene_sha256") else
            "scene: another scene file or other scene values" for d in diff]


def run_pipeline(out: str | Path = "demfem_out/run", duration: float = 1.0,
                 young_modulus: Optional[float] = None, sample_interval: float = 0.02,
                 threads: int = 1, v_rel: float = 0.2, discard_before: Optional[float] = None,
                 checkpoint_every: float = 15.0,
                 log: Callable[[str], None] = print,
                 progress: bool | Callable[[float, int], None] = False,
                 scene: Any = None, fresh: bool = False) -> dict[str, Any]:
    """Run calibration, the DEM of the table and its analysis; write the outputs.

    Args:
        out: output folder (created).
        duration: simulated time of the table run, s.
        young_modulus: Young's modulus of the glass, Pa (default: the scene's; the default
            scene has the paper's 45 GPa).
        sample_interval: time between recorded samples, s.
        threads: DEM engine threads (results are bitwise the same on any number).
        v_rel: relative impact speed of the calibration's two cartridges, m/s.
        discard_before: start of the force and coordination statistics, s (default: half
            the run, after the pack has begun to form).
        checkpoint_every: wall time between checkpoints of the table run, s. An interrupted
            job (Ctrl-C) started again with the same settings resumes from the last one.
        log: where the report's lines go.
        progress: callback ``progress(sim_time_s, steps)`` of the table run, or ``True`` for
            a :class:`demfem.progress.ProgressBar` on standard error started with the run.
        scene: the table: None (built-in default), an
            :class:`~demfem.scenes.AccumulationTable`, or the path of its TOML file.
        fresh: replace a run with other settings in ``out`` (its outputs are removed) and
            ignore any checkpoint, instead of refusing it / resuming.

    Returns:
        The summary (also written to ``summary.json``): calibration, the run's numbers,
        collision statistics and the output paths.
    """
    from demfem.jobs import OutputFolder

    # every argument checked before any work
    from demfem.dem.table_run import check_run_arguments

    check_run_arguments(duration, sample_interval, threads)
    v_rel = check_positive("v_rel", v_rel)
    discard = 0.5 * duration if discard_before is None else check_range(
        "discard_before", discard_before, hi=duration, hi_open=False)
    table = load_scene(scene)
    if young_modulus is not None:
        table = dataclasses.replace(table, young_modulus=check_positive("young_modulus",
                                                                         young_modulus))
    settings = _settings(table, duration, sample_interval, v_rel, discard, table.contact_model)
    with OutputFolder(out, COMMAND, settings, fresh=fresh, outputs=OUTPUT_FILES,
                      record=_RUN_RECORD, compare=_compare) as folder:
        return _run(folder, table, duration, sample_interval, threads, v_rel, discard,
                    checkpoint_every, log, progress)


def _run(folder, table, duration: float, sample_interval: float, threads: int, v_rel: float,
         discard: float, checkpoint_every: float, log: Callable[[str], None],
         progress: bool | Callable[[float, int], None]) -> dict[str, Any]:
    """The run in its (locked, checked) output folder."""
    from demfem.calibration import calibration_report, force_vs_modulus, write_calibration
    from demfem.cartridge import Cartridge
    from demfem.io.strict_json import write_json_atomic
    from demfem.progress import ProgressBar
    from demfem.dem.table_run import TableRun, checkpoint_state, run_table

    out = folder.path
    complete = folder.fields.get("status") == "complete"
    if not complete:
        folder.update(status="running")

    # 1. calibration
    log("== 1. calibration: the equivalent sphere ==")
    # the scene's cartridge (a table's [cartridge]); a mesh table's spheres are given directly
    cartridge = getattr(table, "cartridge", None) or Cartridge()
    log(calibration_report(v_rel, cartridge))
    cal = force_vs_modulus(cartridge, np.logspace(7, 11, 9), v_rel)
    log(f"\nMaximum contact force, two cartridges at v_rel = {v_rel:g} m/s (Fig. 3 analogue):")
    log(cal.format())
    cal_csv, cal_png = write_calibration(out, cal)

    # 2. DEM of the table
    log(f"\n== 2. DEM: the accumulation table, {table.n_spheres} spheres, "
        f"E = {table.young_modulus:.3g} Pa, {duration:g} s ==")
    run_path = out / "table_run.npz"
    checkpoint = out / _CHECKPOINT
    run = None
    if complete and run_path.exists():
        run = TableRun.load(_verified_run(folder, run_path))
        log(f"  the same run is complete in {out}: its record is reused")
    if run is None:
        bar = ProgressBar(duration, label="table") if progress is True else None
        callback = bar if bar is not None else (progress if callable(progress) else None)
        try:
            try:
                run = run_table(table, duration, sample_interval, threads=threads,
                                model=table.contact_model, progress=callback,
                                checkpoint=checkpoint, checkpoint_every=checkpoint_every,
                                fresh=folder.fresh)
            finally:
                if bar is not None:
                    bar.close()
        except SimulationInterrupted:
            state = checkpoint_state(checkpoint)
            if state is not None:
                log(f"interrupted: started again with the same settings, the job resumes "
                    f"from its checkpoint at t = {state['sim_time_s']:.4g} s ({checkpoint})")
            else:
                log(f"interrupted before the first checkpoint (every {checkpoint_every:g} s "
                    "of wall time): nothing to resume")
            raise
        run.save(run_path)
        folder.add_files([run_path])
    info = run.info
    log(f"  {info['steps']} steps of {info['dt']:.3g} s in {info['wall_time_s']:.1f} s wall "
        f"({table.n_spheres * info['steps'] / max(info['wall_time_s'], 1e-9):.3g} "
        f"particle-steps/s), effects: {', '.join(info['effects'])}")

    # 3. analysis and figures
    from demfem.run_report import write_analysis

    result = write_analysis(out, run, table, duration, discard, sample_interval, log)
    result = {"calibration": {"v_rel_m_per_s": v_rel, "young_modulus_Pa": cal.E.tolist(),
                              "models": list(cal.models), "max_force_N": cal.forces.tolist()},
              **result}
    result["files"] = [str(p) for p in (cal_csv, cal_png, run_path)] + result["files"]
    log("\n== next ==")
    for step in NEXT_STEPS:
        log(f"  {step}")
    summary_path = write_json_atomic(out / "summary.json", result)
    folder.update(status="complete")
    log(f"\nwritten to {out}: " + ", ".join(str(Path(p).relative_to(out))
                                          for p in result["files"])
        + f", {summary_path.name}, {folder.record_path.name}")
    return result


def _verified_run(folder, run_path: Path) -> Path:
    """``table_run.npz`` of a complete run, checked against the SHA-256 in the record (a
    record of an earlier version names it ``table_run_sha256``)."""
    from demfem.jobs import sha256_file

    if folder.relative(run_path) in folder.files:
        return folder.verify(run_path)
    legacy = folder.fields.get("table_run_sha256")
    if legacy is None or sha256_file(run_path) != legacy:
        raise CheckpointError(f"damaged run file {run_path}: its SHA-256 differs from the "
                              f"one in {folder.record_path}; start afresh ({folder.fresh_hint})")
    return run_path
