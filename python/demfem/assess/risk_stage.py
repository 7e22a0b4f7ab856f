"""Risk: from each collision's surface stresses to a breakage probability per cartridge and
an expected number of broken cartridges per hour.

Per event k and surface s (inner, outer), Weibull weakest link on the effective area
(:mod:`demfem.risk`, ASTM C1683):

    P_k,s = 1 − exp(−(A_k,s / A_0) (σ_k,s / σ_0)^m)      (σ ≤ 0 or A = 0: P = 0)

with, when slow crack growth is on (default), σ the equivalent static stress of the
half-sine pulse of the collision's contact duration τ_k over the strength test's reference
time t_ref, σ_eq = σ_p [(τ/t_ref) Γ((n+1)/2)/(√π Γ(n/2+1))]^{1/n}
(:func:`demfem.risk.half_sine_equivalent_stress`, n = 25 for borosilicate). A collision breaks
one of its two cartridges with P_k = 1 − (1 − P_k,inner)(1 − P_k,outer); both partners of a
sphere–sphere collision take the same load and each gets its own P_k (independent glass).

The unit of risk is a passage: one cartridge from its insertion on the table to its exit
(:mod:`demfem.assess.passages`; a re-fed sphere id carries several). Over the statistics
window [t_0, T] (W = T − t_0), passage p with events k survives with Π(1 − P_k):
P_window,p = 1 − Π(1 − P_k). The table breaks Σ_p P_window,p / W cartridges per second; that
times 3600 is the hourly number, the same whichever way it is summed (per event for small P:
3600 Σ h_k / W, h_k = −ln(1 − P_k) per loaded cartridge). The probability that one passage
breaks is that rate over the table's own discharge (exits / W) — or over a throughput the
user names, when the window has no exits. A user's throughput Q different from the table's
gives Q × P_passage per hour beside the table's own figure: it assumes the table in
production looks like the simulated one, which the discharge rate shown beside it lets the
user judge. The steady state of the window is checked by :func:`steady_state`.

SI units: Pa, m², s; rates per second unless named per hour.
"""
from __future__ import annotations

import math
from typing import Any, Optional, Sequence

import numpy as np

from demfem.errors import InvalidParameterError, check_positive, check_range
from demfem.risk import (INNER_SURFACE, OUTER_SURFACE, SCG_BOROSILICATE, SlowCrackGrowth,
                         SurfaceStrength)
from demfem.risk.fatigue import half_sine_sn_factor

__all__ = ["event_probabilities", "surface_probability", "hazard_components",
           "equivalent_stress", "passage_risk", "event_hazard", "steady_state",
           "worst_events", "partner_name", "risk_map"]

def surface_probability(surface: SurfaceStrength, stress: np.ndarray,
                        area: np.ndarray) -> np.ndarray:
    """Per-event failure probability of one surface, vectorised: the single-element case of
    :meth:`SurfaceStrength.failure_probability` (the same formula, evaluated in log space:
    exact down to P ~ 1e-300). ``stress`` in Pa, ``area`` in m², shape (n,)."""
    s = np.asarray(stress, float)
    a = np.asarray(area, float)
    if np.any(np.isnan(s)) or np.any(np.isinf(s)):
        raise InvalidParameterError("invalid stress: every value must be a finite number of "
                                    "Pa (NaN or infinite found)")
    if np.any(~np.isfinite(a)) or np.any(a < 0):
        raise InvalidParameterError("invalid area: every value must be a finite number of m² "
                                    ">= 0")
    out = np.zeros(np.broadcast(s, a).shape)
    on = (s > 0) & (a > 0)
    log_r = (np.log(a[on] / surface.reference_area)
             + surface.weibull_modulus * np.log(s[on] / surface.characteristic_strength))
    out[on] = -np.expm1(-np.exp(np.minimum(log_r, 700.0)))
    return out


