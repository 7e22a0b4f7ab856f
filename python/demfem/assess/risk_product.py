"""The risk stage's products: ``risk.json`` (strict JSON), ``events.parquet``,
``passages.parquet`` (CSV on request), ``events.vtp`` and ``cartridges.vtp`` (ParaView) and
``risk_arrays.npz`` (the arrays the figures are drawn from that no other file holds: the risk
map and each passage's P), with the statement of what each number rests on (``basis``) and
the warnings of the report. Every one is kept in a finished folder; the per-event
probabilities are in ``events.parquet`` only."""
from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import Any, Optional

import numpy as np

from demfem.assess.risk_stage import (event_hazard, event_probabilities, hazard_components,
                                      partner_name, passage_risk, risk_map, steady_state,
                                      worst_events)

__all__ = ["risk_document", "VTK_EVENTS"]

#: Most events written to ``events.vtp`` (the window's likeliest to break a cartridge; ASCII
#: VTK of all ~10^6 events of a run would be ~200 MB).
VTK_EVENTS = 20_000


def _write_vtk(out: Path, run, events: np.ndarray, p: dict[str, np.ndarray],
               stress: dict[str, np.ndarray], passages: np.ndarray, pr: dict[str, Any],
               inside: np.ndarray) -> list[Path]:
    """``events.vtp``: the window's :data:`VTK_EVENTS` events with the largest P_k at their
    contact points (m), with P_k, force (N), σ1 inner and outer (Pa), time (s), partner
    (0 cartridge, 1 wall) and the cartridge; ``cartridges.vtp``: every cartridge at its last
    position on the table (m) with its last passage's P over the window, events and hazard.
    For ParaView (Glyph or Point Gaussian)."""
    from demfem.io.vtk import write_vtp

    idx = np.flatnonzero(inside)
    idx = idx[np.argsort(-p["p_event"][idx], kind="stable")][:VTK_EVENTS]
    pts = np.column_stack([events["x"][idx], events["y"][idx], events["z"][idx]])
    ok = np.all(np.isfinite(pts), axis=1)
    idx, pts = idx[ok], pts[ok]
    files = [write_vtp(out / "events.vtp", pts, {
        "p_event": p["p_event"][idx], "force_N": stress["force_N"][idx],
        "sigma_inner_Pa": stress["sigma_inner_Pa"][idx],
        "sigma_outer_Pa": stress["sigma_outer_Pa"][idx], "time_s": events["time"][idx],
        "partner": events["partner"][idx].astype(np.int64),
        "cartridge": events["i"][idx].astype(np.int64)})]
    pos = np.asarray(run.positions, float)
    finite = np.all(np.isfinite(pos), axis=2)
    last = np.where(finite.any(axis=0), pos.shape[0] - 1 - np.argmax(finite[::-1], axis=0), -1)
    seen = last >= 0
    where = pos[last[seen], np.flatnonzero(seen)]
    # each sphere's last passage (the table is sorted by sphere id, then start)
    latest = np.full(run.n_particles, -1, np.int64)
    latest[passages["particle"]] = np.arange(len(passages))
    k = latest[seen]
    files.append(write_vtp(out / "cartridges.vtp", where, {
        "cartridge": np.flatnonzero(seen).astype(np.int64),
        "radius": np.asarray(run.radii, float)[seen],
        "passage": k, "p_window": pr["p_window"][k],
        "n_events": np.asarray(pr["n_events"], np.int64)[k],
        "hazard": pr["hazard"][k]}))
    return files


