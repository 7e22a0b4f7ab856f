"""`demfem assess`: from every collision of a DEM run of the table to a breakage probability
per cartridge, in six resumable stages (:data:`demfem.assess.stages.STAGES`):

1. **calibration** — the cartridge's equivalent body, its Hertz–Reissner law and the stress
   model in use (``calibration.json``);
2. **dem** — the table run (:func:`demfem.dem.table_run.run_table`, ``table_run.npz``;
   checkpoints into ``table.ck`` and resumes mid-run);
3. **events** — impact events above the minimum speed (``events.npz``);
4. **stress** — force, duration, σ1 and stressed area per event (``stress.npz``);
5. **risk** — P per event, per cartridge and per hour, steady state, worst events, risk map
   (``risk.json``, ``events.parquet``, ``passages.parquet``, ``risk_arrays.npz``);
6. **report** — ``report.html`` and the figures.

SI units throughout: m, s, kg, N, Pa.
"""
from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np

from demfem.assess.events import DEFAULT_MIN_SPEED
from demfem.assess.npz import load_npz, save_npz
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
OUTPUT_FILES = ("calibration.json", "table_run.npz", "events.npz", "stress.npz", "risk.json",
                "events.parquet", "passages.parquet", "events.csv", "passages.csv",
                "events.vtp", "cartridges.vtp",
                "risk_arrays.npz", "report.html")


def _model_words(model: Any, pair_geometry: str) -> str:
    """The stress model in words, for the console and the report."""
    if isinstance(model, StressModel) or model == "shell":
        m = StressModel.default() if model == "shell" else model
        return (f"shell bending only, sigma1 = {m.beta_inner:.3g} F/t^2 (inner), "
                f"{m.beta_outer:.3g} F/t^2 (outer), t = {m.thickness:g} m ({m.source})")
    return ("the contact field with friction (Hertz, Hamilton 1983) on the outer surface on "
            "top of the shell's bending; two cartridges "
            + ("crossed at 90 degrees (a point contact)" if pair_geometry == "crossed" else
               "side by side along the body (a line contact)")
            + ", walls and gate along the body (demfem.stress)")


def _calibration_stresses(forces: np.ndarray, table, e_stress: float, model: Any,
                          pair_geometry: str, surfaces: dict[str, Any],
                          flaw_depth: Optional[float] = None) -> dict[str, Any]:
    """σ1 outside and inside of two cartridges at the calibration's forces, without friction
    and sliding at the table's μ (Pa)."""
    from demfem.stress.stage import collision_stresses

    f = np.asarray(forces, float)
    kw = dict(model=model, cartridge=table.cartridge, pair_geometry=pair_geometry,
              friction=table.friction, weibull_modulus_inner=surfaces["inner"].weibull_modulus,
              weibull_modulus_outer=surfaces["outer"].weibull_modulus, flaw_depth=flaw_depth)
    speeds = np.full(f.shape, 0.0)
    code = np.zeros(f.shape, np.int64)
    still = collision_stresses(speeds, code, e_stress, table.poisson_ratio, measured_force=f,
                               measured_impulse=f * 1e-4, **kw)
    slide = collision_stresses(speeds, code, e_stress, table.poisson_ratio, measured_force=f,
                               measured_impulse=f * 1e-4, measured_tangential=table.friction * f,
                               **kw)
    return {"sigma_outer_Pa": still["sigma_outer_Pa"], "sigma_inner_Pa": still["sigma_inner_Pa"],
            "sigma_outer_sliding_Pa": slide["sigma_outer_Pa"]}


def _stress_curves(stress: dict[str, np.ndarray], table, e_stress: float, model: Any,
                   pair_geometry: str, surfaces: dict[str, Any],
                   flaw_depth: Optional[float]) -> dict[str, Any]:
    """The model's σ1 of two cartridges over the events' force range, for the figure."""
    top = float(np.max(stress["force_N"])) if len(stress["force_N"]) else 1.0
    f = np.geomspace(max(1e-3, 1e-3 * top), max(top, 1e-2), 40)
    return {"force_N": f, "friction": table.friction,
            **_calibration_stresses(f, table, e_stress, model, pair_geometry, surfaces,
                                    flaw_depth)}


