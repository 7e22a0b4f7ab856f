#!/usr/bin/env python3
"""The paper's Figs. 12-13 against demfem: the cluster's max case with springs, upright and
with 2 and 3 tilted so that their bottom or top end hits 1 first; per pair and region the
peak contact forces, the FEM's σ1 on 1 and the closed-form submodel's σ1
(:mod:`demfem.fem.cluster_submodel`), and the closed form at the paper's own forces (55 N
bottom with 10 N tangential, 80 N top with 14 N) for a point and a line contact.

Run: ``python benches/cluster_submodel.py`` (shells, 3 ms per case; ≈ 2-4 min per case on 2
shared cores, the 2-layer tets ≈ 5 min); ``--cases upright,bottom,top,bottom_lifted,bottom_tet1,top_tet1,top_tet2`` (the last three:
tets, 0.6 and 0.3 ms, the mesh check of the tilted impacts), ``--duration S``, ``--root DIR``
(the runs' folders, default ``demfem_out/cluster_submodel/<case>``; a finished run there with
the same settings is reused and only its outputs are redone), ``--evaluate-only`` (no FEM at
all: the submodel of the saved runs, the FEM's numbers from their ``summary.json``). Writes
``docs/data/cluster_submodel.json`` and prints the table.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any, Optional

import numpy as np

from demfem.io.atomic import write_text_atomic
from demfem.io.strict_json import dumps
from demfem.scenes import CartridgeCluster

ROOT = Path(__file__).resolve().parents[1]

#: The cases: field overrides of the max case with springs (shells unless the overrides say
#: otherwise), and a duration of their own (None: --duration).
CASES: dict[str, tuple[dict[str, Any], Optional[float]]] = {
    "upright": ({}, None),
    "bottom": ({"tilt_2_deg": -2.0, "tilt_3_deg": -2.0}, None),
    "top": ({"tilt_2_deg": 2.0, "tilt_3_deg": 2.0}, None),
    # 2 alone, lifted so that its bottom edge meets 1 mid-body (10 mm up, in the stress
    # model's range); 3 stays upright: lifted and tilted too, it arrives after 2 has pushed 1
    # away from it and never touches (the run refuses that as an unresolved impact)
    "bottom_lifted": ({"tilt_2_deg": -2.0, "offset_2_z": 0.01}, None),
    # the mesh check of the tilted impacts: tets, through 2's impact and 3's
    "bottom_tet1": ({"tilt_2_deg": -2.0, "tilt_3_deg": -2.0, "elements": "tet", "layers": 1},
                    6e-4),
    "top_tet1": ({"tilt_2_deg": 2.0, "tilt_3_deg": 2.0, "elements": "tet", "layers": 1}, 6e-4),
    "top_tet2": ({"tilt_2_deg": 2.0, "tilt_3_deg": 2.0, "elements": "tet", "layers": 2}, 3e-4),
}
KEYS = ("1-2_bottom", "1-2_top", "1-3_bottom", "1-3_top")


def case_cluster(name: str) -> CartridgeCluster:
    return CartridgeCluster.load_case("max", **{"springs": True, "elements": "shell",
                                               **CASES[name][0]})


def paper_forces() -> dict[str, Any]:
    """The closed form at the paper's peak forces (Fig. 11: 55 N bottom with 10 N tangential,
    80 N top with 14 N), the paper's cartridge and glass (E = 45 GPa)."""
    from demfem.cartridge import Cartridge
    from demfem.errors import InvalidParameterError
    from demfem.stress import contact_stresses

    c = Cartridge()
    half, body = 0.5 * c.length, c.body_length
    geoms: dict[str, dict[str, Any]] = {
        "point, crossed 90 deg, mid-body": {"geometry": "crossed", "crossing_angle_deg": 90.0},
        "point, crossed 90 deg, at the rim": {"geometry": "crossed", "crossing_angle_deg": 90.0,
                                              "location": "rim"},
        "point, crossed 90 deg, below the shoulder": {"geometry": "crossed",
                                                      "crossing_angle_deg": 90.0,
                                                      "location": "shoulder"},
        "line over the whole body (54.5 mm)": {"geometry": "parallel", "contact_length": body},
        "line over half the length (32 mm)": {"geometry": "parallel", "contact_length": half},
        "line over 10 mm": {"geometry": "parallel", "contact_length": 0.01},
    }
    out: dict[str, Any] = {}
    for name, kw in geoms.items():
        row: dict[str, Any] = {}
        for label, f, q in (("bottom_55N", 55.0, 10.0), ("top_80N", 80.0, 14.0)):
            try:
                s = contact_stresses(f, q, cartridge=c, friction_coefficient=0.2, **kw)
            except InvalidParameterError as exc:
                row[label] = {"refused": str(exc)}
                continue
            row[label] = {"normal_force_N": f, "tangential_force_N": q,
                          "outer_sigma1_Pa": float(s.outer_sigma1_max),
                          "inner_sigma1_Pa": float(s.inner_sigma1_max),
                          "outer_effective_area_m2": float(s.outer_effective_area),
                          "inner_effective_area_m2": float(s.inner_effective_area)}
        out[name] = row
    return out


