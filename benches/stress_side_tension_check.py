#!/usr/bin/env python3
"""The outer tension away from the contact — the tube's sides, where a point load ovalises it —
of the contact-stress model against the resolved FEM.

With the flaw-depth correction of the assess job the contact-edge tension of a frictionless
crossed contact falls below the bending compression at the rim, and the outer σ1 of
:func:`demfem.stress.contact_stresses` becomes its ``outer_ring_Pa`` term: the largest tension
of the wall's own bending field, with the effective area of that field normalised by its own
peak (``cylinder_load.point_load_table``: ``ring_peak``, ``ring_area``). The FEM verification of
benches/stress_verification.py compared only the outer peak at the contact's rim. This checks
the side term — its value, where it is, its Weibull effective area (m = 6) — for crossed
contacts at 45 N and 100 N, μ = 0, on the stored verification's tube (R = 5.8 mm, t = 1.1 mm,
30 mm long, free: inertia relief; the model on a body of the same length, as
benches/stress_cylinder_check.py does it):

* **FEM, linear tets** (:func:`demfem.stress.resolved_fem.solve_frictions`): the stored
  verification's grading (``Grading.for_patch``: t/8 within 1.25 √(R t) of the load, t/2 far
  away) at levels 1 and 0.8 — the same meshes as docs/data/stress_verification.json, whose inner
  σ1 they must reproduce (the sanity check of this extraction) — and a grading that resolves
  the sides (``far_layers=4``: t/4 far away) at levels 1, 0.8, 0.64. The side field is
  recovered from the displacements by ``surface_fit_stresses`` as in the verification (fit
  radius 4 h) and with a 2 h radius (the 4 h fit biases a bending field low: see below).
* **FEM, quadratic tets** (CalculiX C3D10, :func:`demfem.stress.resolved_fem.run_calculix_case`)
  on the side grading at level 1 (t/4 far away): the reference (CalculiX's own nodal stresses;
  the surface fit of its displacements beside them); at the first force also on the
  verification's grading (t/2 far away: its own mesh convergence).
* **Held opposite**: the tube squeezed between two equal crossed contacts (``build_mesh(...,
  opposite=True)``; the model's ``support="opposite"``), at 100 N: linear tets level 1 and
  C3D10 with the verification's grading.
* **The body's length**: the model on the default cartridge (a 54.5 mm body, what assess
  uses) against C3D10 on a free 54.5 mm tube (the verification's grading), 45 N.

Extraction: the outer surface σ1 (largest in-plane principal stress) over the region farther
than 3 a from the contact's centre (from both contacts when held opposite; geodesic distance
on the outer surface), its maximum and where it is (angle around the tube from the contact,
axial distance from it), and A = ∫⟨σ1/σ1,side max⟩^6 dA over that region on the whole tube
(``surface_peak`` on the region's triangles: 4 images of the quarter). The model's field is
summed on the same region (``cylinder_load``), and its ``outer_ring_Pa`` and outer effective
area come from ``contact_stresses`` (with the assess job's flaw depth, where the side term makes
the outer σ1). Targets: σ1 within 10 %, area within 25 %.

    python benches/stress_side_tension_check.py                  # all (≈ 10 min on 2 cores)
    python benches/stress_side_tension_check.py --no-ccx --levels 1,0.8
    python benches/stress_side_tension_check.py --markdown       # the docs' table, from the JSON

Writes docs/data/stress_side_tension_check.json. Needs gmsh (pip) and, for the C3D10 cases,
ccx (apt-get install calculix-ccx).
"""
from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import shutil
import sys
import time
from functools import partial
from pathlib import Path
from typing import Any, Optional

import numpy as np

from demfem.cartridge import Cartridge
from demfem.materials import PAPER_GLASS
from demfem.stress import contact_stresses
from demfem.stress import cylinder_load as cl
from demfem.stress import resolved_fem as rf
from demfem.stress.fem_recovery import surface_peak

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "data" / "stress_side_tension_check.json"
STORED = ROOT / "docs" / "data" / "stress_verification.json"

E, NU = PAPER_GLASS.E, PAPER_GLASS.nu
M_OUT = 6.0
#: The assess job's characteristic flaw depth (m) of the brief's check: with it the contact
#: term of a frictionless crossed contact is below the side term at 45 and 100 N.
FLAW_DEPTH = 2.913e-5
#: The region of the side term: farther than this many contact radii from the contact centre.
EXCLUSION_A = 3.0
SIGMA_TOL, AREA_TOL = 0.10, 0.25
FIT_PER_EDGE = (4.0, 2.0)
T_WALL = Cartridge().wall_thickness


