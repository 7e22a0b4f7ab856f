"""The six stages of ``demfem assess`` (:data:`JOB_STAGES`, in the order of
:data:`demfem.assess.stages.STAGES`), each a :class:`~demfem.assess.job.Stage`:

1. :class:`CalibrationStage` — the cartridge's equivalent body, its Hertz–Reissner law and
   the stress model in use (``calibration.json``; product: its content);
2. :class:`DemStage` — the table run (:func:`demfem.dem.table_run.run_table`; checkpoints
   into ``table.ck`` and resumes mid-run): ``table_run.npz``, the record a finished folder
   keeps (:func:`kept_record`), and the intermediate ``table_run_full.npz``, the whole
   record; product: the whole :class:`~demfem.dem.table_run.TableRun`;
3. :class:`EventsStage` — impact events above the minimum speed (the intermediate
   ``events.npz``; product: the events and their counts; digest: the counts);
4. :class:`StressStage` — force, duration, σ1 and stressed area per event (the
   intermediate ``stress.npz``; product: its arrays; digest: their largest values);
5. :class:`RiskStage` — P per event, per cartridge and per hour, steady state, worst events,
   risk map (``risk.json``, ``events.parquet``, ``passages.parquet``, ``events.vtp``,
   ``cartridges.vtp``, ``risk_arrays.npz``; product: ``risk.json``'s content);
6. :class:`ReportStage` — ``report.html`` and the figures.

Each stage's ``files`` are its products, kept in a finished folder; its ``intermediates``
are removed once the job has finished (:func:`demfem.assess.job.run_stages`).

SI units throughout: m, s, kg, N, Pa.
"""
from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING, Any, Callable, Optional

import numpy as np

from demfem.assess.figures import FIGURES
from demfem.assess.job import JobContext, Stage, StageOutput
from demfem.assess.npz import load_npz, save_npz
from demfem.stress.stress_model import StressModel

if TYPE_CHECKING:
    from demfem.dem.table_run import TableRun

__all__ = ["JOB_STAGES", "CalibrationStage", "DemStage", "EventsStage", "StressStage",
           "RiskStage", "ReportStage", "kept_record", "SINGLE_PRECISION_SAMPLES"]

#: The DEM record's per-sphere samples that a finished folder keeps in single precision.
SINGLE_PRECISION_SAMPLES = ("positions", "velocities", "forces", "coordination")


def kept_record(run: TableRun) -> TableRun:
    """The DEM record a finished assessment keeps (``table_run.npz``): ``run`` with its
    per-sphere samples (:data:`SINGLE_PRECISION_SAMPLES`) in single precision (7 significant
    digits; ≈ 17 MB instead of 48 MB on the default job) and without its whole contacts
    (78 MB; the events made of them are in ``events.parquet``), marked so in
    ``info["kept_record"]``. Every number of the job is computed from the whole record
    (``table_run_full.npz``) before it is removed."""
    import dataclasses

    from demfem.analysis.contact_events import CONTACT_EVENT_DTYPE

    single: dict[str, Any] = {k: np.asarray(getattr(run, k)).astype(np.float32)
                              for k in SINGLE_PRECISION_SAMPLES}
    return dataclasses.replace(
        run, **single, contact_events=np.zeros(0, CONTACT_EVENT_DTYPE),
        info={**run.info, "kept_record": {
            "samples_in_single_precision": list(SINGLE_PRECISION_SAMPLES),
            "contact_events": "not kept (the assessment's events are in events.parquet)"}})


def _num(value: Any) -> float:
    """A digest's number (strict JSON writes NaN as null)."""
    return math.nan if value is None else float(value)


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
                          flaw_depth: Optional[float] = None,
                          place: str = "body") -> dict[str, Any]:
    """σ1 outside and inside of two cartridges at the calibration's ``forces`` (N), without
    friction and sliding at the table's μ (Pa), at Young's modulus ``e_stress`` (Pa), at one
    place on the cartridge (``place``; for ``"mix"`` the likeliest place of a contact between
    cartridges, :mod:`demfem.assess.places`), named in ``place``."""
    from demfem.assess.places import PLACE_WEIGHTS, PLACES, pair_place_weights
    from demfem.stress.stage import collision_stresses

    if place == "mix":
        place = PLACES[int(np.argmax(PLACE_WEIGHTS["weights"]["cartridge"]))]
    f = np.asarray(forces, float)
    kw = dict(model=model, cartridge=table.cartridge, pair_geometry=pair_geometry,
              friction=table.friction, weibull_modulus_inner=surfaces["inner"].weibull_modulus,
              weibull_modulus_outer=surfaces["outer"].weibull_modulus, flaw_depth=flaw_depth,
              place_weights=pair_place_weights(f.size, place).reshape(f.shape + (-1,)))
    speeds = np.full(f.shape, 0.0)
    code = np.zeros(f.shape, np.int64)
    still = collision_stresses(speeds, code, e_stress, table.poisson_ratio, measured_force=f,
                               measured_impulse=f * 1e-4, **kw)
    slide = collision_stresses(speeds, code, e_stress, table.poisson_ratio, measured_force=f,
                               measured_impulse=f * 1e-4, measured_tangential=table.friction * f,
                               **kw)
    return {"sigma_outer_Pa": still["sigma_outer_Pa"], "sigma_inner_Pa": still["sigma_inner_Pa"],
            "sigma_outer_sliding_Pa": slide["sigma_outer_Pa"], "place": place}


