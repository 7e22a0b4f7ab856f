#!/usr/bin/env python3
"""FEM tables of a contact near the open rim, below the shoulder and mid-body
(:mod:`demfem.stress.place_fem`), the factors of ``contact_stresses(location=...)`` drawn from
them, and the model against the FEM at the place.

    python benches/stress_place_tables.py                  # run what is missing, factors, table
    python benches/stress_place_tables.py --only run       # the FEM cases only (≈ 20 min, 22 cases)
    python benches/stress_place_tables.py --only factors   # python/demfem/stress/place_factors.json
    python benches/stress_place_tables.py --only markdown  # the tables, from the JSON

Cases: the default cartridge (``Cartridge()``), crossed cartridges at 90° (the Hertz circle),
F = 1, 10, 45, 100 N, μ = 0 and 0.2 (both traction directions from one solve), at
place = body (mid-body), rim (s = max(t/2, 1.5 a) from the open end face; at 45 N also
s = 1, 2, 4 mm), shoulder (s = max(t/2, 1.5 a) below the body–shoulder junction), all on the
grading ``Grading.for_patch`` × :data:`LEVEL`; the mesh study: rim and body 45 N, μ = 0, on
levels 1, 0.8, 0.64 (:func:`demfem.stress.resolved_fem.richardson`).

Writes docs/data/stress_place_tables.json after every case (a rerun skips the cases it has;
``--fresh`` starts over) and prints the markdown tables.
"""
from __future__ import annotations

import argparse
import datetime
import json
import math
import platform
import sys
import time
from pathlib import Path
from typing import Any, Optional

import numpy as np

from demfem.cartridge import Cartridge
from demfem.stress import place_fem as pf
from demfem.stress.resolved_fem import richardson

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "data" / "stress_place_tables.json"
FACTORS = ROOT / "python" / "demfem" / "stress" / "place_factors.json"

#: The production mesh level (a factor on every size and the growth rate of the grading).
LEVEL = 0.64
#: Mesh-study levels, coarse to fine.
STUDY_LEVELS = (1.0, 0.8, 0.64)
FORCES = (1.0, 10.0, 45.0, 100.0)
FRICTIONS = (0.0, 0.2)
#: The rim distances of the decay study at 45 N, m.
RIM_DECAY = (1e-3, 2e-3, 4e-3)


def log(msg: str) -> None:
    print(msg, flush=True)


def key(place: str, force: float, distance: Optional[float], level: float) -> str:
    d = "default" if distance is None else f"{distance * 1e3:g}mm"
    return f"{place}|{force:g}N|{d}|level{level:g}"


def case_list() -> list[tuple[str, float, Optional[float], float]]:
    """(place, F, distance, level) in the order of priority."""
    out: list[tuple[str, float, Optional[float], float]] = []
    for f in (45.0, 10.0):
        out += [("rim", f, None, LEVEL), ("body", f, None, LEVEL)]
        if f == 45.0:
            out += [("rim", 45.0, None, lv) for lv in STUDY_LEVELS if lv != LEVEL]
            out += [("body", 45.0, None, lv) for lv in STUDY_LEVELS if lv != LEVEL]
    out += [("shoulder", 45.0, None, LEVEL), ("shoulder", 10.0, None, LEVEL)]
    for f in (1.0, 100.0):
        out += [("rim", f, None, LEVEL), ("body", f, None, LEVEL), ("shoulder", f, None, LEVEL)]
    out += [("rim", 45.0, d, LEVEL) for d in RIM_DECAY]
    out += [("rim", 10.0, d, LEVEL) for d in RIM_DECAY]
    return out


def load() -> dict[str, Any]:
    if OUT.exists():
        return json.loads(OUT.read_text())
    return {}


def save(data: dict[str, Any]) -> None:
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(json.dumps(data, indent=1, default=float) + "\n")


def run(data: dict[str, Any], budget_s: float) -> None:
    data.setdefault("meta", {})
    data["meta"].update({
        "date": datetime.date.today().isoformat(), "machine": platform.platform(),
        "python": sys.version.split()[0], "level": LEVEL, "study_levels": list(STUDY_LEVELS),
        "frictions": list(FRICTIONS), "cartridge": repr(Cartridge()),
        "direction": "+1: traction toward the shoulder (+z), -1: toward the open end"})
    cases = data.setdefault("cases", {})
    t_start = time.perf_counter()
    for place, f, d, lv in case_list():
        k = key(place, f, d, lv)
        if k in cases:
            continue
        if time.perf_counter() - t_start > budget_s:
            log(f"budget of {budget_s:.0f} s spent: stopping before {k}")
            break
        t0 = time.perf_counter()
        fr = FRICTIONS if lv == LEVEL else (0.0,)
        r = pf.place_case(f, place, distance=d, level=lv, frictions=fr)
        wall = time.perf_counter() - t0
        entry = r.as_dict()
        entry.update({"level": lv, "wall_s": wall, "distance_given_m": d})
        cases[k] = entry
        save(data)
        o, i = r.peak()
        log(f"{k}: outer {o.sigma1_max / 1e6:.1f} MPa ({o.face}), inner "
            f"{i.sigma1_max / 1e6:.1f} MPa ({i.face}), {r.stats['tets']:.0f} tets, "
            f"{wall:.0f} s")