def log(msg: str) -> None:
    print(msg, flush=True)


# ---------------------------------------------------------------------------------------------
# extraction
# ---------------------------------------------------------------------------------------------


def _geodesic(body: rf.TubeSegment, P: np.ndarray, opposite: bool) -> np.ndarray:
    """Distance on the outer surface (m) of points P (..., 3) from the contact centre (0, R, 0)
    (and from (0, −R, 0) when held opposite): hypot(R θ, z)."""
    th = np.arctan2(P[..., 0], P[..., 1])
    d = np.hypot(body.outer_radius * th, P[..., 2])
    if opposite:
        d = np.minimum(d, np.hypot(body.outer_radius * (math.pi - th), P[..., 2]))
    return d


def side_peak(mesh: rf.ResolvedMesh, stress: np.ndarray, exclusion: float,
              recovery: str) -> dict[str, float]:
    """The outer surface's σ1 over the triangles all of whose nodes are farther than
    ``exclusion`` (m) from the contact(s): the peak (Pa), where (θ from the contact, deg; z,
    m) and the effective area (m², whole tube, m = 6, normalised by this peak)."""
    F = mesh.outer_faces
    far = np.all(_geodesic(mesh.body, mesh.nodes[F[:, :3]], mesh.opposite) > exclusion, axis=1)
    p = surface_peak(mesh, F[far], stress, None, M_OUT, recovery)
    return {"sigma1_Pa": p.sigma1_max,
            "theta_deg": math.degrees(math.atan2(p.position[0], p.position[1])),
            "z_m": float(abs(p.position[2])), "area_m2": p.effective_area}


def _fits(mesh: rf.ResolvedMesh, u: np.ndarray) -> dict[float, np.ndarray]:
    """The outer surface's stresses recovered from the displacements with fit radii
    max(k h, a/10), k in :data:`FIT_PER_EDGE` (k = 4: the verification's)."""
    snn = -rf.surface_pressure(mesh, mesh.nodes)
    return {k: rf.surface_fit_stresses(mesh, u, mesh.outer_faces, E, NU, snn,
                                       window=0.1 * mesh.patch.contact_radius, per_edge=k,
                                       one_sided=True)[0] for k in FIT_PER_EDGE}


def _mesh(F: float, body: rf.TubeSegment, far_layers: Optional[float], level: float,
          opposite: bool, order: int) -> rf.ResolvedMesh:
    patch = rf.crossed_cylinders_patch(F, body.outer_radius, E, NU)
    base = (rf.Grading.for_patch(patch, body) if far_layers is None
            else rf.Grading.for_patch(patch, body, far_layers=far_layers))
    return rf.build_mesh(body, patch, base.scaled(level), opposite=opposite, order=order)


def fem_linear(F: float, far_layers: Optional[float], level: float, *,
               opposite: bool = False, half_length: float = 15e-3) -> dict[str, Any]:
    """demfem's Tet4 static solve (μ = 0) and the side term from the two fits."""
    body = rf.TubeSegment.from_cartridge(Cartridge(), half_length=half_length)
    t0 = time.perf_counter()
    mesh = _mesh(F, body, far_layers, level, opposite, 1)
    res = rf.solve_frictions(mesh, E, NU, [0.0], m_outer=M_OUT)[0.0]
    t_solve = time.perf_counter() - t0
    ex = EXCLUSION_A * mesh.patch.contact_radius
    side = {f"fit_{k:g}h": side_peak(mesh, s, ex, f"surface_fit {k:g}h")
            for k, s in _fits(mesh, res.displacement_normal).items()}
    wall = time.perf_counter() - t0
    return {"element": "Tet4", "force_N": F, "level": level,
            "far_size_m": mesh.grading.far_size, "opposite": opposite,
            "tube_length_m": 2 * half_length, "tets": int(len(mesh.tets)),
            "nodes": int(len(mesh.nodes)), "exclusion_m": ex, "side": side,
            "inner_sigma1_Pa": res.inner.sigma1_max if res.inner else math.nan,
            "inner_area_m2": res.inner.effective_area if res.inner else math.nan,
            "rim_outer_sigma1_Pa": res.outer.sigma1_max,
            "times_s": {**res.times, "solve_and_fit_total": t_solve}, "wall_s": wall,
            "support": res.support}