def _event_min_force(table, e_stress: float, v_min: float) -> float:
    """Peak force (N) of a cartridge–cartridge impact at ``v_min`` (m/s) at Young's modulus
    ``e_stress`` (Pa): a contact that began slower is an event if the DEM measured at least
    this force on it (pressed by the queue)."""
    from demfem.assess.impact import ImpactLaw, cartridge_body

    if v_min <= 0:
        return 0.0
    body = cartridge_body(e_stress, table.poisson_ratio, table.cartridge)
    return float(ImpactLaw(body, body).force(np.array([v_min]))[0])


def _stress_curves(ctx: JobContext, stress: dict[str, np.ndarray]) -> dict[str, Any]:
    """The model's σ1 of two cartridges over the events' force range, for the figure."""
    top = float(np.max(stress["force_N"])) if len(stress["force_N"]) else 1.0
    f = np.geomspace(max(1e-3, 1e-3 * top), max(top, 1e-2), 40)
    return {"force_N": f, "friction": ctx.table.friction,
            **_calibration_stresses(f, ctx.table, ctx.stress_young_modulus, ctx.model,
                                    ctx.pair_geometry, ctx.surfaces, ctx.flaw_depth,
                                    ctx.place)}


def _hazard_of_force(ctx: JobContext, events: np.ndarray, stress: dict[str, np.ndarray],
                     window: tuple[float, float]
                     ) -> tuple[Callable[[np.ndarray], np.ndarray], float]:
    """h(F): the hazard (both partners) of a cartridge–cartridge impact of peak force F (N) at
    the window's hard impacts' median friction ratio Q/F and the calibrated law's duration at
    F, for the tail model; and the force cap, the law's force of a 1 m/s impact (N)."""
    from demfem.assess.impact import ImpactLaw, cartridge_body
    from demfem.assess.places import pair_place_weights
    from demfem.assess.risk_stage import event_probabilities
    from demfem.stress.stage import collision_stresses

    table, e_stress, surfaces = ctx.table, ctx.stress_young_modulus, ctx.surfaces
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
                                measured_tangential=ratio * f, model=ctx.model,
                                cartridge=table.cartridge, pair_geometry=ctx.pair_geometry,
                                friction=table.friction,
                                weibull_modulus_inner=surfaces["inner"].weibull_modulus,
                                weibull_modulus_outer=surfaces["outer"].weibull_modulus,
                                flaw_depth=ctx.flaw_depth,
                                place_weights=pair_place_weights(f.size, ctx.place))
        p = event_probabilities(st, surfaces["inner"], surfaces["outer"], ctx.slow_crack_growth)
        return 2.0 * -np.log1p(-p["p_event"])

    return hazard, float(f_grid[-1])


class CalibrationStage(Stage):
    """The equivalent body, its Hertz–Reissner law at six impact speeds and the stress
    model's σ1 at their forces; product: ``calibration.json``'s content."""

    name = "calibration"
    files = ("calibration.json",)

    def title(self, ctx: JobContext) -> str:
        return "equivalent body, contact law and stress model"

    def run(self, ctx: JobContext) -> StageOutput:
        from demfem.assess.impact import ImpactLaw, cartridge_body
        from demfem.io.strict_json import write_json_atomic

        table, e_stress = ctx.table, ctx.stress_young_modulus
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
               "stress_model": ctx.settings["stress_model"], "pair_geometry": ctx.pair_geometry}
        cal.update(_calibration_stresses(law.force(np.array(speeds)), table, e_stress,
                                         ctx.model, ctx.pair_geometry, ctx.surfaces,
                                         ctx.flaw_depth, ctx.place))
        path = ctx.out / "calibration.json"
        write_json_atomic(path, cal)
        return StageOutput([path])

    def load(self, ctx: JobContext) -> dict[str, Any]:
        return json.loads((ctx.out / "calibration.json").read_text(encoding="utf-8"))

    def show(self, ctx: JobContext) -> None:
        cal, log = ctx.produced[self.name], ctx.log
        log("  v_n [m/s]: " + " ".join(f"{v:g}" for v in cal["speeds_m_per_s"]))
        log("  F [N]:     " + " ".join(f"{f:.3g}" for f in cal["force_N"]))
        log("  stress model: " + _model_words(ctx.model, ctx.pair_geometry))
        at = f" at the {cal['place']}" if "place" in cal else ""
        log(f"  sigma1 outer [MPa]{at}, no friction / at mu = "
            f"{ctx.table.friction:g}: " + " ".join(
                f"{a / 1e6:.3g}/{b / 1e6:.3g}" for a, b in zip(cal["sigma_outer_Pa"],
                                                              cal["sigma_outer_sliding_Pa"])))
        log(f"  sigma1 inner [MPa]{at}: " + " ".join(f"{a / 1e6:.3g}"
                                                     for a in cal["sigma_inner_Pa"]))


