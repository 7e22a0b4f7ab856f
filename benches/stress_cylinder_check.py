"""The contact-stress model with the cylindrical wall against the stored resolved FEM.

Reads docs/data/stress_verification.json (the FEM study of benches/stress_verification.py:
crossed cartridges at 1, 10, 45, 100 N with μ = 0 and 0.2 on a free 30 mm tube, the parallel
contact of 45 N over 10 mm held opposite, CalculiX C3D10 on the crossed 45 N case; it is not
rerun here) and compares, for each case, the peak σ1 and the Weibull effective area on both
surfaces:

* "old": the model stored beside the FEM (Reissner's shallow sphere for point contacts, the
  plane-strain ring for line contacts);
* "new": :func:`demfem.stress.contact_stresses` as it is now (the wall as a cylindrical shell
  with the thick-plate correction, :mod:`demfem.stress.cylinder_load`) on the FEM's tube: a
  cartridge whose body is the FEM's 30 mm, free ("new_body": the default cartridge, a
  54.5 mm body: the free tube's beam moment differs, F L/8 at the load);
* "FEM": the reference of docs/stress-verification.md (its finest level, or Richardson's
  extrapolation where that qualifies), and CalculiX where there is one.

Targets: σ1 within 10 %, effective areas within 25 %. Also the sensitivity of the new model to
the curved-bar (Winkler–Bach) factors on the hoop bending (without them), and to the free
length of the tube (the FEM's 30 mm instead of the cartridge body's), and the cost of one
evaluation of the series and of the tables. Prints the table and writes
docs/data/stress_cylinder_check.json.

    python benches/stress_cylinder_check.py [--json docs/data/stress_cylinder_check.json]
"""
from __future__ import annotations

import argparse
import json
import math
import platform
import time
from pathlib import Path
from typing import Any

import numpy as np

from demfem.cartridge import Cartridge
from demfem.stress import contact_stresses
from demfem.stress import cylinder_load as cl
from demfem.stress.hertz import contact_modulus

ROOT = Path(__file__).resolve().parents[1]
FEM_FILE = ROOT / "docs" / "data" / "stress_verification.json"
OUT_FILE = ROOT / "docs" / "data" / "stress_cylinder_check.json"
SIGMA_TOL, AREA_TOL = 0.10, 0.25
KEYS = (("outer_sigma1", "outer_sigma1_max", "outer_sigma1_Pa", SIGMA_TOL, 1e-6, "MPa"),
        ("inner_sigma1", "inner_sigma1_max", "inner_sigma1_Pa", SIGMA_TOL, 1e-6, "MPa"),
        ("outer_area", "outer_effective_area", "outer_effective_area_m2", AREA_TOL, 1e6, "mm2"),
        ("inner_area", "inner_effective_area", "inner_effective_area_m2", AREA_TOL, 1e6, "mm2"))


def _row(old: dict[str, Any], new: Any, body: Any, fem: dict[str, Any],
         ccx: dict[str, Any] | None = None) -> dict[str, Any]:
    row: dict[str, Any] = {}
    for name, mkey, fkey, tol, scale, unit in KEYS:
        o, n, f = float(old[mkey]), float(np.ravel(getattr(new, mkey))[0]), float(fem[fkey])
        nb = float(np.ravel(getattr(body, mkey))[0])
        entry = {"unit": unit, "old": o * scale, "new": n * scale, "fem": f * scale,
                 "new_body": nb * scale, "old_ratio": o / f, "new_ratio": n / f,
                 "new_body_ratio": nb / f, "tolerance": tol, "old_met": abs(o / f - 1) <= tol,
                 "new_met": abs(n / f - 1) <= tol, "new_body_met": abs(nb / f - 1) <= tol}
        if ccx is not None and name in ccx:
            c = ccx[name]
            entry.update({"calculix": c * scale, "calculix_fit": ccx[name + "_fit"] * scale,
                          "new_ratio_calculix": n / c, "old_ratio_calculix": o / c,
                          "new_ratio_calculix_fit": n / ccx[name + "_fit"],
                          "new_met_calculix": abs(n / c - 1) <= tol,
                          "old_met_calculix": abs(o / c - 1) <= tol})
        row[name] = entry
    return row