def fem_c3d10(F: float, far_layers: Optional[float], level: float, *, opposite: bool = False,
              half_length: float = 15e-3) -> dict[str, Any]:
    """CalculiX C3D10 (μ = 0): the side term from its own nodal stresses and from the 2 h
    surface fit of its displacements."""
    body = rf.TubeSegment.from_cartridge(Cartridge(), half_length=half_length)
    t0 = time.perf_counter()
    mesh = _mesh(F, body, far_layers, level, opposite, 2)
    res = rf.run_calculix_case(mesh, E, NU, [0.0], m_outer=M_OUT, threads=2)[0.0]
    ex = EXCLUSION_A * mesh.patch.contact_radius
    fit = _fits(mesh, res.displacement_normal)[FIT_PER_EDGE[-1]]
    side = {"calculix": side_peak(mesh, res.stress_normal, ex, "calculix"),
            f"fit_{FIT_PER_EDGE[-1]:g}h": side_peak(mesh, fit, ex, "surface_fit")}
    wall = time.perf_counter() - t0
    return {"element": "C3D10", "force_N": F, "level": level,
            "far_size_m": mesh.grading.far_size, "opposite": opposite,
            "tube_length_m": 2 * half_length, "tets": int(len(mesh.tets)),
            "nodes": int(len(mesh.nodes)), "exclusion_m": ex, "side": side,
            "inner_sigma1_Pa": res.inner.sigma1_max if res.inner else math.nan,
            "rim_outer_sigma1_Pa": res.outer.sigma1_max, "times_s": res.times, "wall_s": wall}


# ---------------------------------------------------------------------------------------------
# the model
# ---------------------------------------------------------------------------------------------


def _cartridge(body_length: Optional[float]) -> Cartridge:
    cart = Cartridge()
    if body_length is None:
        return cart
    return Cartridge(length=cart.length - cart.body_length + body_length)


def model_field(F: float, a: float, body_length: float, support: str,
                curved: bool = True) -> dict[str, float]:
    """The model's wall field (:func:`cylinder_load.cylinder_load_field`, as
    ``point_load_table`` builds it: the Hertz circle, computational cylinder twice the body,
    free over the body for "inertia") on the region farther than 3 a from the contact(s):
    peak σ1 (Pa), where, effective area (m²); and over the whole surface."""
    cart = Cartridge()
    t, R = cart.wall_thickness, cart.body_mid_radius
    shell = cl.CylinderShell(R, t, 1.0, cart.material.nu, 2.0 * body_length)
    fld = cl.cylinder_load_field(shell, F, partial(cl.hertz_disc_spectrum, radius=a),
                                 support=support, free_length=body_length, curved=curved)
    x, th = cl._surface_grid(shell, body_length, 4.0 * t)
    r_out = R + 0.5 * t
    s1 = fld.surface_stresses(x, th, "outer", grid=True)["s1"]
    d = np.hypot(x[:, None], r_out * th[None, :])
    if support == "opposite":
        d = np.minimum(d, np.hypot(x[:, None], r_out * (math.pi - th[None, :])))
    out: dict[str, float] = {}
    for name, field in (("region", np.where(d > EXCLUSION_A * a, s1, 0.0)), ("whole", s1)):
        p, area, k = cl._peak_area(field, x, th, r_out, M_OUT)
        out.update({f"{name}_sigma1_Pa": p, f"{name}_area_m2": area,
                    f"{name}_theta_deg": math.degrees(th[k[1]]), f"{name}_z_m": float(x[k[0]])})
    return out