class DemStage(Stage):
    """The table run, until steady or for a fixed time, with its onsets reduced to their
    digest (:func:`demfem.assess.events.without_onsets`): the whole record
    (``table_run_full.npz``, an intermediate) and the one a finished folder keeps
    (``table_run.npz``, :func:`kept_record`); product: the whole
    :class:`~demfem.dem.table_run.TableRun` (the one in memory when it has just run)."""

    name = "dem"
    files = ("table_run.npz",)
    intermediates = ("table_run_full.npz",)

    def title(self, ctx: JobContext) -> str:
        table = ctx.table
        return (f"the table, {table.n_spheres} spheres, E = {table.young_modulus:.3g} Pa, "
                + (f"until the collision rate is steady (at most {ctx.duration:g} s)"
                   if ctx.rule else f"{ctx.duration:g} s")
                + (", re-fed" if table.refeed else ""))

    def run(self, ctx: JobContext) -> StageOutput:
        from demfem.assess.events import without_onsets
        from demfem.dem.table_run import run_table
        from demfem.progress import ProgressBar

        bar = ProgressBar(ctx.duration, label="table") if ctx.progress else None
        try:
            run = run_table(ctx.table, ctx.duration, ctx.sample_interval, threads=ctx.threads,
                            progress=bar, checkpoint=ctx.out / "table.ck",
                            checkpoint_every=ctx.checkpoint_every, fresh=ctx.fresh,
                            record_events=True, steady=ctx.rule,
                            keep_events=(ctx.min_speed,
                                         _event_min_force(ctx.table, ctx.stress_young_modulus,
                                                          ctx.min_speed)),
                            seed=ctx.seed)
        finally:
            if bar is not None:
                bar.close()
        run = without_onsets(run, ctx.min_speed)  # their counts and speeds, not ~250 MB of onsets
        full = run.save(ctx.out / "table_run_full.npz")
        kept = kept_record(run).save(ctx.out / "table_run.npz")
        return StageOutput([kept, full], run)

    def load(self, ctx: JobContext) -> TableRun:
        from demfem.dem.table_run import TableRun

        full = ctx.out / "table_run_full.npz"
        # a folder of an earlier version holds the whole record as table_run.npz
        return TableRun.load(full if full.is_file() else ctx.out / "table_run.npz")

    def recall(self, ctx: JobContext) -> TableRun:
        from demfem.dem.table_run import TableRun

        return TableRun.load(ctx.out / "table_run.npz")

    def show(self, ctx: JobContext) -> None:
        run, rule, log = ctx.produced[self.name], ctx.rule, ctx.log
        dig = run.info.get("onset_digest") or {"n_sphere_onsets": len(run.onsets),
                                                 "n_wall_onsets": len(run.wall_onsets)}
        log(f"  {run.info['steps']} steps of {run.info['dt']:.3g} s, "
            f"{dig['n_sphere_onsets'] + dig['n_wall_onsets']} contact onsets "
            f"({dig['n_sphere_onsets']} between cartridges, {dig['n_wall_onsets']} with walls, "
            f"gate and belt), wall {run.info['wall_time_s']:.1f} s")
        if rule is not None:
            end = ctx.window()[1]
            check = run.info.get("steady") or {}
            log(f"  {'steady' if check.get('steady') else 'NOT steady'} at t = {end:g} s: impacts "
                f"per {rule.period:g} s period {check.get('counts')} (standard error of the mean "
                f"{check.get('relative_error', float('nan')):.1%}, tolerance {rule.tolerance:.0%})")