def _write_places_vtk(out: Path, run, cartridge: Any, events: np.ndarray,
                      p: dict[str, np.ndarray], stress: dict[str, np.ndarray],
                      inside: np.ndarray) -> Path:
    """``cartridge_places.vtp``: the events of ``events.vtp`` at their places on one
    reference cartridge (its frame: z up its axis from the open end, m): a point on the
    outer surface per event and place it may land on (rim t/2 above the end, mid-body, or
    t/2 below the shoulder), at the azimuth of the contact point seen from the cartridge's
    centre on the table; with that place's term of P_k (``p_event_place``), the place
    (0 body, 1 rim, 2 shoulder), its weight, the event and its force (N)."""
    from demfem.assess.events import centres_at
    from demfem.io.vtk import write_vtp

    c = cartridge
    idx = np.flatnonzero(inside)
    idx = idx[np.argsort(-p["p_event"][idx], kind="stable")][:VTK_EVENTS]
    t, r = c.wall_thickness, 0.5 * c.body_outer_diameter
    heights = np.array([0.5 * c.body_length, 0.5 * t, c.body_length - 0.5 * t])
    centre = centres_at(run, events["time"][idx], np.asarray(events["i"][idx], np.int64))
    theta = np.arctan2(events["y"][idx] - centre[:, 1], events["x"][idx] - centre[:, 0])
    w = np.asarray(p["place_weight"], float)[idx]
    ev, pl = np.nonzero(w > 0)
    pts = np.column_stack([r * np.cos(theta[ev]), r * np.sin(theta[ev]), heights[pl]])
    ok = np.all(np.isfinite(pts), axis=1)
    ev, pl, pts = ev[ok], pl[ok], pts[ok]
    k = idx[ev]
    return write_vtp(out / "cartridge_places.vtp", pts, {
        "p_event_place": np.asarray(p["p_event_by_place"], float)[k, pl],
        "place": pl.astype(np.int64), "weight": w[ev, pl], "event": k.astype(np.int64),
        "force_N": stress["force_N"][k],
        "sigma_outer_Pa": np.asarray(stress["sigma_outer_Pa_by_place"], float)[k, pl],
        "sigma_inner_Pa": np.asarray(stress["sigma_inner_Pa_by_place"], float)[k, pl]})


def _place_summary(p: dict[str, np.ndarray], parts: dict[str, np.ndarray],
                   inside: np.ndarray) -> dict[str, Any]:
    """Shares of the window's hazard by place on the cartridge (``place_share``) and by
    place and surface (``place_surface_share``) from the events' hazard ``parts``
    (:func:`hazard_components`), when the events have places."""
    if "place_weight" not in p:
        return {}
    tot = sum(float(v[inside].sum()) for v in parts.values())
    if tot <= 0:
        return {"place_share": None, "place_surface_share": None}
    both = {k: float(v[inside].sum()) / tot for k, v in parts.items()}
    places: dict[str, float] = {}
    for k, v in both.items():
        places[k.split()[0]] = places.get(k.split()[0], 0.0) + v
    return {"place_share": places, "place_surface_share": both}


def _place_columns(stress: dict[str, np.ndarray], p: dict[str, np.ndarray]
                   ) -> dict[str, np.ndarray]:
    """``events.parquet``'s place columns: the worst place the event may land on (whose σ1
    the stress columns hold) and each place's term w_p P_k,p of ``p_event``."""
    from demfem.stress.model import LOCATIONS

    if "place_weight" not in p:
        return {}
    cols: dict[str, np.ndarray] = {
        "place": np.asarray(LOCATIONS, dtype="U8")[np.asarray(stress["place_index"],
                                                               np.int64)]}
    for j, name in enumerate(LOCATIONS):
        cols[f"weight_{name}"] = np.asarray(p["place_weight"], float)[:, j]
        cols[f"p_event_{name}"] = np.asarray(p["p_event_by_place"], float)[:, j]
    return cols


def _stress_basis(model: Any, settings: dict[str, Any]) -> str:
    """What the stresses rest on, in words."""
    from demfem.stress.stress_model import StressModel

    if isinstance(model, StressModel) or model == "shell":
        m = StressModel.default() if model == "shell" else model
        return (f"Stress model (shell bending only): sigma1 = beta F/t^2 with beta_inner = "
                f"{m.beta_inner:.4g}, beta_outer = {m.beta_outer:.4g}, t = {m.thickness:g} m; "
                f"stressed areas {m.area_factor_inner:.4g} (inner) and "
                f"{m.area_factor_outer:.4g} (outer) times the Hertz patch pi a^2. Source: "
                f"{m.source}. It leaves out the contact stress on the outer surface.")
    pair = settings.get("pair_geometry", "crossed")
    depth = settings.get("flaw_depth_m")
    place = settings.get("place", "body")
    return ("Stress model (demfem.stress, docs/stress.md): on the outer surface the contact "
            "field with the measured friction force (Hertz; Hamilton 1983: the trailing-edge "
            "tension p0 [(1 - 2 nu)/3 + (4 + nu) pi mu/8]) on top of the wall's bending, on "
            "the inner surface the bending tension under the load (the body as a cylindrical "
            "shell: Bijlaard's double series in Sanders-Koiter theory with the wall's "
            "thick-plate correction; the ring under a line load); Weibull effective areas of "
            "both fields. The DEM's spheres carry no axis, so the geometry is assumed: two "
            "cartridges "
            + ("crossed at 90 degrees (a point contact: the severe case)" if pair == "crossed"
               else "side by side along the body (a line contact)")
            + ", walls and gate along the body (a line contact). "
            + (f"The contact-edge tension is taken as a flaw {depth:.3g} m deep feels it (the "
               "flaw that fails at the outer surface's characteristic strength unless given; "
               "docs/stress.md)." if depth else
               "No flaw-depth correction: the surface value of the contact-edge tension "
               "(conservative where the contact field is shallower than the flaws).")
            + " " + _place_basis(place))