def model(F: float, body_length: Optional[float]) -> dict[str, Any]:
    """:func:`contact_stresses` (μ = 0, with and without the flaw depth) on a cartridge whose
    body is ``body_length`` (None: the default 54.5 mm), and the field behind its side term
    held by inertia (what it uses), held opposite, and without the curved-bar factor."""
    cart = _cartridge(body_length)
    lf = cart.body_length
    t0 = time.perf_counter()
    r = contact_stresses(F, 0.0, cartridge=cart, weibull_modulus_outer=M_OUT,
                         flaw_depth=FLAW_DEPTH)
    bare = contact_stresses(F, 0.0, cartridge=cart, weibull_modulus_outer=M_OUT)
    t_call = time.perf_counter() - t0
    tab = cl.point_load_table(cart.body_mid_radius, cart.wall_thickness, cart.material.nu, lf,
                              10.0, M_OUT)
    a = float(r.a)
    u = a / cart.wall_thickness
    return {"body_length_m": lf, "a_m": a,
            "outer_ring_Pa": float(r.outer_ring_Pa),
            "outer_sigma1_flaw_Pa": float(r.outer_sigma1_max),
            "outer_area_flaw_m2": float(r.outer_effective_area),
            "outer_from_contact_flaw": bool(r.outer_from_contact),
            "outer_contact_flaw_Pa": float(r.outer_contact_Pa),
            "outer_bending_Pa": float(r.outer_bending_Pa),
            "outer_sigma1_surface_Pa": float(bare.outer_sigma1_max),
            "inner_sigma1_Pa": float(r.inner_sigma1_max),
            "ring_area_table_m2": float(np.interp(u, tab["c_over_t"], tab["ring_area"]))
            * cart.wall_thickness ** 2,
            "call_s": t_call,
            "field_inertia": model_field(F, a, lf, "inertia"),
            "field_opposite": model_field(F, a, lf, "opposite"),
            "field_inertia_no_curved_bar": model_field(F, a, lf, "inertia", curved=False)}


# ---------------------------------------------------------------------------------------------
# the study
# ---------------------------------------------------------------------------------------------


def _stored_inner(F: float) -> dict[str, float]:
    """The inner σ1 per level of the stored verification (crossed, μ = 0)."""
    if not STORED.exists():
        return {}
    d = json.loads(STORED.read_text())
    for c in d.get("crossed", {}).get("cases", []):
        if c["force_N"] == F and c["friction"] == 0.0:
            return {f"{lv['level']:g}": lv["results"]["0.0"]["inner"]["sigma1_max_Pa"]
                    for lv in c["fem"]["levels"]}
    return {}


def _say(tag: str, run: dict[str, Any]) -> None:
    cells = "; ".join(f"{k} {v['sigma1_Pa'] / 1e6:.2f} MPa at {v['theta_deg']:.0f} deg, "
                      f"z {v['z_m'] * 1e3:.2f} mm, A {v['area_m2'] * 1e6:.1f} mm2"
                      for k, v in run["side"].items())
    log(f"  {tag} {run['element']} level {run['level']:g} far {run['far_size_m'] * 1e3:.3f} mm "
        f"({run['tets']} el., {run['wall_s']:.0f} s): side {cells}; inner "
        f"{run['inner_sigma1_Pa'] / 1e6:.2f} MPa")