def equivalent_stress(peak: np.ndarray, duration: np.ndarray,
                      scg: Optional[SlowCrackGrowth]) -> np.ndarray:
    """σ_eq (Pa) of half-sine pulses of peak ``peak`` (Pa) lasting ``duration`` (s) over the
    reference time of ``scg`` (:func:`demfem.risk.half_sine_equivalent_stress`, vectorised
    over durations); ``scg=None``: the peak itself (no slow crack growth)."""
    peak = np.asarray(peak, float)
    if scg is None:
        return np.maximum(peak, 0.0)
    n = scg.crack_growth_exponent
    factor = (np.asarray(duration, float) / scg.reference_time * half_sine_sn_factor(n)) ** (1 / n)
    return np.maximum(peak, 0.0) * factor


def event_probabilities(stress: dict[str, np.ndarray], inner: SurfaceStrength = INNER_SURFACE,
                        outer: SurfaceStrength = OUTER_SURFACE,
                        scg: Optional[SlowCrackGrowth] = SCG_BOROSILICATE) -> dict[str, np.ndarray]:
    """``p_inner``, ``p_outer``, ``p_event`` and the stresses used (``sigma_eq_inner_Pa``,
    ``sigma_eq_outer_Pa``) of each event from the stress stage's arrays ``sigma_inner_Pa``,
    ``sigma_outer_Pa``, ``area_inner_m2``, ``area_outer_m2``, ``duration_s``.

    With places (the stress stage's ``place_weight`` and ``*_by_place`` arrays,
    :mod:`demfem.assess.places`): the expectation over the event's place,
    P_k = Σ_p w_p P_k,p, and the same for each surface; ``p_event_by_place``,
    ``p_inner_by_place``, ``p_outer_by_place`` (n, 3) hold the terms w_p P_k,p, whose rows
    sum to ``p_event``, ``p_inner``, ``p_outer``. The equivalent stresses are those of the
    worst place (the one-value stress fields)."""
    tau = stress["duration_s"]
    s_in = equivalent_stress(stress["sigma_inner_Pa"], tau, scg)
    s_out = equivalent_stress(stress["sigma_outer_Pa"], tau, scg)
    if "place_weight" not in stress:
        p_in = surface_probability(inner, s_in, stress["area_inner_m2"])
        p_out = surface_probability(outer, s_out, stress["area_outer_m2"])
        p = -np.expm1(np.log1p(-p_in) + np.log1p(-p_out))
        return {"p_inner": p_in, "p_outer": p_out, "p_event": p,
                "sigma_eq_inner_Pa": s_in, "sigma_eq_outer_Pa": s_out}
    w = np.asarray(stress["place_weight"], float)
    tau2 = np.asarray(tau, float)[:, None]
    pi = surface_probability(inner, equivalent_stress(stress["sigma_inner_Pa_by_place"], tau2,
                                                      scg), stress["area_inner_m2_by_place"])
    po = surface_probability(outer, equivalent_stress(stress["sigma_outer_Pa_by_place"], tau2,
                                                      scg), stress["area_outer_m2_by_place"])
    pe = -np.expm1(np.log1p(-pi) + np.log1p(-po))
    by = {"p_inner_by_place": w * pi, "p_outer_by_place": w * po, "p_event_by_place": w * pe}
    return {"p_inner": by["p_inner_by_place"].sum(axis=1),
            "p_outer": by["p_outer_by_place"].sum(axis=1),
            "p_event": by["p_event_by_place"].sum(axis=1), **by,
            "p_inner_at_place": pi, "p_outer_at_place": po, "place_weight": w,
            "sigma_eq_inner_Pa": s_in, "sigma_eq_outer_Pa": s_out}


