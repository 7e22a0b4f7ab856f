"""The main job: the paper's pipeline on the built-in default scene, from one call.

:func:`run_pipeline` runs, in order, every stage of the method that demfem has today:

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

The FEM of the seven-cartridge cluster and the breakage risk (stages 4-5 of the paper) are
not in demfem yet; the report says so instead of inventing numbers.

Outputs in ``out``: ``calibration.csv`` and ``calibration_force_vs_E.png``, ``table_run.npz``
(the whole record, :class:`demfem.studies.table_run.TableRun`), ``collisions.csv`` (one row
per contact onset), ``summary.json``, ``table_time_series.png``, ``collisions.png``,
``table_end.png``, a ParaView series ``vtk/table.pvd`` and ``run.json`` (the run's settings:
the scene's TOML text and SHA-256, duration, sample interval, E, ...). Every file is written
atomically; JSON files are strict (no NaN: null).

An output folder that holds another run is refused (:class:`~demfem.errors.
SettingsMismatchError` naming the settings that differ) unless ``fresh=True``, which removes
the old run's outputs first; one that holds the same run resumes it.

SI units throughout: m, s, kg, N, Pa.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np

from demfem.errors import (CheckpointError, SettingsMismatchError, SimulationInterrupted,
                           check_positive, check_range)

__all__ = ["run_pipeline", "load_scene", "NOT_YET", "OUTPUT_FILES"]

#: The paper's stages demfem does not run yet (printed by the report, kept in the summary).
NOT_YET = ("FEM of the seven-cartridge cluster (stage 4)",
           "breakage probability per cartridge from the DEM collisions (stage 5)")

#: Files a run writes into its output folder (besides the ``vtk/`` series): removed by a
#: fresh start so that no old output stays beside the new ones.
OUTPUT_FILES = ("calibration.csv", "calibration_force_vs_E.png", "table_run.npz",
                "collisions.csv", "collisions.png", "summary.json", "table_time_series.png",
                "table_end.png", "run.json")
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


def _clear_outputs(out: Path) -> None:
    """Remove a previous run's outputs (and only those) from ``out``."""
    from demfem.studies.table_run import remove_checkpoint

    for name in OUTPUT_FILES:
        (out / name).unlink(missing_ok=True)
    remove_checkpoint(out / _CHECKPOINT)
    vtk = out / "vtk"
    if vtk.is_dir():
        for p in (*vtk.glob("table_*.vtp"), vtk / "table.pvd"):
            p.unlink(missing_ok=True)
        if not any(vtk.iterdir()):
            vtk.rmdir()


