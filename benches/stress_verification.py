#!/usr/bin/env python3
"""Verification of the contact-stress model (:mod:`demfem.stress`) against a resolved FEM
(issue 39, part 2): the superposition model vs demfem's static Tet4 FEM on meshes graded to
the contact (three levels, Richardson) vs CalculiX 2.20 with C3D10 on the crossed 45 N case.

    python benches/stress_verification.py                 # everything (≈ 20–30 min, 2 cores)
    python benches/stress_verification.py --cases block   # the half-space check (≈ 1 min)
    python benches/stress_verification.py --cases crossed --forces 45 --no-ccx

Cases (docs/stress-verification.md has the discussion):

* ``block``: the Hertz pressure (and a sliding traction, μ = 0.2) on a quarter block 20 a
  wide and deep, clamped at its base: the surface's peak tension must converge to
  (1 − 2ν)/3 p0 (Johnson 1985 eq. 3.45) and p0 [(1 − 2ν)/3 + (4 + ν)πμ/8] (Hamilton 1983),
  the radial stress at the centre to −(1 + 2ν)/2 p0.
* ``crossed``: the default cartridge's body (a tube R = 5.8 mm, t = 1.1 mm, 30 mm long,
  free: inertia relief) under the Hertz pressure of two crossed cartridges at 90° at
  F = 1, 10, 45, 100 N, μ = 0 and 0.2 (the traction q = μ p along the axis).
* ``parallel``: the same tube under a Hertz line contact 10 mm long, 45 N, held by an equal
  contact on the opposite side (the model's default ``ring_support = "opposite"``).
* ``ccx``: the crossed 45 N case (μ = 0, 0.2) in CalculiX with quadratic tets.

Writes docs/data/stress_verification.json and prints the table. Needs gmsh (pip) and, for
the CalculiX case, ccx (apt-get install calculix-ccx).
"""
from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import sys
import time
from pathlib import Path
from typing import Any, Optional

import numpy as np
from scipy.integrate import quad
from scipy.special import kei

import demfem
from demfem.cartridge import Cartridge
from demfem.materials import PAPER_GLASS
from demfem.risk import INNER_SURFACE, OUTER_SURFACE
from demfem.stress import resolved_fem as rf

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "data" / "stress_verification.json"

E, NU, RHO = PAPER_GLASS.E, PAPER_GLASS.nu, PAPER_GLASS.density
M_OUT, M_IN = OUTER_SURFACE.weibull_modulus, INNER_SURFACE.weibull_modulus
#: Mesh levels (factors on every size and the growth rate), coarse to fine.
LEVELS_BLOCK = (1.0, 0.7, 0.5)
LEVELS_TUBE = (1.0, 0.8, 0.64)
LEVELS_PARALLEL = (1.25, 1.0, 0.8)


def log(msg: str) -> None:
    print(msg, flush=True)


def peak_dict(p: Optional[rf.SurfacePeak]) -> Optional[dict[str, Any]]:
    return None if p is None else p.as_dict()


def model_dict(cs: Any) -> dict[str, Any]:
    out = {}
    for k, v in cs.__dict__.items():
        try:
            out[k] = float(np.asarray(v))
        except (TypeError, ValueError):
            out[k] = str(v)
    return out


def study(meshes_for: Any, levels: tuple[float, ...], frictions: list[float],
          label: str) -> dict[str, Any]:
    """Solve every level; Richardson per friction, per surface, for σ1 and A_eff."""
    runs: list[dict[str, Any]] = []
    for lev in levels:
        t0 = time.perf_counter()
        mesh = meshes_for(lev)
        res = rf.solve_frictions(mesh, E, NU, frictions, m_outer=M_OUT, m_inner=M_IN)
        wall = time.perf_counter() - t0
        row = {"level": lev, "tets": int(len(mesh.tets)), "nodes": int(len(mesh.nodes)),
               "mesh": mesh.stats, "wall_s": wall,
               "results": {str(mu): r.as_dict() for mu, r in res.items()}}
        runs.append(row)
        for mu, r in res.items():
            inner = (f"inner {r.inner.sigma1_max / 1e6:8.2f} MPa A {r.inner.effective_area:.3g}"
                     if r.inner else "")
            log(f"  {label} level {lev:4.2f} ({len(mesh.tets):7d} tets, {wall:6.1f} s) mu {mu}: "
                f"outer {r.outer.sigma1_max / 1e6:8.2f} MPa A {r.outer.effective_area:.3g} "
                f"at s {r.outer.surface_s * 1e3:.3f} z {r.outer.surface_z * 1e3:.3f} mm; "
                + inner)
    conv: dict[str, Any] = {}
    h = [run["level"] for run in runs]
    for mu in frictions:
        key = str(mu)
        c: dict[str, Any] = {}
        for surf in ("outer", "inner"):
            if runs[0]["results"][key][surf] is None:
                continue
            for q in ("sigma1_max_Pa", "effective_area_m2"):
                vals = [run["results"][key][surf][q] for run in runs]
                c[f"{surf}_{q}"] = {"levels": vals, **rf.richardson(h, vals)}
            alt = [run["results"][key]["alternatives"]["nodal_average"][surf]["sigma1_max_Pa"]
                   for run in runs]
            c[f"{surf}_sigma1_nodal_average"] = {"levels": alt}
        conv[key] = c
    return {"levels": runs, "convergence": conv}


