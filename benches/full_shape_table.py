"""The default table with full-shape cartridges (the fast exact body of revolution) beside the
same table with equivalent spheres: where on a cartridge its contacts land, with what, at what
angle, how many cartridges tilt or fall, and how the two engines' contact statistics compare
(issue 40, items 2 and 3).

Both runs are the default table's geometry (840 cartridges, the gate swinging, the belt
packing them) at the same Young's modulus, from the same start, **re-fed** by default: what
leaves through the outlet is put back upstream at the first free re-feed site (cartridges
upright, where the engine's exact contact test finds the site free:
``RigidSimulation.reinsert_body``, :func:`demfem.dem.refeed_removed_bodies`), so the table
runs "in operation" with a steady population instead of draining (about 20 cartridges a
second leave at its downstream end). ``--no-refeed`` runs the draining table (the table then
keeps its upstream column filled at the start, as before). The spheres run with the
calibrated Hertz–Reissner–Mindlin law that ``demfem assess`` uses; the cartridges with Hertz
at the local radii of the two surfaces (the rigid engine has no shell compliance).

For every contact onset after ``--warmup`` with a normal speed of at least ``--min-speed``
(the filter of ``demfem assess``, 5 mm/s), the full-shape run records the place on each
cartridge (:data:`demfem.rigid.PLACES`: rim, body, shoulder, neck, flange), the partner
(another cartridge, or the wall by name), the angle between the two axes (or between the axis
and the wall's surface) and the speeds. Every ``--sample`` seconds it records the tilt of
every cartridge on the table. The sphere run gives the same onsets by partner.

    python benches/full_shape_table.py --duration 3.0 --warmup 2.0 --threads 2

Every ``--sample`` seconds the cartridges on the table are counted (``tilt``: ``on_table``,
and ``reinserted``, the re-insertions so far). Results go to ``docs/data/full_shape_table.json`` (distributions as counts), and a summary to
stdout. The full-shape run costs about 20 times the spheres (docs/performance.md).
"""
from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path
from typing import Any

import numpy as np

from demfem import dem, rigid
from demfem.assess.events import DEFAULT_MIN_SPEED
from demfem.io.strict_json import write_json_atomic
from demfem.scenes import AccumulationTable

OUT = Path(__file__).resolve().parent.parent / "docs" / "data" / "full_shape_table.json"
#: Tilt classes (degrees from upright): upright, tilted beyond 5°, leaning beyond 30°, fallen
#: beyond 60°.
TILTS = (5.0, 30.0, 60.0)
SPEED_EDGES = (0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 10.0)
ANGLE_EDGES = (0.0, 5.0, 15.0, 30.0, 60.0, 90.0)


def _partner_names(partner: np.ndarray, is_wall: np.ndarray, names: list[str]) -> np.ndarray:
    return np.array([names[p] if w and p < len(names) else ("cartridge" if not w else "wall")
                     for p, w in zip(partner, is_wall)], dtype=object)


def _speeds(v: np.ndarray) -> dict[str, Any]:
    if v.size == 0:
        return {"n": 0}
    q = np.quantile(v, [0.5, 0.9, 0.99])
    return {"n": int(v.size), "median_m_per_s": float(q[0]), "p90_m_per_s": float(q[1]),
            "p99_m_per_s": float(q[2]), "max_m_per_s": float(v.max()),
            "histogram": np.histogram(v, SPEED_EDGES)[0].tolist()}


def _by_partner(partner: np.ndarray, speed: np.ndarray, seconds: float,
                bodies: float) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for name in sorted(set(partner.tolist())):
        sel = partner == name
        out[str(name)] = {"onsets_per_s_per_cartridge": float(sel.sum()) / seconds / bodies,
                          **_speeds(speed[sel])}
    return out


