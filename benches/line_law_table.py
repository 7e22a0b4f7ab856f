#!/usr/bin/env python3
"""What the FEM-calibrated line-contact law changes on the table: the default table run with
the equivalent sphere's Hertz–Reissner–Mindlin law and with ``model="fem_line"`` (a linear
spring calibrated on the FEM of two cartridges side by side), same scene, same duration;
first-line force, coordination, speeds, collision speeds and the peak force of each impact
by its law. Writes ``docs/data/line_law_table.json``.

Run: ``python benches/line_law_table.py`` (``--duration``, 0.6 s by default: ≈ 2 min).
"""
from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

from demfem.cartridge import Cartridge
from demfem.contact import ContactBody, max_contact_force
from demfem.fem.line_law import line_contact_stiffness
from demfem.io.atomic import write_text_atomic
from demfem.scenes import AccumulationTable
from demfem.dem.table_run import run_table


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=0.6)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", default=str(Path(__file__).resolve().parents[1] / "docs/data/line_law_table.json"))
    args = ap.parse_args()
    table = AccumulationTable()
    cart = Cartridge()
    body = ContactBody.from_cartridge(cart)
    m_star = 0.5 * cart.mass
    k_n, _ = line_contact_stiffness(cart.material.E, cart.material.nu)
    res = {}
    for model in ("hertz_reissner_mindlin", "fem_line"):
        t0 = time.perf_counter()
        run = run_table(table, duration=args.duration, sample_interval=0.02, threads=args.threads,
                        model=model)
        wall = time.perf_counter() - t0
        s = run.summary()
        on = run.onsets
        keep = on[on["time"] >= 0.5 * args.duration]
        vn = np.asarray(keep["normal_speed"], float)
        vn = vn[vn >= 5e-3]
        if model == "fem_line":
            force = vn * math.sqrt(k_n * m_star)
        else:
            force = np.array([max_contact_force(body, body, float(v), "hertz_reissner") for v in vn])
        res[model] = {
            "wall_time_s": wall, "dt_s": float(run.info["dt"]),
            "first_line_force_mean_N": s.get("first_line_force_mean_N"),
            "first_line_force_peak_N": s.get("first_line_force_peak_N"),
            "mean_coordination": s.get("mean_coordination"),
            "impacts_over_5mm_per_s": int(vn.size),
            "normal_speed_median_m_per_s": float(np.median(vn)) if vn.size else None,
            "normal_speed_q99_m_per_s": float(np.quantile(vn, 0.99)) if vn.size else None,
            "impact_force_median_N": float(np.median(force)) if vn.size else None,
            "impact_force_q99_N": float(np.quantile(force, 0.99)) if vn.size else None,
            "impact_force_max_N": float(force.max()) if vn.size else None,
        }
        print(model, json.dumps(res[model]))
    res["k_n_N_per_m"] = k_n
    res["duration_s"] = args.duration
    write_text_atomic(args.out, json.dumps(res, indent=1) + "\n")


if __name__ == "__main__":
    main()