#: Observed orders accepted for Richardson's extrapolation (linear tets: stresses converge
#: at order 1–2; outside this range the three levels are not in the asymptotic range).
ORDER_RANGE = (0.5, 4.0)


def _pick(c: dict[str, Any]) -> float:
    """Richardson's value when the three levels converge monotonically at an order in
    :data:`ORDER_RANGE` and the extrapolation moves the finest value by no more than the last
    refinement did; else the finest level's."""
    p = c.get("order", math.nan)
    lv = c["levels"]
    if (c.get("monotone") and ORDER_RANGE[0] <= p <= ORDER_RANGE[1]
            and abs(c["extrapolated"] - lv[-1]) <= abs(lv[-1] - lv[-2])):
        return float(c["extrapolated"])
    return float(lv[-1])


def converged(st: dict[str, Any], mu: float, surf: str, q: str) -> float:
    """The converged value (:func:`_pick`)."""
    return _pick(st["convergence"][str(mu)][f"{surf}_{q}"])


def finest(st: dict[str, Any], mu: float, surf: str, key: str) -> Any:
    return st["levels"][-1]["results"][str(mu)][surf][key]


# ---------------------------------------------------------------------------------------------


def case_block(levels: tuple[float, ...]) -> dict[str, Any]:
    log("== block: Hertz (+ Hamilton traction) on a half-space ==")
    patch = rf.sphere_on_flat_patch(45.0, 5.8e-3, E, NU)
    a, p0 = patch.contact_radius, patch.peak_pressure
    body = rf.HalfSpaceBlock(20 * a, 20 * a)
    base = rf.Grading.for_patch(patch, body)
    st = study(lambda lev: rf.build_mesh(body, patch, base.scaled(lev)), levels, [0.0, 0.2],
               "block")
    exact = {"0.0": rf.hamilton_max_tension(NU, 0.0), "0.2": rf.hamilton_max_tension(NU, 0.2)}
    table = []
    for mu in (0.0, 0.2):
        vals = st["convergence"][str(mu)]["outer_sigma1_max_Pa"]["levels"]
        nod = st["convergence"][str(mu)]["outer_sigma1_nodal_average"]["levels"]
        ex = exact[str(mu)]
        row = {"friction": mu, "exact_over_p0": ex,
               "fem_over_p0": [v / p0 for v in vals],
               "error_pct": [100 * (v / p0 / ex - 1) for v in vals],
               "nodal_average_over_p0": [v / p0 for v in nod],
               "effective_area_over_pi_a2": [
                   run["results"][str(mu)]["outer"]["effective_area_m2"] / (math.pi * a * a)
                   for run in st["levels"]]}
        table.append(row)
        log(f"  mu {mu}: exact {ex:.4f} p0; FEM " + ", ".join(f"{v:.4f}" for v in
                                                              row["fem_over_p0"])
            + "; errors " + ", ".join(f"{e:+.1f} %" for e in row["error_pct"]))
    # exact effective area at μ = 0 (σ_r = (1−2ν)/3 p0 (a/r)² outside): 2π a²/(2m − 2)
    return {"a_m": a, "p0_Pa": p0, "study": st, "table": table,
            "exact_effective_area_mu0_over_pi_a2": 2.0 / (2 * M_OUT - 2)}


