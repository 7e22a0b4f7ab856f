"""When a running table is in a steady state: the rule that stops a table run once its mean
collision rate is known well enough, and the statistics of a finished run's window.

The table in operation is periodic and noisy, not constant: the gate opens and closes with
period T, and the collision rate swings with it (on the default table by a factor of 3 within
a period); over several periods it wanders further, as jams form at the gate and break (on
the default table re-fed, impacts per 2 s period over 2–20 s: 36 100, 35 300, 59 100, 52 400,
40 300, 31 600, 40 900, 43 300, 41 500). So the rate is counted over **whole gate periods**
from the end of the warm-up (the pack forming after the start), and the run is steady at the
end of a period when at least ``min_periods`` periods have been counted and the standard
error of their mean, s/√N, is at most ``tolerance`` of the mean. The statistics window is
then every period since the warm-up. (Two consecutive periods agreeing is no test: the first
two above agree within 1.2 % and the next differs by 50 %.) Impacts are the contact onsets
the assessment counts as events: normal speed ≥ ``min_speed``, not on the walls named in
``excluded_walls`` (the belt). A table whose gate does not move uses periods of 1 s.

On the data above the relative standard error is 18, 13, 10.6, 10.5 and 8.9 % after 3 to 7
periods: the default rule (at least 4 periods, 10 %) stops at 16 s.

SI units: s, m/s.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any, Sequence

import numpy as np

from demfem.errors import InvalidParameterError, check_positive, check_range

__all__ = ["SteadyRule", "period_rates", "relative_error"]


@dataclass(frozen=True)
class SteadyRule:
    """Stop a table run once its mean collision rate is known well enough (module docstring).

    Attributes:
        period: length of one counting period, s (the gate period; > 0).
        min_periods: fewest periods counted before the run may stop (≥ 2).
        warmup: start of the counting, s (≥ 0): the first period begins here.
        tolerance: largest relative standard error s/(√N mean) of the impacts per period
            (> 0).
        min_speed: normal speed of an impact, m/s (≥ 0).
        excluded_walls: engine indices of walls whose contacts are not impacts (the belt).
    """

    period: float
    min_periods: int = 4
    warmup: float = 2.0
    tolerance: float = 0.10
    min_speed: float = 5e-3
    excluded_walls: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        check_positive("period", self.period)
        if isinstance(self.min_periods, bool) or not isinstance(self.min_periods, int) \
                or self.min_periods < 2:
            raise InvalidParameterError(f"invalid min_periods = {self.min_periods!r}: must be "
                                        "a whole number >= 2")
        check_range("warmup", self.warmup, 0.0, math.inf, lo_open=False)
        check_positive("tolerance", self.tolerance)
        check_range("min_speed", self.min_speed, 0.0, math.inf, lo_open=False)

    def to_dict(self) -> dict[str, Any]:
        """Strict-JSON fields (for run settings)."""
        d = asdict(self)
        d["excluded_walls"] = list(self.excluded_walls)
        return d

    def periods_at(self, t: float, dt: float) -> int:
        """Whole periods from the warm-up to ``t`` (s; within ``dt``), or −1 when ``t`` does
        not end one."""
        k = (t - self.warmup) / self.period
        n = round(k)
        return n if n >= 1 and abs(t - self.warmup - n * self.period) <= dt else -1

    def due(self, t: float, dt: float) -> bool:
        """Whether time ``t`` (s) ends the ``min_periods``-th or a later whole period."""
        return self.periods_at(t, dt) >= self.min_periods

    def impacts(self, onsets: dict[str, np.ndarray]) -> np.ndarray:
        """Times (s) of the onsets that are impacts, from the engine's onset columns (time,
        partner, partner_is_wall, normal_speed)."""
        wall = np.asarray(onsets["partner_is_wall"], bool)
        excluded = wall & np.isin(np.asarray(onsets["partner"], np.int64),
                                  np.asarray(self.excluded_walls, np.int64))
        keep = (np.asarray(onsets["normal_speed"], float) >= self.min_speed) & ~excluded
        return np.asarray(onsets["time"], float)[keep]

    def check(self, t: float, impact_times: np.ndarray) -> dict[str, Any]:
        """Steadiness of the window from the warm-up to ``t`` (s): ``steady``, ``window_s``
        (start, end), the impacts per period (``counts``) and the relative standard error of
        their mean (``relative_error``)."""
        n = max(int(round((t - self.warmup) / self.period)), 0)
        counts = period_rates(impact_times, self.warmup, self.period, n)
        err = relative_error(counts)
        return {"steady": bool(n >= self.min_periods and err <= self.tolerance),
                "window_s": [self.warmup, self.warmup + n * self.period],
                "counts": [int(c) for c in counts], "relative_error": err,
                "tolerance": self.tolerance, "period_s": self.period}


def relative_error(values: Sequence[float] | np.ndarray) -> float:
    """Relative standard error of the mean of ``values``: s/(√N mean) with the sample standard
    deviation s (inf for fewer than two values or a zero mean)."""
    x = np.asarray(values, float)
    m = float(np.mean(x)) if len(x) else 0.0
    if len(x) < 2 or m <= 0:
        return math.inf
    return float(np.std(x, ddof=1) / math.sqrt(len(x)) / m)


def period_rates(times: Sequence[float] | np.ndarray, start: float, period: float, n: int,
                 weights: Sequence[float] | np.ndarray | None = None) -> np.ndarray:
    """Number of ``times`` (s) — or the sum of their ``weights`` — in each of the ``n``
    half-open periods [start + k period, start + (k + 1) period), k = 0 … n − 1 (s)."""
    t = np.asarray(times, float)
    k = np.floor((t - start) / period)
    inside = (k >= 0) & (k < n)
    w = None if weights is None else np.asarray(weights, float)[inside]
    return np.bincount(k[inside].astype(np.int64), weights=w, minlength=max(n, 0))[:n].astype(
        float)