def _prepare_folder(out: Path, settings: dict[str, Any], fresh: bool) -> Optional[dict]:
    """Check ``out`` against this run's settings; returns the previous run's record when it
    is the same run (to resume or reuse), else None after clearing the old outputs (fresh)
    or refusing them."""
    from demfem.io.atomic import clean_stale_temporaries
    from demfem.io.strict_json import read_record
    from demfem.studies.table_run import settings_differences

    clean_stale_temporaries(out)
    record_path = out / _RUN_RECORD
    previous = read_record(record_path, ("settings",), fresh, "run record", "demfem run")
    if not record_path.exists() and not fresh and any(
            (out / n).exists() for n in ("summary.json", "table_run.npz", _CHECKPOINT, "vtk")):
        raise SettingsMismatchError(
            f"the output folder {out} holds another run (without a run record {_RUN_RECORD}"
            "): choose another output folder, or replace it (fresh=True, demfem run "
            "--fresh)")
    if previous is not None and not fresh:
        old = dict(previous["settings"])
        diff = settings_differences({k: v for k, v in old.items() if k != "scene_toml"},
                                    {k: v for k, v in settings.items() if k != "scene_toml"})
        if diff:
            raise SettingsMismatchError(
                f"the output folder {out} holds a run with other settings ("
                + "; ".join(d if not d.startswith("scene_sha256") else
                            "scene: another scene file or other scene values"
                            for d in diff)
                + "): use the same settings to resume it, another output folder, or "
                "replace it (fresh=True, demfem run --fresh)")
        return previous
    _clear_outputs(out)
    return None


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
    from demfem.calibration import calibration_report, force_vs_modulus, write_calibration
    from demfem.cartridge import Cartridge
    from demfem.io.strict_json import write_json_atomic
    from demfem.progress import ProgressBar
    from demfem.studies.table_run import (TableRun, check_run_arguments, checkpoint_state,
                                          run_table, sha256_file)

    # every argument checked before any work
    check_run_arguments(duration, sample_interval, threads)
    v_rel = check_positive("v_rel", v_rel)
    discard = 0.5 * duration if discard_before is None else check_range(
        "discard_before", discard_before, hi=duration, hi_open=False)
    table = load_scene(scene)
    if young_modulus is not None:
        table = dataclasses.replace(table, young_modulus=check_positive("young_modulus",
                                                                         young_modulus))
    model = table.contact_model
    settings = _settings(table, duration, sample_interval, v_rel, discard, model)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    previous = _prepare_folder(out, settings, fresh)
    record_path = out / _RUN_RECORD
    record = {"format": 1, "status": "running", "settings": settings}
    if previous is None or previous.get("status") != "complete":
        write_json_atomic(record_path, record)

    # 1. calibration
    log("== 1. calibration: the equivalent sphere ==")
    log(calibration_report(v_rel))
    cal = force_vs_modulus(Cartridge(), np.logspace(7, 11, 9), v_rel)
    log(f"\nMaximum contact force, two cartridges at v_rel = {v_rel:g} m/s (Fig. 3 analogue):")
    log(cal.format())
    cal_csv, cal_png = write_calibration(out, cal)

    # 2. DEM of the table
    log(f"\n== 2. DEM: the accumulation table, {table.n_spheres} spheres, "
        f"E = {table.young_modulus:.3g} Pa, {duration:g} s ==")
    run_path = out / "table_run.npz"
    checkpoint = out / _CHECKPOINT
    run = None
    if previous is not None and previous.get("status") == "complete" and run_path.exists():
        if sha256_file(run_path) != previous.get("table_run_sha256"):
            raise CheckpointError(f"damaged run file {run_path}: its SHA-256 differs from the "
                                  f"one in {record_path}; start afresh (fresh=True, demfem "
                                  "run --fresh)")
        run = TableRun.load(run_path)
        log(f"  the same run is complete in {out}: its record is reused")
    if run is None:
        bar = ProgressBar(duration, label="table") if progress is True else None
        callback = bar if bar is not None else (progress if callable(progress) else None)
        try:
            try:
                run = run_table(table, duration, sample_interval, threads=threads, model=model,
                                progress=callback, checkpoint=checkpoint,
                                checkpoint_every=checkpoint_every, fresh=fresh)
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
    info = run.info
    log(f"  {info['steps']} steps of {info['dt']:.3g} s in {info['wall_time_s']:.1f} s wall "
        f"({table.n_spheres * info['steps'] / max(info['wall_time_s'], 1e-9):.3g} "
        f"particle-steps/s), effects: {', '.join(info['effects'])}")

    # 3. analysis and figures
    from demfem.studies.run_report import write_analysis

    result = write_analysis(out, run, table, duration, discard, sample_interval, log)
    result = {"calibration": {"v_rel_m_per_s": v_rel, "young_modulus_Pa": cal.E.tolist(),
                              "models": list(cal.models), "max_force_N": cal.forces.tolist()},
              **result}
    result["files"] = [str(p) for p in (cal_csv, cal_png, run_path)] + result["files"]
    result["not_yet"] = list(NOT_YET)
    log("\n== not in demfem yet ==")
    for stage in NOT_YET:
        log(f"  {stage}")
    summary_path = write_json_atomic(out / "summary.json", result)
    write_json_atomic(record_path, {**record, "status": "complete",
                                    "table_run_sha256": sha256_file(run_path)})
    log(f"\nwritten to {out}: " + ", ".join(str(Path(p).relative_to(out))
                                          for p in result["files"])
        + f", {summary_path.name}, {record_path.name}")
    return result