def hazard_components(events: np.ndarray, p: dict[str, np.ndarray],
                      by_place: bool = True) -> dict[str, np.ndarray]:
    """The hazard each event puts on the cartridges (:func:`event_hazard`) split into parts
    that add up to it exactly: by surface (``outer``, ``inner``), and with places (and
    ``by_place``) by place and surface (``"rim outer"``, ``"body inner"``, …; the place's
    weight times its hazard −ln(1 − P_k,p,s), in proportion). ``by_place=False`` with places
    gives the two surfaces summed over the places."""
    from demfem.stress.model import LOCATIONS

    loads = np.where(events["j"] >= 0, 2.0, 1.0)
    h = -np.log1p(-np.asarray(p["p_event"], float)) * loads
    if "p_inner_at_place" not in p:
        hi = -np.log1p(-np.asarray(p["p_inner"], float))
        ho = -np.log1p(-np.asarray(p["p_outer"], float))
        tot = hi + ho
        safe = np.where(tot > 0, tot, 1.0)
        return {"outer": np.where(tot > 0, h * ho / safe, 0.0),
                "inner": np.where(tot > 0, h * hi / safe, 0.0)}
    w = np.asarray(p["place_weight"], float)
    parts = {"outer": w * -np.log1p(-np.asarray(p["p_outer_at_place"], float)),
             "inner": w * -np.log1p(-np.asarray(p["p_inner_at_place"], float))}
    tot = parts["outer"].sum(axis=1) + parts["inner"].sum(axis=1)
    scale = np.where(tot > 0, h / np.where(tot > 0, tot, 1.0), 0.0)
    if not by_place:
        return {s: parts[s].sum(axis=1) * scale for s in ("outer", "inner")}
    return {f"{place} {s}": parts[s][:, j] * scale
            for j, place in enumerate(LOCATIONS) for s in ("outer", "inner")}


def passage_risk(events: np.ndarray, p_event: np.ndarray, table: np.ndarray,
                 window: tuple[float, float],
                 throughput_per_hour: Optional[float] = None) -> dict[str, Any]:
    """Per-passage probabilities over the window, and the hourly rate.

    Args:
        events: the event table (:data:`demfem.assess.events.EVENT_DTYPE`).
        p_event: (n_events,) P_k.
        table: the run's passages (:func:`demfem.assess.passages.passages`).
        window: (t_0, T), s.
        throughput_per_hour: cartridges per hour the user's line runs at (> 0), or None for
            the table's own discharge in the window.

    Every hourly figure is one number: the expected broken cartridges per second of the
    table, Σ_p P_window,p / W over the passages p on it in the window (W = T − t_0), times
    3600 (``broken_per_hour_table``); for small P it equals 3600 Σ_k h_k / W with
    h_k = −ln(1 − P_k) per loaded cartridge (``broken_per_hour_small_p``). The probability
    that one passage breaks is that rate over the discharge: ``p_passage`` =
    broken per hour / passages per hour (the table's own, or the user's throughput where the
    window has no exits). At a user's throughput the hourly number is ``p_passage`` times it
    (``broken_per_hour_at_throughput``); ``broken_per_hour`` is that when a throughput is
    given, else the table's own.

    Returns:
        per passage: ``p_window``, ``exposure_s``, ``n_events``, ``hazard``
        (Σ −ln(1 − P_k) of its events); per event: ``passage_i``, ``passage_j`` (−1: a wall or
        outside the window); and the scalars of :func:`demfem.assess.passages.table_flow`
        with ``broken_per_hour_table``, ``broken_per_hour_small_p``, ``p_passage``,
        ``broken_per_hour_at_throughput``, ``broken_per_hour``, ``throughput_per_hour``,
        ``throughput_source`` and ``unassigned_events`` (a cartridge partner on no
        passage: 0 in a consistent run).
    """
    from demfem.assess.passages import passage_of_events, table_flow

    q_user = (None if throughput_per_hour is None
              else check_positive("throughput_per_hour", throughput_per_hour))
    flow = table_flow(table, window)
    t0, t1 = window
    w = flow["window_s"]
    inside = (events["time"] >= t0) & (events["time"] <= t1)
    p_in = np.asarray(p_event, float)
    neg_log = np.log1p(-np.where(inside, p_in, 0.0))
    m = len(table)
    log_surv = np.zeros(m)
    counts = np.zeros(m, np.int64)
    out_pass = {}
    unassigned = 0
    for col in ("i", "j"):
        who = np.asarray(events[col], np.int64)
        k = passage_of_events(table, who, events["time"])
        ok = inside & (k >= 0)
        unassigned += int(np.sum(inside & (who >= 0) & (k < 0)))
        np.add.at(log_surv, k[ok], neg_log[ok])
        np.add.at(counts, k[ok], 1)
        out_pass[f"passage_{col}"] = np.where(inside, k, -1)
    p_window = -np.expm1(log_surv)
    per_s = float(p_window.sum() / w)
    q_table = flow["discharge_per_hour"]
    q = q_table if q_table > 0 else q_user
    p_passage = 3600.0 * per_s / q if q else math.nan
    at_user = p_passage * q_user if q_user is not None else math.nan
    return {**out_pass, "p_window": p_window, "exposure_s": flow["exposure_s"],
            "n_events": counts, "hazard": -log_surv,
            **{k: v for k, v in flow.items() if k != "exposure_s"},
            "broken_per_hour_table": 3600.0 * per_s,
            "broken_per_hour_small_p": 3600.0 * float(-log_surv.sum()) / w,
            "p_passage": p_passage, "broken_per_hour_at_throughput": at_user,
            "broken_per_hour": at_user if q_user is not None else 3600.0 * per_s,
            "throughput_per_hour": q_user if q_user is not None else q_table,
            "throughput_source": "user" if q_user is not None else "table",
            "unassigned_events": unassigned}