def case_row(name: str, folder: Path, duration: float, evaluate_only: bool) -> dict[str, Any]:
    from demfem.fem.cluster_run import run_cluster
    from demfem.fem.cluster_submodel import submodel_from_folder

    c = case_cluster(name)
    t0 = time.perf_counter()
    if evaluate_only:
        summary = json.loads((folder / "summary.json").read_text())
        sub = submodel_from_folder(folder).summary()
    else:
        summary = run_cluster(c, duration=CASES[name][1] or duration, out=folder,
                              progress=False, n_snapshots=6,
                              log=lambda line: print(f"  {name}: {line}", flush=True))
        sub = summary["submodel"]
    command_s = time.perf_counter() - t0
    pairs = {}
    for key in KEYS:
        fp = summary["force_peaks"][key]
        sp = sub["pairs"][key]
        fem = summary.get("submodel", {}).get("pairs", {}).get(key, {})
        pairs[key] = {
            "normal_force_N": fp["normal_N"], "raw_normal_force_N": fp["raw_normal_N"],
            "tangential_force_N": fp["tangential_N"], "force_time_s": fp["time_s"],
            "fem_zone_sigma1_Pa": summary["sigma1_zone_max_Pa"][key],
            "fem_zone_outer_sigma1_Pa": fem.get("fem_zone_outer_sigma1_Pa"),
            "fem_zone_inner_sigma1_Pa": fem.get("fem_zone_inner_sigma1_Pa"),
            "submodel_geometry": sp["geometry"], "contact_length_m": sp["contact_length_m"],
            "contact_z_m": sp["contact_z_m"], "location": sp["location"],
            "model_location": sp["model_location"], "in_model_range": sp["in_model_range"],
            "submodel_outer_sigma1_Pa": sp["outer_sigma1_Pa"],
            "submodel_inner_sigma1_Pa": sp["inner_sigma1_Pa"],
            "submodel_outer_effective_area_m2": sp.get("outer_effective_area_m2"),
            "submodel_inner_effective_area_m2": sp.get("inner_effective_area_m2"),
            **_mid_body(c, sp),
        }
    return {"fields": CASES[name][0], "elements": c.elements, "springs": c.springs,
            "mode": "evaluate-only" if evaluate_only else "run (a saved run.npz reused)",
            "duration_s": summary["duration_s"], "fem_wall_time_s": summary["wall_time_s"],
            "command_s": command_s, "steps": summary["steps"], "n_elements": summary["n_elements"],
            "energy_balance_error": summary["energy_balance_error"],
            "fem_sigma1_body_max_Pa": summary["sigma1_body_max_Pa"],
            "fem_sigma1_body_max_time_s": summary["sigma1_body_max_time_s"],
            "first_contact": c.first_contact(), "pairs": pairs}