def crossed_model(F: float, mu: float) -> dict[str, Any]:
    t0 = time.perf_counter()
    cs = demfem.stress.contact_stresses(F, mu * F, geometry="crossed",
                                        weibull_modulus_outer=M_OUT,
                                        weibull_modulus_inner=M_IN)
    return {**model_dict(cs), "time_s": time.perf_counter() - t0}


def case_crossed(forces: list[float], levels: tuple[float, ...]) -> dict[str, Any]:
    log("== crossed cartridges (90 deg), mid-body, free tube (inertia relief) ==")
    cart = Cartridge()
    body = rf.TubeSegment.from_cartridge(cart, half_length=15e-3)
    out: dict[str, Any] = {"tube": {"outer_radius_m": body.outer_radius,
                                    "thickness_m": body.thickness,
                                    "length_m": 2 * body.half_length,
                                    "support": "free (inertia relief), symmetric quarter"},
                           "cases": []}
    for F in forces:
        patch = rf.crossed_cylinders_patch(F, body.outer_radius, E, NU)
        base = rf.Grading.for_patch(patch, body)
        t0 = time.perf_counter()
        st = study(lambda lev: rf.build_mesh(body, patch, base.scaled(lev)), levels,
                   [0.0, 0.2], f"crossed {F:g} N")
        wall = time.perf_counter() - t0
        for mu in (0.0, 0.2):
            out["cases"].append({
                "force_N": F, "friction": mu, "a_m": patch.contact_radius,
                "p0_Pa": patch.peak_pressure,
                "hertz_edge_Pa": rf.hamilton_max_tension(NU, mu) * patch.peak_pressure,
                "model": crossed_model(F, mu), "fem": st if mu == 0.0 else "see friction 0.0",
                "fem_converged": {
                    "outer_sigma1_Pa": converged(st, mu, "outer", "sigma1_max_Pa"),
                    "inner_sigma1_Pa": converged(st, mu, "inner", "sigma1_max_Pa"),
                    "outer_effective_area_m2": converged(st, mu, "outer", "effective_area_m2"),
                    "inner_effective_area_m2": converged(st, mu, "inner", "effective_area_m2"),
                    "outer_position_m": finest(st, mu, "outer", "position_m"),
                    "inner_position_m": finest(st, mu, "inner", "position_m"),
                    "convergence": st["convergence"][str(mu)]},
                "fem_wall_s_all_levels_both_frictions": wall,
                "fem_wall_s_finest": st["levels"][-1]["wall_s"],
            })
    return out


def case_parallel(levels: tuple[float, ...], force: float = 45.0,
                  length: float = 10e-3) -> dict[str, Any]:
    log("== parallel cartridges: line contact along the body, held by an equal contact "
        "opposite ==")
    cart = Cartridge()
    body = rf.TubeSegment.from_cartridge(cart, half_length=15e-3)
    patch = rf.parallel_cylinders_patch(force, length, body.outer_radius, E, NU)
    t = body.thickness
    # the Hertz half-width (27 µm at 45 N over 10 mm) is not resolved: a line contact has no
    # tension at its edge (μ = 0) and its field is gone within a few b; the load acts as a
    # line load on the nodes along the strip. Ring bending everywhere around the ring: the
    # wall zone (12 mm from the loaded lines) covers the whole cross-section.
    base = rf.Grading(contact_size=t / 10, edge_size=t / 10, far_size=t / 2, growth=0.3,
                      wall_size=t / 5, wall_zone=12e-3)
    out: dict[str, Any] = {"force_N": force, "contact_length_m": length,
                           "half_width_b_m": patch.semi_axis_s, "p0_Pa": patch.peak_pressure,
                           "tube_length_m": 2 * body.half_length, "cases": []}
    for support, opposite in (("opposite", True),):
        t0 = time.perf_counter()
        st = study(lambda lev: rf.build_mesh(body, patch, base.scaled(lev), opposite=opposite),
                   levels, [0.0], f"parallel/{support}")
        wall = time.perf_counter() - t0
        tm = time.perf_counter()
        cs = demfem.stress.contact_stresses(force, 0.0, geometry="parallel",
                                            contact_length=length, ring_support=support,
                                            weibull_modulus_outer=M_OUT,
                                            weibull_modulus_inner=M_IN)
        out["cases"].append({
            "support": support, "model": {**model_dict(cs), "time_s": time.perf_counter() - tm},
            "fem": st,
            "fem_converged": {
                "outer_sigma1_Pa": converged(st, 0.0, "outer", "sigma1_max_Pa"),
                "inner_sigma1_Pa": converged(st, 0.0, "inner", "sigma1_max_Pa"),
                "outer_effective_area_m2": converged(st, 0.0, "outer", "effective_area_m2"),
                "inner_effective_area_m2": converged(st, 0.0, "inner", "effective_area_m2"),
                "outer_position_m": finest(st, 0.0, "outer", "position_m"),
                "inner_position_m": finest(st, 0.0, "inner", "position_m")},
            "fem_wall_s_all_levels": wall})
    return out


