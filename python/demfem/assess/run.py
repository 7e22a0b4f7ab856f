"""`demfem assess`: from every collision of a DEM run of the table to a breakage probability
per cartridge, in six resumable stages (:data:`demfem.assess.stages.STAGES`):

1. **calibration** — the cartridge's equivalent body, its Hertz–Reissner law and the stress
   model in use (``calibration.json``);
2. **dem** — the table run (:func:`demfem.dem.table_run.run_table`; checkpoints into
   ``table.ck`` and resumes mid-run): ``table_run.npz`` (the record a finished folder
   keeps: samples in single precision, without the whole contacts) and, until the job has
   finished, ``table_run_full.npz`` (the whole record);
3. **events** — impact events above the minimum speed (``events.npz``, until finished);
4. **stress** — force, duration, σ1 and stressed area per event (``stress.npz``, until
   finished);
5. **risk** — P per event, per cartridge and per hour, steady state, worst events, risk map
   (``risk.json``, ``events.parquet``, ``passages.parquet``, ``events.vtp``,
   ``cartridges.vtp``, ``risk_arrays.npz``);
6. **report** — ``report.html`` and the figures.

:func:`assess` checks its arguments, then goes through the stages
(:data:`demfem.assess.job_stages.JOB_STAGES`, each a :class:`demfem.assess.job.Stage`) with
:func:`demfem.assess.job.run_stages` on one :class:`~demfem.assess.stages.StageBook`: a
stage completed before is read back, any other runs, and the job ends after
``stop_after``. Once the last stage has completed, the intermediates (``table_run_full.npz``,
``events.npz``, ``stress.npz``) are removed: a finished default job keeps 96 MB instead of
364 MB (docs/output-folders.md gives the files and their sizes).

SI units throughout: m, s, kg, N, Pa.
"""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any, Callable, Optional

from demfem.assess.events import DEFAULT_MIN_SPEED
from demfem.assess.job import JobContext, run_stages
from demfem.assess.job_stages import JOB_STAGES
from demfem.assess.stages import STAGES, StageBook
from demfem.stress.stress_model import StressModel
from demfem.errors import InvalidParameterError, check_count, check_positive, check_range

__all__ = ["assess", "OUTPUT_FILES", "QUICK_DURATION", "DEFAULT_DURATION", "FULL_DURATION",
           "steady_rule", "duration_help", "STEADY_DEFAULT", "STEADY_FULL"]

#: Longest simulated time of the default run, s: it runs until the collision rate is steady
#: (:func:`steady_rule`: the mean impacts per gate period known to 10 %), at most this long.
DEFAULT_DURATION = 24.0
#: ``quick``: a fixed 0.1 s smoke run, statistics over its second half.
QUICK_DURATION = 0.1
#: ``full``: until the mean is known to 5 % (at least 8 periods), at most this long, s
#: (docs/assess.md gives the measured difference from the default).
FULL_DURATION = 60.0


#: The steady rule's (fewest gate periods, largest relative standard error of their mean
#: impacts) of the default run and of ``full``.
STEADY_DEFAULT = (4, 0.10)
STEADY_FULL = (8, 0.05)


def duration_help() -> str:
    """The run-length rule in words, from the constants the code uses (for help texts)."""
    return (f"until the collision rate is steady (the mean impacts per gate period known to "
            f"{STEADY_DEFAULT[1]:.0%}, at least {STEADY_DEFAULT[0]} periods after a 2 s "
            f"warm-up), at most {DEFAULT_DURATION:g} s; --full: to {STEADY_FULL[1]:.0%} over "
            f"at least {STEADY_FULL[0]} periods, at most {FULL_DURATION:g} s; --quick: "
            f"{QUICK_DURATION:g} s")


