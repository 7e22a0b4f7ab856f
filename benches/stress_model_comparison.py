"""The hourly number and the ranking of belt speeds under the former shell-only stress model
and the contact-stress model of demfem.stress, on the same DEM runs (issue: the stress the
glass really sees at a contact).

For each belt speed the default table runs once (``demfem assess`` up to its events stage,
re-fed, a fixed duration); the stresses and the risk are then evaluated under each model from
the same events:

* ``shell``: σ1 = β F/t² (the shell's bending only, the former default);
* ``contact``: demfem.stress with the measured friction force, cartridges crossed at 90°,
  the outer surface's characteristic flaw depth, each event weighted over the places on the
  cartridge (body, rim, shoulder) by the full-shape table's counts (the default of demfem
  assess, ``--place mix``);
* ``contact, body only``: the same with every event at mid-body (``--place body``, the
  default before the places);
* ``contact, no flaw correction``: the body-only model at the surface value;
* ``contact, parallel``: two cartridges along the body (line contacts), body only.

    python benches/stress_model_comparison.py [--duration 6] [--out demfem_out/model_cmp]
    python benches/stress_model_comparison.py --folder RUN   # one existing folder's events
    python benches/stress_model_comparison.py --reuse        # the belt speeds' folders again

Writes ``docs/data/stress_model_comparison.json`` and prints a table. SI units; hourly
numbers per hour.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time
from pathlib import Path
from typing import Optional

import numpy as np

VARIANTS = {
    "shell": dict(model="shell", place="body"),
    "contact": dict(model="contact", pair_geometry="crossed", flaw="characteristic",
                    place="mix"),
    "contact, body only": dict(model="contact", pair_geometry="crossed",
                               flaw="characteristic", place="body"),
    "contact, no flaw correction": dict(model="contact", pair_geometry="crossed", flaw=None,
                                        place="body"),
    "contact, parallel": dict(model="contact", pair_geometry="parallel",
                              flaw="characteristic", place="body"),
}


def evaluate(out: Path, table, variant: dict) -> dict:
    """The hourly number of one assessment folder's events under one stress model."""
    from demfem.assess.events import EVENT_DTYPE
    from demfem.assess.npz import load_npz
    from demfem.assess.places import event_place_weights
    from demfem.assess.risk_stage import event_probabilities, hazard_components, passage_risk
    from demfem.risk import INNER_SURFACE, OUTER_SURFACE, SCG_BOROSILICATE
    from demfem.risk.interval import hourly_interval_from_events
    from demfem.stress.stage import characteristic_flaw_depth, collision_stresses
    from demfem.dem.table_run import TableRun

    run = TableRun.load(out / "table_run.npz")
    ev = load_npz(out / "events.npz")["events"].astype(EVENT_DTYPE)
    flaw = variant.get("flaw")
    c = (characteristic_flaw_depth(OUTER_SURFACE.characteristic_strength)
         if flaw == "characteristic" else None)
    st = collision_stresses(ev["normal_speed"], ev["partner"], table.young_modulus,
                            table.poisson_ratio, measured_force=ev["peak_force"],
                            measured_impulse=ev["impulse"],
                            measured_tangential=ev["peak_tangential_force"],
                            model=variant["model"], cartridge=table.cartridge,
                            pair_geometry=variant.get("pair_geometry", "crossed"),
                            friction=table.friction, flaw_depth=c,
                            place_weights=event_place_weights(
                                ev, [str(x) for x in run.info.get("wall_names", [])],
                                variant.get("place", "body")))
    p = event_probabilities(st, INNER_SURFACE, OUTER_SURFACE, SCG_BOROSILICATE)
    end = float(run.info["duration"])
    window = (min(2.0, end / 2), end)
    pr = passage_risk(ev, p["p_event"], run.passages(), window)
    inside = (ev["time"] >= window[0]) & (ev["time"] <= window[1])
    comps = hazard_components(ev[inside], {k: v[inside] for k, v in p.items()},
                              by_place=False)
    ci = hourly_interval_from_events(ev[inside], p["p_event"][inside], window,
                                     table.gate_period, components=comps)
    h_in = float(-np.log1p(-p["p_inner"][inside]).sum())
    h_out = float(-np.log1p(-p["p_outer"][inside]).sum())
    rel = (ci.lower / ci.estimate, ci.upper / ci.estimate) if ci.estimable else (math.nan,) * 2
    place_share = None
    if "place_weight" in p:
        parts = hazard_components(ev[inside], {k: v[inside] for k, v in p.items()})
        tot = sum(float(v.sum()) for v in parts.values())
        place_share = {k: float(v.sum()) / tot for k, v in parts.items()} if tot > 0 else None
    return {"broken_per_hour": pr["broken_per_hour"],
            "ci95": [pr["broken_per_hour"] * rel[0], pr["broken_per_hour"] * rel[1]],
            "p_passage": pr["p_passage"], "discharge_per_hour": pr["discharge_per_hour"],
            "outer_share": h_out / (h_in + h_out) if h_in + h_out > 0 else math.nan,
            "max_sigma_outer_MPa": float(st["sigma_outer_Pa"][inside].max() / 1e6),
            "max_sigma_inner_MPa": float(st["sigma_inner_Pa"][inside].max() / 1e6),
            "place_surface_share": place_share}