def case_ccx(level: float, force: float = 45.0) -> dict[str, Any]:
    log("== CalculiX 2.20, C3D10, crossed 45 N ==")
    body = rf.TubeSegment.from_cartridge(Cartridge(), half_length=15e-3)
    patch = rf.crossed_cylinders_patch(force, body.outer_radius, E, NU)
    base = rf.Grading.for_patch(patch, body)
    t0 = time.perf_counter()
    mesh = rf.build_mesh(body, patch, base.scaled(level), order=2)
    res = rf.run_calculix_case(mesh, E, NU, [0.0, 0.2], m_outer=M_OUT, m_inner=M_IN,
                               threads=2)
    wall = time.perf_counter() - t0
    out = {"level": level, "tets": int(len(mesh.tets)), "nodes": int(len(mesh.nodes)),
           "mesh": mesh.stats, "wall_s": wall, "results": {}}
    for mu, r in res.items():
        out["results"][str(mu)] = r.as_dict()
        fit_o, fit_i = r.alternatives["surface_fit"]
        log(f"  ccx mu {mu}: outer {r.outer.sigma1_max / 1e6:.2f} MPa (fit "
            f"{fit_o.sigma1_max / 1e6:.2f}), inner {r.inner.sigma1_max / 1e6:.2f} MPa (fit "
            f"{fit_i.sigma1_max / 1e6:.2f}); {len(mesh.tets)} C3D10, {wall:.0f} s")
    return out


def quasi_static(cart: Cartridge) -> dict[str, float]:
    """Periods of the local shell mode under a contact and of the tube's ovalising ring mode,
    against the contact's duration."""
    R = cart.body_mid_radius
    t = cart.wall_thickness
    D = E * t ** 3 / (12 * (1 - NU ** 2))
    ell = (D * R * R / (E * t)) ** 0.25
    k_r = 8 * D / ell ** 2
    # effective mass of the Reissner deflection w ∝ kei(r/ℓ): ρ t ℓ² 2π ∫ kei² x dx / kei(0)²
    shape = 2 * math.pi * quad(lambda x: kei(x) ** 2 * x, 0, 40, limit=200)[0] / kei(0) ** 2
    m_eff = RHO * t * ell ** 2 * shape
    t_local = 2 * math.pi / math.sqrt(k_r / m_eff)
    # ring (plane strain) n = 2: ω = n(n²−1)/√(n²+1) √(E' t² / (12 ρ R⁴)), E' = E/(1−ν²)
    n = 2
    w_ring = n * (n * n - 1) / math.sqrt(n * n + 1) * math.sqrt(
        E / (1 - NU ** 2) * t * t / (12 * RHO * R ** 4))
    return {"bending_length_m": ell, "reissner_stiffness_N_per_m": k_r,
            "local_effective_mass_kg": m_eff, "local_mode_period_s": t_local,
            "ring_n2_period_s": 2 * math.pi / w_ring,
            "contact_duration_s": "30-100e-6 (calibration; 33 us for two 20 mm tubes at "
                                  "0.2 m/s, docs/fem-calculix.md)"}


def refresh(res: dict[str, Any]) -> dict[str, Any]:
    """Recompute the converged values from the stored levels (the rule of :func:`converged`)."""
    for c in res.get("crossed", {}).get("cases", []):
        conv = c["fem_converged"]["convergence"]
        for surf in ("outer", "inner"):
            c["fem_converged"][f"{surf}_sigma1_Pa"] = _pick(conv[f"{surf}_sigma1_max_Pa"])
            c["fem_converged"][f"{surf}_effective_area_m2"] = _pick(
                conv[f"{surf}_effective_area_m2"])
    for c in res.get("parallel", {}).get("cases", []):
        conv = c["fem"]["convergence"]["0.0"]
        c["fem_converged"]["convergence"] = conv
        for surf in ("outer", "inner"):
            c["fem_converged"][f"{surf}_sigma1_Pa"] = _pick(conv[f"{surf}_sigma1_max_Pa"])
            c["fem_converged"][f"{surf}_effective_area_m2"] = _pick(
                conv[f"{surf}_effective_area_m2"])
    return res