def full_shapes(table: AccumulationTable, a: argparse.Namespace) -> dict[str, Any]:
    """Run the full-shape table; returns its distributions."""
    description = table.build()
    start = time.perf_counter()
    sim = rigid.from_scene(description, particle="revolution", record_onsets=True,
                           threads=a.threads)
    refeed = rigid.refeed_of(description) if a.refeed else None
    print(f"revolution: {len(sim)} cartridges, dt {sim.dt:.3e} s, "
          f"{'re-fed' if refeed else 'not re-fed'}", flush=True)
    cart = table.cartridge
    cols: dict[str, list[Any]] = {k: [] for k in (
        "time", "place_body", "place_partner", "partner", "axis_angle_deg", "normal_speed",
        "tangential_speed", "height_body")}
    tilt_rows = []
    t = 0.0
    while t < a.duration - 1e-12:
        if a.max_wall is not None and time.perf_counter() - start > a.max_wall:
            print(f"  stopped at t = {t:.2f} s: --max-wall {a.max_wall:g} s reached", flush=True)
            break
        t = min(a.duration, t + a.sample)
        rigid.run(sim, t, refeed=refeed)
        ev = rigid.contact_places(sim, cart, description.walls)
        keep = (np.asarray(ev["time"]) >= a.warmup) & (
            np.asarray(ev["normal_speed"]) >= a.min_speed)
        partner = np.where(ev["partner_kind"] == "wall", ev["partner_name"],
                           ev["partner_kind"])
        for key, col in (("time", ev["time"]), ("place_body", ev["place_body"]),
                         ("place_partner", ev["place_partner"]), ("partner", partner),
                         ("axis_angle_deg", ev["axis_angle_deg"]),
                         ("normal_speed", ev["normal_speed"]),
                         ("tangential_speed", ev["tangential_speed"]),
                         ("height_body", ev["height_body"])):
            cols[key].extend(np.asarray(col)[keep].tolist())
        sim.clear_records()
        alive = np.asarray(sim.alive(), bool)
        tilt = np.degrees(np.asarray(sim.tilt_angles(), float))[alive]
        tilt_rows.append({"time_s": t, "on_table": int(alive.sum()),
                          "reinserted": int(len(sim.reinsertions()[0])),
                          **{f"beyond_{x:g}_deg": int(np.count_nonzero(tilt > x))
                             for x in TILTS},
                          "max_tilt_deg": float(np.nanmax(tilt)) if tilt.size else 0.0})
        print(f"  t = {t:.2f} s  wall {time.perf_counter() - start:7.1f} s  on table "
              f"{tilt_rows[-1]['on_table']}  re-inserted {tilt_rows[-1]['reinserted']}  "
              f"tilted > 5 deg {tilt_rows[-1]['beyond_5_deg']}  "
              f"fallen > 60 deg {tilt_rows[-1]['beyond_60_deg']}", flush=True)
    wall = time.perf_counter() - start
    c = {k: np.asarray(v, dtype=object if k.startswith(("place", "partner")) else float)
         for k, v in cols.items()}
    seconds = t - a.warmup
    bodies = float(np.mean([r["on_table"] for r in tilt_rows if r["time_s"] > a.warmup]
                           or [len(sim)]))
    by_place: dict[str, Any] = {}
    partners = sorted(set(c["partner"].tolist()))
    for partner in partners:
        sel = c["partner"] == partner
        row: dict[str, Any] = {}
        for place in rigid.PLACES:
            s = sel & (c["place_body"] == place)
            row[place] = int(s.sum())
        row["total"] = int(sel.sum())
        by_place[str(partner)] = row
    pair = c["partner"] == "cartridge"
    pair_places: dict[str, int] = {}
    for pb, pp in zip(c["place_body"][pair], c["place_partner"][pair]):
        key = "-".join(sorted((str(pb), str(pp))))
        pair_places[key] = pair_places.get(key, 0) + 1
    return {
        "wall_s": wall, "dt_s": float(sim.dt), "bodies_mean": bodies, "reached_s": t,
        "refeed": refeed is not None, "reinsertions": int(len(sim.reinsertions()[0])),
        "onsets": int(c["time"].size),
        "by_partner": _by_partner(c["partner"], c["normal_speed"], seconds, bodies),
        "place_by_partner": by_place,
        "pair_place_pairs": dict(sorted(pair_places.items(), key=lambda kv: -kv[1])),
        "pair_axis_angle_deg_histogram": {
            "edges": list(ANGLE_EDGES),
            "counts": np.histogram(c["axis_angle_deg"][pair], ANGLE_EDGES)[0].tolist()},
        "tilt": tilt_rows,
    }


