"""Does one gate period dominate the hazard? The check that says when the interval of
:mod:`demfem.risk.interval` describes the window's scatter and when it cannot.

The interval over gate periods treats the periods as exchangeable draws of one distribution.
On the table that holds between ordinary periods (their hazard totals scatter by a
coefficient of variation of about 0.2 on the default table) but not for rare events of
another kind: a cartridge squeezed between the oscillating gate and a side wall (a *jam*)
loads it quasi-statically at about 100 N for a whole stroke, and its one period carried 64
times the median period's hazard and about 68 % of a 62-s run's (``docs/uncertainty.md``,
``benches/interval_coverage.py``). Such a period is not one more draw of the ordinary
scatter, and a window that holds one, or holds none, cannot say from its few periods how
often they happen.

**The check.** With Y_b the hazard totals of the window's n whole periods:

* a period *dominates* when Y_b > ``ratio`` × median(Y) (default 5: with the ordinary
  scatter's CV of 0.25 a period above 1.9 × the median is already rare; a factor of 5 is far
  outside it and far below a jam's 64);
* with such a period, its share Y_b / Σ Y and its place in time are reported, and the
  number is flagged: one event carries it, the interval is no statement about how often such
  events happen;
* without one, the zero-count binomial bound says how rare dominant periods must be for the
  window to have missed them at the given confidence: at most a fraction
  1 − (1 − c)^(1/n) of the periods (one-sided; 0.35 for 7 periods at 95 %). The interval is
  conditional on them being rarer than that; a long run or replicas measure it.

SI units: s; the weights' unit per period (hazard).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from demfem.errors import InvalidParameterError, check_positive, check_range
from demfem.risk._validate import as_array, check_same_shape

__all__ = ["DOMINANCE_RATIO", "PeriodDominance", "period_dominance"]

#: A period dominates when its hazard exceeds this multiple of the median period's.
DOMINANCE_RATIO = 5.0


@dataclass(frozen=True)
class PeriodDominance:
    """The result of :func:`period_dominance`.

    Attributes:
        n_periods: whole periods in the window.
        period_s: their length, s.
        totals: (n_periods,) hazard per period (the weights' unit).
        median: median period total.
        largest: the largest period total; largest_index: its period (0-based);
        largest_window_s: (start, end) of that period, s.
        largest_share: largest / Σ totals (NaN when Σ = 0).
        largest_over_median: largest / median (inf when the median is 0 and largest > 0).
        ratio: the dominance ratio used.
        dominant: indices of the periods above ratio × median.
        dominated: whether any period dominates.
        unseen_bound: without a dominant period, the largest fraction of periods that could
            dominate and still be missed by n periods at ``confidence`` (one-sided zero-count
            binomial bound); NaN with one.
        confidence: in (0, 1).
    """

    n_periods: int
    period_s: float
    totals: NDArray[np.float64]
    median: float
    largest: float
    largest_index: int
    largest_window_s: tuple[float, float]
    largest_share: float
    largest_over_median: float
    ratio: float
    dominant: tuple[int, ...]
    dominated: bool
    unseen_bound: float
    confidence: float

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready summary (no per-period array beyond the totals)."""
        def num(x: float) -> Any:
            return float(x) if math.isfinite(x) else None
        return {"n_periods": self.n_periods, "period_s": self.period_s,
                "period_totals": [float(v) for v in self.totals],
                "median": self.median, "largest": self.largest,
                "largest_window_s": list(self.largest_window_s),
                "largest_share": num(self.largest_share),
                "largest_over_median": num(self.largest_over_median),
                "ratio": self.ratio, "dominant_periods": list(self.dominant),
                "dominated": self.dominated, "unseen_bound": num(self.unseen_bound),
                "confidence": self.confidence}


def period_dominance(times: NDArray[np.float64] | Any, weights: NDArray[np.float64] | Any,
                     window: tuple[float, float], period: float, *,
                     ratio: float = DOMINANCE_RATIO,
                     confidence: float = 0.95) -> PeriodDominance:
    """The dominance check over the whole periods of ``window`` (module docstring).

    Args:
        times: (n,) event times, s. weights: (n,) their hazards ≥ 0.
        window: (start, end), s; the periods run from start, whole periods only.
        period: block length, s (the gate period).
        ratio: dominance ratio (> 1). confidence: for the unseen bound, in (0, 1).
    Raises:
        InvalidParameterError: bad arrays, a window of fewer than two whole periods.
    """
    from demfem.risk.interval import block_totals

    t = as_array("times", times, ndim=1, unit="s")
    w = as_array("weights", weights, 0.0, math.inf, lo_open=False, ndim=1)
    check_same_shape(times=t, weights=w)
    block = check_positive("period", period)
    r = check_range("ratio", ratio, 1.0, math.inf)
    conf = check_range("confidence", confidence, 0.0, 1.0)
    t0 = check_range("window start", window[0])
    t1 = check_range("window end", window[1], t0, math.inf)
    n = int(math.floor((t1 - t0) / block + 1e-9))
    if n < 2:
        raise InvalidParameterError(f"invalid window = {tuple(window)}: holds {n} whole "
                                    f"period(s) of {block:g} s, at least 2 needed")
    y = np.asarray(block_totals(t, w, t0, block, n), float)
    med = float(np.median(y))
    k = int(np.argmax(y))
    big = float(y[k])
    tot = float(y.sum())
    over = big / med if med > 0 else (math.inf if big > 0 else math.nan)
    dom = tuple(int(i) for i in np.flatnonzero(y > r * med)) if big > 0 else ()
    unseen = math.nan if dom else 1.0 - (1.0 - conf) ** (1.0 / n)
    return PeriodDominance(n, block, y, med, big, k, (t0 + k * block, t0 + (k + 1) * block),
                           big / tot if tot > 0 else math.nan, over, r, dom, bool(dom),
                           unseen, conf)