def steady_rule(table, full: bool = False, min_speed: float = DEFAULT_MIN_SPEED):
    """The :class:`demfem.dem.steady.SteadyRule` of an assessment of ``table``: periods
    of the gate (1 s for a still gate) counted from a 2 s warm-up, at least 4 of them and the
    relative standard error of their mean impacts at most 10 % (``full``: 8 and 5 %),
    impacts as the events stage counts them (not the belt)."""
    from demfem.assess.events import NOT_IMPACTS
    from demfem.dem.steady import SteadyRule

    names = [str(w["name"]) for w in table.build().walls]
    return SteadyRule(period=float(table.gate_period) if table.gate_amplitude > 0 else 1.0,
                      min_periods=(STEADY_FULL if full else STEADY_DEFAULT)[0], warmup=2.0,
                      tolerance=(STEADY_FULL if full else STEADY_DEFAULT)[1],
                      min_speed=min_speed,
                      excluded_walls=tuple(k for k, n in enumerate(names) if n in NOT_IMPACTS))

#: Files the job writes (removed by a fresh start), besides the DEM checkpoint.
OUTPUT_FILES = ("calibration.json", "table_run.npz", "table_run_full.npz", "events.npz",
                "stress.npz", "risk.json",
                "events.parquet", "passages.parquet", "events.csv", "passages.csv",
                "events.vtp", "cartridges.vtp", "cartridge_places.vtp",
                "risk_arrays.npz", "report.html")