def event_hazard(events: np.ndarray, p: np.ndarray) -> np.ndarray:
    """The hazard each event puts on the cartridges: −ln(1 − P_k) times the cartridges it
    loads (2 for two cartridges, 1 against a wall, ``j`` = −1), so that sums of it are sums
    of the cartridges' hazards."""
    return -np.log1p(-np.asarray(p, float)) * np.where(events["j"] >= 0, 2.0, 1.0)


def steady_state(events: np.ndarray, p_event: np.ndarray, window: tuple[float, float],
                 period: Optional[float] = None, tolerance: float = 0.10) -> dict[str, Any]:
    """How steady the window is: events and hazard (Σ −ln(1 − P_k), both partners) per second
    in its first and second half, their ratio, and the Poisson z = (n_2 − n_1)/√(n_1 + n_2)
    of the event counts; and, when the window holds at least two whole ``period`` s (the
    gate's, counted from its start), the events and hazard of each period (``period_events``,
    ``period_hazard``) and the relative standard error of their means (``relative_error``,
    ``hazard_relative_error``: s/(√N mean), the statistical uncertainty of the rate and of
    the hourly risk from the window's length).

    ``steady``: with periods, the events' relative standard error at most ``tolerance`` (the
    rate swings within a gate period and wanders over several, so only whole periods count
    and only their scatter measures the uncertainty); without, |z| < 2."""
    from demfem.dem.steady import period_rates, relative_error

    t0, t1 = window
    mid = 0.5 * (t0 + t1)
    half = 0.5 * (t1 - t0)
    t = events["time"]
    h = event_hazard(events, p_event)
    a = (t >= t0) & (t < mid)
    b = (t >= mid) & (t <= t1)
    n1, n2 = int(a.sum()), int(b.sum())
    z = (n2 - n1) / math.sqrt(n1 + n2) if n1 + n2 > 0 else 0.0
    h1, h2 = float(h[a].sum()), float(h[b].sum())
    out: dict[str, Any] = {
        "window_s": [t0, t1], "events_first_half": n1, "events_second_half": n2,
        "rate_first_half_per_s": n1 / half if half > 0 else math.nan,
        "rate_second_half_per_s": n2 / half if half > 0 else math.nan,
        "rate_ratio": n2 / n1 if n1 > 0 else math.nan, "poisson_z": z,
        "steady": bool(abs(z) < 2.0), "criterion": "poisson_z",
        "hazard_first_half": h1, "hazard_second_half": h2,
        "hazard_ratio": h2 / h1 if h1 > 0 else math.nan}
    n_periods = int(math.floor((t1 - t0) / period + 1e-9)) if period else 0
    if period and n_periods >= 2:
        counts = period_rates(t, t0, period, n_periods)
        hz = period_rates(t, t0, period, n_periods, weights=h)
        err = relative_error(counts)
        out.update({"period_s": float(period), "period_events": [int(c) for c in counts],
                    "period_hazard": [float(x) for x in hz],
                    "relative_error": err, "hazard_relative_error": relative_error(hz),
                    "tolerance": float(tolerance), "criterion": "periods",
                    "steady": bool(err <= tolerance)})
    return out