def _calculix(d: dict[str, Any], mu: float) -> dict[str, float]:
    """CalculiX's own stresses (and, as ``*_fit``, the surface fit of its displacements)."""
    r = d["calculix"]["results"][str(mu)]
    fit = r["alternatives"]["surface_fit"]
    out = {}
    for surf in ("outer", "inner"):
        out[f"{surf}_sigma1"] = r[surf]["sigma1_max_Pa"]
        out[f"{surf}_area"] = r[surf]["effective_area_m2"]
        out[f"{surf}_sigma1_fit"] = fit[surf]["sigma1_max_Pa"]
        out[f"{surf}_area_fit"] = fit[surf]["effective_area_m2"]
    return out


def _timoshenko(cart: Any, nu: float, force: float, a: float, free: float) -> dict[str, float]:
    """The alternative spread: thin shell (no layer correction) under a uniform disc of
    Timoshenko's equivalent radius b' = √(1.6 c² + t²) − 0.675 t (T&WK §19), c the uniform
    disc with the Hertz circle's centre moment, c = a exp(−(4/3 − ln 2 − 1/2)): inner peak
    and outer axial stress at the rim x = a, MPa."""
    t, r_mid = cart.wall_thickness, cart.body_mid_radius
    c = a * math.exp(-(4.0 / 3.0 - math.log(2.0) - 0.5))
    bp = math.sqrt(1.6 * c * c + t * t) - 0.675 * t
    shell = cl.CylinderShell(r_mid, t, cart.material.E, nu, 2.0 * free)
    fld = cl.cylinder_load_field(shell, force, lambda kx, ky: cl.uniform_disc_spectrum(
        kx, ky, bp), free_length=free, thick=False, k_max=30.0 / (0.325 * t))
    return {"b_prime_m": bp,
            "inner_sigma1_MPa": float(fld.surface_stresses(0.0, 0.0, "inner")["s1"]) / 1e6,
            "rim_axial_MPa": float(fld.surface_stresses(a, 0.0, "outer")["xx"]) / 1e6}


def _sensitivity(cart: Any, nu: float, fem: dict[str, Any]) -> dict[str, Any]:
    """The new wall field's inner peak and rim bending without the curved-bar factors, with
    the FEM tube's free length (30 mm) instead of the body's, and with Timoshenko's
    equivalent radius on the thin shell instead of the layer correction (30 mm tube)."""
    t, r_mid = cart.wall_thickness, cart.body_mid_radius
    e_star = contact_modulus(cart.material.E, nu, cart.material.E, nu)
    out: dict[str, Any] = {"crossed": [], "parallel": {}}
    tabs = {"shipped": cl.point_load_table(r_mid, t, nu, cart.body_length, 10.0, 6.0),
            "no_curved_bar": cl.point_load_table(r_mid, t, nu, cart.body_length, 10.0, 6.0,
                                                 False),
            "free_30mm": cl.point_load_table(r_mid, t, nu, 30e-3, 10.0, 6.0)}
    r_out = 0.5 * cart.body_outer_diameter
    for F in sorted({c["force_N"] for c in fem["crossed"]["cases"]}):
        a = (3.0 * F * r_out / (4.0 * e_star)) ** (1.0 / 3.0)
        row = {"force_N": F}
        for k, tab in tabs.items():
            u = a / t
            g = tab["c_over_t"]
            scale = F / t**2 / 1e6
            row[k] = {"inner_sigma1_MPa": float(np.interp(u, g, tab["inner_peak"])) * scale,
                      "inner_area_mm2": float(np.interp(u, g, tab["inner_area"])) * t * t * 1e6,
                      "rim_axial_MPa": float(np.interp(u, g, tab["rim_axial"][:, 0])) * scale}
        row["timoshenko_b_prime_30mm"] = _timoshenko(cart, nu, F, a, 30e-3)
        case = next(c for c in fem["crossed"]["cases"] if c["force_N"] == F
                    and c["friction"] == 0.0)
        row["fem"] = {"inner_sigma1_MPa": case["fem_converged"]["inner_sigma1_Pa"] / 1e6,
                      "rim_axial_MPa": (case["fem_converged"]["outer_sigma1_Pa"]
                                        - case["hertz_edge_Pa"]) / 1e6}
        out["crossed"].append(row)
    par = fem["parallel"]
    F, L = par["force_N"], par["contact_length_m"]
    for k, (lf, curved) in {"shipped": (cart.body_length, True),
                            "no_curved_bar": (cart.body_length, False),
                            "free_30mm": (30e-3, True)}.items():
        p = cl.line_load_profile(r_mid, t, nu, L, "opposite", lf, 10.0, 6.0, curved)
        out["parallel"][k] = {"inner_sigma1_MPa": p["inner_peak"] * F / t**2 / 1e6,
                              "outer_sigma1_MPa": p["outer_peak"] * F / t**2 / 1e6,
                              "inner_area_mm2": p["inner_area"] * 1e6,
                              "outer_area_mm2": p["outer_area"] * 1e6}
    return out