# --------------------------------------------------------------------------------------------
# reading the table
# --------------------------------------------------------------------------------------------


def peak(entry: dict[str, Any], mu: float, surface: str, direction: Optional[int] = None
         ) -> dict[str, Any]:
    """The case's peak on ``surface`` at ``mu``: the given traction direction, or the worse
    one (larger outer σ1) when None."""
    cands = [c for c in entry["cases"] if abs(c["mu"] - mu) < 1e-12]
    if direction is not None and mu > 0:
        cands = [c for c in cands if c["direction"] == direction]
    if not cands:
        raise KeyError(f"mu {mu} not in case")
    best = max(cands, key=lambda c: c["outer"]["sigma1_max_Pa"])
    return best[surface]


def contact_term(force: float, mu: float) -> float:
    """The local contact term the model uses at mid-body (Hertz rim tension / Hamilton), Pa."""
    from demfem.stress import contact_stresses

    return float(contact_stresses(force, mu * force).outer_contact_Pa)


def fem_terms(entry: dict[str, Any], force: float, mu: float) -> dict[str, float]:
    """The FEM's numbers per model term: inner σ1 and area, the outer bending at the contact
    edge (outer peak − the contact term), the far outer peak and area."""
    o, i = peak(entry, mu, "outer"), peak(entry, mu, "inner")
    return {"inner": i["sigma1_max_Pa"], "inner_area": i["effective_area_m2"],
            "outer": o["sigma1_max_Pa"], "outer_area": o["effective_area_m2"],
            "outer_bending": o["sigma1_max_Pa"] - contact_term(force, mu),
            "ring": o["far_sigma1_Pa"], "ring_area": o["far_effective_area_m2"]}


def factors(data: dict[str, Any]) -> dict[str, Any]:
    """k(place, F, μ) = FEM(place) / FEM(body) on the same grading, per model term."""
    cases = data["cases"]
    table: dict[str, Any] = {}
    for place in ("rim", "shoulder"):
        rows = []
        for f in FORCES:
            kp, kb = key(place, f, None, LEVEL), key("body", f, None, LEVEL)
            if kp not in cases or kb not in cases:
                continue
            for mu in FRICTIONS:
                p_, b_ = fem_terms(cases[kp], f, mu), fem_terms(cases[kb], f, mu)
                rows.append({"force_N": f, "mu": mu,
                             "inner": p_["inner"] / b_["inner"],
                             "inner_area": p_["inner_area"] / b_["inner_area"],
                             "outer_bending": p_["outer_bending"] / b_["outer_bending"],
                             "ring": p_["ring"] / b_["ring"],
                             "ring_area": p_["ring_area"] / b_["ring_area"]})
        table[place] = rows
    return table


def write_factors(data: dict[str, Any]) -> dict[str, Any]:
    t = factors(data)
    out: dict[str, Any] = {
        "description": "contact_stresses(location='rim'|'shoulder'): factors on the model's "
                       "global terms, k = FEM(place) / FEM(body) on the same grading "
                       "(demfem.stress.place_fem, benches/stress_place_tables.py), per normal "
                       "force (N) and friction coefficient; crossed/point contacts on the "
                       "default cartridge",
        "source": "docs/data/stress_place_tables.json",
        "level": LEVEL,
        "terms": {"inner": "inner_bending_Pa", "inner_area": "inner_effective_area (bending)",
                  "outer_bending": "outer_bending_Pa", "ring": "outer_ring_Pa",
                  "ring_area": "the ring term's effective area"},
        "places": {}}
    for place, rows in t.items():
        if not rows:
            continue
        forces = sorted({r["force_N"] for r in rows})
        mus = sorted({r["mu"] for r in rows})
        block: dict[str, Any] = {"force_N": forces, "mu": mus,
                                 "distance": "max(t/2, 1.5 a) from the open end face" if
                                 place == "rim" else "max(t/2, 1.5 a) below the body-shoulder "
                                 "junction"}
        for term in ("inner", "inner_area", "outer_bending", "ring", "ring_area"):
            grid = np.full((len(mus), len(forces)), np.nan)
            for r in rows:
                grid[mus.index(r["mu"]), forces.index(r["force_N"])] = r[term]
            block[term] = [[round(float(v), 5) for v in row] for row in grid]
        out["places"][place] = block
    FACTORS.write_text(json.dumps(out, indent=1) + "\n")
    return out


