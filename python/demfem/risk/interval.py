"""Confidence intervals for the rate of a weighted point process observed over whole blocks
of time (the gate periods of the table in operation).

A rate here is ``scale × Σ w_k / W``: events k at times t_k carrying weights w_k ≥ 0 (1 for
a count, the hazard −ln(1 − P_k) of each loaded cartridge for the breakage rate) over the
observed time W; ``scale`` converts per second into the unit reported (3600 for per hour).

**Blocks.** Events within a gate period are correlated: the gate's swing sets the collision
rate within the period, and a jam lifts every impact of the period together. So the
statistic is built from **block totals** Y_b = Σ_{k in block b} w_k over n whole blocks of
length T (the period) from the window's start, and the blocks, not the events, are the
independent units. The rate is m/T × scale with m the mean block total; events after the last
whole block are not used (the estimate and its interval refer to the same n T seconds).
Correlation between consecutive periods (jams that last longer than a period) is not removed
by one-period blocks: pass a multiple of the gate period as ``period`` to make longer blocks;
:attr:`RateInterval.lag1_autocorrelation` of the block totals says whether that is needed.

**Interval (default ``"log-t"``).** Student-t on the log scale:

    rate × exp(± t_{n−1, (1+c)/2} r),   r = s / (√n m)

with s the sample standard deviation of the block totals (r is the relative standard error
of the rate, the delta-method standard error of its logarithm). Chosen by simulated coverage
(``docs/uncertainty.md``, ``tests/python/test_risk_interval.py``): with 4–7 blocks the
percentile and BCa bootstraps cover a 95 % interval only 77–86 % of the time (the plug-in
variance and normal-like quantiles), the log-t interval 94–95 % for log-normal weights and
88 % for a hazard ∝ F^6.6 of an exponential force tail, equal to the bootstrap-t on the log
scale, which is far wider and erratic with few blocks. The log scale puts the longer arm above
the estimate, where the unseen hard impacts of a heavy-tailed weight push the truth. For a
heavier force tail (infinite variance of the hazard) no block interval covers (47–65 %): use
:func:`demfem.risk.tail.tail_corrected_rate`. The bootstrap over blocks remains available
(``"percentile"``, ``"studentized-log"``), all series of one call resampled with the same
draws.

**Splits.** Group labels (place on the table, partner) and weight components (the inner and
outer surface's parts of each event's hazard, which add up exactly) are split into series
whose block totals come from the same blocks, so each split's interval and its share of the
total are consistent with the total's. A share's interval is the Student-t interval of the
ratio estimator Σ Y_g / Σ Y (linearised: residuals Y_g,b − R Y_b), clipped to [0, 1], or the
percentile of the bootstrap draws' ratios with a bootstrap method.

**Degenerate cases.** Fewer than two whole blocks: no interval (``status`` ``"too few
blocks"``, lower and upper NaN); the estimate is then Σ w / W over the whole window. No event
of positive weight in the blocks: estimate and lower bound 0, upper bound from the Poisson
zero-count bound (the rule of three: −ln((1 − c)/2) events in n T) times ``max_weight``, the
largest weight one event could carry; without it the upper bound is +inf, since nothing in
the data bounds how heavy an unseen event would be (``status`` ``"no events"``).

SI units: s; rates per second times ``scale``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any, Mapping, Optional, Sequence

import numpy as np
from numpy.typing import NDArray
from scipy import stats

from demfem.errors import InvalidParameterError, check_count, check_positive, check_range
from demfem.risk._validate import as_array, check_same_shape

__all__ = ["METHODS", "RateInterval", "block_totals", "interval_from_blocks",
           "rate_interval", "hourly_interval_from_events"]

#: Interval methods: the default first.
METHODS = ("log-t", "percentile", "studentized-log")


@dataclass(frozen=True)
class RateInterval:
    """A rate with its confidence interval (units: per second × the call's ``scale``).

    Attributes:
        estimate, lower, upper: the rate and the interval's bounds.
        confidence: the interval's nominal coverage, in (0, 1).
        method: how the interval was made (:data:`METHODS`).
        status: ``"ok"``, ``"too few blocks"`` (no interval) or ``"no events"`` (no event of
            positive weight: [0, zero-count bound]).
        n_blocks: whole blocks used; block_s: their length, s; window_s: (start, end) of the
            time the estimate covers, s.
        n_events: events of positive weight in that time.
        relative_standard_error: s/(√n m) of the block totals (inf when undefined).
        lag1_autocorrelation: of the block totals (NaN for fewer than 3 blocks).
        share, share_lower, share_upper: a split's share of the total and its interval (NaN
            for the total itself).
        splits: ``{grouping: {label: RateInterval}}`` from the same blocks (and draws).
    """

    estimate: float
    lower: float
    upper: float
    confidence: float
    method: str
    status: str
    n_blocks: int
    block_s: float
    window_s: tuple[float, float]
    n_events: int
    relative_standard_error: float
    lag1_autocorrelation: float
    share: float = math.nan
    share_lower: float = math.nan
    share_upper: float = math.nan
    splits: Mapping[str, Mapping[str, "RateInterval"]] = field(default_factory=dict)

    @property
    def estimable(self) -> bool:
        """Whether the data gave an interval (``status == "ok"``)."""
        return self.status == "ok"

    @property
    def relative_half_width(self) -> float:
        """(upper − lower) / (2 estimate); inf without an estimate or a finite bound."""
        if not (self.estimate > 0 and math.isfinite(self.upper) and math.isfinite(self.lower)):
            return math.inf
        return (self.upper - self.lower) / (2.0 * self.estimate)

    @property
    def factor(self) -> float:
        """How far the interval reaches either way as a factor: max(upper/estimate,
        estimate/lower) (inf when a bound is 0, missing or infinite)."""
        if not (self.estimate > 0 and self.lower > 0 and math.isfinite(self.upper)):
            return math.inf
        return max(self.upper / self.estimate, self.estimate / self.lower)

    def to_dict(self) -> dict[str, Any]:
        """Strict-JSON fields (non-finite numbers as ``None``), splits nested."""
        def num(x: float) -> Optional[float]:
            return float(x) if math.isfinite(x) else None

        out: dict[str, Any] = {
            "estimate": num(self.estimate), "lower": num(self.lower), "upper": num(self.upper),
            "confidence": self.confidence, "method": self.method, "status": self.status,
            "relative_half_width": num(self.relative_half_width), "factor": num(self.factor),
            "n_blocks": self.n_blocks, "block_s": self.block_s,
            "window_s": [float(v) for v in self.window_s], "n_events": self.n_events,
            "relative_standard_error": num(self.relative_standard_error),
            "lag1_autocorrelation": num(self.lag1_autocorrelation)}
        if math.isfinite(self.share):
            out.update(share=self.share, share_lower=num(self.share_lower),
                       share_upper=num(self.share_upper))
        if self.splits:
            out["splits"] = {g: {str(k): v.to_dict() for k, v in d.items()}
                             for g, d in self.splits.items()}
        return out


def block_totals(times: NDArray[np.float64], weights: NDArray[np.float64], start: float,
                 block: float, n_blocks: int) -> NDArray[np.float64]:
    """Sums of ``weights`` over the events of each half-open block [start + b·block,
    start + (b+1)·block), b = 0 … n_blocks − 1 (times in s).

    ``weights``: (n_events,) or (n_series, n_events); returns (n_blocks,) or
    (n_series, n_blocks). One ``np.bincount`` pass: 10⁶ events take milliseconds.
    """
    t = np.asarray(times, float)
    w = np.asarray(weights, float)
    one = w.ndim == 1
    w2 = w[None, :] if one else w
    k = np.floor((t - start) / block)
    inside = (k >= 0) & (k < n_blocks)
    kb = k[inside].astype(np.int64)
    s = w2.shape[0]
    flat = (np.arange(s)[:, None] * n_blocks + kb[None, :]).ravel()
    out = np.asarray(np.bincount(flat, weights=w2[:, inside].ravel(), minlength=s * n_blocks),
                     dtype=np.float64).reshape(s, n_blocks)
    return out[0] if one else out


def _lag1(y: NDArray[np.float64]) -> NDArray[np.float64]:
    """Lag-1 autocorrelation of each row of y (NaN for < 3 columns or constant rows)."""
    if y.shape[-1] < 3:
        return np.full(y.shape[0], math.nan)
    d = y - y.mean(axis=-1, keepdims=True)
    den = (d * d).sum(axis=-1)
    num = (d[:, 1:] * d[:, :-1]).sum(axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, num / np.where(den > 0, den, 1.0), math.nan)


def interval_from_blocks(totals: NDArray[np.float64], block_s: float, *,
                         confidence: float = 0.95, method: str = "log-t", scale: float = 1.0,
                         n_boot: int = 2000, seed: int = 0,
                         max_weight: Optional[float] = None,
                         share_of: Optional[int] = None) -> dict[str, NDArray[np.float64]]:
    """Rate and interval of each series of block totals (the numpy core of
    :func:`rate_interval`; module docstring for the methods).

    Args:
        totals: (n_series, n_blocks) sums of the weights per block, ≥ 0, n_blocks ≥ 2.
        block_s: length of a block, s.
        confidence: nominal coverage in (0, 1).
        method: one of :data:`METHODS`.
        scale: factor from per second to the unit reported (> 0).
        n_boot, seed: bootstrap resamples and seed (bootstrap methods only); every series is
            resampled with the same draws.
        max_weight: largest weight one event could carry, for the upper bound of a series
            without events (None: +inf).
        share_of: row of ``totals`` that the shares are taken of (None: no shares).

    Returns:
        ``estimate``, ``lower``, ``upper``, ``relative_standard_error``, ``zero`` (bool: no
        positive total), and with ``share_of`` ``share``, ``share_lower``, ``share_upper``;
        each (n_series,).
    """
    y = np.asarray(totals, float)
    s_count, n = y.shape
    if n < 2:
        raise InvalidParameterError(f"invalid n_blocks = {n}: must be at least 2")
    alpha = 1.0 - confidence
    to_rate = scale / block_s
    m = y.mean(axis=1)
    sd = y.std(axis=1, ddof=1)
    zero = ~(m > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(zero, math.inf, sd / (math.sqrt(n) * np.where(zero, 1.0, m)))
    tq = float(stats.t.ppf(1.0 - alpha / 2.0, n - 1))
    if method not in METHODS:
        raise InvalidParameterError(f"invalid method = {method!r}: must be one of {METHODS}")
    draws: Optional[NDArray[np.float64]] = None
    if method == "log-t":
        r_ok = np.where(zero, 0.0, r)                             # zero rows are set below
        lo, hi = m * np.exp(-tq * r_ok), m * np.exp(tq * r_ok)
    else:
        rng = np.random.default_rng(seed)
        counts = rng.multinomial(n, np.full(n, 1.0 / n), size=n_boot).astype(float)
        d = (y @ counts.T) / n                                    # (series, n_boot) means
        draws = d
        if method == "percentile":
            lo = np.quantile(d, alpha / 2.0, axis=1)
            hi = np.quantile(d, 1.0 - alpha / 2.0, axis=1)
        else:                                                     # studentized-log
            var_b = ((y * y) @ counts.T - n * d * d) / (n - 1)
            with np.errstate(divide="ignore", invalid="ignore"):
                r_b = np.sqrt(np.maximum(var_b, 0.0)) / (math.sqrt(n) * d)
                t_b = (np.log(d) - np.log(m)[:, None]) / r_b
            t_b = np.where(np.isnan(t_b), 0.0, t_b)              # resample equal to the data
            q_lo = np.quantile(t_b, alpha / 2.0, axis=1)
            q_hi = np.quantile(t_b, 1.0 - alpha / 2.0, axis=1)
            with np.errstate(invalid="ignore", over="ignore"):
                lo, hi = m * np.exp(-q_hi * r), m * np.exp(-q_lo * r)
    # no event of positive weight: [0, zero-count bound × heaviest possible event]
    zero_upper = (-math.log(alpha / 2.0) / (n * block_s) * scale
                  * (max_weight if max_weight is not None else math.inf))
    lo = np.where(zero, 0.0, lo * to_rate)
    hi = np.where(zero, zero_upper, hi * to_rate)
    out = {"estimate": m * to_rate, "lower": lo, "upper": hi,
           "relative_standard_error": r, "zero": zero}
    if share_of is not None:
        tot = y[share_of]
        big = tot.sum()
        with np.errstate(invalid="ignore", divide="ignore"):
            share = y.sum(axis=1) / big if big > 0 else np.full(s_count, math.nan)
        if draws is None:
            resid = y - share[:, None] * tot[None, :]
            se = resid.std(axis=1, ddof=1) / math.sqrt(n) / tot.mean() if big > 0 \
                else np.full(s_count, math.nan)
            s_lo, s_hi = share - tq * se, share + tq * se
        else:
            with np.errstate(invalid="ignore", divide="ignore"):
                ratio = draws / draws[share_of][None, :]
            s_lo = np.nanquantile(ratio, alpha / 2.0, axis=1) if big > 0 else share
            s_hi = np.nanquantile(ratio, 1.0 - alpha / 2.0, axis=1) if big > 0 else share
        out.update(share=share, share_lower=np.clip(s_lo, 0.0, 1.0),
                   share_upper=np.clip(s_hi, 0.0, 1.0))
    return out


def _labels(field_name: str, labels: Any, n: int) -> tuple[list[Any], NDArray[np.int64]]:
    arr = np.asarray(labels)
    if arr.ndim != 1 or arr.shape[0] != n:
        raise InvalidParameterError(f"invalid {field_name}: shape {arr.shape} does not match "
                                    f"the {n} events")
    if arr.dtype.kind == "f" and not np.all(np.isfinite(arr)):
        raise InvalidParameterError(f"invalid {field_name}: labels must not be NaN")
    uniq, inv = np.unique(arr, return_inverse=True)
    return [u.item() if hasattr(u, "item") else u for u in uniq], inv.astype(np.int64)


def rate_interval(event_times: Sequence[float] | NDArray[np.float64],
                  event_weights: Sequence[float] | NDArray[np.float64]
                  | Mapping[str, Sequence[float] | NDArray[np.float64]] | None,
                  window: tuple[float, float], period: float, *,
                  groups: Sequence[Any] | NDArray[Any] | Mapping[str, Any] | None = None,
                  scale: float = 1.0, confidence: float = 0.95, method: str = "log-t",
                  n_boot: int = 2000, seed: int = 0,
                  max_weight: Optional[float] = None) -> RateInterval:
    """Rate of a weighted point process over a window of whole blocks, with its confidence
    interval and, in the same call, its splits (module docstring).

    Args:
        event_times: (n,) event times, s.
        event_weights: (n,) weights ≥ 0 (None: counts, weight 1), or a mapping of component
            name → (n,) weights ≥ 0 whose sum is the event's weight (the components become the
            grouping ``"component"``).
        window: (t_0, t_1), s: the blocks start at t_0; only whole blocks are used.
        period: block length, s (> 0): the gate period or a multiple of it.
        groups: (n,) labels (grouping ``"group"``) or a mapping grouping name → (n,) labels
            (e.g. ``{"place": ..., "partner": ...}``); each label's events become a split.
        scale: per second → unit reported (3600: per hour); > 0.
        confidence: nominal coverage in (0, 1).
        method: ``"log-t"`` (default), ``"percentile"`` or ``"studentized-log"``.
        n_boot: bootstrap resamples (≥ 100; bootstrap methods only). seed: their seed.
        max_weight: heaviest weight one event could carry (> 0), for the upper bound when no
            event of positive weight was seen (None: +inf).

    Returns:
        :class:`RateInterval` of the total, with ``splits[grouping][label]``.

    Raises:
        InvalidParameterError: NaN or infinite times or weights, negative weights, arrays that
            do not match, a window with t_1 ≤ t_0, a period ≤ 0, a confidence outside (0, 1),
            an unknown method, ``n_boot`` < 100.
    """
    t = as_array("event_times", event_times, ndim=1, unit="s")
    n_ev = t.shape[0]
    if event_weights is None:
        comps: dict[str, NDArray[np.float64]] = {}
        w = np.ones(n_ev)
    elif isinstance(event_weights, Mapping):
        if not event_weights:
            raise InvalidParameterError("invalid event_weights: the mapping is empty")
        comps = {str(k): as_array(f"event_weights[{k!r}]", v, 0.0, math.inf, lo_open=False,
                                  ndim=1) for k, v in event_weights.items()}
        for k, v in comps.items():
            check_same_shape(event_times=t, **{f"event_weights[{k!r}]": v})
        w = np.sum(list(comps.values()), axis=0)
    else:
        w = as_array("event_weights", event_weights, 0.0, math.inf, lo_open=False, ndim=1)
        check_same_shape(event_times=t, event_weights=w)
        comps = {}
    t0 = check_range("window start", window[0])
    t1 = check_range("window end", window[1], t0, math.inf)
    block = check_positive("period", period)
    conf = check_range("confidence", confidence, 0.0, 1.0)
    sc = check_positive("scale", scale)
    if method not in METHODS:
        raise InvalidParameterError(f"invalid method = {method!r}: must be one of {METHODS}")
    nb = check_count("n_boot", n_boot, 100)
    mw = None if max_weight is None else check_positive("max_weight", max_weight)
    grouping = {} if groups is None else (dict(groups) if isinstance(groups, Mapping)
                                          else {"group": groups})

    # series: total, then each grouping's labels, then the weight components
    names: list[tuple[str, Any]] = [("", None)]
    rows = [w]
    for g, labels in grouping.items():
        uniq, inv = _labels(f"groups[{g!r}]" if isinstance(groups, Mapping) else "groups",
                            labels, n_ev)
        for code, lab in enumerate(uniq):
            names.append((str(g), lab))
            rows.append(np.where(inv == code, w, 0.0))
    for c, wc in comps.items():
        names.append(("component", c))
        rows.append(wc)
    series = np.vstack(rows)

    n_blocks = int(math.floor((t1 - t0) / block + 1e-9))
    if n_blocks < 2:
        inside = (t >= t0) & (t <= t1)
        est = series[:, inside].sum(axis=1) / (t1 - t0) * sc
        npos = ((series[:, inside] > 0).sum(axis=1))
        results = [RateInterval(float(est[i]), math.nan, math.nan, conf, method,
                                "too few blocks", n_blocks, block, (t0, t1), int(npos[i]),
                                math.inf, math.nan) for i in range(len(names))]
    else:
        end = t0 + n_blocks * block
        totals = block_totals(t, series, t0, block, n_blocks)
        res = interval_from_blocks(totals, block, confidence=conf, method=method, scale=sc,
                                   n_boot=nb, seed=seed, max_weight=mw, share_of=0)
        inside = (t >= t0) & (t < end)
        npos = (series[:, inside] > 0).sum(axis=1)
        lag = _lag1(totals)
        results = []
        for i in range(len(names)):
            kw: dict[str, Any] = {}
            if i > 0:
                kw = dict(share=float(res["share"][i]), share_lower=float(res["share_lower"][i]),
                          share_upper=float(res["share_upper"][i]))
            results.append(RateInterval(
                float(res["estimate"][i]), float(res["lower"][i]), float(res["upper"][i]),
                conf, method, "no events" if res["zero"][i] else "ok", n_blocks, block,
                (t0, end), int(npos[i]), float(res["relative_standard_error"][i]),
                float(lag[i]), **kw))
    splits: dict[str, dict[str, RateInterval]] = {}
    for (g, lab), r in zip(names[1:], results[1:]):
        splits.setdefault(g, {})[str(lab)] = r
    return replace(results[0], splits=splits)


def hourly_interval_from_events(events: NDArray[Any], p_event: NDArray[np.float64],
                                window: tuple[float, float], period: float, *,
                                wall_names: Sequence[str] = (),
                                p_surfaces: Optional[Mapping[str, NDArray[np.float64]]] = None,
                                components: Optional[Mapping[str, NDArray[np.float64]]] = None,
                                scale: float = 3600.0, confidence: float = 0.95,
                                method: str = "log-t", n_boot: int = 2000, seed: int = 0,
                                max_weight: Optional[float] = None) -> RateInterval:
    """Broken cartridges per hour (small-P form, 3600 Σ h / W) with its interval, split by
    place (``"with"``: the wall's name or ``"cartridge"``), by partner type (``"partner"``:
    ``"sphere"``/``"wall"``) and, with ``p_surfaces``, by surface (``"component"``).

    Each event's hazard is h_k = −ln(1 − P_k) times the cartridges it loads (2 for two
    cartridges, 1 against a wall: ``j`` = −1), so that Σ h is the cartridges' summed hazard.

    Args:
        events: the event table (:data:`demfem.assess.events.EVENT_DTYPE`: uses ``time``,
            ``j``, ``partner``, ``wall``).
        p_event: (n,) P_k in [0, 1).
        window, period: as :func:`rate_interval` (s).
        wall_names: the run's wall names by index (``info["wall_names"]``).
        p_surfaces: optional mapping surface → (n,) P_k,surface with
            1 − P_k = Π_s (1 − P_k,s) (``{"inner": p_inner, "outer": p_outer}``): their
            hazards add up to h_k exactly.
        components: optional mapping name → (n,) hazards (the cartridges loaded counted)
            whose sum over the names is each event's h_k (e.g. by place on the cartridge and
            surface, :func:`demfem.assess.risk_stage.hazard_components`); instead of
            ``p_surfaces``, as the grouping ``"component"``.
        scale: per second → reported unit (3600: per hour; pass broken_per_hour /
            (Σ h / W) to carry the interval onto a number computed otherwise).
        confidence, method, n_boot, seed, max_weight: as :func:`rate_interval`.
    """
    p = as_array("p_event", p_event, 0.0, 1.0, lo_open=False, ndim=1)
    ev = np.asarray(events)
    if ev.shape != p.shape:
        raise InvalidParameterError(f"invalid p_event: shape {p.shape} does not match the "
                                    f"events {ev.shape}")
    loads = np.where(np.asarray(ev["j"]) >= 0, 2.0, 1.0)
    partner = np.where(np.asarray(ev["partner"]) == 0, "sphere", "wall")
    wall = np.asarray(ev["wall"], np.int64)
    names = np.array(list(wall_names) + ["wall"], dtype=object)
    place = np.where(partner == "sphere", "cartridge",
                     names[np.where((wall >= 0) & (wall < len(wall_names)), wall, -1)])
    if components is not None and p_surfaces:
        raise InvalidParameterError("invalid components: give components or p_surfaces, "
                                    "not both")
    if components is not None:
        weights: Any = {str(k): as_array(f"components[{k!r}]", v, 0.0, math.inf,
                                         lo_open=False, ndim=1)
                        for k, v in components.items()}
    elif p_surfaces:
        weights = {str(k): -np.log1p(-as_array(f"p_surfaces[{k!r}]", v, 0.0, 1.0,
                                                    lo_open=False, ndim=1)) * loads
                        for k, v in p_surfaces.items()}
    else:
        weights = -np.log1p(-p) * loads
    return rate_interval(ev["time"], weights, window, period,
                         groups={"with": place.astype(str), "partner": partner},
                         scale=scale, confidence=confidence, method=method, n_boot=n_boot,
                         seed=seed, max_weight=max_weight)