def main() -> None:
    from demfem.assess import assess
    from demfem.scenes.table import AccumulationTable

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=6.0, help="simulated time, s (6)")
    ap.add_argument("--speeds", default="0.1,0.2,0.3", help="belt speeds, m/s")
    ap.add_argument("--out", default="demfem_out/model_cmp")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--reuse", action="store_true",
                    help="evaluate the belt speeds' folders under --out that already hold "
                         "their events.npz instead of running their DEM again")
    ap.add_argument("--folder", default=None,
                    help="instead of running the belt speeds: evaluate the variants on one "
                         "assessment folder of the default table that still holds its "
                         "events.npz (a job stopped after its events stage, or unfinished); "
                         "prints the hourly numbers")
    args = ap.parse_args()
    if args.folder is not None:
        folder = Path(args.folder)
        if not (folder / "events.npz").is_file():
            ap.error(f"{folder / 'events.npz'} is missing: a finished assessment keeps no "
                     "events.npz; run this bench's belt speeds, or stop a job after its "
                     "events stage")
        table = dataclasses.replace(AccumulationTable(), refeed=True)
        for name, var in VARIANTS.items():
            r = evaluate(folder, table, var)
            print(f"{name:30s} {r['broken_per_hour']:.3g} per hour [{r['ci95'][0]:.3g}, "
                  f"{r['ci95'][1]:.3g}]  outer share {r['outer_share']:.4f}  max sigma1 "
                  f"outer {r['max_sigma_outer_MPa']:.3g} MPa, inner "
                  f"{r['max_sigma_inner_MPa']:.3g} MPa")
            if r["place_surface_share"]:
                print("    by place and surface: " + ", ".join(
                    f"{k} {100 * v:.3g} %" for k, v in r["place_surface_share"].items()))
        return
    rows = {}
    for v in (float(x) for x in args.speeds.split(",")):
        table = dataclasses.replace(AccumulationTable(), belt_velocity=v, refeed=True)
        out = Path(args.out) / f"belt_{v:g}"
        start = time.perf_counter()
        dem_s: Optional[float] = None
        if not (args.reuse and (out / "events.npz").is_file()):
            assess(table, out=out, duration=args.duration,
                   discard_before=min(2.0, args.duration / 2), stop_after="events",
                   threads=args.threads, log=lambda _: None)
            dem_s = time.perf_counter() - start
        rows[v] = {"dem_wall_s": dem_s, **{name: evaluate(out, table, var)
                                            for name, var in VARIANTS.items()}}
        print(f"belt {v:g} m/s: " + (f"DEM {dem_s:.0f} s" if dem_s is not None else
                                     "DEM reused"), flush=True)
    print(f"\n{'model':32s} " + " ".join(f"{'belt ' + format(v, 'g') + ' m/s':>34s}"
                                        for v in rows))
    for name in VARIANTS:
        cells = []
        for v in rows:
            r = rows[v][name]
            cells.append(f"{r['broken_per_hour']:9.3g} [{r['ci95'][0]:8.2g}, "
                         f"{r['ci95'][1]:8.2g}]")
        print(f"{name:32s} " + " ".join(f"{c:>34s}" for c in cells))
    print("\nranking (gentlest first):")
    for name in VARIANTS:
        order = sorted(rows, key=lambda v: rows[v][name]["broken_per_hour"])
        print(f"  {name:32s} " + " < ".join(f"{v:g}" for v in order))
    doc = {"duration_s": args.duration, "window_s": [2.0, args.duration],
           "variants": {k: {kk: str(vv) for kk, vv in v.items()} for k, v in VARIANTS.items()},
           "belt_speeds": {str(v): r for v, r in rows.items()},
           "command": "python benches/stress_model_comparison.py --duration "
                      f"{args.duration:g}" + (" --reuse" if args.reuse else "")}
    path = Path(__file__).resolve().parents[1] / "docs" / "data" / "stress_model_comparison.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(doc, indent=1, default=float) + "\n")
    print(f"written {path}")


if __name__ == "__main__":
    main()