def _place_basis(place: str) -> str:
    """Where on the cartridge the events are taken to land, in words."""
    from demfem.assess.places import PLACE_WEIGHTS

    if place != "mix":
        return (f"Place on the cartridge: every event at the {place} "
                + ("(mid-body, away from the rim and the shoulder)." if place == "body" else
                   "(the stress model's FEM factors for that place, docs/stress.md)."))
    w = PLACE_WEIGHTS["weights"]["cartridge"]
    return ("Place on the cartridge: the spheres carry no height, so each event's place is "
            "weighted by the full-shape table's counts for its partner (docs/cartridge-"
            f"places.md): between cartridges body {w[0]:.0%}, rim {w[1]:.0%}, shoulder "
            f"{w[2]:.0%}; P_k is the expectation over the places, and the hazard splits by "
            "place exactly. The place is not conditioned on the force (the full-shape table "
            "recorded it per partner only).")


def _basis(model, scg, ev_summary: dict[str, Any], e_stress: float, table,
           stress: dict[str, np.ndarray], surfaces: dict[str, Any],
           settings: Optional[dict[str, Any]] = None) -> list[str]:
    inner, outer = surfaces["inner"], surfaces["outer"]

    measured = ev_summary.get("measured") and math.isclose(float(table.young_modulus), e_stress,
                                                           rel_tol=1e-12)
    if measured:
        law = stress["law_force_N"]
        ok = law > 0
        ratio = (float(np.median(stress["force_N"][ok] / law[ok])) if ok.any() else math.nan)
        force_line = (
            "Peak force: measured in the DEM, the largest normal force of each contact over "
            "the steps it lasted (the table's damping and the queue's pressure included); its "
            "duration is that of the half-sine with the measured peak and impulse, "
            "(pi/2) J / F_max. The median ratio of the measured peak to the calibrated "
            f"Hertz-Reissner law's at the onset speed is {ratio:.3g}.")
    else:
        force_line = (
            "Peak force: the calibrated Hertz-Reissner law (paper eq. 12, demfem.contact."
            f"max_contact_force) at E = {e_stress:.3g} Pa for the default 3 mL cartridge's "
            "equivalent body; the DEM's restitution (damping) is not applied to the peak "
            "(undamped, an upper bound).")
    lines = [
        "Impact speeds: the DEM of the table (equivalent spheres, Hertz-Reissner-Mindlin "
        f"contacts, E = {table.young_modulus:.3g} Pa"
        + (", re-fed: the table in operation" if table.refeed else ", not re-fed: a batch")
        + f"); every contact onset with normal speed >= {ev_summary['min_speed_m_per_s']:g} "
        "m/s is an event"
        + (" (and a slower one that the DEM pressed to at least the force of an impact at that "
           "speed)" if ev_summary.get("measured") else "")
        + f" ({ev_summary['n_dropped']} slower onsets dropped, the fastest of them at "
        f"{ev_summary['max_dropped_speed_m_per_s']:.3g} m/s). {ev_summary['note']}.",
        force_line,
        _stress_basis(model, settings or {}),
        ("Weibull strength (planning assumptions, NOT measured on any product)"
         if not surfaces["measured"] else
         f"Weibull strength (measured: {', '.join(surfaces['measured'])} surface)")
        + f": inner m = {inner.weibull_modulus:.3g}, sigma_0 = "
        f"{inner.characteristic_strength / 1e6:.4g} MPa on A_0 = {inner.reference_area:g} m^2; "
        f"outer m = {outer.weibull_modulus:.3g}, sigma_0 = "
        f"{outer.characteristic_strength / 1e6:.4g} MPa on A_0 = {outer.reference_area:g} m^2. "
        f"Source: {surfaces['source']}. With m = 6-10, a 20 % change of sigma_0 changes P by a "
        "factor 3-9: the absolute probabilities are only as good as the strength data, their "
        "ratios between table settings much better.",
        ("Slow crack growth: half-sine pulse of the contact duration, equivalent static "
         f"stress over t_ref = {scg.reference_time:g} s with n = {scg.crack_growth_exponent:g} "
         f"({scg.source})." if scg is not None else
         "Slow crack growth: off (the peak stress acts as if held over the strength test)."),
        "Combination: collisions and surfaces independent, P = 1 - prod(1 - P_k) "
        "(conservative for repeated hits on one spot); both cartridges of a collision get "
        "their own P_k.",
        "Per hour: hazard rate per cartridge over the window, residence time by Little's law "
        "(mean number on the table / throughput); for small P the hourly number is 3600 x "
        "the summed hazard rate of the simulated population, independent of the throughput "
        "as long as the table holds that population.",
    ]
    return lines