class EventsStage(Stage):
    """The impact events of the table run (:func:`demfem.assess.events.impact_events`);
    product: (events, their counts)."""

    name = "events"
    intermediates = ("events.npz",)

    def title(self, ctx: JobContext) -> str:
        return f"impact events (normal speed >= {ctx.min_speed:g} m/s)"

    def run(self, ctx: JobContext) -> StageOutput:
        from demfem.assess.events import impact_events

        events, summary = impact_events(
            ctx.produced["dem"], ctx.min_speed,
            _event_min_force(ctx.table, ctx.stress_young_modulus, ctx.min_speed))
        path = ctx.out / "events.npz"
        save_npz(path, events=events, summary=np.array(json.dumps(summary)))
        return StageOutput([path])

    def load(self, ctx: JobContext) -> tuple[np.ndarray, dict[str, Any]]:
        from demfem.assess.events import EVENT_DTYPE

        data = load_npz(ctx.out / "events.npz")
        return data["events"].astype(EVENT_DTYPE), json.loads(str(data["summary"]))

    def recall(self, ctx: JobContext) -> None:
        return None

    def digest(self, ctx: JobContext) -> dict[str, Any]:
        """The events' counts (:func:`demfem.assess.events.impact_events`' summary)."""
        return dict(ctx.produced[self.name][1])

    def show(self, ctx: JobContext) -> None:
        from demfem.assess.events import count_line

        ctx.log("  " + count_line(ctx.digests[self.name]))


class StressStage(Stage):
    """Force, duration, σ1 and stressed area per event
    (:func:`demfem.stress.stage.collision_stresses`), from the DEM's measured forces when
    the stresses are at the DEM's modulus, else from the calibrated law at the onset speed;
    product: the arrays of ``stress.npz``."""

    name = "stress"
    intermediates = ("stress.npz",)

    def title(self, ctx: JobContext) -> str:
        return "force, duration, sigma1 and stressed area per event"

    @staticmethod
    def _measured(ctx: JobContext) -> bool:
        """Whether the stresses take the DEM's measured forces: they hold at its modulus
        only."""
        summary = ctx.digests["events"]
        return bool(summary.get("measured")) and math.isclose(
            float(ctx.table.young_modulus), ctx.stress_young_modulus, rel_tol=1e-12)

    def begin(self, ctx: JobContext) -> None:
        summary, e_stress = ctx.digests["events"], ctx.stress_young_modulus
        ctx.log("  forces: " + (
            "measured in the DEM (peak of each contact; duration from its impulse)"
            if self._measured(ctx) else "calibrated law at the onset speed"
            + (f" (the DEM ran at E = {ctx.table.young_modulus:.3g} Pa, the stresses "
               f"are at {e_stress:.3g} Pa)" if summary.get("measured") else "")))

    def run(self, ctx: JobContext) -> StageOutput:
        from demfem.assess.places import event_place_weights
        from demfem.stress.stage import collision_stresses

        events, surfaces = ctx.produced["events"][0], ctx.surfaces
        use_measured = self._measured(ctx)
        wall_names = [str(x) for x in ctx.produced["dem"].info.get("wall_names", [])]
        stress = collision_stresses(
            events["normal_speed"], events["partner"], ctx.stress_young_modulus,
            ctx.table.poisson_ratio,
            measured_force=events["peak_force"] if use_measured else None,
            measured_impulse=events["impulse"] if use_measured else None,
            measured_tangential=(events["peak_tangential_force"] if use_measured
                                 else None),
            model=ctx.model, cartridge=ctx.table.cartridge, pair_geometry=ctx.pair_geometry,
            friction=ctx.table.friction,
            weibull_modulus_inner=surfaces["inner"].weibull_modulus,
            weibull_modulus_outer=surfaces["outer"].weibull_modulus,
            flaw_depth=ctx.flaw_depth,
            place_weights=event_place_weights(events, wall_names, ctx.place))
        path = ctx.out / "stress.npz"
        save_npz(path, **stress)
        return StageOutput([path])

    def load(self, ctx: JobContext) -> dict[str, np.ndarray]:
        return load_npz(ctx.out / "stress.npz")

    def recall(self, ctx: JobContext) -> None:
        return None

    def digest(self, ctx: JobContext) -> dict[str, Any]:
        """The number of events and their largest force and σ1 outside and inside."""
        stress = ctx.produced[self.name]
        n = len(stress["force_N"])
        return {"n_events": n, **({k: float(np.max(stress[k])) for k in
                                   ("force_N", "sigma_outer_Pa", "sigma_inner_Pa")}
                                  if n else {})}

    def show(self, ctx: JobContext) -> None:
        d = ctx.digests[self.name]
        if d["n_events"]:
            ctx.log(f"  peak force up to {_num(d['force_N']):.3g} N, sigma1 up to "
                    f"{_num(d['sigma_outer_Pa']) / 1e6:.3g} MPa outside and "
                    f"{_num(d['sigma_inner_Pa']) / 1e6:.3g} MPa inside")


