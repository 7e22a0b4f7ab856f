"""When a running table is in a steady state: the rule that stops a table run once its
collision rate is steady, and the steadiness of a finished run's statistics window.

The table in operation is periodic, not constant: the gate opens and closes with period T, and
the collision rate swings with it (on the default table by a factor of 3 within a period). So
the rate is compared over **whole gate periods**: the run is steady at time t when each of the
last ``window_periods`` periods before t holds a number of impacts within ``tolerance`` of
their mean, and t is past ``warmup`` (the pack forming after the start). Impacts are the
contact onsets that the assessment would count as events: normal speed ≥ ``min_speed``, not
on the walls named in ``excluded_walls`` (the belt). A table whose gate does not move uses
periods of ``still_period`` s.

Measured on the default table with re-feeding (840 cartridges, 45 GPa; impacts per 2 s gate
period over 2–10 s: 86 900, 72 100, 84 700, 79 100): the pack forms within the first 2 s,
after which the periods agree within ±10 %; without re-feeding the table drains (840 → 698
cartridges in 10 s) and the rate keeps falling.

SI units: s, m/s.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any, Sequence

import numpy as np

from demfem.errors import InvalidParameterError, check_positive, check_range

__all__ = ["SteadyRule", "period_rates"]


@dataclass(frozen=True)
class SteadyRule:
    """Stop a table run once its collision rate is steady (module docstring).

    Attributes:
        period: length of one comparison period, s (the gate period; > 0).
        window_periods: periods compared, and the statistics window's length in periods (≥ 2).
        warmup: earliest start of the window, s (≥ 0).
        tolerance: largest relative deviation of a period's impacts from the window's mean
            (> 0).
        min_speed: normal speed of an impact, m/s (≥ 0).
        excluded_walls: engine indices of walls whose contacts are not impacts (the belt).
    """

    period: float
    window_periods: int = 2
    warmup: float = 2.0
    tolerance: float = 0.15
    min_speed: float = 5e-3
    excluded_walls: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        check_positive("period", self.period)
        if isinstance(self.window_periods, bool) or not isinstance(self.window_periods, int) \
                or self.window_periods < 2:
            raise InvalidParameterError(f"invalid window_periods = {self.window_periods!r}: "
                                        "must be a whole number >= 2")
        check_range("warmup", self.warmup, 0.0, math.inf, lo_open=False)
        check_positive("tolerance", self.tolerance)
        check_range("min_speed", self.min_speed, 0.0, math.inf, lo_open=False)

    def to_dict(self) -> dict[str, Any]:
        """Strict-JSON fields (for run settings)."""
        d = asdict(self)
        d["excluded_walls"] = list(self.excluded_walls)
        return d

    @property
    def window(self) -> float:
        """Length of the statistics window, s."""
        return self.window_periods * self.period

    def due(self, t: float, dt: float) -> bool:
        """Whether time ``t`` (s) ends a whole period past the warm-up (within ``dt``)."""
        if t + dt < self.warmup + self.window:
            return False
        k = round(t / self.period)
        return abs(t - k * self.period) <= dt

    def impacts(self, onsets: dict[str, np.ndarray]) -> np.ndarray:
        """Times (s) of the onsets that are impacts, from the engine's onset columns (time,
        partner, partner_is_wall, normal_speed)."""
        wall = np.asarray(onsets["partner_is_wall"], bool)
        excluded = wall & np.isin(np.asarray(onsets["partner"], np.int64),
                                  np.asarray(self.excluded_walls, np.int64))
        keep = (np.asarray(onsets["normal_speed"], float) >= self.min_speed) & ~excluded
        return np.asarray(onsets["time"], float)[keep]

    def check(self, t: float, impact_times: np.ndarray) -> dict[str, Any]:
        """Steadiness of the window ending at ``t`` (s): ``steady``, ``window_s`` (start,
        end), the impacts per period (``counts``) and the largest relative deviation from
        their mean (``deviation``)."""
        start = t - self.window
        counts = period_rates(impact_times, start, self.period, self.window_periods)
        mean = float(np.mean(counts))
        dev = float(np.max(np.abs(counts / mean - 1.0))) if mean > 0 else math.inf
        return {"steady": bool(start >= self.warmup - 1e-12 and dev <= self.tolerance),
                "window_s": [start, t], "counts": [int(c) for c in counts],
                "deviation": dev, "tolerance": self.tolerance, "period_s": self.period}


def period_rates(times: Sequence[float] | np.ndarray, start: float, period: float,
                 n: int) -> np.ndarray:
    """Number of ``times`` (s) in each of the ``n`` periods of length ``period`` (s) from
    ``start`` (s)."""
    edges = start + period * np.arange(n + 1)
    return np.histogram(np.asarray(times, float), edges)[0].astype(float)
