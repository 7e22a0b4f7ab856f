"""The main job from Python: ``demfem.assess.assess`` on a short run, then its output read
back with ``demfem.assess.load_assessment`` into pandas.

The hourly number's interval is made over whole gate periods of the statistics window (at
least two; ``docs/uncertainty.md``), and the default table's gate period is 2 s, so a run of
seconds gives a number without an interval. To show both in under a minute this example
shortens the gate's period to 40 ms (amplitude 2 mm, so the gate moves at most 0.31 m/s) on
a table of 400 cartridges, runs 0.2 s and takes its statistics over the last 0.16 s (four
gate periods). **A demonstration of the API, not an assessment**: ``demfem assess`` says so
in its warnings; the default job runs the table until its collision rate is steady (minutes).

From the folder it prints the expected broken cartridges per hour with its 95 % interval
(``risk.json``'s summary) and, from the events table (``events.parquet``, one row per
collision event, SI units in the column names), the hazard by partner (another cartridge, or
the wall by name): each event's hazard −ln(1 − P) times the cartridges it loads (2 between
cartridges, 1 against a wall or the gate), summed per partner over the statistics window, per
hour and as a share; and the hazard by place on the cartridge from the events' place terms
(``p_event_rim`` …, which add up to ``p_event``), beside ``risk.json``'s ``place_share``.

Run:  python examples/assess_from_python.py [OUT]     (default demfem_out/assess_example)

What it prints after assess's own stage lines (2-core machine, shared; about 30 s):

    == the assessment read back from demfem_out/assess_example ==
    expected broken cartridges per hour: 0.0103 (95 % interval 0.000456 - 0.231, a factor 22.5 either way, over 4 gate periods); 9402 events in the window
    hazard by partner (events table, t = 0.04 - 0.2 s):
                events hazard per hour  share
    cartridge     9049          0.0103 0.9996
    gate            25        3.54e-06 0.0003
    lower_side     142        3.23e-07 0.0000
    tilted         186        2.04e-08 0.0000
    hazard by place on the cartridge: rim 97.0%, body 1.3%, shoulder 1.7% (risk.json: body 1.3%, rim 97.0%, shoulder 1.7%)

(the interval is wide: four gate periods of a table that has not settled; the default job's
is a factor of about 1.2.)
"""
from __future__ import annotations

import math
import sys

import numpy as np

from demfem.assess import assess, load_assessment
from demfem.scenes import AccumulationTable

DURATION = 0.2          # s of simulated time
DISCARD = 0.04          # s: the statistics window starts here (whole gate periods after it)


def main(out: str = "demfem_out/assess_example") -> dict[str, float]:
    # 1. the job: calibration -> DEM -> events -> stress -> risk -> report, into `out`
    table = AccumulationTable(n_spheres=400, gate_period=0.04, gate_amplitude=0.002, refeed=True)
    assess(table, out=out, duration=DURATION, discard_before=DISCARD, threads=2, fresh=True)

    # 2. read it back: risk.json's summary, events and passages as pandas DataFrames
    a = load_assessment(out)
    s = a.summary
    interval = a.risk["interval"]                             # over whole gate periods
    lo, hi = s["broken_per_hour_ci95"] or (math.nan, math.nan)
    print(f"\n== the assessment read back from {out} ==")
    print(f"expected broken cartridges per hour: {s['broken_per_hour']:.3g} (95 % interval "
          f"{lo:.3g} - {hi:.3g}, a factor {interval['factor']:.3g} either way, over "
          f"{interval['n_blocks']} gate periods); {s['n_events_window']} events in the window")

    # 3. the hazard by partner, from the events table
    ev = a.events[a.events["in_window"]]
    loads = np.where(ev["j"] >= 0, 2.0, 1.0)                  # cartridges the event loads
    hazard = -np.log1p(-ev["p_event"].to_numpy()) * loads
    partner = np.where(ev["partner"] == "wall", ev["wall"], "cartridge")
    t0, t1 = a.risk["window_s"]
    by = (ev.assign(hazard=hazard, with_=partner).groupby("with_")
          .agg(events=("hazard", "size"), hazard=("hazard", "sum")))
    by["hazard per hour"] = 3600.0 * by.pop("hazard") / (t1 - t0)
    by["share"] = by["hazard per hour"] / by["hazard per hour"].sum()
    by.index.name = None
    print(f"hazard by partner (events table, t = {t0:g} - {t1:g} s):")
    print(by.sort_values("share", ascending=False).to_string(
        formatters={"hazard per hour": "{:.3g}".format, "share": "{:.4f}".format}))
    # 4. where on the cartridge: each event's terms w_p P_p by place add up to its P
    places = ("rim", "body", "shoulder")
    p_event = ev["p_event"].to_numpy()
    frac = {pl: np.divide(ev[f"p_event_{pl}"].to_numpy(), p_event, out=np.zeros(len(ev)),
                          where=p_event > 0) for pl in places}
    total = hazard.sum()
    print("hazard by place on the cartridge: " + ", ".join(
        f"{pl} {float((hazard * frac[pl]).sum() / total):.1%}" for pl in places)
        + f" (risk.json: {', '.join(f'{k} {v:.1%}' for k, v in s['place_share'].items())})")
    return {"broken_per_hour": s["broken_per_hour"], "lower": lo, "upper": hi,
            "cartridge_share": float(by["share"].get("cartridge", 0.0))}


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "demfem_out/assess_example")
