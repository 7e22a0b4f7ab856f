"""Impact events from a DEM run: one row per contact onset hard enough to matter.

What the record holds: :func:`demfem.dem.table_run.run_table` logs every contact onset,
sphere–sphere (partners i and j) and sphere–wall (the wall's index and the contact point), with
the time and the normal and tangential relative speed at onset (against a moving wall, the gate,
relative to its surface). Sphere–sphere events are partner type ``"sphere"``; impacts on the
side walls, the back, the tilted wall and the gate are partner type ``"wall"`` (a flat glass
half-space in the stress stage, :data:`demfem.assess.impact.PARTNERS`). Contacts with the belt
are not events: the equivalent sphere on the belt is a cartridge standing on its base, loaded
along its axis, not the side-wall impact the stress model describes (walls named in
:data:`NOT_IMPACTS`).

Position: the record samples the centres every ``sample_interval``; the centres of i and j at
the onset time are interpolated linearly between the two samples around it (nearest sample if
a partner left in between), and the contact point is c_i + r_i (c_j − c_i)/|c_j − c_i|.

Measured contacts: a run recorded with ``record_events`` (as ``demfem assess`` records it)
holds every whole contact with its duration, peak normal force and normal impulse measured in
the DEM step by step (:data:`demfem.analysis.contact_events.CONTACT_EVENT_DTYPE`); the events
are then made from those (``measured`` True), and their contact point is the engine's at
onset. Without them (older runs) the events are the onsets, and force and duration come from
the calibrated law at the onset speed in the stress stage.

Minimum-speed filter: onsets with a normal speed below ``min_speed`` (default 5 mm/s) are
dropped (with measured contacts, only those whose measured peak force is also below
``min_force``, the force of an impact at ``min_speed``: a contact that began gently but was
then pressed hard by the queue behind it is kept). Most onsets of a packed table are resting chatter (spheres in a pack touching and
parting at a few mm/s); at 5 mm/s two default cartridges meet with a peak force of ≈ 0.27 N
(Hertz–Reissner, E = 45 GPa), a σ1 of ≈ 0.4 MPa: negligible for breakage, so the filter only
sheds bookkeeping. The report states how many onsets it dropped and their largest speed.

SI units: s, m, m/s.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from demfem.errors import InvalidParameterError, check_range

__all__ = ["EVENT_DTYPE", "DEFAULT_MIN_SPEED", "NOT_IMPACTS", "impact_events", "count_line",
           "onset_digest", "without_onsets", "ONSET_SPEED_BINS",
           "events_of_cartridge", "events_per_cartridge"]

#: Walls whose contacts are not side impacts on a cartridge (the floor it stands on).
NOT_IMPACTS = ("belt",)

#: Default minimum normal impact speed of an event, m/s.
DEFAULT_MIN_SPEED = 5e-3

#: Fields of the event table: partners i, j (j = -1 for a wall), partner code (0 sphere,
#: 1 wall), the wall's index in the run's ``info["wall_names"]`` (-1 for a sphere), onset
#: time (s), contact point (m), normal and tangential relative speed at onset (m/s), impact
#: angle atan2(v_t, v_n) (rad); measured in the DEM (``measured``; NaN otherwise): peak
#: normal force (N), contact duration (s), normal impulse (N s), peak tangential (friction)
#: force (N); ``pressed``: kept for its force although it began slower than the minimum
#: speed (a contact pressed by the queue, not an impact).
EVENT_DTYPE = np.dtype([
    ("i", "i8"), ("j", "i8"), ("partner", "i8"), ("wall", "i8"), ("time", "f8"),
    ("x", "f8"), ("y", "f8"), ("z", "f8"),
    ("normal_speed", "f8"), ("tangential_speed", "f8"), ("impact_angle", "f8"),
    ("peak_force", "f8"), ("duration", "f8"), ("impulse", "f8"), ("measured", "?"),
    ("peak_tangential_force", "f8"), ("pressed", "?"),
])


def centres_at(run, t: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Centres (n, 3) of spheres ``idx`` at times ``t`` (s), interpolated between samples."""
    times = np.asarray(run.times, float)
    k = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 1)
    k1 = np.minimum(k + 1, len(times) - 1)
    span = times[k1] - times[k]
    w = np.where(span > 0, (t - times[k]) / np.where(span > 0, span, 1.0), 0.0)
    w = np.clip(w, 0.0, 1.0)[:, None]
    p0 = run.positions[k, idx]
    p1 = run.positions[k1, idx]
    out = (1.0 - w) * p0 + w * p1
    near = np.where(w < 0.5, p0, p1)
    bad = ~np.all(np.isfinite(out), axis=1)
    out[bad] = near[bad]
    bad = ~np.all(np.isfinite(out), axis=1)
    out[bad] = np.where(np.isfinite(p0[bad]), p0[bad], p1[bad])
    return out