def _interval(events: np.ndarray, p: dict[str, np.ndarray], parts: dict[str, np.ndarray],
              inside: np.ndarray, window: tuple[float, float], period: Optional[float],
              wall_names: list[str], pr: dict[str, Any]) -> dict[str, Any]:
    """The 95 % interval of the hourly number over whole gate periods (block totals,
    Student-t on the log scale: :func:`demfem.risk.interval.hourly_interval_from_events`),
    with its splits by place on the table, by partner, by surface (mechanism) and, with
    places, by place on the cartridge and by place and surface (the events' hazard
    ``parts``, :func:`hazard_components`), carried onto the headline figures as relative
    bounds. Without two whole periods: no interval."""
    from demfem.risk.interval import hourly_interval_from_events

    block = float(period) if period else 1.0
    ev = events[inside]
    parts = {k: v[inside] for k, v in parts.items()}
    places_on = "place_weight" in p
    comps: dict[str, np.ndarray] = parts
    if places_on:  # the surfaces summed over the places
        comps = {s: np.sum([v for k, v in parts.items() if k.endswith(" " + s)], axis=0)
                 for s in ("outer", "inner")}
    ci = hourly_interval_from_events(ev, p["p_event"][inside], window, block,
                                     wall_names=wall_names, components=comps)
    if places_on:
        places = {pl: parts[f"{pl} outer"] + parts[f"{pl} inner"]
                  for pl in {k.split()[0]: None for k in parts}}
        by_place = hourly_interval_from_events(ev, p["p_event"][inside], window, block,
                                               wall_names=wall_names, components=places)
        by_both = hourly_interval_from_events(ev, p["p_event"][inside], window, block,
                                              wall_names=wall_names, components=parts)
        splits = dict(ci.splits)
        splits["place"] = by_place.splits.get("component", {})
        splits["place_surface"] = by_both.splits.get("component", {})
        ci = replace(ci, splits=splits)

    def carried(value: float) -> Optional[list[float]]:
        if not (ci.estimable and ci.estimate > 0 and math.isfinite(value)):
            return None
        return [value * ci.lower / ci.estimate, value * ci.upper / ci.estimate]

    doc = ci.to_dict()
    doc["note"] = ("per hour at the table's own state, over the whole gate periods of the "
                   "window (block totals of the hazard, Student-t on the log scale); the "
                   "headline's interval is this one's relative width carried onto it")
    return {"headline": carried(pr["broken_per_hour"]),
            "table": carried(pr["broken_per_hour_table"]), "document": doc}