def print_table(res: dict[str, Any]) -> None:
    rows = []
    for c in res.get("crossed", {}).get("cases", []):
        m, f = c["model"], c["fem_converged"]
        rows.append((f"crossed {c['force_N']:g} N mu {c['friction']}", m, f))
    for c in res.get("parallel", {}).get("cases", []):
        rows.append((f"parallel 45 N/{c['support']}", c["model"], c["fem_converged"]))
    cc = res.get("calculix")
    if cc:
        for mu, r in cc["results"].items():
            log(f"CalculiX C3D10 45 N mu {mu}: outer {r['outer']['sigma1_max_Pa'] / 1e6:.1f} MPa "
                f"(A {r['outer']['effective_area_m2']:.3g}), inner "
                f"{r['inner']['sigma1_max_Pa'] / 1e6:.1f} MPa "
                f"(A {r['inner']['effective_area_m2']:.3g}); surface fit of its displacements: "
                f"{r['alternatives']['surface_fit']['outer']['sigma1_max_Pa'] / 1e6:.1f} / "
                f"{r['alternatives']['surface_fit']['inner']['sigma1_max_Pa'] / 1e6:.1f} MPa")
    if not rows:
        return
    log("\ncase                          | outer s1 model / FEM (MPa)  ratio | inner s1 model / "
        "FEM (MPa) ratio | A_out model/FEM | A_in model/FEM")
    for name, m, f in rows:
        ro = m["outer_sigma1_max"] / f["outer_sigma1_Pa"] if f["outer_sigma1_Pa"] else math.nan
        ri = m["inner_sigma1_max"] / f["inner_sigma1_Pa"] if f["inner_sigma1_Pa"] else math.nan
        ao = m["outer_effective_area"] / f["outer_effective_area_m2"] \
            if f["outer_effective_area_m2"] else math.nan
        ai = m["inner_effective_area"] / f["inner_effective_area_m2"] \
            if f["inner_effective_area_m2"] else math.nan
        log(f"{name:30s}| {m['outer_sigma1_max'] / 1e6:8.1f} / {f['outer_sigma1_Pa'] / 1e6:8.1f}"
            f"  {ro:5.2f} | {m['inner_sigma1_max'] / 1e6:7.1f} / {f['inner_sigma1_Pa'] / 1e6:7.1f}"
            f"  {ri:5.2f} | {ao:6.2f} | {ai:6.2f}")