def study(forces: list[float], levels: list[float], ccx: bool,
          opposite_force: Optional[float], long_force: Optional[float]) -> dict[str, Any]:
    out: dict[str, Any] = {"cases": []}
    have_ccx = ccx and shutil.which("ccx") is not None
    if ccx and not have_ccx:
        log("ccx not found: the C3D10 cases are skipped")
    for F in forces:
        log(f"== crossed {F:g} N, mu 0, free 30 mm tube ==")
        case: dict[str, Any] = {"force_N": F, "model_30mm": model(F, 30e-3),
                                "model_body": model(F, None), "stored_inner_Pa": _stored_inner(F)}
        m = case["model_30mm"]
        log(f"  model (30 mm body): side {m['outer_ring_Pa'] / 1e6:.2f} MPa (field: "
            f"{m['field_inertia']['region_sigma1_Pa'] / 1e6:.2f} at "
            f"{m['field_inertia']['region_theta_deg']:.0f} deg, z "
            f"{m['field_inertia']['region_z_m'] * 1e3:.2f} mm, A "
            f"{m['field_inertia']['region_area_m2'] * 1e6:.1f} mm2); inner "
            f"{m['inner_sigma1_Pa'] / 1e6:.2f} MPa")
        case["verification_grading"] = []
        for lev in [lv for lv in levels if lv in (1.0, 0.8)]:
            run = fem_linear(F, None, lev)
            case["verification_grading"].append(run)
            _say("verification grading", run)
        case["side_grading"] = []
        for lev in levels:
            run = fem_linear(F, 4.0, lev)
            case["side_grading"].append(run)
            _say("side grading", run)
        if len(case["side_grading"]) == 3:
            h = [r["level"] for r in case["side_grading"]]
            case["richardson"] = {
                k: {q: rf.richardson(h, [r["side"][k][q] for r in case["side_grading"]])
                    for q in ("sigma1_Pa", "area_m2")}
                for k in case["side_grading"][0]["side"]}
        if have_ccx:
            if F == forces[0]:
                # the C3D10 reference's own mesh convergence (far t/2 → t/4), and the grading
                # of the 54.5 mm tube's case
                run = fem_c3d10(F, None, 1.0)
                case["c3d10_verification_grading"] = run
                _say("verification grading", run)
            run = fem_c3d10(F, 4.0, 1.0)
            case["c3d10"] = run
            _say("side grading", run)
        out["cases"].append(case)
    if opposite_force is not None:
        F = opposite_force
        log(f"== crossed {F:g} N held by an equal contact opposite (squeezed), 30 mm tube ==")
        opp: dict[str, Any] = {"force_N": F, "model_30mm": model(F, 30e-3),
                               "model_body": model(F, None)}
        opp["linear"] = fem_linear(F, 4.0, 1.0, opposite=True)
        _say("side grading", opp["linear"])
        if have_ccx:
            opp["c3d10"] = fem_c3d10(F, None, 1.0, opposite=True)
            _say("verification grading", opp["c3d10"])
        out["opposite"] = opp
    if long_force is not None and have_ccx:
        F = long_force
        log(f"== crossed {F:g} N, free 54.5 mm tube (the default cartridge's body) ==")
        cart = Cartridge()
        lg: dict[str, Any] = {"force_N": F, "model_body": model(F, None)}
        lg["c3d10"] = fem_c3d10(F, None, 1.0, half_length=0.5 * cart.body_length)
        _say("verification grading", lg["c3d10"])
        out["long_tube"] = lg
    return out


# ---------------------------------------------------------------------------------------------
# tables
# ---------------------------------------------------------------------------------------------


def _cell(side: dict[str, float]) -> str:
    return (f"{side['sigma1_Pa'] / 1e6:.2f} MPa, {side['theta_deg']:.0f}°, "
            f"{side['z_m'] * 1e3:.1f} mm, {side['area_m2'] * 1e6:.1f} mm²")


def _ratio(model_v: float, fem_v: float) -> str:
    return f"{100.0 * (model_v / fem_v - 1.0):+.0f} %"