def _period_check(events: np.ndarray, hazard: np.ndarray, inside: np.ndarray,
                  window: tuple[float, float], period: Optional[float],
                  wall_names: list[str], stress: dict[str, np.ndarray]) -> dict[str, Any]:
    """Whether one gate period dominates the window's hazard
    (:func:`demfem.risk.rare_periods.period_dominance`), with a sentence for the report: the
    dominant period and its largest event, or how rare dominant periods must be for the
    window to have missed them. Without a gate or two whole periods: its status only."""
    from demfem.errors import InvalidParameterError
    from demfem.risk.rare_periods import period_dominance

    if not period:
        return {"status": "no gate period"}
    try:
        d = period_dominance(events["time"][inside], hazard[inside], window, float(period))
    except InvalidParameterError as exc:
        return {"status": f"not checked: {exc}"}
    doc: dict[str, Any] = {"status": "ok", **d.to_dict()}
    if d.dominated:
        a, b = d.largest_window_s
        sel = np.flatnonzero(inside & (events["time"] >= a) & (events["time"] < b))
        k = int(sel[np.argmax(hazard[sel])])
        who = ("another cartridge" if int(events["partner"][k]) == 0 else
               partner_name(events[k], wall_names).replace("_", " "))
        share = d.largest_share
        doc["largest_event"] = {"event": k, "time_s": float(events["time"][k]), "with": who,
                                "force_N": float(stress["force_N"][k]),
                                "share_of_period": float(hazard[k] / d.largest)}
        doc["text"] = (
            f"One gate period dominates the hourly number: t = {a:.4g}–{b:.4g} s carries "
            f"{share:.0%} of the window's hazard, {d.largest_over_median:.3g} times the median "
            f"period's (its largest event: cartridge {int(events['i'][k])} against {who} at "
            f"{float(stress['force_N'][k]):.3g} N, t = {float(events['time'][k]):.4g} s). A "
            f"rare event of another kind than the ordinary periods' (a jam) carries the number,"
            f" and {d.n_periods} periods cannot say how often it happens: the interval does "
            "not describe that uncertainty. Run longer (--duration) or replicas "
            "(--replicas) to measure the rate of such periods (docs/uncertainty.md).")
    else:
        doc["text"] = (
            f"No gate period carries more than {d.ratio:g} times the median period's hazard "
            f"(the largest {d.largest_over_median:.3g} times). The interval is conditional on "
            f"such periods (jams) being rare: {d.n_periods} periods without one bound them "
            f"only to at most {d.unseen_bound:.0%} of the periods ({d.confidence:.0%}, "
            "one-sided); on the default table a 62-s run had one in 30 periods, and it "
            "raised the hourly number 2.7-fold (docs/uncertainty.md).")
    return doc


def _tail(events: np.ndarray, stress: dict[str, np.ndarray], p: dict[str, np.ndarray],
          inside: np.ndarray, window: tuple[float, float], period: Optional[float],
          hazard_of_force: Any, force_cap: float) -> dict[str, Any]:
    """Peaks over threshold of the window's cartridge–cartridge peak forces
    (:mod:`demfem.risk.tail`): the GPD fit with its threshold diagnostic, the expected rate of
    impacts harder than any seen, and the hazard per hour with the events above the threshold
    replaced by the model's expectation (forces capped at ``force_cap``, N), beside the
    counted one. A window too short for a fit says why."""
    from demfem.errors import InvalidParameterError
    from demfem.risk.tail import expected_beyond, fit_tail, tail_corrected_rate

    sel = inside & (events["partner"] == 0)
    f = np.asarray(stress["force_N"], float)[sel]
    h = 2.0 * -np.log1p(-np.asarray(p["p_event"], float)[sel])
    w = float(window[1] - window[0])
    try:
        model = fit_tail(f, w)
        beyond = expected_beyond(model, hazard_of_force, upper=force_cap)
        corrected = tail_corrected_rate(f, h, w, hazard_of_force, model=model,
                                        upper=force_cap, times=events["time"][sel],
                                        window=window, period=period or 1.0)
    except InvalidParameterError as exc:
        return {"status": f"no tail model: {exc}"}
    per_h = 3600.0
    return {"status": "ok", "threshold_N": model.threshold, "shape": model.shape,
            "shape_se": model.shape_se, "scale_N": model.scale,
            "n_exceedances": model.n_exceedances, "largest_force_N": model.max_value,
            "force_cap_N": force_cap,
            "impacts_beyond_largest_per_hour": per_h * beyond.rate_beyond,
            "hazard_beyond_largest_per_hour": [per_h * beyond.estimate, per_h * beyond.lower,
                                               per_h * beyond.upper],
            "pairs_hazard_per_hour_counted": per_h * corrected.empirical,
            "pairs_hazard_per_hour_tail_model": [per_h * corrected.estimate,
                                                 per_h * corrected.lower,
                                                 per_h * corrected.upper],
            "note": "cartridge-cartridge events; the hazard of an impact of force F from the "
                    "stress model with the tail events' median friction ratio and the law's "
                    "duration at F; both partners counted"}