class RiskStage(Stage):
    """Weibull probabilities per event, cartridge and hour, the steady state, the worst
    events and the risk map (:func:`demfem.assess.risk_product.risk_document`); product:
    ``risk.json``'s content, which the job returns from here on."""

    name = "risk"
    files = ("risk.json", "events.parquet", "passages.parquet", "events.csv", "passages.csv",
             "events.vtp", "cartridges.vtp", "cartridge_places.vtp", "risk_arrays.npz")

    def title(self, ctx: JobContext) -> str:
        return "Weibull probabilities per event, cartridge and hour"

    def run(self, ctx: JobContext) -> StageOutput:
        from demfem.assess.risk_product import risk_document

        events, summary = ctx.produced["events"]
        stress = ctx.produced["stress"]
        window = ctx.window()
        hof, cap = _hazard_of_force(ctx, events, stress, window)
        files = risk_document(ctx.out, ctx.produced["dem"], ctx.table, events, summary, stress,
                              ctx.model, ctx.slow_crack_growth, window, ctx.throughput,
                              ctx.settings, ctx.stress_young_modulus, csv=ctx.csv,
                              surfaces=ctx.surfaces, hazard_of_force=hof, force_cap=cap)
        return StageOutput(files)

    def load(self, ctx: JobContext) -> dict[str, Any]:
        return json.loads((ctx.out / "risk.json").read_text(encoding="utf-8"))

    def show(self, ctx: JobContext) -> None:
        from demfem.assess.headline import headline, place_line

        risk = ctx.produced[self.name]
        ctx.log("  " + headline(risk["summary"]))
        if place_line(risk["summary"]):
            ctx.log("  " + place_line(risk["summary"]))
        check = risk.get("period_check") or {}
        if check.get("dominated"):
            ctx.log("  Warning: " + check["text"])

    def answer(self, ctx: JobContext) -> dict[str, Any]:
        return ctx.produced[self.name]


class ReportStage(Stage):
    """``report.html`` and its figures (:data:`demfem.assess.figures.FIGURES`) from the
    earlier stages' products; no product of its own."""

    name = "report"
    files = ("report.html", *FIGURES)

    def title(self, ctx: JobContext) -> str:
        return "report.html"

    def run(self, ctx: JobContext) -> StageOutput:
        from demfem.assess.figures import make_figures
        from demfem.assess.report import render_report
        from demfem.io.atomic import write_text_atomic

        out, table, run = ctx.out, ctx.table, ctx.produced["dem"]
        risk, stress = ctx.produced["risk"], ctx.produced["stress"]
        arrays = load_npz(out / "risk_arrays.npz")
        figs = make_figures(out, {
            "map": {k: arrays[f"map_{k}"] for k in ("hazard", "count", "x_edges", "y_edges")},
            "onset_speeds": run.info.get("onset_digest") or run.onsets["normal_speed"],
            "events": ctx.produced["events"][0],
            "window": ctx.window(), "min_speed": ctx.min_speed, "stress": stress,
            "model": ctx.model, "p_window": arrays["p_window"], "steady": risk["steady_state"],
            "walls": table.walls(), "wall_shares": risk["summary"]["wall_share_by_wall"],
            "opening": (table.x_end, table.min_opening_width, table.max_opening_width),
            "stress_curves": _stress_curves(ctx, stress),
            "duration": ctx.window()[1]})
        html_path = write_text_atomic(out / "report.html", render_report(risk, figs, FIGURES))
        return StageOutput([html_path, *(out / n for n in figs)])

    def load(self, ctx: JobContext) -> None:
        return None

    def show(self, ctx: JobContext) -> None:
        ctx.log(f"  written to {ctx.out}: report.html, risk.json, events.parquet, "
                "passages.parquet" + (" (and .csv)" if ctx.csv else "") + ", "
                "events.vtp, cartridges.vtp, cartridge_places.vtp (ParaView), "
                + ", ".join(FIGURES))

    def answer(self, ctx: JobContext) -> dict[str, Any]:
        return ctx.produced["risk"]


#: The stages of the job, in order (their names are :data:`demfem.assess.stages.STAGES`).
JOB_STAGES: tuple[Stage, ...] = (CalibrationStage(), DemStage(), EventsStage(), StressStage(),
                                  RiskStage(), ReportStage())