def markdown(res: dict[str, Any]) -> str:
    """The tables of docs/stress-verification.md from the results."""
    L: list[str] = []
    mp = 1e-6
    blk = res.get("block")
    if blk:
        L += ["| μ | exact σ/p0 | " + " | ".join(f"level {r['level']:g} ({r['tets']} tets)"
                                              for r in blk["study"]["levels"]) + " |",
              "|---|---|" + "---|" * len(blk["study"]["levels"])]
        for row in blk["table"]:
            L.append(f"| {row['friction']:g} | {row['exact_over_p0']:.4f} | " + " | ".join(
                f"{v:.4f} ({e:+.1f} %)" for v, e in zip(row["fem_over_p0"], row["error_pct"]))
                + " |")
        L.append("")
    cr = res.get("crossed")
    if cr:
        L += ["| F (N) | μ | a (mm) | outer σ1 model | outer σ1 FEM (levels) | inner σ1 model | "
              "inner σ1 FEM (levels) | A_out model / FEM (mm²) | A_in model / FEM (mm²) | "
              "FEM s (finest) |",
              "|---|---|---|---|---|---|---|---|---|---|"]
        for c in cr["cases"]:
            m, f = c["model"], c["fem_converged"]
            conv = f["convergence"]
            lv = lambda k: " → ".join(f"{v * mp:.1f}" for v in conv[k]["levels"])  # noqa: E731
            L.append(
                f"| {c['force_N']:g} | {c['friction']:g} | {c['a_m'] * 1e3:.3f} | "
                f"{m['outer_sigma1_max'] * mp:.1f} | {lv('outer_sigma1_max_Pa')} | "
                f"{m['inner_sigma1_max'] * mp:.1f} | {lv('inner_sigma1_max_Pa')} | "
                f"{m['outer_effective_area'] * 1e6:.4f} / "
                f"{conv['outer_effective_area_m2']['levels'][-1] * 1e6:.4f} | "
                f"{m['inner_effective_area'] * 1e6:.3f} / "
                f"{conv['inner_effective_area_m2']['levels'][-1] * 1e6:.3f} | "
                f"{c['fem_wall_s_finest']:.0f} |")
        L.append("")
    pa = res.get("parallel")
    if pa:
        for c in pa["cases"]:
            m, st = c["model"], c["fem"]
            conv = st["convergence"]["0.0"]
            lv = lambda k: " → ".join(f"{v * mp:.1f}" for v in conv[k]["levels"])  # noqa: E731
            L.append(f"| parallel {pa['force_N']:g} N, L {pa['contact_length_m'] * 1e3:g} mm, "
                     f"{c['support']} | outer {m['outer_sigma1_max'] * mp:.1f} vs "
                     f"{lv('outer_sigma1_max_Pa')} | inner {m['inner_sigma1_max'] * mp:.1f} vs "
                     f"{lv('inner_sigma1_max_Pa')} |")
        L.append("")
    cc = res.get("calculix")
    if cc:
        for mu, r in cc["results"].items():
            fo, fi = r["alternatives"]["surface_fit"]["outer"], \
                r["alternatives"]["surface_fit"]["inner"]
            L.append(f"| CalculiX C3D10 ({cc['tets']} el.) μ {mu} | outer "
                     f"{r['outer']['sigma1_max_Pa'] * mp:.1f} (fit {fo['sigma1_max_Pa'] * mp:.1f})"
                     f" | inner {r['inner']['sigma1_max_Pa'] * mp:.1f} (fit "
                     f"{fi['sigma1_max_Pa'] * mp:.1f}) | A_out "
                     f"{r['outer']['effective_area_m2'] * 1e6:.4f} | A_in "
                     f"{r['inner']['effective_area_m2'] * 1e6:.3f} | {cc['wall_s']:.0f} s |")
    return "\n".join(L)


def main(argv: Optional[list[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", default="block,crossed,parallel,ccx")
    ap.add_argument("--forces", default="1,10,45,100")
    ap.add_argument("--ccx-level", type=float, default=1.0,
                    help="mesh level of the CalculiX case (C3D10), default 1.0")
    ap.add_argument("--no-ccx", action="store_true")
    ap.add_argument("--output", default=str(OUT))
    ap.add_argument("--markdown", action="store_true",
                    help="print the tables of docs/stress-verification.md from --output and stop")
    args = ap.parse_args(argv)
    if args.markdown:
        print(markdown(refresh(json.loads(Path(args.output).read_text()))))
        return 0
    cases = [c.strip() for c in args.cases.split(",") if c.strip()]
    forces = [float(f) for f in args.forces.split(",")]
    t_all = time.perf_counter()
    res: dict[str, Any] = {
        "command": "python benches/stress_verification.py " + " ".join(argv or sys.argv[1:]),
        "date": datetime.datetime.now().isoformat(timespec="seconds"),
        "machine": {"cpus": os.cpu_count(), "platform": platform.platform()},
        "material": {"E_Pa": E, "nu": NU, "density": RHO},
        "weibull_moduli": {"outer": M_OUT, "inner": M_IN},
        "levels": {"block": LEVELS_BLOCK, "tube": LEVELS_TUBE, "parallel": LEVELS_PARALLEL},
        "quasi_static": quasi_static(Cartridge()),
    }
    out = Path(args.output)
    if out.exists():  # keep the cases not rerun
        try:
            old = json.loads(out.read_text())
            for k in ("block", "crossed", "parallel", "calculix"):
                if k in old:
                    res[k] = old[k]
        except (OSError, ValueError):
            pass
    if "block" in cases:
        res["block"] = case_block(LEVELS_BLOCK)
    if "crossed" in cases:
        res["crossed"] = case_crossed(forces, LEVELS_TUBE)
    if "parallel" in cases:
        res["parallel"] = case_parallel(LEVELS_PARALLEL)
    if "ccx" in cases and not args.no_ccx:
        res["calculix"] = case_ccx(args.ccx_level)
    res["wall_s"] = time.perf_counter() - t_all
    refresh(res)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(res, indent=1, default=float))
    print_table(res)
    log(f"\nwrote {out} ({res['wall_s']:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