def partner_name(event: Any, wall_names: Sequence[str] = ()) -> str:
    """Who an event's cartridge met: ``cartridge j``, or the wall by its name in
    ``wall_names`` (the run's walls by index; ``wall`` when the index is not among them)."""
    w = int(event["wall"])
    if int(event["partner"]) == 0:
        return f"cartridge {int(event['j'])}"
    return wall_names[w] if 0 <= w < len(wall_names) else "wall"


def worst_events(events: np.ndarray, p: dict[str, np.ndarray], stress: dict[str, np.ndarray],
                 window: tuple[float, float], count: int = 10,
                 wall_names: Sequence[str] = ()) -> list[dict[str, Any]]:
    """The ``count`` events of the window with the largest P_k, as rows (SI units in keys);
    ``with`` names the partner: ``cartridge j`` or the wall (``wall_names`` by index);
    ``place`` the worst place on the cartridge the event may land on (whose σ1 the row
    gives; ``body`` without places)."""
    from demfem.assess.impact import PARTNERS
    from demfem.stress.model import LOCATIONS

    inside = np.flatnonzero((events["time"] >= window[0]) & (events["time"] <= window[1]))
    order = inside[np.argsort(-p["p_event"][inside], kind="stable")][:count]
    rows = []
    for k in order:
        e = events[k]
        rows.append({"event": int(k), "i": int(e["i"]), "j": int(e["j"]),
                     "partner": PARTNERS[int(e["partner"])], "with": partner_name(e, wall_names),
                     "time_s": float(e["time"]),
                     "x_m": float(e["x"]), "y_m": float(e["y"]),
                     "normal_speed_m_per_s": float(e["normal_speed"]),
                     "kind": "pressed by the queue" if bool(e["pressed"]) else "impact",
                     "tangential_force_N": float(e["peak_tangential_force"]),
                     "force_N": float(stress["force_N"][k]),
                     "place": (LOCATIONS[int(stress["place_index"][k])]
                               if "place_index" in stress else "body"),
                     "sigma_inner_Pa": float(stress["sigma_inner_Pa"][k]),
                     "sigma_outer_Pa": float(stress["sigma_outer_Pa"][k]),
                     "p_inner": float(p["p_inner"][k]), "p_outer": float(p["p_outer"][k]),
                     "p_event": float(p["p_event"][k])})
    return rows


def risk_map(events: np.ndarray, p_event: np.ndarray, window: tuple[float, float],
             extent: tuple[float, float, float, float], bins: int = 24) -> dict[str, Any]:
    """2-D histogram over the table (x, y of the contact point) of the hazard the window's
    events put on the cartridges (Σ −ln(1 − P_k), both partners), and of the event count.
    ``extent`` = (x_min, x_max, y_min, y_max), m."""
    x0, x1, y0, y1 = (float(v) for v in extent)
    check_range("extent x_max", x1, x0, math.inf)
    check_range("extent y_max", y1, y0, math.inf)
    sel = (events["time"] >= window[0]) & (events["time"] <= window[1])
    h = event_hazard(events, p_event)
    edges = (np.linspace(x0, x1, bins + 1), np.linspace(y0, y1, bins + 1))
    hz, ex, ey = np.histogram2d(events["x"][sel], events["y"][sel], bins=edges,
                                weights=h[sel])
    cnt, _, _ = np.histogram2d(events["x"][sel], events["y"][sel], bins=edges)
    return {"hazard": hz, "count": cnt, "x_edges": ex, "y_edges": ey}