def spheres(table: AccumulationTable, a: argparse.Namespace) -> dict[str, Any]:
    """Run the sphere table (the engine and law of ``demfem assess``); returns its
    onsets by partner."""
    description = table.build()
    names = [w["name"] for w in description.walls]
    start = time.perf_counter()
    sim = dem.from_scene(description, threads=a.threads, record_onsets=True)
    dem.run(sim, a.duration, refeed=description.refeed if a.refeed else None)
    wall = time.perf_counter() - start
    on = sim.onsets()
    keep = (np.asarray(on["time"]) >= a.warmup) & (np.asarray(on["normal_speed"]) >= a.min_speed)
    partner = _partner_names(np.asarray(on["partner"])[keep],
                             np.asarray(on["partner_is_wall"], bool)[keep], names)
    speed = np.asarray(on["normal_speed"], float)[keep]
    bodies = float(np.asarray(sim.alive(), bool).sum())
    print(f"spheres: {len(sim)} bodies, dt {sim.dt:.3e} s, wall {wall:.1f} s", flush=True)
    return {"wall_s": wall, "dt_s": float(sim.dt), "bodies_end": bodies,
            "onsets": int(speed.size),
            "by_partner": _by_partner(partner, speed, a.duration - a.warmup, bodies)}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--duration", type=float, default=3.0, help="simulated time, s (3)")
    p.add_argument("--warmup", type=float, default=2.0,
                   help="onsets before this time are not counted, s (2)")
    p.add_argument("--sample", type=float, default=0.1, help="tilt sampling interval, s")
    p.add_argument("--min-speed", type=float, default=DEFAULT_MIN_SPEED,
                   help="onsets slower than this are not counted, m/s (as assess)")
    p.add_argument("--young-modulus", type=float, default=45e9, help="Pa (45e9)")
    p.add_argument("--threads", type=int, default=min(2, os.cpu_count() or 1))
    p.add_argument("--max-wall", type=float, default=None,
                   help="stop the full-shape run after this many wall seconds (its counts "
                        "then cover the warm-up's end to the time reached)")
    p.add_argument("--refeed", action=argparse.BooleanOptionalAction, default=True,
                   help="put removed cartridges (and spheres) back upstream (default) or let "
                        "the table drain (--no-refeed)")
    p.add_argument("--out", default=str(OUT))
    a = p.parse_args()
    if not 0 <= a.warmup < a.duration:
        p.error("need 0 <= --warmup < --duration")
    base = dict(wall_height=0.07, young_modulus=a.young_modulus, refeed=a.refeed)
    doc: dict[str, Any] = {
        "command": "python benches/full_shape_table.py " + " ".join(
            f"--{k.replace('_', '-')} {v}" for k, v in vars(a).items() if k != "out"),
        "machine": platform.platform(), "cpus": os.cpu_count(),
        "refeed": bool(a.refeed), "places": list(rigid.PLACES), "speed_edges_m_per_s": list(SPEED_EDGES),
        "tilt_classes_deg": list(TILTS)}
    doc["revolution"] = full_shapes(AccumulationTable(particle="revolution", **base), a)
    # the spheres over the same span as the cartridges reached
    doc["spheres"] = spheres(AccumulationTable(particle="sphere", **base),
                             argparse.Namespace(**{**vars(a),
                                                   "duration": doc["revolution"]["reached_s"]}))
    doc["load_average_end"] = os.getloadavg()
    write_json_atomic(a.out, doc)
    r, s = doc["revolution"], doc["spheres"]
    print(f"\nonsets >= {a.min_speed:g} m/s per second per cartridge, {a.warmup:g}-"
          f"{a.duration:g} s (cartridges to {r['reached_s']:g} s):")
    print("| partner | spheres | cartridges | median speed, spheres / cartridges (m/s) |")
    print("|---|---|---|---|")
    for name in sorted(set(r["by_partner"]) | set(s["by_partner"])):
        rs, rr = s["by_partner"].get(name, {}), r["by_partner"].get(name, {})
        print(f"| {name} | {rs.get('onsets_per_s_per_cartridge', 0):.3g} | "
              f"{rr.get('onsets_per_s_per_cartridge', 0):.3g} | "
              f"{rs.get('median_m_per_s', float('nan')):.3g} / "
              f"{rr.get('median_m_per_s', float('nan')):.3g} |")
    print("\nplace on the cartridge, by partner (onsets):")
    print("| partner | " + " | ".join(rigid.PLACES) + " | total |")
    print("|---|" + "---|" * (len(rigid.PLACES) + 1))
    for name, row in r["place_by_partner"].items():
        print(f"| {name} | " + " | ".join(str(row[k]) for k in rigid.PLACES)
              + f" | {row['total']} |")
    print(f"\n-> {a.out}")


if __name__ == "__main__":
    main()