def markdown(res: dict[str, Any]) -> str:
    """The tables of docs/stress-verification.md from the results."""
    L = ["| F (N) | | side σ1 (MPa) | θ from the contact | z (mm) | A_side (mm², m = 6) | "
         "inner σ1 (MPa) | elements | wall s |",
         "|---|---|---|---|---|---|---|---|---|"]
    for c in res["cases"]:
        F = c["force_N"]
        m, fi = c["model_30mm"], c["model_30mm"]["field_inertia"]
        L.append(f"| {F:g} | **model** (30 mm body): `outer_ring_Pa`, field | "
                 f"**{m['outer_ring_Pa'] / 1e6:.2f}** ({fi['region_sigma1_Pa'] / 1e6:.2f}) | "
                 f"{fi['region_theta_deg']:.0f}° | {fi['region_z_m'] * 1e3:.1f} | "
                 f"**{m['outer_area_flaw_m2'] * 1e6:.1f}** ({fi['region_area_m2'] * 1e6:.1f}) | "
                 f"{m['inner_sigma1_Pa'] / 1e6:.1f} | | |")
        stored = c.get("stored_inner_Pa", {})
        for r in c["verification_grading"]:
            s = r["side"]["fit_4h"]
            st = stored.get(f"{r['level']:g}")
            inner = (f"{r['inner_sigma1_Pa'] / 1e6:.2f} (stored {st / 1e6:.2f})" if st
                     else f"{r['inner_sigma1_Pa'] / 1e6:.2f}")
            L.append(f"| {F:g} | Tet4, verification grading, level {r['level']:g} (far "
                     f"t/{T_WALL / r['far_size_m']:.3g}), fit 4h | {s['sigma1_Pa'] / 1e6:.2f} | "
                     f"{s['theta_deg']:.0f}° | {s['z_m'] * 1e3:.1f} | {s['area_m2'] * 1e6:.1f} | "
                     f"{inner} | {r['tets']} | {r['wall_s']:.0f} |")
        for r in c["side_grading"]:
            s4, s2 = r["side"]["fit_4h"], r["side"]["fit_2h"]
            L.append(f"| {F:g} | Tet4, side grading, level {r['level']:g} (far "
                     f"t/{T_WALL / r['far_size_m']:.3g}), fit 2h (4h) | "
                     f"{s2['sigma1_Pa'] / 1e6:.2f} ({s4['sigma1_Pa'] / 1e6:.2f}) | "
                     f"{s2['theta_deg']:.0f}° | {s2['z_m'] * 1e3:.1f} | "
                     f"{s2['area_m2'] * 1e6:.1f} ({s4['area_m2'] * 1e6:.1f}) | "
                     f"{r['inner_sigma1_Pa'] / 1e6:.2f} | {r['tets']} | {r['wall_s']:.0f} |")
        if "c3d10_verification_grading" in c:
            r = c["c3d10_verification_grading"]
            s = r["side"]["calculix"]
            L.append(f"| {F:g} | C3D10 (CalculiX), verification grading, level 1, own stresses | "
                     f"{s['sigma1_Pa'] / 1e6:.2f} | {s['theta_deg']:.0f}° | "
                     f"{s['z_m'] * 1e3:.1f} | {s['area_m2'] * 1e6:.1f} | "
                     f"{r['inner_sigma1_Pa'] / 1e6:.2f} | {r['tets']} | {r['wall_s']:.0f} |")
        if "c3d10" in c:
            r = c["c3d10"]
            s, sf = r["side"]["calculix"], r["side"]["fit_2h"]
            L.append(f"| {F:g} | **C3D10** (CalculiX), side grading, level 1, own stresses "
                     f"(fit 2h) | **{s['sigma1_Pa'] / 1e6:.2f}** ({sf['sigma1_Pa'] / 1e6:.2f}) | "
                     f"{s['theta_deg']:.0f}° | {s['z_m'] * 1e3:.1f} | "
                     f"**{s['area_m2'] * 1e6:.1f}** ({sf['area_m2'] * 1e6:.1f}) | "
                     f"{r['inner_sigma1_Pa'] / 1e6:.2f} | {r['tets']} | {r['wall_s']:.0f} |")
            L.append(f"| {F:g} | model / C3D10 | "
                     f"{_ratio(m['outer_ring_Pa'], s['sigma1_Pa'])} | | | "
                     f"{_ratio(m['outer_area_flaw_m2'], s['area_m2'])} | | | |")
    L.append("")
    opp = res.get("opposite")
    if opp:
        F = opp["force_N"]
        mo, mi = opp["model_30mm"]["field_opposite"], opp["model_30mm"]["field_inertia"]
        mb = opp["model_body"]["field_opposite"]
        L += [f"Held by an equal crossed contact opposite, {F:g} N (model: "
              "`cylinder_load_field(..., support=\"opposite\")`):", "",
              "| | side σ1 (MPa) | θ | z (mm) | A_side (mm²) | elements | wall s |",
              "|---|---|---|---|---|---|---|",
              f"| model, 30 mm body, held opposite | {mo['region_sigma1_Pa'] / 1e6:.2f} | "
              f"{mo['region_theta_deg']:.0f}° | {mo['region_z_m'] * 1e3:.1f} | "
              f"{mo['region_area_m2'] * 1e6:.1f} | | |",
              f"| model, 30 mm body, free (inertia; what assess uses) | "
              f"{mi['region_sigma1_Pa'] / 1e6:.2f} | {mi['region_theta_deg']:.0f}° | "
              f"{mi['region_z_m'] * 1e3:.1f} | {mi['region_area_m2'] * 1e6:.1f} | | |",
              f"| model, 54.5 mm body, held opposite | {mb['region_sigma1_Pa'] / 1e6:.2f} | "
              f"{mb['region_theta_deg']:.0f}° | {mb['region_z_m'] * 1e3:.1f} | "
              f"{mb['region_area_m2'] * 1e6:.1f} | | |"]
        r = opp["linear"]
        s2, s4 = r["side"]["fit_2h"], r["side"]["fit_4h"]
        L.append(f"| Tet4, side grading, level 1, fit 2h (4h) | {s2['sigma1_Pa'] / 1e6:.2f} "
                 f"({s4['sigma1_Pa'] / 1e6:.2f}) | {s2['theta_deg']:.0f}° | "
                 f"{s2['z_m'] * 1e3:.1f} | {s2['area_m2'] * 1e6:.1f} | {r['tets']} | "
                 f"{r['wall_s']:.0f} |")
        if "c3d10" in opp:
            r = opp["c3d10"]
            s = r["side"]["calculix"]
            L.append(f"| C3D10, verification grading, level 1, own stresses | "
                     f"{s['sigma1_Pa'] / 1e6:.2f} | {s['theta_deg']:.0f}° | "
                     f"{s['z_m'] * 1e3:.1f} | {s['area_m2'] * 1e6:.1f} | {r['tets']} | "
                     f"{r['wall_s']:.0f} |")
            L.append(f"| model / C3D10 | {_ratio(mo['region_sigma1_Pa'], s['sigma1_Pa'])} | | | "
                     f"{_ratio(mo['region_area_m2'], s['area_m2'])} | | |")
        L.append("")
    lg = res.get("long_tube")
    if lg:
        F = lg["force_N"]
        m = lg["model_body"]
        s = lg["c3d10"]["side"]["calculix"]
        L += [f"The default cartridge's 54.5 mm body, {F:g} N, free:", "",
              f"| model (`contact_stresses`, default cartridge) | C3D10, free 54.5 mm tube "
              f"({lg['c3d10']['tets']} el., {lg['c3d10']['wall_s']:.0f} s) | model / FEM |",
              "|---|---|---|",
              f"| {m['outer_ring_Pa'] / 1e6:.2f} MPa, "
              f"{m['field_inertia']['region_theta_deg']:.0f}°, "
              f"{m['field_inertia']['region_z_m'] * 1e3:.1f} mm, "
              f"{m['outer_area_flaw_m2'] * 1e6:.1f} mm² | {_cell(s)} | "
              f"σ1 {_ratio(m['outer_ring_Pa'], s['sigma1_Pa'])}, A "
              f"{_ratio(m['outer_area_flaw_m2'], s['area_m2'])} |", ""]
    return "\n".join(L)


