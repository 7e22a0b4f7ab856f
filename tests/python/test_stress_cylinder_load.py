"""demfem.stress.cylinder_load: the cylindrical wall under a local radial load, against closed
forms (the harmonics' plate, ring, beam and axisymmetric limits; a band load around the tube;
a diametral pair of line loads along a long tube = the ring; the free tube's beam moment;
Timoshenko's thick-plate equivalent radius), convergence in the number of terms and of the
tables, and the verification against the stored resolved FEM (docs/data/
stress_verification.json) that benches/stress_cylinder_check.py tabulates."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import j1

from demfem.cartridge import Cartridge
from demfem.errors import InvalidParameterError
from demfem.stress import contact_stresses
from demfem.stress import cylinder_load as cl
from demfem.stress.ring import ring_surface_stresses

R, T, E, NU = 5.25e-3, 1.1e-3, 45e9, 0.22
D = E * T**3 / (12 * (1 - NU * NU))
FEM_FILE = Path(__file__).resolve().parents[2] / "docs" / "data" / "stress_verification.json"


def _compliance(lam: float, n: float) -> float:
    return float(np.linalg.inv(cl.mode_stiffness(lam, n, R, T, E, NU))[2, 2])


def test_harmonics_have_the_plate_ring_beam_and_axisymmetric_limits():
    K = cl.mode_stiffness(np.array([100.0, 2e3]), np.array([0, 7]), R, T, E, NU)
    assert np.allclose(K, np.swapaxes(K, -1, -2))
    # axisymmetric (n = 0, N_x = 0): D λ⁴ + E t/R², exactly
    lam = 2.0 / math.sqrt(R * T)
    assert _compliance(lam, 0) == pytest.approx(1 / (D * lam**4 + E * T / R**2), rel=1e-12)
    # the ring (λ → 0, n ≥ 2): R⁴/(D (n² − 1)²) — Donnell would give n⁴ (the O(t²/R²) rest
    # is Sanders' own: 1 + t²/(12 R²))
    for n in (2, 3, 5):
        assert _compliance(1e-4 / R, n) == pytest.approx(
            R**4 / (D * (n * n - 1) ** 2) * (1 + T * T / (12 * R * R)), rel=1e-4)
    # the beam (n = 1, λ → 0): a load q cos θ is q π R per length on E I = E π R³ t
    lam = 1e-3 / R
    assert _compliance(lam, 1) == pytest.approx(1 / (E * T * R * R * lam**4), rel=1e-2)
    # the plate (k R ≫ 1): 1/(D k⁴)
    k = 3000 / R
    for ang in (0.0, 0.5, 1.0):
        assert _compliance(k * math.cos(ang) + 1e-9, k * math.sin(ang) * R) == pytest.approx(
            1 / (D * k**4), rel=1e-2)


def test_layer_correction_limits():
    nu = NU
    s = np.array([1e-4, 0.0099, 0.0101, 0.5, 5.0, 50.0, 400.0])
    c = cl.layer_correction(s, nu)
    # finite at s → 0: 4(1+ν)/5, (1+ν)/5 (the series meets the closed form at s = 0.01)
    assert c["loaded_sum"][0] == pytest.approx(0.8 * (1 + nu), rel=1e-6)
    assert c["far_sum"][0] == pytest.approx(0.2 * (1 + nu), rel=1e-6)
    assert c["loaded_sum"][1] == pytest.approx(c["loaded_sum"][2], rel=1e-5)
    assert c["far_sum"][1] == pytest.approx(c["far_sum"][2], rel=1e-5)
    # the layer itself (correction + thin plate + half-space) against its closed form
    x = 0.5
    sh2 = math.sinh(x) ** 2
    layer_top = c["loaded_sum"][3] - (1 + 2 * nu) - 6 * (1 + nu) / x**2
    assert layer_top == pytest.approx(-((1 + 2 * nu) * sh2 + x * x) / (sh2 - x * x), rel=1e-10)
    layer_far = c["far_sum"][3] + 6 * (1 + nu) / x**2
    assert layer_far == pytest.approx(2 * (1 + nu) * x * math.sinh(x) / (sh2 - x * x), rel=1e-10)
    # s → ∞: the layer is the half-space on the loaded face, nothing on the other: the
    # correction cancels the thin plate, ∓6(1 ± ν)/s²
    big = s[-2:]
    assert np.allclose(c["loaded_sum"][-2:], 6 * (1 + nu) / big**2, rtol=1e-6)
    assert np.allclose(c["far_sum"][-2:], -6 * (1 + nu) / big**2, rtol=1e-6)
    assert np.allclose(c["loaded_diff"][-2:], -6 * (1 - nu) / big**2, rtol=1e-6)
    assert np.allclose(c["far_diff"][-2:], 6 * (1 - nu) / big**2, rtol=1e-6)
    with pytest.raises(InvalidParameterError, match="s"):
        cl.layer_correction(-1.0, nu)


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
@pytest.mark.parametrize("c_over_t", [0.05, 0.3, 1.0, 1.5])
def test_thick_correction_is_timoshenkos_equivalent_radius(c_over_t):
    """At the centre of the unloaded face a uniform load of radius c on a thick plate bends it
    like a thin plate loaded over b' = √(1.6 c² + t²) − 0.675 t (Timoshenko & Woinowsky-Krieger
    §19, from Woinowsky-Krieger's thick-plate theory): the moment changes by
    (1 + ν) P/(4π) ln(c/b'). The elastic-layer correction, integrated over the load's Hankel
    transform, gives the same radius to 1.5 %."""
    c, P = c_over_t * T, 1.0

    def f(k: float) -> float:
        x = k * c
        return (cl.layer_correction(k * T, NU)["far_sum"] * P / (2 * math.pi)
                * (2 * j1(x) / x if x > 1e-8 else 1.0) * k)

    edges = np.concatenate([[0.0], np.geomspace(1e-2 / T, 200 / T, 200)])
    dsum = sum(quad(f, a, b, limit=100)[0] for a, b in zip(edges[:-1], edges[1:]))
    d_moment = dsum * T * T / 12          # σ_r + σ_θ = 12 M / t² at the centre
    b_layer = c * math.exp(-4 * math.pi * d_moment / ((1 + NU) * P))
    b_timoshenko = math.sqrt(1.6 * c * c + T * T) - 0.675 * T
    assert b_layer == pytest.approx(b_timoshenko, rel=0.015)


def test_a_band_load_around_the_tube_is_the_beam_on_an_elastic_foundation():
    """Uniform q over |x| < h all around (n = 0): Hetényi's beam on an elastic foundation,
    k = E t/R², β⁴ = 3(1 − ν²)/(R t)²: M(0) = q e^{−βh} sin(βh)/(2β²), w(0) = (q/k)(1 −
    e^{−βh} cos βh), N_θ = −E t w/R, N_x = 0."""
    h, q, Lc = 0.5e-3, 1e5, 0.2
    beta = (3 * (1 - NU**2) / (R * T) ** 2) ** 0.25
    shell = cl.CylinderShell(R, T, E, NU, Lc)
    fld = cl.cylinder_load_field(shell, q * 2 * h * 2 * math.pi * R,
                                 lambda kx, ky: cl.rectangle_spectrum(kx, ky, h, 0.0) * (ky == 0),
                                 support="ends", thick=False, curved=False, n_max=0, m_max=4000)
    i, o = (fld.surface_stresses(0.0, 0.0, s) for s in ("inner", "outer"))
    moment = float(i["xx"] - o["xx"]) * T * T / 12
    w = q * R * R / (E * T) * (1 - math.exp(-beta * h) * math.cos(beta * h))
    assert moment == pytest.approx(q * math.exp(-beta * h) * math.sin(beta * h) / (2 * beta**2),
                                   rel=1e-5)
    assert float(i["tt"] + o["tt"]) * T / 2 == pytest.approx(-E * T * w / R, rel=1e-8)
    assert abs(float(i["xx"] + o["xx"])) < 1e-9 * float(i["xx"])


def test_a_long_diametral_pair_of_line_loads_is_the_ring():
    """W per length along the whole of a long tube, held by its mirror opposite: far from the
    ends the plane ring of ring.py (M = W R/π at the load, −W R(1/2 − 1/π) at the side; thin,
    no curved-bar factor, no thick-plate correction, the series cut at n = 600)."""
    Lc = 0.4
    shell = cl.CylinderShell(R, T, E, NU, Lc)
    fld = cl.cylinder_load_field(shell, Lc, lambda kx, ky: cl.line_spectrum(kx, ky, Lc),
                                 support="opposite", thick=False, curved=False, n_max=600,
                                 m_max=40)
    th = np.array([0.0, math.pi / 4, math.pi / 2])
    ring = ring_surface_stresses(th, 1.0, R, T, "opposite", curved=False)
    for s in ("inner", "outer"):
        assert np.allclose(fld.surface_stresses(0.0, th, s)["tt"], ring[s], rtol=5e-3, atol=0)


@pytest.mark.parametrize("support,free,x", [("ends", None, 0.012), ("ends", None, 0.02),
                                            ("inertia", 0.06, 0.012), ("inertia", 0.06, 0.02)])
def test_the_tube_carries_the_beam_moment_of_its_support(support, free, x):
    """Equilibrium of the n = 1 harmonics: away from the load the axial force resultants make
    the bending moment of the beam — simply supported at ±L_c/2, F(L_c/2 − x)/2, or free and
    held by its d'Alembert force, F(L_f/2 − x)²/(2 L_f) (F L_f/8 at the load)."""
    F, Lc = 10.0, 0.06
    shell = cl.CylinderShell(R, T, E, NU, Lc)
    fld = cl.cylinder_load_field(shell, F, lambda kx, ky: cl.hertz_disc_spectrum(kx, ky, 1e-4),
                                 support=support, free_length=free)
    th = np.linspace(-math.pi, math.pi, 721)
    nx = T * (fld.surface_stresses(x, th, "outer")["xx"]
              + fld.surface_stresses(x, th, "inner")["xx"]) / 2
    moment = -np.trapezoid(nx * np.cos(th), th) * R * R
    expected = F * (Lc / 2 - x) / 2 if support == "ends" else F * (free / 2 - x) ** 2 / (2 * free)
    assert moment == pytest.approx(expected, rel=0.015)


def test_series_and_tables_converge():
    shell = cl.CylinderShell(R, T, E, NU, 0.109)
    a = 0.2e-3
    spec = lambda kx, ky: cl.hertz_disc_spectrum(kx, ky, a)  # noqa: E731
    vals = [cl.cylinder_load_field(shell, 45.0, spec, free_length=0.0545, k_max=k / T)
            .surface_stresses(np.array([0.0, 0.0]), np.array([0.0, a / (R + T / 2)]),
                              "inner")["s1"] for k in (16.0, 24.0, 36.0)]
    assert np.allclose(vals[1], vals[2], rtol=1e-3) and np.allclose(vals[0], vals[2], rtol=3e-3)
    # the table against the series, at a node and between nodes
    tab = cl.point_load_table(R, T, NU, 0.0545, 10.0, 6.0)
    g = tab["c_over_t"]
    for u in (g[15], 0.5 * (g[15] + g[16]), 0.5 * (g[20] + g[21])):
        fld = cl.cylinder_load_field(shell, 1.0, lambda kx, ky: cl.hertz_disc_spectrum(
            kx, ky, u * T), free_length=0.0545)
        direct = float(fld.surface_stresses(0.0, 0.0, "inner")["s1"]) * T * T
        assert float(np.interp(u, g, tab["inner_peak"])) == pytest.approx(direct, rel=5e-3)
        rim = float(fld.surface_stresses(u * T, 0.0, "outer")["xx"]) * T * T
        assert float(np.interp(u, g, tab["rim_axial"][:, 0])) == pytest.approx(rim, rel=1e-2)
    # a point load on the thick wall is finite, and a contact of radius a ≪ t hardly matters
    assert np.all(np.isfinite(tab["inner_peak"]))
    assert tab["inner_peak"][0] == pytest.approx(tab["inner_peak"][5], rel=2e-3)
    assert np.all(np.diff(tab["inner_peak"]) <= 1e-9)   # a larger patch bends less
    # the effective area on a finer grid: the same to 1 %
    fld = cl.cylinder_load_field(shell, 1.0, lambda kx, ky: cl.hertz_disc_spectrum(
        kx, ky, 0.0), free_length=0.0545)
    x = np.linspace(0.0, 4 * T, 321)
    th = np.linspace(0.0, 4 * T / R, 321)
    p, area, _ = cl._peak_area(fld.surface_stresses(x, th, "inner", grid=True)["s1"], x, th,
                               R - T / 2, 10.0)
    assert area / T**2 == pytest.approx(tab["inner_area"][0], rel=1e-2)


def test_bad_input_names_the_field():
    shell = cl.CylinderShell(R, T, E, NU, 0.06)
    spec = lambda kx, ky: cl.hertz_disc_spectrum(kx, ky, 1e-4)  # noqa: E731
    for kwargs, field in (({"support": "glue"}, "support"), ({"free_length": 0.1}, "free_length"),
                          ({"k_max": -1.0}, "k_max"), ({"n_max": -1}, "n_max")):
        with pytest.raises(InvalidParameterError, match=field):
            cl.cylinder_load_field(shell, 1.0, spec, **kwargs)
    with pytest.raises(InvalidParameterError, match="force"):
        cl.cylinder_load_field(shell, 0.0, spec)
    with pytest.raises(InvalidParameterError, match="thickness"):
        cl.CylinderShell(R, 2 * R, E, NU, 0.06)
    with pytest.raises(InvalidParameterError, match="nu"):
        cl.CylinderShell(R, T, E, 0.6, 0.06)
    with pytest.raises(InvalidParameterError, match="surface"):
        cl.cylinder_load_field(shell, 1.0, spec).surface_stresses(0.0, 0.0, "middle")
    with pytest.raises(InvalidParameterError, match="support"):
        cl.line_load_profile(R, T, NU, 0.01, "ends", 0.05, 10.0, 6.0)
    with pytest.raises(InvalidParameterError, match="contact_length"):
        cl.line_load_profile(R, T, NU, 0.06, "opposite", 0.05, 10.0, 6.0)


def _fem():
    return json.loads(FEM_FILE.read_text())


def test_against_the_resolved_fem():
    """The verification (benches/stress_cylinder_check.py, docs/stress-verification.md): the
    model on the FEM's tube (30 mm, free) against the FEM's finest level — inner σ1 within 10 %
    in all 8 crossed cases and the parallel one; outer σ1 within 10 % except crossed 10 N
    without friction (+10.1 %); the FEM's inner effective area, which its linear tets
    underestimate (CalculiX gives 1.8 × at 45 N), within 25 % of CalculiX's."""
    d = _fem()
    ref = Cartridge()
    cart = Cartridge(length=ref.length - ref.body_length + d["crossed"]["tube"]["length_m"])
    assert cart.body_length == pytest.approx(0.03)
    misses = []
    for case in d["crossed"]["cases"]:
        F, mu = case["force_N"], case["friction"]
        r = contact_stresses(F, mu * F, cartridge=cart)
        fem = case["fem_converged"]
        assert float(r.inner_sigma1_max) == pytest.approx(fem["inner_sigma1_Pa"], rel=0.10)
        if abs(float(r.outer_sigma1_max) / fem["outer_sigma1_Pa"] - 1) > 0.10:
            misses.append((F, mu))
        if F == 45.0:
            ccx = d["calculix"]["results"][str(mu)]
            assert float(r.inner_sigma1_max) == pytest.approx(ccx["inner"]["sigma1_max_Pa"],
                                                              rel=0.10)
            assert float(r.inner_effective_area) == pytest.approx(
                ccx["inner"]["effective_area_m2"], rel=0.25)
    assert misses == [(10.0, 0.0)]
    par = d["parallel"]
    fem = par["cases"][0]["fem_converged"]
    r = contact_stresses(par["force_N"], 0.0, geometry="parallel",
                         contact_length=par["contact_length_m"], cartridge=cart)
    assert float(r.inner_sigma1_max) == pytest.approx(fem["inner_sigma1_Pa"], rel=0.10)
    assert float(r.outer_sigma1_max) == pytest.approx(fem["outer_sigma1_Pa"], rel=0.10)
    assert float(r.outer_effective_area) == pytest.approx(fem["outer_effective_area_m2"],
                                                          rel=0.25)


SIDE_FILE = FEM_FILE.parent / "stress_side_tension_check.json"


def test_the_side_tension_against_the_resolved_fem():
    """The outer tension away from the contact (the tube's sides; what the outer σ1 is once
    the flaw depth attenuates the contact term) against CalculiX C3D10 on the same tube
    (benches/stress_side_tension_check.py, docs/stress-verification.md): crossed 45 and 100 N,
    μ = 0, free 30 mm tube — ``outer_ring_Pa`` within 10 % (−4 %), its effective area
    (m = 6, normalised by its own peak) within 25 % (+1 %), the peak on the tube's flank
    (65–75° from the contact, within 2.5 mm of its plane); the default cartridge's 54.5 mm
    body (what assess uses) at 45 N; held by an equal contact opposite at 100 N (the side
    itself, 90°)."""
    d = json.loads(SIDE_FILE.read_text())
    ref = Cartridge()
    tube = Cartridge(length=ref.length - ref.body_length + 0.03)
    flaw = d["flaw_depth_m"]
    t, r_mid, nu = ref.wall_thickness, ref.body_mid_radius, ref.material.nu
    for case in d["cases"]:
        F = case["force_N"]
        fem = case["c3d10"]["side"]["calculix"]
        assert 65.0 < fem["theta_deg"] < 75.0 and fem["z_m"] < 2.5e-3
        r = contact_stresses(F, 0.0, cartridge=tube, flaw_depth=flaw)
        assert not bool(r.outer_from_contact)
        assert float(r.outer_sigma1_max) == float(r.outer_ring_Pa)
        assert float(r.outer_ring_Pa) == pytest.approx(fem["sigma1_Pa"], rel=0.10)
        assert float(r.outer_effective_area) == pytest.approx(fem["area_m2"], rel=0.25)
    lg = d["long_tube"]
    fem = lg["c3d10"]["side"]["calculix"]
    r = contact_stresses(lg["force_N"], 0.0, flaw_depth=flaw)
    assert not bool(r.outer_from_contact)
    assert float(r.outer_ring_Pa) == pytest.approx(fem["sigma1_Pa"], rel=0.10)
    assert float(r.outer_effective_area) == pytest.approx(fem["area_m2"], rel=0.25)
    opp = d["opposite"]
    fem = opp["c3d10"]["side"]["calculix"]
    assert abs(fem["theta_deg"] - 90.0) < 3.0
    shell = cl.CylinderShell(r_mid, t, E, nu, 0.06)
    a = opp["model_30mm"]["a_m"]
    fld = cl.cylinder_load_field(shell, opp["force_N"],
                                 lambda kx, ky: cl.hertz_disc_spectrum(kx, ky, a),
                                 support="opposite")
    x, th = cl._surface_grid(shell, 0.03, 4.0 * t)
    s1 = fld.surface_stresses(x, th, "outer", grid=True)["s1"]
    peak, area, k = cl._peak_area(s1, x, th, r_mid + 0.5 * t, 6.0)
    assert abs(math.degrees(th[k[1]]) - 90.0) < 3.0
    assert peak == pytest.approx(fem["sigma1_Pa"], rel=0.10)
    assert area == pytest.approx(fem["area_m2"], rel=0.25)