# --------------------------------------------------------------------------------------------
# markdown
# --------------------------------------------------------------------------------------------


def mpa(x: float) -> str:
    return f"{x / 1e6:.1f}"


def mm2(x: float) -> str:
    return f"{x * 1e6:.4f}" if x < 1e-7 else f"{x * 1e6:.3f}"


def pct(a: float, b: float) -> str:
    return f"{100.0 * (a / b - 1.0):+.0f} %" if b else "n/a"


def markdown(data: dict[str, Any]) -> str:
    from demfem.stress import contact_stresses

    cases = data.get("cases", {})
    lines: list[str] = []
    lines.append("### FEM at the place (level %g) and mid-body on the same grading\n" % LEVEL)
    lines.append("| place | F (N) | μ (dir.) | outer σ1 (MPa) | where (outer) | inner σ1 (MPa) "
                 "| where (inner) | A_out (mm²) | A_in (mm²) | far outer σ1 (MPa) | body: outer "
                 "/ inner / A_out / A_in | tets | wall (s) |")
    lines.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for place in ("body", "rim", "shoulder"):
        for f in FORCES:
            k = key(place, f, None, LEVEL)
            if k not in cases:
                continue
            e, b = cases[k], cases.get(key("body", f, None, LEVEL))
            for c in e["cases"]:
                mu, dr = c["mu"], c["direction"]
                o, i = c["outer"], c["inner"]
                bo = peak(b, mu, "outer", dr if dr else None) if b else None
                bi = peak(b, mu, "inner", dr if dr else None) if b else None
                ref = (f"{mpa(bo['sigma1_max_Pa'])} / {mpa(bi['sigma1_max_Pa'])} / "
                       f"{mm2(bo['effective_area_m2'])} / {mm2(bi['effective_area_m2'])}"
                       if bo and bi else "")
                dtxt = "" if mu == 0 else (" (→ shoulder)" if dr > 0 else " (→ open end)")
                lines.append(
                    f"| {place} | {f:g} | {mu:g}{dtxt} | {mpa(o['sigma1_max_Pa'])} | "
                    f"{o['face']}, dz {o['dz_m'] * 1e3:+.2f} mm | {mpa(i['sigma1_max_Pa'])} | "
                    f"{i['face']}, dz {i['dz_m'] * 1e3:+.2f} mm | "
                    f"{mm2(o['effective_area_m2'])} | {mm2(i['effective_area_m2'])} | "
                    f"{mpa(o['far_sigma1_Pa'])} | {ref} | {e['mesh']['tets']:.0f} | "
                    f"{e['wall_s']:.0f} |")
    # decay
    lines.append("\n### Decay of the rim effect (μ = 0; s from the open end face)\n")
    lines.append("| F (N) | s (mm) | outer σ1 | inner σ1 | A_out (mm²) | A_in (mm²) | inner / body |")
    lines.append("|---|---|---|---|---|---|---|")
    for f in (10.0, 45.0):
        b = cases.get(key("body", f, None, LEVEL))
        for d in (None,) + RIM_DECAY:
            e = cases.get(key("rim", f, d, LEVEL))
            if e is None:
                continue
            o, i = peak(e, 0.0, "outer"), peak(e, 0.0, "inner")
            ratio = (f"{i['sigma1_max_Pa'] / peak(b, 0.0, 'inner')['sigma1_max_Pa']:.3f}"
                     if b else "")
            lines.append(f"| {f:g} | {e['distance_m'] * 1e3:.2f} | {mpa(o['sigma1_max_Pa'])} | "
                         f"{mpa(i['sigma1_max_Pa'])} | {mm2(o['effective_area_m2'])} | "
                         f"{mm2(i['effective_area_m2'])} | {ratio} |")
        if b:
            o, i = peak(b, 0.0, "outer"), peak(b, 0.0, "inner")
            lines.append(f"| {f:g} | mid-body | {mpa(o['sigma1_max_Pa'])} | "
                         f"{mpa(i['sigma1_max_Pa'])} | {mm2(o['effective_area_m2'])} | "
                         f"{mm2(i['effective_area_m2'])} | 1 |")
    # mesh study
    lines.append("\n### Mesh study (45 N, μ = 0; levels %s)\n" % ", ".join(map(str, STUDY_LEVELS)))
    lines.append("| place | quantity | levels | Richardson | change of the last step |")
    lines.append("|---|---|---|---|---|")
    study: dict[str, Any] = {}
    for place in ("rim", "body"):
        es = [cases.get(key(place, 45.0, None, lv)) for lv in STUDY_LEVELS]
        if any(e is None for e in es):
            continue
        for q, surf, fld in (("outer σ1", "outer", "sigma1_max_Pa"),
                             ("inner σ1", "inner", "sigma1_max_Pa"),
                             ("A_out", "outer", "effective_area_m2"),
                             ("A_in", "inner", "effective_area_m2")):
            vals = [peak(e, 0.0, surf)[fld] for e in es]  # type: ignore[arg-type]
            rr = richardson(list(STUDY_LEVELS), vals)
            study[f"{place} {q}"] = {"values": vals, **rr}
            fmt = mpa if "σ" in q else mm2
            lines.append(f"| {place} | {q} | {' → '.join(fmt(v) for v in vals)} | "
                         f"{fmt(rr['extrapolated']) if rr['monotone'] else 'not monotone'} | "
                         f"{rr['change_last_pct']:.1f} % |")
        tets = [e["mesh"]["tets"] for e in es]  # type: ignore[index]
        walls = [e["wall_s"] for e in es]  # type: ignore[index]
        lines.append(f"| {place} | tets / wall (s) | "
                     f"{' → '.join(f'{t:.0f} / {w:.0f}' for t, w in zip(tets, walls))} | | |")
    # ratio convergence
    if all(key(p, 45.0, None, lv) in cases for p in ("rim", "body") for lv in STUDY_LEVELS):
        ks = [peak(cases[key("rim", 45.0, None, lv)], 0.0, "inner")["sigma1_max_Pa"]
              / peak(cases[key("body", 45.0, None, lv)], 0.0, "inner")["sigma1_max_Pa"]
              for lv in STUDY_LEVELS]
        lines.append(f"| rim / body | inner σ1 factor | {' → '.join(f'{k:.3f}' for k in ks)} "
                     "| | |")
    data["mesh_study"] = study
    # model vs FEM
    lines.append("\n### The model at the place against the FEM at the place\n")
    lines.append("| place | F (N) | μ | outer σ1 model / FEM | inner σ1 model / FEM | A_out model "
                 "/ FEM (mm²) | A_in model / FEM (mm²) | k_inner | k_out_bend |")
    lines.append("|---|---|---|---|---|---|---|---|---|")
    verify = []
    have_factors = FACTORS.exists()
    for place in ("body", "rim", "shoulder"):
        for f in FORCES:
            e = cases.get(key(place, f, None, LEVEL))
            if e is None or not have_factors:
                continue
            for mu in FRICTIONS:
                try:
                    o, i = peak(e, mu, "outer"), peak(e, mu, "inner")
                except KeyError:
                    continue
                try:
                    cs = contact_stresses(f, mu * f, location=place)
                    cb = contact_stresses(f, mu * f)
                except Exception as ex:  # the factors may lack this place yet
                    log(f"model at {place}: {ex}")
                    continue
                mo, mi = float(cs.outer_sigma1_max), float(cs.inner_sigma1_max)
                ao, ai = float(cs.outer_effective_area), float(cs.inner_effective_area)
                row = {"place": place, "force_N": f, "mu": mu, "model_outer": mo,
                       "fem_outer": o["sigma1_max_Pa"], "model_inner": mi,
                       "fem_inner": i["sigma1_max_Pa"], "model_A_out": ao,
                       "fem_A_out": o["effective_area_m2"], "model_A_in": ai,
                       "fem_A_in": i["effective_area_m2"],
                       "k_inner": float(cs.inner_bending_Pa / cb.inner_bending_Pa),
                       "k_outer_bending": float(cs.outer_bending_Pa / cb.outer_bending_Pa)}
                verify.append(row)
                lines.append(
                    f"| {place} | {f:g} | {mu:g} | {mpa(mo)} / {mpa(o['sigma1_max_Pa'])} "
                    f"({pct(mo, o['sigma1_max_Pa'])}) | {mpa(mi)} / {mpa(i['sigma1_max_Pa'])} "
                    f"({pct(mi, i['sigma1_max_Pa'])}) | {mm2(ao)} / "
                    f"{mm2(o['effective_area_m2'])} ({pct(ao, o['effective_area_m2'])}) | "
                    f"{mm2(ai)} / {mm2(i['effective_area_m2'])} "
                    f"({pct(ai, i['effective_area_m2'])}) | {row['k_inner']:.3f} | "
                    f"{row['k_outer_bending']:.3f} |")
    data["verification"] = verify
    return "\n".join(lines)


def main(argv: Optional[list[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", choices=("run", "factors", "markdown"), default=None)
    ap.add_argument("--fresh", action="store_true", help="start the JSON over")
    ap.add_argument("--budget", type=float, default=math.inf,
                    help="stop starting new FEM cases after this many seconds")
    args = ap.parse_args(argv)
    data = {} if args.fresh else load()
    if args.only in (None, "run"):
        run(data, args.budget)
    if args.only in (None, "factors"):
        write_factors(data)
        log(f"wrote {FACTORS.relative_to(ROOT)}")
    if args.only in (None, "markdown"):
        print(markdown(data))
        save(data)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