def _mid_body(c: CartridgeCluster, sp: dict[str, Any]) -> dict[str, Any]:
    """For a point contact evaluated at the rim or the shoulder: the mid-body closed form at
    its peak inner σ1's force (Q = μ F), the value without the place factors."""
    from demfem.stress import contact_stresses

    if sp["model_location"] == "body" or sp["geometry"] != "crossed" or \
            not sp.get("inner_sigma1_at_normal_force_N"):
        return {}
    f = sp["inner_sigma1_at_normal_force_N"]
    s = contact_stresses(f, c.friction * f, geometry="crossed", crossing_angle_deg=90.0,
                         cartridge=c.cartridge, friction_coefficient=c.friction)
    return {"mid_body_at_peak_force_N": f, "mid_body_outer_sigma1_Pa": float(s.outer_sigma1_max),
            "mid_body_inner_sigma1_Pa": float(s.inner_sigma1_max)}


def _mpa(x: Any) -> str:
    return "–" if x is None else f"{x / 1e6:.3g}"


def table(cases: dict[str, Any]) -> str:
    lines = ["| case | pair, half | F_n / F_t, N | FEM σ1 zone (outer / inner), MPa | "
             "submodel | submodel σ1 outer / inner, MPa |",
             "|---|---|---|---|---|---|"]
    for name, row in cases.items():
        for key, p in row["pairs"].items():
            if p["normal_force_N"] <= 0:
                continue
            geo = p["submodel_geometry"] + (f" {p['contact_length_m'] * 1e3:.3g} mm"
                                             if p["contact_length_m"] else " 90°")
            loc = p["model_location"] + ("" if p["in_model_range"] else
                                         f" (contact at the {p['location']})")
            lines.append(
                f"| {name} | {key} | {p['normal_force_N']:.3g} / {p['tangential_force_N']:.2g} "
                f"| {_mpa(p['fem_zone_sigma1_Pa'])} ({_mpa(p['fem_zone_outer_sigma1_Pa'])} / "
                f"{_mpa(p['fem_zone_inner_sigma1_Pa'])}) | {geo}, {loc} | "
                f"{_mpa(p['submodel_outer_sigma1_Pa'])} / {_mpa(p['submodel_inner_sigma1_Pa'])} |")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--duration", type=float, default=3e-3)
    ap.add_argument("--root", default=str(ROOT / "demfem_out" / "cluster_submodel"))
    ap.add_argument("--evaluate-only", action="store_true")
    ap.add_argument("--out", default=str(ROOT / "docs" / "data" / "cluster_submodel.json"))
    a = ap.parse_args()
    names = [n for n in a.cases.split(",") if n]
    for n in names:
        if n not in CASES:
            raise SystemExit(f"unknown case {n!r}: one of {', '.join(CASES)}")
    cases = {}
    for n in names:
        print(f"{n}: {CASES[n][0] or 'upright'}", flush=True)
        cases[n] = case_row(n, Path(a.root) / n, a.duration, a.evaluate_only)
    from demfem.fem.cluster_run import PAPER_VALUES

    paper = paper_forces()
    doc = {"what": __doc__.splitlines()[0], "cases": cases, "paper_values": PAPER_VALUES,
           "closed_form_at_paper_forces": paper,
           "numpy": np.__version__}
    write_text_atomic(Path(a.out), dumps(doc, indent=1) + "\n")
    print(table(cases))
    print("\nclosed form at the paper's forces (outer / inner σ1, MPa):")
    for g, row in paper.items():
        cells = []
        for label, v in row.items():
            cells.append(f"{label}: " + ("refused" if "refused" in v else
                                         f"{_mpa(v['outer_sigma1_Pa'])} / "
                                         f"{_mpa(v['inner_sigma1_Pa'])}"))
        print(f"  {g}: " + "; ".join(cells))
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