def impact_events(run, min_speed: float = DEFAULT_MIN_SPEED,
                  min_force: float = math.inf) -> tuple[np.ndarray, dict[str, Any]]:
    """The impact events of a :class:`~demfem.dem.table_run.TableRun` with a normal
    speed ≥ ``min_speed`` (m/s, ≥ 0) or, for measured contacts, a peak normal force ≥
    ``min_force`` (N, ≥ 0; default: no such rescue), sphere–sphere and sphere–wall (not the
    belt), in time order, as an array of :data:`EVENT_DTYPE`; and a summary: ``n_onsets``
    (all recorded onsets, belt contacts included), ``n_events`` (of which ``n_wall_events``,
    and per wall ``wall_events``), ``n_dropped``, ``max_dropped_speed_m_per_s``,
    ``min_speed_m_per_s``, ``measured`` (forces and durations measured in the DEM),
    ``partners_recorded``, ``note``."""
    v_min = check_range("min_speed", min_speed, 0.0, math.inf, lo_open=False)
    f_min = math.inf if min_force == math.inf else check_range(
        "min_force", min_force, 0.0, math.inf, lo_open=False)
    if run.info.get("events_recorded"):
        return _measured_events(run, v_min, f_min)
    o = run.onsets
    keep = np.asarray(o["normal_speed"], float) >= v_min
    sel = o[keep]
    ev = np.zeros(len(sel), EVENT_DTYPE)
    for k in ("i", "j", "time", "normal_speed", "tangential_speed", "impact_angle"):
        ev[k] = sel[k]
    ev["partner"], ev["wall"] = 0, -1
    ev["peak_force"] = ev["duration"] = ev["impulse"] = ev["peak_tangential_force"] = np.nan
    if len(sel):
        t = np.asarray(sel["time"], float)
        ci = centres_at(run, t, np.asarray(sel["i"]))
        cj = centres_at(run, t, np.asarray(sel["j"]))
        d = cj - ci
        norm = np.linalg.norm(d, axis=1)
        unit = np.where(norm[:, None] > 0, d / np.where(norm > 0, norm, 1.0)[:, None], 0.0)
        point = ci + np.asarray(run.radii, float)[np.asarray(sel["i"])][:, None] * unit
        ev["x"], ev["y"], ev["z"] = point[:, 0], point[:, 1], point[:, 2]
    names = [str(n) for n in run.info.get("wall_names", [])]
    w = np.asarray(run.wall_onsets)
    # per wall index: is a contact with it an impact (walls not named in the run: yes)
    impact_by_wall = np.array([n not in NOT_IMPACTS for n in names]
                              + [True] * (int(w["wall"].max()) + 1 - len(names) if len(w) else 0),
                              bool)
    impact_wall = impact_by_wall[np.asarray(w["wall"], np.int64)]
    w_speed = np.asarray(w["normal_speed"], float)
    w_keep = impact_wall & (w_speed >= v_min)
    ws = w[w_keep]
    wev = np.zeros(len(ws), EVENT_DTYPE)
    for k in ("i", "wall", "time", "normal_speed", "tangential_speed", "impact_angle",
              "x", "y", "z"):
        wev[k] = ws[k]
    wev["j"], wev["partner"] = -1, 1
    wev["peak_force"] = wev["duration"] = wev["impulse"] = np.nan
    wev["peak_tangential_force"] = np.nan
    ev = np.concatenate([ev, wev])
    ev = ev[np.argsort(ev["time"], kind="stable")]
    dropped = np.concatenate([np.asarray(o["normal_speed"], float)[~keep],
                              w_speed[impact_wall & ~w_keep]])
    per_wall = {n: int(np.sum(ws["wall"] == k)) for k, n in enumerate(names)
                if n not in NOT_IMPACTS}
    n_belt = int(len(w) - impact_wall.sum())
    return ev, _summary(len(o) + len(w), ev, int(len(wev)), per_wall, n_belt, dropped, v_min,
                        names, measured=False)


#: Bin edges (m/s) of the onset-speed histogram an assessment keeps instead of every onset.
ONSET_SPEED_BINS = np.geomspace(1e-6, 10.0, 141)


def _impact_walls(run) -> np.ndarray:
    names = [str(n) for n in run.info.get("wall_names", [])]
    w = np.asarray(run.wall_onsets)
    n_walls = max(len(names), int(w["wall"].max()) + 1 if len(w) else 0)
    return np.array([k >= len(names) or names[k] not in NOT_IMPACTS for k in range(n_walls)],
                    bool)