def _hazard_of_force(events: np.ndarray, stress: dict[str, np.ndarray], table, e_stress: float,
                     model: Any, pair_geometry: str, surfaces: dict[str, Any],
                     flaw_depth: Optional[float], scg: Any, window: tuple[float, float]
                     ) -> tuple[Any, float]:
    """h(F): the hazard (both partners) of a cartridge–cartridge impact of peak force F (N) at
    the window's hard impacts' median friction ratio Q/F and the calibrated law's duration at
    F, for the tail model; and the force cap, the law's force of a 1 m/s impact (N)."""
    from demfem.assess.impact import ImpactLaw, cartridge_body
    from demfem.assess.risk_stage import event_probabilities
    from demfem.stress.stage import collision_stresses

    body = cartridge_body(e_stress, table.poisson_ratio, table.cartridge)
    law = ImpactLaw(body, body)
    speeds = np.geomspace(1e-4, 1.0, 200)
    f_grid, tau_grid = law.force(speeds), law.duration(speeds)
    sel = ((events["time"] >= window[0]) & (events["time"] <= window[1])
           & (events["partner"] == 0))
    f_ev = np.asarray(stress["force_N"], float)[sel]
    ratio = 0.0
    if f_ev.size:
        hard = f_ev >= np.quantile(f_ev, 0.9)
        ratio = float(np.median(np.asarray(stress["tangential_force_N"], float)[sel][hard]
                                / f_ev[hard]))

    def hazard(force: np.ndarray) -> np.ndarray:
        f = np.maximum(np.asarray(force, float), 1e-9)
        tau = np.interp(f, f_grid, tau_grid)
        st = collision_stresses(np.zeros(f.shape), np.zeros(f.shape, np.int64), e_stress,
                                table.poisson_ratio, measured_force=f,
                                measured_impulse=f * tau / (0.5 * np.pi),
                                measured_tangential=ratio * f, model=model,
                                cartridge=table.cartridge, pair_geometry=pair_geometry,
                                friction=table.friction,
                                weibull_modulus_inner=surfaces["inner"].weibull_modulus,
                                weibull_modulus_outer=surfaces["outer"].weibull_modulus,
                                flaw_depth=flaw_depth)
        p = event_probabilities(st, surfaces["inner"], surfaces["outer"], scg)
        return 2.0 * -np.log1p(-p["p_event"])

    return hazard, float(f_grid[-1])


def _event_min_force(table, e_stress: float, v_min: float) -> float:
    """Peak force (N) of a cartridge–cartridge impact at ``v_min`` (m/s): a contact that began
    slower is an event if the DEM measured at least this force on it (pressed by the
    queue)."""
    from demfem.assess.impact import ImpactLaw, cartridge_body

    if v_min <= 0:
        return 0.0
    body = cartridge_body(e_stress, table.poisson_ratio, table.cartridge)
    return float(ImpactLaw(body, body).force(np.array([v_min]))[0])


