"""The statistics of replicas: a pooled rate over independent replicas with its confidence
interval, and the simulation that checks how often such intervals cover the truth.

**The merged number.** Replica r reports an expected number of broken cartridges Y_r over
its statistics window (Σ_p P_window,p, the sum over its passages) and the hours H_r that
window stands for (W_r / 3600 s at the table's own discharge; exits_r / Q at a throughput
Q the user names). The merged hourly number is the pooled ratio

    R = Σ_r Y_r / Σ_r H_r,

the number one long run of Σ W_r seconds would report: every replica weighs by its length.

**Its interval (``"replicas-log-t"``).** The replicas, not the events or the gate periods,
are the independent units: each starts from its own perturbed state and shares nothing with
the others, so their scatter measures the uncertainty whatever the correlation in time
within a run (jams longer than a gate period, the warm-up's drift). With n ≥ 2 replicas the
ratio estimator's linearised standard error

    se(R) = √(Σ_r (Y_r − R H_r)² / (n − 1)) / (√n H̄),    r = se(R) / R,

gives the Student-t interval on the log scale, R exp(± t_{n−1,(1+c)/2} r): the method of
:mod:`demfem.risk.interval` (``"log-t"``) with replicas as the blocks, and for replicas of
equal length exactly its numbers (``tests/python/test_replicas.py`` checks it). The log scale
puts the longer arm above the estimate, where unseen hard impacts push the truth. The
simulation below (:func:`coverage`) compares it with a percentile bootstrap over replicas
and with the log-t over every gate period of every replica pooled (``"periods-log-t"``,
more degrees of freedom but valid only if the periods are independent);
``docs/replicas.md`` gives the numbers.

SI units: s; rates per hour.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Optional, Sequence

import numpy as np
from scipy import stats

from demfem.errors import InvalidParameterError, check_count, check_range

__all__ = ["RatioInterval", "ratio_interval", "replica_numbers", "merge_replicas",
           "dominant_periods",
           "stopping_half_width", "precision_met", "PRECISION_MIN_REPLICAS",
           "PRECISION_SPREAD_CONFIDENCE", "simulate_replicas", "coverage", "COVERAGE_METHODS"]

#: Methods :func:`coverage` compares; the first is the one replicas use.
COVERAGE_METHODS = ("replicas-log-t", "replicas-percentile", "periods-log-t")

#: The precision rule: fewest replicas it may stop at, and the one-sided confidence of the
#: upper bound on the replicas' spread that it judges the half-width with
#: (:func:`stopping_half_width`).
PRECISION_MIN_REPLICAS = 5
PRECISION_SPREAD_CONFIDENCE = 0.8


@dataclass(frozen=True)
class RatioInterval:
    """A pooled rate Σ Y / Σ H over replicas with its confidence interval.

    Attributes:
        estimate, lower, upper: the rate and the interval's bounds (the unit of Y per unit
            of H: broken cartridges per hour for replicas).
        confidence: nominal coverage in (0, 1).
        n: replicas; dof: the t quantile's degrees of freedom (n − 1).
        relative_standard_error: se(R)/R (inf when undefined).
        status: ``"ok"``; ``"one replica"`` (no interval); ``"no breakage"`` (every Y is 0:
            estimate and lower bound 0, no upper bound from the data).
        method: ``"replicas-log-t"``.
    """

    estimate: float
    lower: float
    upper: float
    confidence: float
    n: int
    dof: int
    relative_standard_error: float
    status: str
    method: str = "replicas-log-t"

    @property
    def relative_half_width(self) -> float:
        """(upper − lower) / (2 estimate); inf without an estimate or a finite interval."""
        if not (self.estimate > 0 and math.isfinite(self.lower)
                and math.isfinite(self.upper)):
            return math.inf
        return (self.upper - self.lower) / (2.0 * self.estimate)

    @property
    def factor(self) -> float:
        """How far the interval reaches either way as a factor, max(upper/estimate,
        estimate/lower); inf when a bound is 0, missing or infinite."""
        if not (self.estimate > 0 and self.lower > 0 and math.isfinite(self.upper)):
            return math.inf
        return max(self.upper / self.estimate, self.estimate / self.lower)

    def to_dict(self) -> dict[str, Any]:
        """Strict-JSON fields (non-finite numbers as ``None``)."""
        def num(x: float) -> Optional[float]:
            return float(x) if math.isfinite(x) else None

        return {"estimate": num(self.estimate), "lower": num(self.lower),
                "upper": num(self.upper), "confidence": self.confidence, "n": self.n,
                "dof": self.dof, "relative_standard_error": num(self.relative_standard_error),
                "relative_half_width": num(self.relative_half_width),
                "factor": num(self.factor), "status": self.status, "method": self.method}


def ratio_interval(numerators: Sequence[float] | np.ndarray,
                   denominators: Sequence[float] | np.ndarray,
                   confidence: float = 0.95) -> RatioInterval:
    """Σ Y / Σ H over replicas with its Student-t interval on the log scale (module text).

    Args:
        numerators: (n,) Y_r ≥ 0 (expected broken cartridges in replica r's window).
        denominators: (n,) H_r > 0 (the hours that window stands for).
        confidence: nominal coverage in (0, 1).
    """
    y = np.asarray(numerators, float)
    h = np.asarray(denominators, float)
    if y.ndim != 1 or h.shape != y.shape or len(y) == 0:
        raise InvalidParameterError(
            f"invalid replicas: numerators {y.shape} and denominators {h.shape} must be two "
            "equally long non-empty lists")
    if not (np.all(np.isfinite(y)) and np.all(y >= 0)):
        raise InvalidParameterError("invalid numerators: every replica's expected breakages "
                                    "must be a finite number >= 0")
    if not (np.all(np.isfinite(h)) and np.all(h > 0)):
        raise InvalidParameterError("invalid denominators: every replica's hours must be a "
                                    "finite number > 0")
    conf = check_range("confidence", confidence, 0.0, 1.0)
    n = len(y)
    est = float(y.sum() / h.sum())
    if n < 2:
        return RatioInterval(est, math.nan, math.nan, conf, n, 0, math.inf, "one replica")
    if not est > 0:
        return RatioInterval(0.0, 0.0, math.inf, conf, n, n - 1, math.inf, "no breakage")
    resid = y - est * h
    se = math.sqrt(float(resid @ resid) / (n - 1)) / (math.sqrt(n) * float(h.mean()))
    r = se / est
    tq = float(stats.t.ppf(0.5 + conf / 2.0, n - 1))
    return RatioInterval(est, est * math.exp(-tq * r), est * math.exp(tq * r), conf, n, n - 1,
                         r, "ok")


def stopping_half_width(iv: RatioInterval,
                        spread_confidence: float = PRECISION_SPREAD_CONFIDENCE) -> float:
    """The relative half-width the precision rule judges: that of ``iv`` with the replicas'
    relative spread r replaced by its one-sided ``spread_confidence`` upper bound,
    r √((n − 1)/χ²_{1−c, n−1}), i.e. sinh(t r_up) (the log-t interval's (upper − lower) /
    2 estimate). Stopping on the interval's own half-width stops most often where the
    spread happens to come out small, and such intervals cover less: 88–91 % instead of
    95 % in the simulation of ``docs/replicas.md``; judged this way, and not before
    :data:`PRECISION_MIN_REPLICAS` replicas, 93–95 % (at 23–40 % more replicas). inf
    without an interval."""
    if iv.status != "ok" or iv.n < 2 or not math.isfinite(iv.relative_standard_error):
        return math.inf
    c = check_range("spread_confidence", spread_confidence, 0.0, 1.0)
    k = math.sqrt((iv.n - 1) / float(stats.chi2.ppf(1.0 - c, iv.n - 1)))
    tq = float(stats.t.ppf(0.5 + iv.confidence / 2.0, iv.n - 1))
    a = tq * iv.relative_standard_error * k
    return math.sinh(a) if a < 700 else math.inf


def precision_met(iv: RatioInterval, precision: float) -> bool:
    """Whether the precision rule stops at ``iv``: at least :data:`PRECISION_MIN_REPLICAS`
    replicas and :func:`stopping_half_width` at most ``precision`` (a fraction)."""
    return iv.n >= PRECISION_MIN_REPLICAS and stopping_half_width(iv) <= precision


def replica_numbers(risk: dict[str, Any]) -> dict[str, Any]:
    """What the merge needs of one assessment's risk document (``risk.json``):

    ``expected_broken`` Y = Σ_p P_window,p, the expected broken cartridges over the window
    (the table's own hourly number × W / 3600 s); ``hours`` H, the hours that window stands
    for: W / 3600 at the table's own discharge, exits / Q at a throughput Q the user named
    (W / 3600 when no cartridge left in the window, as :func:`demfem.assess.risk_stage.
    passage_risk` then does), so that Y / H is the replica's ``broken_per_hour``; and the
    window, exits, events, largest force, steadiness and ``settings`` (to compare replicas).
    """
    s = risk["summary"]
    t0, t1 = (float(v) for v in risk["window_s"])
    w = t1 - t0
    y = float(s["broken_per_hour_table"]) * w / 3600.0
    exits = int(s.get("exits_window") or 0)
    user = s.get("throughput_source") == "user"
    hours = exits / float(s["throughput_per_hour"]) if user and exits > 0 else w / 3600.0
    steady = risk.get("steady_state") or {}
    check = risk.get("period_check") or {}
    return {"window_s": [t0, t1], "expected_broken": y, "hours": hours,
            "periods_checked": int(check.get("n_periods") or 0),
            "dominant_periods": len(check.get("dominant_periods") or ()),
            "broken_per_hour": y / hours, "broken_per_hour_reported": s.get("broken_per_hour"),
            "throughput_source": s.get("throughput_source"),
            "throughput_per_hour": s.get("throughput_per_hour"), "exits_window": exits,
            "n_events_window": int(s.get("n_events_window") or 0),
            "max_force_N": s.get("max_force_N"), "steady": bool(steady.get("steady")),
            "hazard_relative_error": steady.get("hazard_relative_error"),
            "settings": risk.get("settings", {})}


def dominant_periods(records: Sequence[dict[str, Any]],
                     confidence: float = 0.95) -> dict[str, Any]:
    """How often one gate period dominates a replica's hazard (a jam,
    :mod:`demfem.risk.rare_periods`), pooled over replicas: k dominant periods of N checked,
    the fraction k / N with its Clopper–Pearson interval, and the replicas that had one.
    This is what a single run cannot measure and replicas can."""
    k = sum(int(r.get("dominant_periods") or 0) for r in records)
    n = sum(int(r.get("periods_checked") or 0) for r in records)
    conf = check_range("confidence", confidence, 0.0, 1.0)
    a = (1.0 - conf) / 2.0
    lo = 0.0 if k == 0 or n == 0 else float(stats.beta.ppf(a, k, n - k + 1))
    hi = (1.0 if n == 0 else 1.0 if k == n else float(stats.beta.ppf(1.0 - a, k + 1, n - k)))
    return {"dominant": k, "periods": n, "fraction": k / n if n else None,
            "ci": [lo, hi] if n else None, "confidence": conf,
            "replicas": [r.get("name") for r in records if r.get("dominant_periods")]}


def _comparable(settings: dict[str, Any]) -> dict[str, Any]:
    """A replica's settings without its seed (the one thing replicas differ in)."""
    return {k: v for k, v in settings.items() if k not in ("seed", "start_seed")}


def merge_replicas(records: Sequence[dict[str, Any]],
                   confidence: float = 0.95) -> dict[str, Any]:
    """The merged numbers of replicas (records of :func:`replica_numbers` with ``name``):
    the pooled hourly number Σ Y / Σ H with its interval (:func:`ratio_interval`), the
    table's own rate and discharge pooled over the windows, the events and the replicas'
    own hourly numbers. Replicas of different settings are refused with
    :class:`~demfem.errors.SettingsMismatchError` naming both replicas and each difference.
    """
    from demfem.errors import SettingsMismatchError
    from demfem.jobs import settings_differences

    if not records:
        raise InvalidParameterError("invalid records: no replica to merge")
    first = records[0]
    ref = _comparable(first.get("settings") or {})
    for rec in records[1:]:
        diff = settings_differences(ref, _comparable(rec.get("settings") or {}))
        if diff:
            raise SettingsMismatchError(
                f"replicas of different settings cannot be merged: {rec.get('name')} differs "
                f"from {first.get('name')} (" + "; ".join(diff) + "); rerun them with the "
                "same settings, or keep each set in its own folder")
        if rec.get("throughput_source") != first.get("throughput_source"):
            raise SettingsMismatchError(
                f"replicas of different settings cannot be merged: {rec.get('name')} gives "
                f"its number at the {rec.get('throughput_source')}'s throughput, "
                f"{first.get('name')} at the {first.get('throughput_source')}'s")
    y = np.array([r["expected_broken"] for r in records], float)
    h = np.array([r["hours"] for r in records], float)
    w = np.array([r["window_s"][1] - r["window_s"][0] for r in records], float)
    exits = np.array([r["exits_window"] for r in records], float)
    iv = ratio_interval(y, h, confidence)
    per = y / h
    judged = stopping_half_width(iv)
    return {**iv.to_dict(), "broken_per_hour": iv.estimate,
            "judged_half_width": judged if math.isfinite(judged) else None,
            "broken_per_hour_table": float(3600.0 * y.sum() / w.sum()),
            "discharge_per_hour": float(3600.0 * exits.sum() / w.sum()),
            "p_passage": float(y.sum() / exits.sum()) if exits.sum() > 0 else None,
            "expected_broken_total": float(y.sum()), "hours_total": float(h.sum()),
            "window_total_s": float(w.sum()),
            "n_events_window": int(sum(r["n_events_window"] for r in records)),
            "per_replica": [float(x) for x in per],
            "dominant_periods": dominant_periods(records, confidence),
            "between_replica_cv": (float(np.std(per, ddof=1) / np.mean(per))
                                   if len(per) > 1 and np.mean(per) > 0 else None),
            "replicas": [r.get("name") for r in records],
            "throughput_source": first.get("throughput_source"),
            "all_steady": all(r.get("steady") for r in records)}


def simulate_replicas(rng: np.random.Generator, n_replicas: int, periods: int = 7,
                      hard_impacts: float = 0.5, tail_index: float = 2.5,
                      jam_sigma: float = 0.5,
                      jam_correlation: float = 0.0) -> tuple[np.ndarray, float]:
    """Synthetic per-period hazards of ``n_replicas`` replicas, and the true mean per period.

    A model of the table's hourly risk: each gate period carries a Poisson number of hard
    impacts (mean ``hard_impacts`` × a log-normal jam factor of mean 1 and log-sd
    ``jam_sigma``, common to the period; its logarithm is an AR(1) series over the periods of
    a replica with lag-1 correlation ``jam_correlation``: jams that outlast a period), each
    with a Pareto hazard of tail index
    ``tail_index`` (scale 1, mean α/(α − 1)): the rare hardest impact dominates, as on the
    default table (one 45 N impact in seven periods carries most of the hazard; with the
    defaults a period's hazard has a coefficient of variation of about 2, the measured one).

    Returns:
        (n_replicas, periods) hazards and their true mean per period.
    """
    n = check_count("n_replicas", n_replicas, 1)
    p = check_count("periods", periods, 1)
    a = check_range("tail_index", tail_index, 1.0, math.inf)
    rho = check_range("jam_correlation", jam_correlation, -1.0, 1.0)
    z = rng.normal(size=(n, p))
    for j in range(1, p):  # stationary AR(1) of unit variance
        z[:, j] = rho * z[:, j - 1] + math.sqrt(1.0 - rho * rho) * z[:, j]
    jam = np.exp(jam_sigma * z - 0.5 * jam_sigma ** 2)
    counts = rng.poisson(hard_impacts * jam)
    out = np.zeros((n, p))
    total = int(counts.sum())
    if total:
        w = rng.pareto(a, size=total) + 1.0
        np.add.at(out.ravel(), np.repeat(np.arange(n * p), counts.ravel()), w)
    return out, hard_impacts * a / (a - 1.0)


def coverage(n_replicas: int, n_sim: int = 2000, *, periods: int = 7,
             hard_impacts: float = 0.5, tail_index: float = 2.5, jam_sigma: float = 0.5,
             jam_correlation: float = 0.0, confidence: float = 0.95,
             method: str = "replicas-log-t", seed: int = 0, n_boot: int = 400,
             precision: Optional[float] = None, batch: int = 2,
             max_replicas: int = 64, rule: str = "judged") -> dict[str, Any]:
    """How often the interval of ``n_replicas`` replicas covers the true rate, over
    ``n_sim`` simulated sets (:func:`simulate_replicas`), for one of
    :data:`COVERAGE_METHODS`. With ``precision`` (``"replicas-log-t"`` only), replicas are
    added ``batch`` at a time until :func:`precision_met` (``rule="judged"``, as
    ``assess_replicas`` does) or the interval's own half-width is at most that fraction
    (``rule="naive"``), or ``max_replicas`` is reached: the coverage of the interval where
    it stopped.

    Returns:
        ``coverage`` (fraction of sets whose interval holds the truth), ``below`` and
        ``above`` (the truth below the lower / above the upper bound), ``median_factor`` (of
        the finite intervals), ``undefined`` (sets with no interval: no breakage at all) and,
        with ``precision``, ``median_replicas`` and ``reached`` (the fraction that met it).
    """
    from demfem.risk.interval import interval_from_blocks

    if method not in COVERAGE_METHODS:
        raise InvalidParameterError(f"invalid method = {method!r}: must be one of "
                                    f"{COVERAGE_METHODS}")
    n0 = check_count("n_replicas", n_replicas, 2)
    sims = check_count("n_sim", n_sim, 1)
    step = check_count("batch", batch, 1)
    most = check_count("max_replicas", max_replicas, n0)
    if precision is not None and method != COVERAGE_METHODS[0]:
        raise InvalidParameterError(f"invalid method = {method!r} with a precision: only "
                                    f"{COVERAGE_METHODS[0]!r} adds replicas")
    rng = np.random.default_rng(seed)
    below = above = undefined = reached = 0
    factors, used = [], []
    for _ in range(sims):
        hz, truth = simulate_replicas(rng, n0, periods, hard_impacts, tail_index, jam_sigma,
                                      jam_correlation)
        if precision is not None:
            while True:
                iv = ratio_interval(hz.sum(axis=1), np.full(len(hz), float(periods)),
                                    confidence)
                met = (precision_met(iv, precision) if rule == "judged"
                       else iv.relative_half_width <= precision)
                if met or len(hz) >= most:
                    break
                more, _ = simulate_replicas(rng, min(step, most - len(hz)), periods,
                                            hard_impacts, tail_index, jam_sigma,
                                            jam_correlation)
                hz = np.vstack([hz, more])
            used.append(len(hz))
            reached += met
        n = len(hz)
        y = hz.sum(axis=1)
        h = np.full(n, float(periods))
        if method == "replicas-log-t":
            iv = ratio_interval(y, h, confidence)
            lo, hi, est = iv.lower, iv.upper, iv.estimate
        elif method == "replicas-percentile":
            est = float(y.sum() / h.sum())
            pick = rng.integers(0, n, size=(n_boot, n))
            draws = y[pick].sum(axis=1) / h[pick].sum(axis=1)
            lo, hi = np.quantile(draws, [0.5 - confidence / 2, 0.5 + confidence / 2])
        else:
            res = interval_from_blocks(hz.reshape(1, -1), 1.0, confidence=confidence)
            lo, hi, est = (float(res[k][0]) for k in ("lower", "upper", "estimate"))
        if not (est > 0 and math.isfinite(hi)):
            undefined += 1
            continue
        below += truth < lo
        above += truth > hi
        if lo > 0:
            factors.append(max(hi / est, est / lo))
    ok = sims - undefined
    out: dict[str, Any] = {"coverage": (ok - below - above) / ok if ok else math.nan,
           "below": below / ok if ok else math.nan, "above": above / ok if ok else math.nan,
           "median_factor": float(np.median(factors)) if factors else math.nan,
           "undefined": undefined / sims, "n_sim": sims, "n_replicas": n0,
           "periods": periods, "tail_index": tail_index, "jam_correlation": jam_correlation,
           "method": method}
    if precision is not None:
        out.update(precision=precision, median_replicas=float(np.median(used)),
                   reached=reached / sims, rule=rule)
    return out