def risk_document(out: Path, run, table, events: np.ndarray, ev_summary: dict[str, Any],
                  stress: dict[str, np.ndarray], model, scg, window: tuple[float, float],
                  throughput: Optional[float], settings: dict[str, Any],
                  e_stress: float, csv: bool = False,
                  surfaces: Optional[dict[str, Any]] = None,
                  hazard_of_force: Any = None, force_cap: float = math.inf) -> list[Path]:
    """Compute the risk stage and write its files into ``out`` (``events.parquet``,
    ``passages.parquet`` and, with ``csv``, the same as CSV); returns their paths."""
    from demfem.assess.npz import flatten, save_npz
    from demfem.assess.tables import events_columns, passages_columns, write_table
    from demfem.io.strict_json import write_json_atomic
    from demfem.materials import PAPER_GLASS
    from demfem.risk import INNER_SURFACE, OUTER_SURFACE

    if surfaces is None:
        surfaces = {"inner": INNER_SURFACE, "outer": OUTER_SURFACE, "measured": [],
                    "source": "planning assumptions of demfem.risk"}
    p = event_probabilities(stress, surfaces["inner"], surfaces["outer"], scg)
    passages = run.passages()
    pr = passage_risk(events, p["p_event"], passages, window, throughput)
    rule = settings.get("until_steady") or {}
    period = rule.get("period") or (float(table.gate_period) if table.gate_amplitude > 0
                                    else None)
    steady = steady_state(events, p["p_event"], window, period, rule.get("tolerance", 0.10))
    wall_names = [str(x) for x in run.info.get("wall_names", [])]
    worst = worst_events(events, p, stress, window, wall_names=wall_names)
    pos = run.positions[np.isfinite(run.positions[..., 0])]
    pad = float(np.max(run.radii))
    extent = (float(pos[:, 0].min()) - pad, float(pos[:, 0].max()) + pad,
              float(pos[:, 1].min()) - pad, float(pos[:, 1].max()) + pad)
    rmap = risk_map(events, p["p_event"], window, extent)
    inside = (events["time"] >= window[0]) & (events["time"] <= window[1])
    # shares of the cartridges' hazard: an impact of two cartridges loads both
    h_in = float(event_hazard(events, p["p_inner"])[inside].sum())
    h_out = float(event_hazard(events, p["p_outer"])[inside].sum())
    hazard = event_hazard(events, p["p_event"])
    h_all = float(hazard[inside].sum())
    by_wall = {name: float(hazard[inside & (events["wall"] == k)].sum()) / h_all
               for k, name in enumerate(wall_names)
               if h_all > 0 and np.any(inside & (events["wall"] == k))}
    w = pr["window_s"]
    parts = hazard_components(events, p)  # by surface, and by place when there are places
    ci = _interval(events, p, parts, inside, window, period, wall_names, pr)
    periods = _period_check(events, hazard, inside, window, period, wall_names, stress)

    def mx(a: np.ndarray) -> Optional[float]:
        return float(np.max(a)) if a.size else None

    summary = {
        "n_events_window": int(inside.sum()),
        "event_rate_per_s": float(inside.sum() / w) if w > 0 else math.nan,
        "mean_on_table": pr["mean_on_table"], "exits_window": pr["exits"],
        "discharge_per_hour": pr["discharge_per_hour"],
        "residence_time_s": pr["residence_time_s"],
        "passages_in_window": pr["passages_in_window"],
        "p_passage": pr["p_passage"],
        "p_window_max": mx(pr["p_window"]),
        "throughput_per_hour": pr["throughput_per_hour"],
        "throughput_source": pr["throughput_source"],
        "broken_per_hour": pr["broken_per_hour"],
        "broken_per_hour_table": pr["broken_per_hour_table"],
        "broken_per_hour_small_p": pr["broken_per_hour_small_p"],
        "broken_per_hour_at_throughput": pr["broken_per_hour_at_throughput"],
        "broken_per_hour_ci95": ci["headline"],
        "broken_per_hour_table_ci95": ci["table"],
        "unassigned_events": pr["unassigned_events"],
        "inner_share": h_in / (h_in + h_out) if h_in + h_out > 0 else math.nan,
        "n_wall_events_window": int(np.sum(inside & (events["partner"] == 1))),
        "wall_share": (float(hazard[inside & (events["partner"] == 1)].sum()) / h_all
                       if h_all > 0 else math.nan),
        "wall_share_by_wall": by_wall,
        "max_force_N": mx(stress["force_N"][inside]),
        "forces_measured": bool(ev_summary.get("measured")) and math.isclose(
            float(table.young_modulus), e_stress, rel_tol=1e-12),
        "max_sigma_inner_Pa": mx(stress["sigma_inner_Pa"][inside]),
        "max_sigma_outer_Pa": mx(stress["sigma_outer_Pa"][inside]),
        **_place_summary(p, parts, inside),
    }
    warnings = []
    if table.young_modulus < PAPER_GLASS.E:
        warnings.append(f"The DEM runs at a reduced Young's modulus E = "
                        f"{table.young_modulus:.3g} Pa (glass: {PAPER_GLASS.E:.3g} Pa): the "
                        "impact speeds come from a softer table; the forces are evaluated at "
                        f"E = {e_stress:.3g} Pa. Measured effect (docs/accuracy-cost.md, "
                        "docs/studies.md): at 1e8 Pa the coordination is off by 27 %, the "
                        "speeds by 25 %, the forces by 60-70 % (2-4x lower than at 45 GPa) and "
                        "the collision-speed distribution by a KS distance of 0.49; the "
                        "ranking of set-ups survives (Spearman 0.92), the numbers do not.")
    if not steady["steady"]:
        warnings.append(
            "The collision rate drifts across the statistics window ("
            + (f"the mean events of its {len(steady['period_events'])} gate periods have a "
               f"relative standard error of {steady['relative_error']:.0%}, tolerance "
               f"{steady['tolerance']:.0%}" if steady["criterion"] == "periods" else
               f"Poisson z = {steady['poisson_z']:.2f}")
            + "): the window is not a steady state; run longer (--full, --duration).")
    if not table.refeed:
        warnings.append("The table is not re-fed: it drains as cartridges leave, so its "
                        "collision rate has no steady state (assess re-feeds by default).")
    if pr["exits"] == 0:
        warnings.append("No cartridge left the table in the statistics window: the table's "
                        "own throughput is unknown"
                        + (", the probability per passage uses the throughput given"
                           if throughput is not None else
                           "; give --throughput for a probability per passage") + ".")
    if w < 0.5:
        warnings.append(f"Short statistics window ({w:.3g} s, less than a quarter of the "
                        "gate period of the default table): a smoke run, not an assessment.")
    if periods.get("dominated"):
        warnings.append(periods["text"])
    tail = (_tail(events, stress, p, inside, window, period, hazard_of_force, force_cap)
            if hazard_of_force is not None else {"status": "not asked for"})
    doc = {"format": 2, "summary": summary, "interval": ci["document"], "tail": tail,
           "period_check": periods,
           "steady_state": steady, "worst_events": worst,
           "events": ev_summary, "warnings": warnings,
           "basis": _basis(model, scg, ev_summary, e_stress, table, stress, surfaces, settings),
           "strength": {"source": surfaces["source"], "measured": surfaces["measured"]},
           "window_s": list(window), "settings": settings,
           "settings_flat": {k: v for k, v in flatten(settings).items()
                             if not k.startswith("stress_model.units")}}
    files = [write_json_atomic(out / "risk.json", doc)]
    extra = {"passage_i": pr["passage_i"], "passage_j": pr["passage_j"],
             "pressed": events["pressed"],
             "peak_tangential_force_N": events["peak_tangential_force"],
             "force_N": stress["force_N"], "contact_radius_m": stress["contact_radius_m"],
             "duration_s": stress["duration_s"], "law_force_N": stress["law_force_N"],
             "sigma_inner_Pa": stress["sigma_inner_Pa"],
             "sigma_outer_Pa": stress["sigma_outer_Pa"],
             "area_inner_m2": stress["area_inner_m2"], "area_outer_m2": stress["area_outer_m2"],
             "p_inner": p["p_inner"], "p_outer": p["p_outer"], "p_event": p["p_event"],
             "in_window": inside, **_place_columns(stress, p)}
    files += write_table(out / "events.parquet", events_columns(events, extra, wall_names),
                         csv)
    files += write_table(out / "passages.parquet", passages_columns(passages, run.tags, pr),
                         csv)
    files += _write_vtk(out, run, events, p, stress, passages, pr, inside)
    if "place_weight" in p:
        files.append(_write_places_vtk(out, run, table.cartridge, events, p, stress, inside))
    files.append(save_npz(out / "risk_arrays.npz", p_window=pr["p_window"],
                          **{f"map_{k}": v for k, v in rmap.items()}))
    return files