def assess(scene: Any = None, out: str | Path = "demfem_out/assess",
           duration: Optional[float] = None, quick: bool = False, full: bool = False,
           throughput: Optional[float] = None, fresh: bool = False,
           sample_interval: Optional[float] = None, min_speed: float = DEFAULT_MIN_SPEED,
           discard_before: Optional[float] = None,
           stress_model: Optional[str | StressModel] = None, pair_geometry: str = "crossed",
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
                "pair_geometry": pair_geometry,
                "slow_crack_growth": dataclasses.asdict(scg) if scg else None,
                "inner_surface": dataclasses.asdict(surfaces["inner"]),
                "outer_surface": dataclasses.asdict(surfaces["outer"]),
                "strength_source": surfaces["source"], "flaw_depth_m": c_flaw,
                "dem_model": table.contact_model, "dem_events": "measured",
                "tables": "parquet+csv" if csv else "parquet"}
    if seed is not None:
        settings["start_seed"] = seed
    out = Path(out)
    # the folder's lock is held from here to the end, released on return or error
    book = StageBook(out, settings, fresh, OUTPUT_FILES)
    try:
        from demfem.assess.figures import FIGURES as figures_names

        n_st = len(STAGES)

        def header(k: int, text: str, done: bool) -> None:
            log(f"== {k}/{n_st} {STAGES[k - 1]}: {text}" + (" (done before: reused) ==" if done
                                                              else " =="))

        # 1. calibration
        from demfem.assess.impact import ImpactLaw, cartridge_body

        done = book.is_done("calibration")
        header(1, "equivalent body, contact law and stress model", done)
        cal_path = out / "calibration.json"
        if not done:
            from demfem.io.strict_json import write_json_atomic

            body = cartridge_body(e_stress, table.poisson_ratio, table.cartridge)
            law = ImpactLaw(body, body)
            speeds = [0.005, 0.01, 0.02, 0.05, 0.1, 0.2]
            cal = {"young_modulus_Pa": e_stress, "poisson_ratio": body.nu,
                   "mass_kg": body.mass, "hertz_radius_m": body.radius,
                   "shell_thickness_m": body.shell_thickness, "shell_radius_m": body.shell_radius,
                   "reissner_stiffness_N_per_m": body.k_reissner,
                   "law": "hertz_reissner (eq. 12 of the paper)",
                   "speeds_m_per_s": speeds, "force_N": law.force(np.array(speeds)),
                   "duration_s": law.duration(np.array(speeds)),
                   "stress_model": settings["stress_model"], "pair_geometry": pair_geometry}
            cal.update(_calibration_stresses(law.force(np.array(speeds)), table, e_stress,
                                             model, pair_geometry, surfaces, c_flaw))
            write_json_atomic(cal_path, cal)
            book.complete("calibration", [cal_path])
        cal = json.loads(cal_path.read_text(encoding="utf-8"))
        log("  v_n [m/s]: " + " ".join(f"{v:g}" for v in cal["speeds_m_per_s"]))
        log("  F [N]:     " + " ".join(f"{f:.3g}" for f in cal["force_N"]))
        log("  stress model: " + _model_words(model, pair_geometry))
        log("  sigma1 outer [MPa], no friction / at mu = "
            f"{table.friction:g}: " + " ".join(
                f"{a / 1e6:.3g}/{b / 1e6:.3g}" for a, b in zip(cal["sigma_outer_Pa"],
                                                              cal["sigma_outer_sliding_Pa"])))
        log("  sigma1 inner [MPa]: " + " ".join(f"{a / 1e6:.3g}" for a in cal["sigma_inner_Pa"]))
        if stop_after == "calibration":
            return {"stopped_after": "calibration"}

        # 2. DEM
        from demfem.dem.table_run import TableRun, run_table

        run_path = out / "table_run.npz"
        done = book.is_done("dem")
        header(2, f"the table, {table.n_spheres} spheres, E = {table.young_modulus:.3g} Pa, "
                  + (f"until the collision rate is steady (at most {duration:g} s)" if rule
                     else f"{duration:g} s") + (", re-fed" if table.refeed else ""), done)
        if not done:
            from demfem.progress import ProgressBar

            bar = ProgressBar(duration, label="table") if progress else None
            try:
                run = run_table(table, duration, sample_interval, threads=threads,
                                progress=bar, checkpoint=out / "table.ck",
                                checkpoint_every=checkpoint_every, fresh=fresh,
                                record_events=True, steady=rule,
                                keep_events=(v_min, _event_min_force(table, e_stress, v_min)),
                                seed=seed)
            finally:
                if bar is not None:
                    bar.close()
            from demfem.assess.events import without_onsets

            run = without_onsets(run, v_min)  # their counts and speeds, not ~250 MB of onsets
            run.save(run_path)
            book.complete("dem", [run_path])
        else:
            run = TableRun.load(run_path)
        dig = run.info.get("onset_digest") or {"n_sphere_onsets": len(run.onsets),
                                                 "n_wall_onsets": len(run.wall_onsets)}
        log(f"  {run.info['steps']} steps of {run.info['dt']:.3g} s, "
            f"{dig['n_sphere_onsets'] + dig['n_wall_onsets']} contact onsets "
            f"({dig['n_sphere_onsets']} between cartridges, {dig['n_wall_onsets']} with walls, "
            f"gate and belt), wall {run.info['wall_time_s']:.1f} s")
        end = float(run.info["duration"])
        if rule is not None:
            # the statistics window: every whole period since the warm-up
            t0 = min(rule.warmup, end)
            check = run.info.get("steady") or {}
            log(f"  {'steady' if check.get('steady') else 'NOT steady'} at t = {end:g} s: impacts "
                f"per {rule.period:g} s period {check.get('counts')} (standard error of the mean "
                f"{check.get('relative_error', float('nan')):.1%}, tolerance {rule.tolerance:.0%})")
        if stop_after == "dem":
            return {"stopped_after": "dem"}

        # 3. events
        from demfem.assess.events import EVENT_DTYPE, count_line, impact_events

        ev_path = out / "events.npz"
        done = book.is_done("events")
        header(3, f"impact events (normal speed >= {v_min:g} m/s)", done)
        if not done:
            events, ev_summary = impact_events(run, v_min, _event_min_force(table, e_stress, v_min))
            save_npz(ev_path, events=events, summary=np.array(json.dumps(ev_summary)))
            book.complete("events", [ev_path])
        data = load_npz(ev_path)
        events = data["events"].astype(EVENT_DTYPE)
        ev_summary = json.loads(str(data["summary"]))
        log("  " + count_line(ev_summary))
        if stop_after == "events":
            return {"stopped_after": "events"}

        # 4. stress
        from demfem.stress.stage import collision_stresses

        st_path = out / "stress.npz"
        done = book.is_done("stress")
        header(4, "force, duration, sigma1 and stressed area per event", done)
        # measured forces hold at the DEM's modulus only
        use_measured = bool(ev_summary.get("measured")) and math.isclose(
            float(table.young_modulus), e_stress, rel_tol=1e-12)
        log("  forces: " + ("measured in the DEM (peak of each contact; duration from its impulse)"
                            if use_measured else "calibrated law at the onset speed"
                            + (f" (the DEM ran at E = {table.young_modulus:.3g} Pa, the stresses "
                               f"are at {e_stress:.3g} Pa)" if ev_summary.get("measured") else "")))
        if not done:
            stress = collision_stresses(
                events["normal_speed"], events["partner"], e_stress, table.poisson_ratio,
                measured_force=events["peak_force"] if use_measured else None,
                measured_impulse=events["impulse"] if use_measured else None,
                measured_tangential=(events["peak_tangential_force"] if use_measured
                                     else None),
                model=model, cartridge=table.cartridge, pair_geometry=pair_geometry,
                friction=table.friction,
                weibull_modulus_inner=surfaces["inner"].weibull_modulus,
                weibull_modulus_outer=surfaces["outer"].weibull_modulus,
                flaw_depth=c_flaw)
            save_npz(st_path, **stress)
            book.complete("stress", [st_path])
        stress = load_npz(st_path)
        if len(events):
            log(f"  peak force up to {stress['force_N'].max():.3g} N, sigma1 up to "
                f"{stress['sigma_outer_Pa'].max() / 1e6:.3g} MPa outside and "
                f"{stress['sigma_inner_Pa'].max() / 1e6:.3g} MPa inside")
        if stop_after == "stress":
            return {"stopped_after": "stress"}

        # 5. risk
        from demfem.assess.headline import headline
        from demfem.assess.risk_product import risk_document

        done = book.is_done("risk")
        header(5, "Weibull probabilities per event, cartridge and hour", done)
        if not done:
            hof, cap = _hazard_of_force(events, stress, table, e_stress, model, pair_geometry,
                                        surfaces, c_flaw, scg, (t0, end))
            files = risk_document(out, run, table, events, ev_summary, stress, model, scg,
                                  (t0, end), q, settings, e_stress, csv=csv,
                                  surfaces=surfaces, hazard_of_force=hof, force_cap=cap)
            book.complete("risk", files)
        risk = json.loads((out / "risk.json").read_text(encoding="utf-8"))
        s = risk["summary"]
        log("  " + headline(s))
        if stop_after == "risk":
            return risk

        # 6. report
        from demfem.assess.figures import make_figures
        from demfem.assess.report import render_report
        from demfem.io.atomic import write_text_atomic

        done = book.is_done("report")
        header(6, "report.html", done)
        if not done:
            arrays = load_npz(out / "risk_arrays.npz")
            figs = make_figures(out, {
                "map": {k: arrays[f"map_{k}"] for k in ("hazard", "count", "x_edges", "y_edges")},
                "onset_speeds": run.info.get("onset_digest") or run.onsets["normal_speed"],
                "events": events,
                "window": (t0, end), "min_speed": v_min, "stress": stress, "model": model,
                "p_window": arrays["p_window"], "steady": risk["steady_state"],
                "walls": table.walls(), "wall_shares": risk["summary"]["wall_share_by_wall"],
                "opening": (table.x_end, table.min_opening_width, table.max_opening_width),
                "stress_curves": _stress_curves(stress, table, e_stress, model, pair_geometry,
                                                surfaces, c_flaw),
                "duration": end})
            html_path = write_text_atomic(out / "report.html",
                                          render_report(risk, figs, figures_names))
            book.complete("report", [html_path, *(out / n for n in figs)])
        log(f"  written to {out}: report.html, risk.json, events.parquet, passages.parquet"
            + (" (and .csv)" if csv else "") + ", "
            "events.vtp, cartridges.vtp (ParaView), "
            + ", ".join(figures_names))
        return risk
    finally:
        book.close()