def onset_digest(run, min_speed: float) -> dict[str, Any]:
    """What an assessment needs of a run's contact onsets, without the onsets: their counts
    (between cartridges, with walls and gate, with the belt), how many impacts (not the belt)
    began slower than ``min_speed`` (m/s) and the fastest of those, and the histogram of all
    impact onsets' normal speeds over :data:`ONSET_SPEED_BINS` (m/s)."""
    v_min = check_range("min_speed", min_speed, 0.0, math.inf, lo_open=False)
    o, wo = np.asarray(run.onsets), np.asarray(run.wall_onsets)
    impact = _impact_walls(run)
    wo_impact = impact[np.asarray(wo["wall"], np.int64)] if len(wo) else np.zeros(0, bool)
    speeds = np.concatenate([np.asarray(o["normal_speed"], float),
                             np.asarray(wo["normal_speed"], float)[wo_impact]])
    slow = speeds[speeds < v_min]
    hist, _ = np.histogram(np.clip(speeds, ONSET_SPEED_BINS[0], ONSET_SPEED_BINS[-1]),
                           bins=ONSET_SPEED_BINS)
    return {"n_sphere_onsets": int(len(o)), "n_wall_onsets": int(len(wo)),
            "n_belt_onsets": int(np.sum(~wo_impact)), "n_impact_onsets": int(len(speeds)),
            "n_slow": int(len(slow)), "max_slow_speed_m_per_s": float(slow.max()) if len(slow)
            else 0.0, "min_speed_m_per_s": v_min,
            "speed_bins_m_per_s": ONSET_SPEED_BINS.tolist(),
            "speed_counts": [int(c) for c in hist]}


def without_onsets(run, min_speed: float):
    """The run with its onsets replaced by their :func:`onset_digest` (in
    ``info["onset_digest"]``): what an assessment keeps (the onsets of a default run are
    ~250 MB; the digest is a few kB). Its measured contact events stay."""
    import dataclasses

    from demfem.analysis.collisions import ONSET_DTYPE, WALL_ONSET_DTYPE

    digest = onset_digest(run, min_speed)
    return dataclasses.replace(run, onsets=np.zeros(0, ONSET_DTYPE),
                               wall_onsets=np.zeros(0, WALL_ONSET_DTYPE),
                               info={**run.info, "onset_digest": digest})


def count_line(summary: dict[str, Any]) -> str:
    """The events stage's counts in the one scheme the console and the report share:
    onsets = belt contacts + slower than the filter + events (pressed ones included)."""
    s = summary
    return (f"{s['n_onsets']} contact onsets = {s['n_belt_contacts']} with the belt (a "
            f"cartridge standing on it, not an impact) + {s['n_dropped']} slower than "
            f"{s['min_speed_m_per_s']:g} m/s (dropped) + {s['n_events']} events "
            f"({s['n_events'] - s.get('n_wall_events', 0)} between cartridges, "
            f"{s.get('n_wall_events', 0)} with walls and gate; {s.get('n_pressed', 0)} of them "
            "slower but pressed by the queue)")


def _summary(n_onsets: int, ev: np.ndarray, n_wall: int, per_wall: dict[str, int], n_belt: int,
             dropped: np.ndarray, v_min: float, names: list[str], measured: bool
             ) -> dict[str, Any]:
    return {"n_onsets": int(n_onsets), "n_events": int(len(ev)),
            "n_pressed": int(np.sum(ev["pressed"])),
            "n_wall_events": n_wall, "wall_events": per_wall,
            "n_belt_contacts": n_belt,
            "n_dropped": int(len(dropped)),
            "max_dropped_speed_m_per_s": float(dropped.max()) if len(dropped) else 0.0,
            "min_speed_m_per_s": v_min, "measured": measured,
            "partners_recorded": ["sphere", "wall"] if names else ["sphere"],
            "note": (f"sphere-sphere and sphere-wall impacts (walls: "
                     f"{', '.join(per_wall) or 'none recorded'}); the {n_belt} contacts with "
                     "the belt are cartridges standing on their base, not side impacts, and "
                     "are not events"
                     + ("; peak force, duration and impulse measured in the DEM" if measured
                        else "; force and duration from the calibrated law at onset speed"))}


