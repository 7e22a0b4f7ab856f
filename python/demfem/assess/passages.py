"""Passages: the unit of risk is one cartridge's passage over the table, from its insertion to
its exit through the opening.

A re-fed table puts a cartridge that left back upstream under the same sphere id, so a sphere
id carries several passages in one run; an infeed inserts new ones. Events, exposure and the
probability of breakage belong to the passage that was on the table when the event happened,
never to the id.

From the run's insertion log (every sphere at t = 0, then each re-insertion) and its removal
log (each exit), :func:`passages` builds the passage table; :func:`passage_of_events` assigns
each event's partners to their passages; :func:`table_flow` gives what the simulation itself
says of the flow in a window: the mean number of cartridges on the table, the discharge rate
and, by Little's law, the residence time.

SI units: s; rates per second unless named per hour.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from demfem.errors import InvalidParameterError

__all__ = ["PASSAGE_DTYPE", "passages", "passage_of_events", "table_flow"]

#: One passage: its sphere id, insertion time (s), exit time (s; NaN while still on the table
#: at the end of the run), and whether it left through the opening (``exited``).
PASSAGE_DTYPE = np.dtype([("particle", "i8"), ("start", "f8"), ("end", "f8"),
                          ("exited", "?")])


def _log(times: Any, index: Any, n: int, name: str) -> tuple[np.ndarray, np.ndarray]:
    t = np.asarray(times, float).reshape(-1)
    i = np.asarray(index).reshape(-1)
    if t.shape != i.shape:
        raise InvalidParameterError(f"invalid {name}: {t.size} times for {i.size} ids")
    if i.size and (not np.issubdtype(i.dtype, np.integer) or i.min() < 0 or i.max() >= n):
        raise InvalidParameterError(f"invalid {name}: sphere ids must be integers in [0, {n})")
    if not np.all(np.isfinite(t)):
        raise InvalidParameterError(f"invalid {name}: times must be finite")
    return t, i.astype(np.int64)


def passages(n: int, removal_times: Any, removal_index: Any, insertion_times: Any = (),
             insertion_index: Any = (), end_time: float = math.inf) -> np.ndarray:
    """The passages of a run of ``n`` spheres, all on the table at t = 0, that left at
    ``removal_times`` (s; ids ``removal_index``) and were put back at ``insertion_times``
    (s; ids ``insertion_index``), the run ending at ``end_time`` (s). Sorted by sphere id and
    start time (:data:`PASSAGE_DTYPE`).

    Raises:
        InvalidParameterError: ids out of range, non-finite times, or a log in which a sphere
            leaves while off the table or is put back while on it.
    """
    if not (isinstance(n, (int, np.integer)) and n >= 0):
        raise InvalidParameterError(f"invalid n = {n!r}: must be an integer >= 0")
    rt, ri = _log(removal_times, removal_index, n, "removal log")
    it, ii = _log(insertion_times, insertion_index, n, "insertion log")
    # merge the two logs per sphere in time order; at equal times an exit comes first (a
    # sphere removed during a chunk is put back at the chunk's end)
    kind = np.concatenate([np.zeros(rt.size, np.int64), np.ones(it.size, np.int64)])
    who = np.concatenate([ri, ii])
    when = np.concatenate([rt, it])
    order = np.lexsort((kind, when, who))
    rows: list[tuple[int, float, float, bool]] = []
    on = np.ones(n, bool)
    start = np.zeros(n)
    for k in order:
        i, t = int(who[k]), float(when[k])
        if kind[k] == 0:
            if not on[i]:
                raise InvalidParameterError(
                    f"invalid removal log: sphere {i} leaves at t = {t:g} s while off the table")
            rows.append((i, float(start[i]), t, True))
            on[i] = False
        else:
            if on[i]:
                raise InvalidParameterError(
                    f"invalid insertion log: sphere {i} is put back at t = {t:g} s while on the "
                    "table")
            on[i], start[i] = True, t
    for on_table in np.flatnonzero(on):
        rows.append((int(on_table), float(start[on_table]), math.nan, False))
    out = np.array(rows, PASSAGE_DTYPE) if rows else np.zeros(0, PASSAGE_DTYPE)
    out = out[np.lexsort((out["start"], out["particle"]))]
    if math.isfinite(end_time):
        still = ~out["exited"]
        if np.any(out["start"][still] > end_time):
            raise InvalidParameterError("invalid insertion log: an insertion after the end of "
                                        f"the run at t = {end_time:g} s")
    return out


def passage_of_events(table: np.ndarray, particle: np.ndarray, time: np.ndarray) -> np.ndarray:
    """Index into the passage ``table`` of the passage sphere ``particle`` was on at ``time``
    (s), for each event; −1 where ``particle`` is −1 (a wall) or the sphere was off the table
    (an event is never given to a passage that had ended or not begun)."""
    particle = np.asarray(particle, np.int64)
    time = np.asarray(time, float)
    out = np.full(particle.shape, -1, np.int64)
    if table.size == 0 or particle.size == 0:
        return out
    # the table is sorted by (particle, start): a global key orders the passages the same way
    span = max(float(np.nanmax(np.concatenate([table["start"], table["end"], time]))), 1.0) * 4
    key_table = table["particle"] * span + table["start"]
    ok = particle >= 0
    key = particle[ok] * span + time[ok]
    k = np.searchsorted(key_table, key, side="right") - 1
    valid = k >= 0
    kk = np.where(valid, k, 0)
    same = valid & (table["particle"][kk] == particle[ok])
    end = table["end"][kk]
    on = same & (np.isnan(end) | (time[ok] <= end))
    out[np.flatnonzero(ok)[on]] = kk[on]
    return out


def table_flow(table: np.ndarray, window: tuple[float, float]) -> dict[str, Any]:
    """What the simulation says of the flow over ``window`` = (t_0, t_1), s:

    - ``exposure_s`` (per passage): its time on the table inside the window;
    - ``mean_on_table``: Σ exposure / (t_1 − t_0), the mean number of cartridges on it;
    - ``exits``: passages that left through the opening inside the window;
    - ``discharge_per_s`` and ``discharge_per_hour``: exits / (t_1 − t_0);
    - ``residence_time_s``: by Little's law, mean_on_table / discharge (NaN without exits);
    - ``passages_in_window``: passages with exposure > 0.
    """
    t0, t1 = (float(window[0]), float(window[1]))
    if not (math.isfinite(t0) and math.isfinite(t1) and t1 > t0):
        raise InvalidParameterError(f"invalid window = {window!r}: must be finite with t_1 > t_0")
    w = t1 - t0
    end = np.where(np.isnan(table["end"]), t1, table["end"])
    exposure = np.clip(np.minimum(end, t1) - np.maximum(table["start"], t0), 0.0, None)
    exits = int(np.sum(table["exited"] & (table["end"] >= t0) & (table["end"] <= t1)))
    mean_on = float(exposure.sum() / w)
    rate = exits / w
    return {"exposure_s": exposure, "mean_on_table": mean_on, "exits": exits,
            "discharge_per_s": rate, "discharge_per_hour": 3600.0 * rate,
            "residence_time_s": mean_on / rate if exits else math.nan,
            "passages_in_window": int(np.sum(exposure > 0)), "window_s": w}