def main(argv: Optional[list[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--forces", default="45,100")
    ap.add_argument("--levels", default="1,0.8,0.64",
                    help="mesh levels of the linear-tet series, coarse to fine")
    ap.add_argument("--no-ccx", action="store_true", help="skip the C3D10 cases")
    ap.add_argument("--opposite-force", type=float, default=100.0,
                    help="force of the case held opposite (N; 0: skip)")
    ap.add_argument("--long-force", type=float, default=45.0,
                    help="force of the 54.5 mm tube case (N; 0: skip; needs ccx)")
    ap.add_argument("--output", default=str(OUT))
    ap.add_argument("--markdown", action="store_true",
                    help="print the tables of docs/stress-verification.md from --output and stop")
    args = ap.parse_args(argv)
    if args.markdown:
        print(markdown(json.loads(Path(args.output).read_text())))
        return 0
    forces = [float(f) for f in args.forces.split(",") if f.strip()]
    levels = [float(v) for v in args.levels.split(",") if v.strip()]
    t0 = time.perf_counter()
    res: dict[str, Any] = {
        "command": "python benches/stress_side_tension_check.py " + " ".join(
            argv if argv is not None else sys.argv[1:]),
        "date": datetime.datetime.now().isoformat(timespec="seconds"),
        "machine": {"cpus": os.cpu_count(), "platform": platform.platform(),
                    "load_average_at_start": list(os.getloadavg())},
        "material": {"E_Pa": E, "nu": NU}, "weibull_modulus_outer": M_OUT,
        "flaw_depth_m": FLAW_DEPTH, "exclusion_contact_radii": EXCLUSION_A,
        "targets": {"sigma1": SIGMA_TOL, "effective_area": AREA_TOL},
        "gradings": {"verification": "Grading.for_patch(patch, body): t/8 within 1.25 sqrt(R t)"
                                     " of the load, t/2 far away",
                     "side": "Grading.for_patch(patch, body, far_layers=4): t/4 far away"},
    }
    res.update(study(forces, levels, not args.no_ccx,
                     args.opposite_force or None, args.long_force or None))
    res["wall_s"] = time.perf_counter() - t0
    out = Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(res, indent=1, default=float) + "\n")
    log("")
    log(markdown(res))
    log(f"wrote {out} ({res['wall_s']:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
