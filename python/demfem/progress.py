"""Progress of long runs: simulated time, steps per second and ETA on one line.

``ProgressBar`` is a callback ``progress(sim_time_s, steps)`` for the DEM and FEM runners. On a
terminal it redraws one line; elsewhere (CI logs, files) it prints a line at most every
``interval`` seconds of wall time so that logs stay short.
"""
from __future__ import annotations

import math
import sys
import time
from typing import Optional, TextIO

from demfem.errors import check_positive

__all__ = ["ProgressBar", "format_duration"]


def format_duration(seconds: float) -> str:
    """``seconds`` as ``1h02m03s`` / ``2m03s`` / ``3.4s``; ``--`` when unknown."""
    if not math.isfinite(seconds) or seconds < 0:
        return "--"
    if seconds < 60:
        return f"{seconds:.1f}s"
    m, s = divmod(int(round(seconds)), 60)
    h, m = divmod(m, 60)
    return f"{h}h{m:02d}m{s:02d}s" if h else f"{m}m{s:02d}s"


class ProgressBar:
    """A progress line for a run of ``duration`` seconds of simulated time.

    Call it as ``bar(sim_time, steps)`` with the simulated time reached (s) and the steps done
    so far; call :meth:`close` at the end. ``width`` is the bar's width in characters. The
    rate and the ETA count from the first call, so neither the set-up before it nor the steps
    of a resumed run's earlier part distort them; until a second call they read ``--``.
    """

    def __init__(self, duration: float, label: str = "run", stream: Optional[TextIO] = None,
                 width: int = 28, interval: float = 0.2, log_interval: float = 10.0) -> None:
        self.duration = check_positive("duration", duration)
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.width = width
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.interval = interval if self.tty else log_interval
        self._t0 = time.perf_counter()
        self._last_draw = -math.inf
        # wall time, steps and simulated time at the first call
        self._first: Optional[tuple[float, int, float]] = None
        self.last_line = ""

    def line(self, sim_time: float, steps: int) -> str:
        """The text of the progress line for ``sim_time`` (s) and ``steps``."""
        now = time.perf_counter()
        elapsed = now - self._t0
        frac = min(max(sim_time / self.duration, 0.0), 1.0)
        filled = int(round(frac * self.width))
        bar = "#" * filled + "-" * (self.width - filled)
        rate = eta = math.nan
        if self._first is not None:
            t1, steps1, sim1 = self._first
            wall, done = now - t1, sim_time - sim1
            if wall > 0 and done > 0:
                rate = (steps - steps1) / wall
                eta = wall * max(self.duration - sim_time, 0.0) / done
        rate_text = f"{rate:,.0f}" if math.isfinite(rate) else "--"
        return (f"{self.label} [{bar}] {100 * frac:5.1f}%  t = {sim_time:.4g}/{self.duration:.4g} s"
                f"  {rate_text} steps/s  elapsed {format_duration(elapsed)}"
                f"  ETA {format_duration(eta)}")

    def __call__(self, sim_time: float, steps: int) -> None:
        now = time.perf_counter()
        if self._first is None:
            self._first = (now, steps, sim_time)
        if now - self._last_draw < self.interval and sim_time < self.duration:
            return
        self._last_draw = now
        self.last_line = self.line(sim_time, steps)
        if self.tty:
            self.stream.write("\r" + self.last_line)
        else:
            self.stream.write(self.last_line + "\n")
        self.stream.flush()

    def close(self) -> None:
        """End the line (on a terminal)."""
        if self.tty:
            self.stream.write("\n")
            self.stream.flush()
