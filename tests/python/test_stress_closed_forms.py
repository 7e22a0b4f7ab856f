"""The closed forms under demfem.stress against published solutions and independent derivations.

Hertz (Johnson, Contact Mechanics 1985), Hamilton 1983 (sliding spherical contact), Hamrock &
Brewe 1983 (elliptical contacts), McEwen 1949 (sliding line contact), Reissner's shallow shell
(Timoshenko & Woinowsky-Krieger), Roark (rings and curved bars). Each check compares the code
with a formula or a published number computed here, or with a second, independent route (the
projection integral against the explicit fields, quadrature of point-force solutions against
Hamilton's explicit equations), never the code against itself.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import kei

from demfem.contact import reissner_stiffness
from demfem.errors import InvalidParameterError
from demfem.stress import effective_area as ea
from demfem.stress import flaw_depth, hamilton, hertz, ring, shell, surface_field

NU = 0.22


# ---- Hertz ------------------------------------------------------------------------------------

def test_point_contact_of_two_spheres_follows_johnson():
    # two glass spheres R = 8 mm, E = 45 GPa, nu = 0.22, F = 10 N (Johnson §4.2)
    E, R, F = 45e9, 8e-3, 10.0
    e_star = E / (2 * (1 - NU**2))
    r_star = R / 2
    a = (3 * F * r_star / (4 * e_star)) ** (1 / 3)
    got = hertz.point_contact(F, r_star, e_star)
    assert got["a"] == pytest.approx(a, rel=1e-12)
    assert got["p0"] == pytest.approx(3 * F / (2 * math.pi * a * a), rel=1e-12)
    assert got["delta"] == pytest.approx(a * a / r_star, rel=1e-12)
    assert hertz.contact_modulus(E, NU) == pytest.approx(e_star, rel=1e-14)
    # the same contact as an "ellipse" of equal curvatures 1/(2R*)
    ell = hertz.elliptical_contact(F, 1 / (2 * r_star), 1 / (2 * r_star), e_star)
    assert ell["a"] == pytest.approx(a, rel=1e-12) and ell["b"] == pytest.approx(a, rel=1e-12)


def test_hertz_surface_tension_at_the_contact_edge():
    # sigma_r = -sigma_theta = (1 - 2 nu)/3 p0 a^2/r^2 outside; -(1 + 2 nu)/2 p0 at the centre
    got = hertz.circular_surface_stresses([1.0, 2.0, 0.0, 0.0], [0.0, 0.0, 0.0, 3.0], NU)
    edge = (1 - 2 * NU) / 3
    assert got["xx"][0] == pytest.approx(edge, rel=1e-12)
    assert got["yy"][0] == pytest.approx(-edge, rel=1e-12)
    assert got["xx"][1] == pytest.approx(edge / 4, rel=1e-12)
    assert got["xx"][2] == pytest.approx(-(1 + 2 * NU) / 2, rel=1e-9)
    assert got["yy"][3] == pytest.approx(edge / 9, rel=1e-12)   # radial along y at r = 3a


def test_elliptical_contact_reduces_to_circle_and_matches_hamrock_brewe():
    e_star = 25e9
    # nearly equal curvatures -> circle
    c = hertz.elliptical_contact(5.0, 100.0, 100.0 * (1 + 1e-7), e_star)
    circ = hertz.point_contact(5.0, 1 / 200.0, e_star)
    assert c["a"] == pytest.approx(circ["a"], rel=1e-6)
    assert c["b"] == pytest.approx(circ["a"], rel=1e-6)
    # Hamrock & Brewe (1983) simplified formulas, within 3 % over their fit's core range
    for alpha_r in (2.0, 5.0, 10.0, 20.0):
        rx = 2e-3
        ry = alpha_r * rx
        A, B = 1 / (2 * ry), 1 / (2 * rx)
        got = hertz.elliptical_contact(12.0, A, B, e_star)
        k = 1.0339 * alpha_r**0.6360
        e_bar = 1.0003 + 0.5968 / alpha_r
        R = 1 / (1 / rx + 1 / ry)
        e_prime = 2 * e_star
        ay = (6 * k * k * e_bar * 12.0 * R / (math.pi * e_prime)) ** (1 / 3)
        ax = (6 * e_bar * 12.0 * R / (math.pi * k * e_prime)) ** (1 / 3)
        assert got["a"] == pytest.approx(ay, rel=0.03), alpha_r
        assert got["b"] == pytest.approx(ax, rel=0.03), alpha_r


def test_elliptical_contact_gives_the_curvatures_back():
    """Independent check of the eccentricity: the surface displacement of the ellipsoidal
    pressure (Boussinesq, integrated numerically) must be δ − A x² − B y² with the B/A asked
    for (Johnson §3.5), also far beyond the range of the Hamrock–Brewe fit."""
    def uz(px, py, a, b):   # (1/π) ∫∫ √(1 − x²/a² − y²/b²) / |P − X| dA, rays from P
        def ray(th):
            c, s = math.cos(th), math.sin(th)
            c2 = c * c / a**2 + s * s / b**2
            c1 = -2 * (px * c / a**2 + py * s / b**2)
            c0 = 1 - px * px / a**2 - py * py / b**2
            r2 = (c1 + math.sqrt(c1 * c1 + 4 * c2 * c0)) / (2 * c2)
            return quad(lambda r: math.sqrt(max(c0 + c1 * r - c2 * r * r, 0)), 0, r2)[0]
        return quad(ray, 0, 2 * math.pi, limit=200)[0] / math.pi

    for ratio in (5.0, 80.0):
        b = math.sqrt(1 - hertz.ellipse_eccentricity_squared(ratio))
        h = 0.05
        u0 = uz(0, 0, 1.0, b)
        A = (u0 - uz(h, 0, 1.0, b)) / h**2
        B = (u0 - uz(0, h * b, 1.0, b)) / (h * b) ** 2
        assert B / A == pytest.approx(ratio, rel=1e-6)


def test_crossed_cylinders_curvatures():
    R = 5.8e-3
    A, B = hertz.crossed_cylinder_curvatures(R, R, 90.0)
    assert A == pytest.approx(1 / (2 * R)) and B == pytest.approx(1 / (2 * R))
    A, B = hertz.crossed_cylinder_curvatures(R, R, 45.0)
    c = math.cos(math.radians(45.0))
    assert A == pytest.approx((1 - c) / (2 * R), rel=1e-12)
    assert B == pytest.approx((1 + c) / (2 * R), rel=1e-12)
    A, B = hertz.crossed_cylinder_curvatures(R, 1e-3, 90.0)   # a cartridge across a 1 mm edge
    assert (A, B) == pytest.approx((1 / (2 * R), 1 / (2 * 1e-3)), rel=1e-12)
    for bad in (0.0, 90.5, math.nan):
        with pytest.raises(InvalidParameterError, match="crossing_angle_deg"):
            hertz.crossed_cylinder_curvatures(R, R, bad)


@pytest.mark.parametrize("beta", [0.9, 0.5, 0.2])
def test_elliptical_edge_tension_closed_forms_against_the_projection_integral(beta):
    major, minor = hertz.elliptical_axis_edge_stresses(beta, NU)
    f = surface_field.elliptical_surface_stresses([1.0, 0.0], [0.0, beta], beta, NU, 512,
                                                  on_edge=True)
    assert f["normal_xx"][0] == pytest.approx(major, abs=1e-6)
    assert f["normal_yy"][1] == pytest.approx(minor, abs=1e-6)
    # the largest edge tension of the normal load is at the ends of the major axis
    phi = np.linspace(0, 2 * math.pi, 721)
    g = surface_field.elliptical_surface_stresses(np.cos(phi), beta * np.sin(phi), beta, NU, 512,
                                                  on_edge=True)
    s1 = surface_field.principal_in_plane(g["normal_xx"], g["normal_yy"], g["normal_xy"])[0]
    assert s1.max() == pytest.approx(major, abs=1e-6)


def test_elliptical_edge_tension_tends_to_the_circle():
    major, minor = hertz.elliptical_axis_edge_stresses(1 - 1e-9, NU)
    assert major == pytest.approx((1 - 2 * NU) / 3, rel=1e-6)
    assert minor == pytest.approx((1 - 2 * NU) / 3, rel=1e-6)


def test_projection_integral_reproduces_the_circular_fields():
    rng = np.random.default_rng(3)
    pts = rng.uniform(-3, 3, (300, 2))
    f = surface_field.elliptical_surface_stresses(pts[:, 0], pts[:, 1], 1.0, NU, 4096)
    n = hertz.circular_surface_stresses(pts[:, 0], pts[:, 1], NU)
    t = hamilton.sliding_surface_stresses(pts[:, 0], pts[:, 1], NU)
    for k in ("xx", "yy", "xy"):
        assert np.max(np.abs(f["normal_" + k] - n[k])) < 2e-3
        assert np.max(np.abs(f["tx_" + k] - t[k])) < 2e-3


def test_hertz_subsurface_on_the_axis_and_the_surface():
    z = np.array([0.1, 0.48, 1.0, 2.0])
    got = hertz.circular_subsurface_stresses(0.0, 0.0, z, 0.3)
    # Johnson §3.4: sigma_z = -p0/(1 + z²/a²), sigma_r = -(1+nu)(1 - z/a atan(a/z)) + 1/(2(1+z²/a²))
    assert got["zz"] == pytest.approx(-1 / (1 + z * z), rel=1e-12)
    sr = -(1.3) * (1 - z * np.arctan(1 / z)) + 0.5 / (1 + z * z)
    assert got["xx"] == pytest.approx(sr, rel=1e-12)
    # off-axis formula continuous onto the axis
    near = hertz.circular_subsurface_stresses(1e-4, 0.0, z, 0.3)
    assert near["xx"] == pytest.approx(sr, abs=1e-6)
    # the classical maximum shear 0.31 p0 at 0.48 a below the centre (nu = 0.3)
    zz = np.linspace(0.2, 0.8, 601)
    ax = hertz.circular_subsurface_stresses(0.0, 0.0, zz, 0.3)
    tau = 0.5 * (ax["xx"] - ax["zz"])
    assert tau.max() == pytest.approx(0.31, abs=0.005)
    assert zz[np.argmax(tau)] == pytest.approx(0.48, abs=0.01)
    # the surface limit outside the contact: (1 - 2 nu)/3 a²/r²
    s = hertz.circular_subsurface_stresses(-1.5, 0.0, 1e-12, NU)
    assert s["xx"] == pytest.approx((1 - 2 * NU) / 3 / 2.25, rel=1e-9)


def test_line_contact_and_its_sliding_field():
    # Johnson §4.3: b = sqrt(4 F' R*/(pi E*)), p0 = 2 F'/(pi b)
    got = hertz.line_contact(900.0, 2.9e-3, 23.6e9)
    b = math.sqrt(4 * 900.0 * 2.9e-3 / (math.pi * 23.6e9))
    assert got["b"] == pytest.approx(b, rel=1e-12)
    assert got["p0"] == pytest.approx(2 * 900.0 / (math.pi * b), rel=1e-12)
    # McEwen on the surface: normal -sqrt(1 - x²) inside, 0 outside; tangential -2x inside,
    # -2(x - sgn(x) sqrt(x² - 1)) outside: tension 2 at the trailing edge x = -1
    x = np.array([-3.0, -1.0, -0.5, 0.5, 2.0])
    s = hertz.line_sliding_stresses(x, 0.0)
    assert s["normal_xx"] == pytest.approx([0, 0, -math.sqrt(0.75), -math.sqrt(0.75), 0],
                                           abs=1e-12)
    t_out = -2 * (x - np.sign(x) * np.sqrt(np.maximum(x * x - 1, 0)))
    t_in = -2 * x
    assert s["tangential_xx"] == pytest.approx(np.where(np.abs(x) > 1, t_out, t_in), abs=1e-12)
    assert hamilton.line_trailing_edge_tension(0.2) == pytest.approx(0.4)


# ---- Hamilton -----------------------------------------------------------------------------------

@pytest.mark.parametrize("mu", [0.1, 0.2])
def test_hamilton_maximum_at_the_trailing_edge(mu):
    nu = 0.3
    expected = (1 - 2 * nu) / 3 + (4 + nu) * math.pi * mu / 8   # Hamilton (1983)
    assert hamilton.trailing_edge_tension(nu, mu) == pytest.approx(expected, rel=1e-14)
    # the explicit surface field peaks there, and nowhere higher
    r, phi = np.meshgrid(np.concatenate([np.linspace(0.0, 1.0, 201), np.geomspace(1, 4, 200)]),
                         np.linspace(0, 2 * math.pi, 721))
    x, y = r * np.cos(phi), r * np.sin(phi)
    f = hamilton.hamilton_surface_stresses(x, y, nu, mu)
    s1 = surface_field.principal_in_plane(f["xx"], f["yy"], f["xy"])[0]
    assert s1.max() == pytest.approx(expected, rel=1e-9)
    k = np.unravel_index(np.argmax(s1), s1.shape)
    assert (x[k], y[k]) == pytest.approx((-1.0, 0.0), abs=1e-9)


def test_hamilton_interior_values_and_the_frictionless_limit():
    x, y = np.array([0.3, -0.5, 0.1]), np.array([0.2, 0.4, -0.7])
    t = hamilton.sliding_surface_stresses(x, y, NU)
    # Hamilton (1983), inside the contact, per mu p0/a
    assert t["xx"] == pytest.approx(-math.pi * (4 + NU) * x / 8, rel=1e-12)
    assert t["yy"] == pytest.approx(-3 * math.pi * NU * x / 8, rel=1e-12)
    assert t["xy"] == pytest.approx(-math.pi * (2 - NU) * y / 8, rel=1e-12)
    # mu = 0: Hamilton's field is Hertz's
    pts = np.random.default_rng(1).uniform(-2, 2, (50, 2))
    h = hamilton.hamilton_surface_stresses(pts[:, 0], pts[:, 1], NU, 0.0)
    n = hertz.circular_surface_stresses(pts[:, 0], pts[:, 1], NU)
    for k in ("xx", "yy", "xy"):
        assert h[k] == pytest.approx(n[k], abs=1e-15)


def test_cerruti_quadrature_against_hamilton_explicit_normal_field(monkeypatch):
    """The same quadrature with Boussinesq's kernel reproduces Hamilton's explicit normal-load
    field beneath the contact: it validates the quadrature the tangential profile relies on."""
    def boussinesq(x, y, z):
        r2 = x * x + y * y
        rho = np.sqrt(r2 + z * z)
        xx = ((1 - 2 * NU) / r2 * ((1 - z / rho) * (x * x - y * y) / r2 + z * y * y / rho**3)
              - 3 * z * x * x / rho**5) / (2 * math.pi)
        return xx, np.zeros_like(xx)

    r = np.array([1.0, 1.02, 1.1, 1.3, 2.0])
    z = np.array([1e-3, 1e-3, 0.02, 0.1, 0.5])
    monkeypatch.setattr(hamilton, "_cerruti_parts", boussinesq)
    got, _ = hamilton.tangential_depth_parts(r, z)
    monkeypatch.undo()
    want = hertz.circular_subsurface_stresses(-r, 0.0, z, NU)["xx"]
    assert got == pytest.approx(want, abs=1e-6)
    # the tangential profile tends to the explicit surface field away from the edge
    assert hamilton.tangential_depth_profile(1.3, 1e-6, NU) == pytest.approx(
        float(hamilton.sliding_surface_stresses(-1.3, 0.0, NU)["xx"]), rel=1e-3)


def test_cerruti_point_force_surface_limit():
    x, y = np.array([-0.5, 0.3]), np.array([0.2, -0.4])
    r = np.hypot(x, y)
    want = -((1 - 2 * NU) * x / r**3 + 3 * NU * x**3 / r**5) / math.pi
    assert hamilton.cerruti_stress_xx(x, y, 1e-12, NU) == pytest.approx(want, rel=1e-9)


def test_shipped_tangential_flaw_table_matches_fresh_quadrature():
    t0, t1 = flaw_depth._circle_tangential_parts()
    d = flaw_depth.DEPTH_RATIOS
    offs = flaw_depth._R_OFFSETS
    for i, j in ((3, 0), (15, 5), (22, 9)):
        theta = flaw_depth._THETA
        p0, p1 = hamilton.tangential_depth_parts(1 + d[i] * offs[j] + 0 * theta,
                                                 d[i] * np.sin(theta))
        w = 2 / math.pi * flaw_depth._THETA_W
        assert t0[i, j] == pytest.approx(float(p0 @ w), rel=1e-6, abs=1e-9)
        assert t1[i, j] == pytest.approx(float(p1 @ w), rel=1e-6, abs=1e-9)


def test_flaw_depth_equivalent_stress():
    # a uniform field is felt whole; the weight is Frank & Lawn's 2/pi / sqrt(c² - z²)
    assert flaw_depth.equivalent_stress(lambda z: np.ones_like(z), 1e-5) == pytest.approx(1.0)
    lin = flaw_depth.equivalent_stress(lambda z: 1 - z / 2e-5, 1e-5)
    assert lin == pytest.approx(1 - 2 / math.pi / 2, rel=1e-6)   # (2/pi) int z/sqrt(c²-z²) = 2c/pi
    mus = tuple(ea.mu_grid(1.0))
    table = flaw_depth.circle_flaw_table(NU, mus)
    surface = hamilton.trailing_edge_tension(NU, np.array(mus))
    ratio = table / surface[None, :]
    assert np.all(ratio <= 1 + 1e-9) and np.all(np.diff(ratio[:, 0]) < 0)   # deeper: less
    assert ratio[0, 0] > 0.99            # c_f = 1e-5 a: the surface value
    print("flaw factor (nu = 0.22, mu = 0) at c_f/a:", ", ".join(
        f"{d:.2g}: {v:.3f}" for d, v in zip(flaw_depth.DEPTH_RATIOS[10::3], ratio[10::3, 0])))


# ---- the shell and the ring ----------------------------------------------------------------------

def test_reissner_point_load_deflection():
    E, t, R, P = 45e9, 1.1e-3, 5.25e-3, 10.0
    ell = shell.characteristic_length(R, t, NU)
    D = E * t**3 / (12 * (1 - NU**2))
    w0 = float(shell.point_load_deflection(0.0, P, R, t, E, NU))
    assert w0 == pytest.approx(P * ell**2 / (8 * D), rel=1e-12)   # kei(0) = -pi/4
    assert w0 == pytest.approx(P / reissner_stiffness(E, NU, t, R), rel=1e-12)
    assert float(shell.point_load_deflection(ell, P, R, t, E, NU)) == pytest.approx(
        -P * ell**2 / (2 * math.pi * D) * kei(1.0), rel=1e-12)


def test_hertz_patch_centre_against_quadrature_of_the_point_solution():
    """The moment sum at the centre of an axisymmetric load is the point solution's moment
    sum averaged over the load (reciprocity of the Laplacian): integrate Reissner's point
    field over the Hertz pressure and compare with the closed form ln(l/c) + 4/3 - gamma."""
    for x_c in (0.02, 0.1):
        def integrand(s):
            f = shell.point_load_surface_stresses(np.array([s * x_c]), NU)
            return 0.5 * (f["inner_r"][0] + f["inner_theta"][0]) * 3 * s * math.sqrt(1 - s * s)

        numeric = quad(integrand, 0, 1, limit=200, points=[0.5])[0]
        inner, _ = shell.hertz_patch_centre_coefficients(1 / x_c, NU)
        assert inner == pytest.approx(numeric, rel=2e-3 + 3 * x_c**2), x_c
        field = shell.hertz_patch_surface_stresses(np.array([0.0, 1e-6 * x_c, 0.01 * x_c]), x_c,
                                                   NU)
        assert field["inner_r"] == pytest.approx(inner, rel=1e-3)
    # outside the patch: the point field plus (1 - nu) P <rho²>/(8 pi r²), <rho²> = 2c²/5
    x = np.array([0.3, 0.6])
    patch = shell.hertz_patch_surface_stresses(x, 0.1, NU)
    point = shell.point_load_surface_stresses(x, NU)
    dm = (1 - NU) * 0.4 * 0.1**2 / (8 * math.pi * x**2)
    assert patch["outer_r"] - point["outer_r"] == pytest.approx(-6 * dm, rel=1e-6)
    assert patch["inner_theta"] - point["inner_theta"] == pytest.approx(-6 * dm, rel=1e-6)


def test_ring_under_a_diametral_line_load_follows_roark():
    m, n = ring.ring_resultants(np.array([0.0, math.pi / 2, math.pi]), "opposite")
    assert m == pytest.approx([1 / math.pi, 1 / math.pi - 0.5, 1 / math.pi], rel=1e-12)
    assert n == pytest.approx([0.0, -0.5, 0.0], abs=1e-12)
    # reacted by the ring's inertia (Roark Table 9.2 case 15): 3WR/(4 pi) under the load
    m, n = ring.ring_resultants(np.array([0.0, math.pi]), "inertia")
    assert m == pytest.approx([3 / (4 * math.pi), 1 / (4 * math.pi)], rel=1e-12)
    assert n == pytest.approx([-1 / (4 * math.pi), 1 / (4 * math.pi)], rel=1e-12)
    # thin ring: +-6M/t² with M = F'R/pi at the load point
    st = ring.ring_surface_stresses(0.0, 1000.0, 5.25e-3, 1.1e-3, curved=False)
    assert st["inner"] == pytest.approx(6 * 1000.0 * 5.25e-3 / math.pi / 1.1e-3**2, rel=1e-12)
    assert st["outer"] == pytest.approx(-st["inner"], rel=1e-12)


@pytest.mark.parametrize("r_over_c,ki,ko", [(2.0, 1.52, 0.73), (4.0, 1.20, 0.85),
                                            (6.0, 1.12, 0.90), (10.0, 1.07, 0.94)])
def test_curved_beam_factors_match_roark_table(r_over_c, ki, ko):
    got = ring.curved_beam_factors(r_over_c * 1.0, 2.0)   # c = t/2 = 1
    assert got == pytest.approx((ki, ko), abs=0.006)


# ---- effective areas -----------------------------------------------------------------------------

def test_effective_area_of_the_hertz_edge_field():
    m = 6.0
    table = ea.contact_table(1.0, NU, m, 1.0, "major")

    def s1(r):
        if r >= 1:
            return (1 - 2 * NU) / 3 / r**2
        dev = (1 - 2 * NU) / 3 * (1 - (1 - r * r) ** 1.5) / (r * r)
        return max(dev - math.sqrt(1 - r * r), -dev - 2 * NU * math.sqrt(1 - r * r))

    peak = (1 - 2 * NU) / 3
    want = quad(lambda r: max(s1(r) / peak, 0) ** m * 2 * math.pi * r, 0.5, 1, limit=200)[0] \
        + math.pi / (m - 1)   # outside: the closed form of int (a/r)^2m dA
    assert table["area"][0, -1] == pytest.approx(want, rel=0.01)
    # the line contact's tensile tail: int (xi - sqrt(xi² - 1))^m dxi behind the edge
    line = ea.line_table(m, 1.0)
    tail = quad(lambda x: (x - math.sqrt(x * x - 1)) ** m, 1, 400, limit=400)[0]
    inside = quad(lambda x: max((-math.sqrt(1 - x * x) - 0.4 * x) / 0.4, 0) ** m, -1, 1,
                  limit=200, points=[-0.99])[0]
    k = list(line["mu"]).index(0.2)
    assert line["area"][k, -1] == pytest.approx(tail + inside, rel=0.01)


def test_area_interpolation_between_nodes():
    m = 6.0
    table = ea.contact_table(1.0, NU, m, 1.0, "major")
    # halfway between mu nodes the interpolated area lies between the nodes' values
    got = ea.interp_mu_tau(table, np.array([0.125]), np.array([1.0]))
    lo, hi = table["area"][2, -1], table["area"][3, -1]
    assert min(lo, hi) <= got[0] <= max(lo, hi)
    assert ea.interp_mu_tau(table, np.array([0.1]), np.array([0.0]))[0] == 0.0
    # the shell tables interpolate smoothly in log(c/l)
    sh = ea.shell_table(NU, 10.0, 6.0)
    x = np.sqrt(ea.SHELL_XC[40] * ea.SHELL_XC[41])
    inner, _ = shell.hertz_patch_centre_coefficients(1 / x, NU)
    assert ea.interp_log(x, ea.SHELL_XC, sh["inner_peak"]) == pytest.approx(inner, rel=1e-4)