def _cost(cart: Any, nu: float) -> dict[str, float]:
    t, r_mid = cart.wall_thickness, cart.body_mid_radius
    shell = cl.CylinderShell(r_mid, t, cart.material.E, nu, 2.0 * cart.body_length)
    spec = lambda kx, ky: cl.hertz_disc_spectrum(kx, ky, 0.2e-3)  # noqa: E731
    t0 = time.perf_counter()
    cl.cylinder_load_field(shell, 45.0, spec, free_length=cart.body_length)
    first = time.perf_counter() - t0
    t0 = time.perf_counter()
    for _ in range(5):
        f = cl.cylinder_load_field(shell, 45.0, spec, free_length=cart.body_length)
        f.surface_stresses(0.0, 0.0, "inner")
    one = (time.perf_counter() - t0) / 5
    cl.point_load_table.cache_clear()
    t0 = time.perf_counter()
    cl.point_load_table(r_mid, t, nu, cart.body_length, 10.0, 6.0)
    table = time.perf_counter() - t0
    return {"modes_solved_first_call_s": first, "one_load_and_point_s": one,
            "point_table_s": table}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--json", default=str(OUT_FILE), help="where to write the results")
    p.add_argument("--markdown", action="store_true",
                   help="print the tables of docs/stress-verification.md from the JSON")
    args = p.parse_args()
    if args.markdown:
        markdown(json.loads(Path(args.json).read_text()))
        return
    d = json.loads(FEM_FILE.read_text())
    cart = Cartridge()
    tube = Cartridge(length=cart.length - cart.body_length + d["crossed"]["tube"]["length_m"])
    nu = cart.material.nu
    m_out, m_in = d["weibull_moduli"]["outer"], d["weibull_moduli"]["inner"]
    rows = []
    for case in d["crossed"]["cases"]:
        F, mu = case["force_N"], case["friction"]
        kw = dict(weibull_modulus_outer=m_out, weibull_modulus_inner=m_in)
        new = contact_stresses(F, mu * F, cartridge=tube, **kw)
        body = contact_stresses(F, mu * F, **kw)
        ccx = _calculix(d, mu) if F == 45.0 else None
        row = {"case": f"crossed {F:g} N, mu {mu:g}", "force_N": F, "friction": mu,
               "a_m": case["a_m"], "hertz_edge_MPa": case["hertz_edge_Pa"] / 1e6,
               "bending_at_rim_MPa": {"old": case["model"]["outer_bending_Pa"] / 1e6,
                                      "new": float(new.outer_bending_Pa) / 1e6,
                                      "new_body": float(body.outer_bending_Pa) / 1e6,
                                      "fem_implied": (case["fem_converged"]["outer_sigma1_Pa"]
                                                      - case["hertz_edge_Pa"]) / 1e6},
               **_row(case["model"], new, body, case["fem_converged"], ccx)}
        rows.append(row)
    par = d["parallel"]
    for case in par["cases"]:
        kw = dict(geometry="parallel", contact_length=par["contact_length_m"],
                  ring_support=case["support"], weibull_modulus_outer=m_out,
                  weibull_modulus_inner=m_in)
        new = contact_stresses(par["force_N"], 0.0, cartridge=tube, **kw)
        body = contact_stresses(par["force_N"], 0.0, **kw)
        rows.append({"case": f"parallel {par['force_N']:g} N over "
                             f"{par['contact_length_m'] * 1e3:g} mm, {case['support']}",
                     "force_N": par["force_N"], "friction": 0.0,
                     **_row(case["model"], new, body, case["fem_converged"])})
    # the table
    head = f"{'case':32s}" + "".join(f" | {name:>26s}" for name, *_ in KEYS)
    print("old / new / FEM (new/FEM); * = target met (sigma1 10 %, area 25 %)")
    print(head)
    for r in rows:
        cells = []
        for name, *_ in KEYS:
            e = r[name]
            fmt = "{:.4g}"
            cells.append(f"{fmt.format(e['old'])}{'*' if e['old_met'] else ' '}/"
                         f"{fmt.format(e['new'])}{'*' if e['new_met'] else ' '}/"
                         f"{fmt.format(e['fem'])} ({e['new_ratio']:.2f})")
        print(f"{r['case']:32s}" + "".join(f" | {c:>26s}" for c in cells))
        if "calculix" in r["inner_sigma1"]:
            cells = [f"CalculiX {r[n]['calculix']:.4g} (new {r[n]['new_ratio_calculix']:.2f},"
                     f" old {r[n]['old_ratio_calculix']:.2f})" for n, *_ in KEYS]
            print(f"{'':32s}" + "".join(f" | {c:>26s}" for c in cells))
    met = {who: {name: int(sum(r[name][f"{who}_met"] for r in rows)) for name, *_ in KEYS}
           for who in ("old", "new", "new_body")}
    print(f"targets met of {len(rows)}: old {met['old']}, new {met['new']}, "
          f"new_body {met['new_body']}")
    sens = _sensitivity(cart, nu, d)
    cost = _cost(cart, nu)
    print("sensitivity (inner sigma1 MPa / rim axial bending MPa):")
    for r in sens["crossed"]:
        print(f"  {r['force_N']:5g} N: " + ", ".join(
            f"{k} {v['inner_sigma1_MPa']:.2f} / {v['rim_axial_MPa']:.2f} "
            + (f"(A_in {v['inner_area_mm2']:.3f})" if "inner_area_mm2" in v else "")
            for k, v in r.items() if k != "force_N"))
    for k, v in sens["parallel"].items():
        print(f"  parallel {k}: inner {v['inner_sigma1_MPa']:.2f}, "
              f"outer {v['outer_sigma1_MPa']:.2f} MPa, A_in {v['inner_area_mm2']:.2f}, A_out {v['outer_area_mm2']:.1f} mm2")
    print("cost: " + ", ".join(f"{k} {v:.3f}" for k, v in cost.items()))
    out = {"command": "python benches/stress_cylinder_check.py",
           "date": time.strftime("%Y-%m-%d %H:%M:%S"),
           "machine": {"platform": platform.platform(), "python": platform.python_version()},
           "fem_source": "docs/data/stress_verification.json (fem_converged; calculix level 1)",
           "targets": {"sigma1": SIGMA_TOL, "effective_area": AREA_TOL},
           "rows": rows, "targets_met": met, "sensitivity": sens, "cost_s": cost}
    Path(args.json).write_text(json.dumps(out, indent=1, default=lambda o: bool(o)
                                          if isinstance(o, np.bool_) else float(o)) + "\n")
    print(f"wrote {args.json}")


def markdown(res: dict[str, Any]) -> None:
    """The model columns of docs/stress-verification.md (old / new against the FEM)."""
    print("| F (N) | μ | outer σ1 old / new / FEM | inner σ1 old / new / FEM | "
          "A_out old / new / FEM (mm²) | A_in old / new / FEM (mm²) |")
    print("|---|---|---|---|---|---|")
    for r in res["rows"]:
        cells = []
        for name, *_ in KEYS:
            e = r[name]
            f = "{:.3g}" if "area" in name else "{:.1f}"
            ratio = f"{100 * (e['new_ratio'] - 1):+.0f} %"
            cells.append(f"{f.format(e['old'])} / **{f.format(e['new'])}** / "
                         f"{f.format(e['fem'])} ({ratio})")
        head = (f"{r['force_N']:g} | {r['friction']:g}" if r["case"].startswith("crossed")
                else f"{r['case']} |")
        print(f"| {head} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