def assess(scene: Any = None, out: str | Path = "demfem_out/assess",
           duration: Optional[float] = None, quick: bool = False, full: bool = False,
           throughput: Optional[float] = None, fresh: bool = False,
           sample_interval: Optional[float] = None, min_speed: float = DEFAULT_MIN_SPEED,
           discard_before: Optional[float] = None,
           stress_model: Optional[str | StressModel] = None, pair_geometry: str = "crossed",
           place: str = "mix",
           flaw_depth: Optional[float | str] = "characteristic",
           stress_young_modulus: Optional[float] = None, slow_crack_growth: bool = True,
           threads: int = 1, checkpoint_every: float = 15.0,
           log: Callable[[str], None] = print, progress: bool = False,
           stop_after: Optional[str] = None, refeed: bool = True,
           csv: bool = False, strength: Optional[str | Path] = None,
           seed: Optional[int] = None) -> dict[str, Any]:
    """Run (or resume) the assessment; returns the risk document (``risk.json``'s content).

    Args:
        scene: the table: None (built-in default), an AccumulationTable or a TOML file.
        out: output folder.
        duration: simulated time of the table, s, fixed (statistics over its second half, or
            from ``discard_before``). Default: run until the collision rate is steady
            (:func:`steady_rule`, :func:`duration_help`), statistics over the steady
            periods.
        quick: a smoke run (0.1 s simulated).
        full: the full-accuracy run (:data:`STEADY_FULL`: the mean known to 5 % over at least
            8 gate periods, at most :data:`FULL_DURATION` s).
        throughput: cartridges per hour of the user's line, > 0; None (default): the table's
            own discharge in the simulation. Given, the report shows both.
        fresh: replace an assessment with other settings in ``out`` instead of refusing it.
        sample_interval: time between recorded samples, s (default 0.02; quick 0.01).
        min_speed: minimum normal impact speed of an event, m/s (≥ 0).
        discard_before: start of the statistics window, s (default: half the run).
        stress_model: ``"contact"`` (default: the contact field with friction on top of the
            shell's bending, :func:`demfem.stress.contact_stresses`), ``"shell"`` (the former
            shell-only closed form) or a :class:`StressModel` (σ1 = β F/t²).
        pair_geometry: the contact of two cartridges, ``"crossed"`` (default: axes at 90°, a
            point contact) or ``"parallel"`` (upright, along the body: a line contact)
            (:data:`demfem.stress.stage.PAIR_GEOMETRIES`); walls: along the body.
        place: where on the cartridge the events land (:mod:`demfem.assess.places`):
            ``"mix"`` (default: each event weighted over body, rim and shoulder by the
            full-shape table's counts for its partner; P is the expectation over them) or
            ``"body"``, ``"rim"``, ``"shoulder"`` (every event there).
        flaw_depth: depth of the outer surface's flaws, m, at which the contact-edge tension
            is felt (:mod:`demfem.stress.flaw_depth`): ``"characteristic"`` (default: the flaw
            that fails at the outer surface's σ_0, c = (K_Ic/(1.12 σ_0))²/π, ≈ 30 µm for the
            planning σ_0 = 70 MPa), a depth in m, or None (the surface value: no correction).
        stress_young_modulus: Young's modulus at which the collision forces are evaluated, Pa
            (default: the scene's, i.e. the DEM's).
        slow_crack_growth: use the half-sine equivalent stress over the contact duration.
        threads: DEM threads (results are the same on any number).
        checkpoint_every: wall time between DEM checkpoints, s.
        log: where progress lines go.
        progress: a progress bar on standard error for the DEM stage.
        stop_after: stop after this stage (one of STAGES): a later call resumes from there.
        refeed: re-insert upstream the cartridges that leave through the opening, so the table
            stays in operation (a batch that drains has no steady state); False runs the
            scene as it is.
        csv: also write ``events.csv`` and ``passages.csv`` beside their Parquet files.
        strength: a strength file (``demfem strength-fit``,
            :func:`demfem.risk.strength_file.load_strength_file`) with the Weibull parameters
            of the user's own glass; None: the planning assumptions of :mod:`demfem.risk`.
        seed: start the table from the perturbed start of this seed (whole number >= 0;
            :func:`demfem.scenes.perturb.perturbed_start`: every cartridge moved in the
            belt's plane by at most half its clearance, 40 µm on the default table), so that
            runs of one scene are independent replicas; None: the scene's own start.
            Recorded in the settings (``start_seed``).
    """
    from demfem.pipeline import load_scene
    from demfem.risk import INNER_SURFACE, OUTER_SURFACE, SCG_BOROSILICATE
    from demfem.risk.strength_file import load_strength_file
    from demfem.dem.table_run import check_run_arguments

    # every argument checked before any work
    if quick and full:
        raise InvalidParameterError("invalid quick = full = True: choose one of quick and full")
    until_steady = duration is None and not quick
    if duration is None:
        duration = QUICK_DURATION if quick else FULL_DURATION if full else DEFAULT_DURATION
    if sample_interval is None:
        sample_interval = min(0.01 if quick else 0.02, float(duration)) if isinstance(
            duration, (int, float)) and math.isfinite(duration) and duration > 0 else 0.02
    check_run_arguments(duration, sample_interval, threads)
    duration = float(duration)
    q = None if throughput is None else check_positive("throughput", throughput)
    v_min = check_range("min_speed", min_speed, 0.0, math.inf, lo_open=False)
    if until_steady and discard_before is not None:
        raise InvalidParameterError(
            f"invalid discard_before = {discard_before!r}: the run until steady takes its "
            "statistics over its steady periods; give a fixed duration to choose the window")
    t0 = 0.5 * duration if discard_before is None else check_range(
        "discard_before", discard_before, 0.0, duration, lo_open=False)
    if not isinstance(csv, bool):
        raise InvalidParameterError(f"invalid csv = {csv!r}: must be True or False")
    if not isinstance(refeed, bool):
        raise InvalidParameterError(f"invalid refeed = {refeed!r}: must be True or False")
    check_positive("checkpoint_every", checkpoint_every)
    if seed is not None:
        seed = check_count("seed", seed, 0)
    if stop_after is not None and stop_after not in STAGES:
        raise InvalidParameterError(f"invalid stop_after = {stop_after!r}: must be one of "
                                    f"{STAGES}")
    table = load_scene(scene)
    if table.contact_model == "fem_line":
        raise InvalidParameterError(
            "invalid contact_model = 'fem_line' for demfem assess: its forces are those of "
            "line contacts along the cartridge body, which the stress model (a point load on "
            "the shell) does not describe; assess the table with 'hertz_reissner_mindlin' "
            "(or 'hertz_mindlin')")
    if refeed and not table.refeed:
        log("note: the scene has refeed = false; assess re-feeds the cartridges that leave so "
            "that the table stays in operation (refeed=False, demfem assess --no-refeed, runs "
            "the scene as a draining batch)")
        table = dataclasses.replace(table, refeed=True)
    rule = steady_rule(table, full, v_min) if until_steady else None
    from demfem.stress.stage import PAIR_GEOMETRIES, STRESS_MODELS

    model: str | StressModel = "contact" if stress_model is None else stress_model
    if not (isinstance(model, StressModel) or model in STRESS_MODELS):
        raise InvalidParameterError(f"invalid stress_model = {model!r}: must be one of "
                                    f"{STRESS_MODELS} or a StressModel")
    if pair_geometry not in PAIR_GEOMETRIES:
        raise InvalidParameterError(f"invalid pair_geometry = {pair_geometry!r}: must be one "
                                    f"of {PAIR_GEOMETRIES}")
    from demfem.assess.places import PLACE_MODES

    if place not in PLACE_MODES:
        raise InvalidParameterError(f"invalid place = {place!r}: must be one of "
                                    f"{', '.join(map(repr, PLACE_MODES))}")
    e_stress = float(table.young_modulus) if stress_young_modulus is None else check_positive(
        "stress_young_modulus", stress_young_modulus)
    scg = SCG_BOROSILICATE if slow_crack_growth else None
    if strength is not None:
        glass = load_strength_file(strength)
        surfaces = {"inner": glass["inner"], "outer": glass["outer"],
                    "source": glass["source"], "measured": list(glass["measured"])}
    else:
        surfaces = {"inner": INNER_SURFACE, "outer": OUTER_SURFACE,
                    "source": "planning assumptions of demfem.risk (not measured on any "
                              "product)", "measured": []}
    from demfem.stress.stage import characteristic_flaw_depth

    if flaw_depth == "characteristic":
        c_flaw: Optional[float] = characteristic_flaw_depth(
            surfaces["outer"].characteristic_strength)
    elif flaw_depth is None:
        c_flaw = None
    else:
        c_flaw = check_range("flaw_depth", flaw_depth, 0.0, 1e-3)
    settings = {"scene": dataclasses.asdict(table), "duration_s": duration,
                "sample_interval_s": float(sample_interval), "min_speed_m_per_s": v_min,
                "statistics_from_s": None if rule else t0,
                "until_steady": rule.to_dict() if rule else None, "throughput_per_hour": q,
                "stress_young_modulus_Pa": e_stress,
                "stress_model": model.to_dict() if isinstance(model, StressModel) else model,
                "pair_geometry": pair_geometry, "place": place,
                "slow_crack_growth": dataclasses.asdict(scg) if scg else None,
                "inner_surface": dataclasses.asdict(surfaces["inner"]),
                "outer_surface": dataclasses.asdict(surfaces["outer"]),
                "strength_source": surfaces["source"], "flaw_depth_m": c_flaw,
                "dem_model": table.contact_model, "dem_events": "measured",
                "tables": "parquet+csv" if csv else "parquet"}
    if seed is not None:
        settings["start_seed"] = seed
    ctx = JobContext(table=table, settings=settings, out=Path(out), log=log,
                     duration=duration, sample_interval=sample_interval, rule=rule,
                     discard_before=t0, min_speed=v_min, throughput=q, model=model,
                     pair_geometry=pair_geometry, stress_young_modulus=e_stress,
                     slow_crack_growth=scg, surfaces=surfaces, flaw_depth=c_flaw, csv=csv,
                     threads=threads, checkpoint_every=checkpoint_every, fresh=fresh,
                     progress=progress, seed=seed, place=place)
    # the folder's lock is held from here to the end, released on return or error
    book = StageBook(ctx.out, settings, fresh, OUTPUT_FILES)
    try:
        return run_stages(ctx, JOB_STAGES, book, stop_after)
    finally:
        book.close()