def _measured_events(run, v_min: float, f_min: float) -> tuple[np.ndarray, dict[str, Any]]:
    """:func:`impact_events` from the run's measured whole contacts."""
    if run.info.get("kept_record") and not len(run.contact_events):
        raise InvalidParameterError(
            "invalid run: it is the record a finished assessment keeps "
            "(demfem.assess.job_stages.kept_record), without its whole contacts; its events "
            "are in the assessment's events.parquet (demfem.assess.load_assessment)")
    c = np.asarray(run.contact_events)
    names = [str(n) for n in run.info.get("wall_names", [])]
    wall = c["partner_is_wall"]
    n_walls = max(len(names), int(c["j"][wall].max()) + 1 if wall.any() else 0)
    impact_by_wall = np.array([k >= len(names) or names[k] not in NOT_IMPACTS
                               for k in range(n_walls)], bool)
    impact = ~wall | impact_by_wall[np.where(wall, c["j"], 0)] if n_walls else ~wall
    hard = (c["normal_speed"] >= v_min) | (c["peak_normal_force"] >= f_min)
    sel = c[impact & hard]
    ev = np.zeros(len(sel), EVENT_DTYPE)
    ev["i"], ev["time"] = sel["i"], sel["time"]
    w = sel["partner_is_wall"]
    ev["j"] = np.where(w, -1, sel["j"])
    ev["wall"] = np.where(w, sel["j"], -1)
    ev["partner"] = w.astype(np.int64)
    for k in ("x", "y", "z", "normal_speed", "tangential_speed"):
        ev[k] = sel[k]
    ev["impact_angle"] = np.arctan2(sel["tangential_speed"], sel["normal_speed"])
    ev["peak_force"], ev["duration"] = sel["peak_normal_force"], sel["duration"]
    ev["impulse"], ev["measured"] = sel["normal_impulse"], True
    ev["peak_tangential_force"] = sel["peak_tangential_force"]
    ev["pressed"] = sel["normal_speed"] < v_min
    ev = ev[np.argsort(ev["time"], kind="stable")]
    per_wall = {n: int(np.sum(w & (sel["j"] == k))) for k, n in enumerate(names)
                if n not in NOT_IMPACTS}
    # the run may have stored only the events it was asked to keep: count the dropped from
    # its onsets (every contact has one), or from their digest
    o, wo = run.onsets, run.wall_onsets
    digest = run.info.get("onset_digest")
    if digest is not None:
        if not math.isclose(float(digest["min_speed_m_per_s"]), v_min, rel_tol=0, abs_tol=0):
            raise InvalidParameterError(
                f"invalid min_speed = {v_min!r}: the run kept only the digest of its onsets, "
                f"made for min_speed = {digest['min_speed_m_per_s']!r} m/s")
        n_drop = max(int(digest["n_impact_onsets"]) - len(ev), 0)
        dropped = np.full(min(n_drop, int(digest["n_slow"])),
                          float(digest["max_slow_speed_m_per_s"]))
        n_all = int(digest["n_sphere_onsets"]) + int(digest["n_wall_onsets"])
        n_belt = int(digest["n_belt_onsets"])
    elif o is not None and wo is not None and len(o) + len(wo) >= len(c):
        wo_impact = impact_by_wall[np.asarray(wo["wall"], np.int64)] if n_walls else \
            np.ones(len(wo), bool)
        speeds = np.concatenate([np.asarray(o["normal_speed"], float),
                                 np.asarray(wo["normal_speed"], float)[wo_impact]])
        n_impact_onsets = len(speeds)
        slow = speeds[speeds < v_min]
        dropped = np.sort(slow)[:max(n_impact_onsets - len(ev), 0)]
        n_all, n_belt = len(o) + len(wo), int(np.sum(~wo_impact))
    else:
        dropped = c["normal_speed"][impact & ~hard]
        n_all, n_belt = len(c), int(np.sum(wall & ~impact))
    return ev, _summary(n_all, ev, int(w.sum()), per_wall, n_belt, dropped, v_min, names,
                        measured=True)


def events_of_cartridge(events: np.ndarray, cartridge: int) -> np.ndarray:
    """Indices into ``events`` of the events cartridge (sphere id) ``cartridge`` takes part in
    (as i or as j): both partners of a sphere–sphere impact are loaded."""
    return np.flatnonzero((events["i"] == cartridge) | (events["j"] == cartridge))


def events_per_cartridge(events: np.ndarray, n: int) -> list[np.ndarray]:
    """For each of the ``n`` cartridges (sphere ids 0..n-1), the indices of its events."""
    out: list[list[int]] = [[] for _ in range(n)]
    for k, (i, j) in enumerate(zip(events["i"], events["j"])):
        out[int(i)].append(k)
        if j >= 0:
            out[int(j)].append(k)
    return [np.asarray(v, np.int64) for v in out]
