"""demfem.stress.contact_stresses: the superposition against its closed-form terms, bad input,
vectorisation, and the issue's order of magnitude for two crossed 3 mL cartridges at 45 N."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from demfem.cartridge import Cartridge
from demfem.errors import InvalidParameterError, ShapeError
from demfem.materials import PAPER_GLASS, TYPE_I_TUBING_GLASS
from demfem.risk import INNER_SURFACE, OUTER_SURFACE
from demfem.stress import ContactStresses, contact_stresses
from demfem.stress import cylinder_load as cl
from demfem.stress.ring import curved_beam_factors

CART = Cartridge()
R_OUT = 0.5 * CART.body_outer_diameter
T = CART.wall_thickness


def _hertz(force: float, E: float, nu: float, r_star: float) -> tuple[float, float]:
    e_star = E / (2 * (1 - nu * nu))
    a = (3 * force * r_star / (4 * e_star)) ** (1 / 3)
    return a, 3 * force / (2 * math.pi * a * a)


@pytest.mark.parametrize("glass", [PAPER_GLASS, TYPE_I_TUBING_GLASS], ids=["45GPa", "73GPa"])
def test_two_crossed_cartridges_at_45N(glass):
    F = 45.0
    out = {mu: contact_stresses(F, mu * F, material=glass) for mu in (0.0, 0.2)}
    # crossed at 90°: a circle, R* = R (a sphere of the cylinders' radius on a flat)
    a, p0 = _hertz(F, glass.E, glass.nu, R_OUT)
    r0 = out[0.0]
    assert float(r0.a) == pytest.approx(a, rel=1e-12) and float(r0.b) == pytest.approx(a)
    assert float(r0.p0) == pytest.approx(p0, rel=1e-12)
    for mu, r in out.items():   # Hamilton: p0 [(1 − 2ν)/3 + (4 + ν) π μ / 8]
        edge = p0 * ((1 - 2 * glass.nu) / 3 + (4 + glass.nu) * math.pi * mu / 8)
        assert float(r.outer_contact_Pa) == pytest.approx(edge, rel=1e-12)
        assert float(r.outer_sigma1_max) == pytest.approx(
            float(r.outer_contact_Pa + r.outer_bending_Pa), rel=1e-12)
        assert bool(r.outer_from_contact)
    # the inner tension is the cylindrical wall's under the Hertz circle of radius a, free
    # over the body's length (the series itself, not its table), at the load; the outer
    # bending is the wall's at the rim, the less compressive of along and around the axis
    shell = cl.CylinderShell(CART.body_mid_radius, T, glass.E, glass.nu, 2 * CART.body_length)
    wall = cl.cylinder_load_field(shell, F, lambda kx, ky: cl.hertz_disc_spectrum(kx, ky, a),
                                  free_length=CART.body_length)
    assert float(r0.inner_sigma1_max) == pytest.approx(
        float(wall.surface_stresses(0.0, 0.0, "inner")["s1"]), rel=2e-3)
    rim = max(float(wall.surface_stresses(a, 0.0, "outer")["xx"]),
              float(wall.surface_stresses(0.0, a / R_OUT, "outer")["tt"]))
    assert float(r0.outer_bending_Pa) == pytest.approx(rim, rel=5e-3)
    assert float(r0.outer_bending_Pa) < 0 < float(r0.outer_ring_Pa)   # compressed at the edge
    # the order of magnitude: ~100 MPa contact-edge tension, above the inner bending
    assert 50e6 < float(r0.outer_contact_Pa) < 200e6
    assert float(r0.outer_contact_Pa) > float(r0.inner_sigma1_max)
    assert float(out[0.2].outer_contact_Pa) > 2.5 * float(r0.outer_contact_Pa)
    print(f"\n{glass.name}, 45 N crossed: a = {a * 1e6:.1f} um, p0 = {p0 / 1e6:.0f} MPa; "
          f"outer contact-edge tension {float(r0.outer_contact_Pa) / 1e6:.1f} MPa (mu = 0), "
          f"{float(out[0.2].outer_contact_Pa) / 1e6:.1f} MPa (mu = 0.2); outer bending at the "
          f"edge {float(r0.outer_bending_Pa) / 1e6:.1f} MPa; outer sigma1 "
          f"{float(r0.outer_sigma1_max) / 1e6:.1f} / {float(out[0.2].outer_sigma1_max) / 1e6:.1f}"
          f" MPa; inner bending {float(r0.inner_sigma1_max) / 1e6:.1f} MPa; areas outer "
          f"{float(r0.outer_effective_area):.3g} / {float(out[0.2].outer_effective_area):.3g} "
          f"m^2, inner {float(r0.inner_effective_area):.3g} m^2")


def test_defaults_and_effective_areas():
    r = contact_stresses(10.0)
    assert isinstance(r, ContactStresses)
    assert r.weibull_modulus_outer == OUTER_SURFACE.weibull_modulus
    assert r.weibull_modulus_inner == INNER_SURFACE.weibull_modulus
    a = float(r.a)
    # frictionless circular contact: the edge field (a/r)² outside gives π a²/(m − 1) at least
    # (plus a little from inside the edge), lowered by the bending offset
    bare = contact_stresses(10.0, weibull_modulus_outer=6.0)
    assert 0 < float(bare.outer_effective_area) < 1.05 * math.pi * a * a / 5
    # a larger m concentrates the area
    assert float(contact_stresses(10.0, weibull_modulus_outer=12.0).outer_effective_area) < \
        float(bare.outer_effective_area)
    assert float(contact_stresses(10.0, weibull_modulus_inner=20.0).inner_effective_area) < \
        float(r.inner_effective_area)
    d = r.to_dict()
    assert set(d) >= {"outer_sigma1_max", "inner_sigma1_max", "outer_effective_area",
                      "inner_effective_area", "outer_contact_Pa", "outer_bending_Pa",
                      "inner_bending_Pa", "p0", "a", "b"}


def test_vectorised_equals_scalar():
    F = np.array([0.3, 2.0, 11.0, 45.0, 80.0])
    Q = np.array([0.0, 0.5, 1.0, 9.0, 40.0])
    for kw in (dict(), dict(crossing_angle_deg=50.0), dict(geometry="edge", edge_radius=2e-3),
               dict(geometry="parallel", contact_length=0.03),
               dict(geometry="wall", contact_length=0.05, ring_support="inertia"),
               dict(flaw_depth=15e-6)):
        vec = contact_stresses(F, Q, **kw).to_dict()
        for k in range(F.size):
            one = contact_stresses(float(F[k]), float(Q[k]), **kw).to_dict()
            for name, value in one.items():
                if isinstance(value, np.ndarray):
                    assert vec[name][k] == pytest.approx(float(value), rel=1e-12, abs=0), \
                        (kw, name, k)
    # broadcasting: a scalar tangential force over an array of normal forces; 2-D arrays
    r = contact_stresses(np.full((2, 3), 20.0), 2.0)
    assert r.outer_sigma1_max.shape == (2, 3)
    with pytest.raises(ShapeError, match="tangential_force"):
        contact_stresses(np.ones(3), np.ones(4))
    with pytest.raises(ShapeError, match="flaw_depth"):
        contact_stresses(np.ones(3), flaw_depth=np.full(2, 1e-5))
    per_event = contact_stresses(np.array([5.0, 5.0]), flaw_depth=np.array([1e-6, 3e-5]))
    assert per_event.outer_contact_Pa[0] > per_event.outer_contact_Pa[1]


def test_crossing_angle_makes_an_ellipse():
    r90 = contact_stresses(20.0)
    r30 = contact_stresses(20.0, crossing_angle_deg=30.0)
    assert float(r30.a) > float(r90.a) > float(r30.b)
    # Hertz: a b p0 = 3F/(2π) whatever the shape
    for r in (r90, r30):
        assert float(r.a * r.b * r.p0) == pytest.approx(3 * 20.0 / (2 * math.pi), rel=1e-12)
    # the frictionless edge tension at the major-axis end: Johnson §3.5
    beta = float(r30.b / r30.a)
    e2 = 1 - beta * beta
    e = math.sqrt(e2)
    major = (1 - 2 * 0.22) * beta / e2 * (math.atanh(e) / e - 1)
    assert float(r30.outer_contact_Pa) == pytest.approx(major * float(r30.p0), rel=1e-6)


def test_line_contacts_bend_the_cylinder():
    F, L = 30.0, 0.04
    r = contact_stresses(F, 0.0, geometry="parallel", contact_length=L)
    w = F / L
    e_star = PAPER_GLASS.E / (2 * (1 - 0.22**2))
    b = math.sqrt(4 * w * (R_OUT / 2) / (math.pi * e_star))
    assert float(r.b) == pytest.approx(b, rel=1e-12)
    assert float(r.p0) == pytest.approx(2 * w / (math.pi * b), rel=1e-12)
    assert float(r.outer_contact_Pa) == 0.0   # no friction: no surface tension of a line contact
    # inner: a contact longer than the ovalisation's axial decay (≈ 9 mm) bends the wall like
    # the ring, M = F'R/π at the load point with the curved-bar stress (Roark), less the
    # load's spread through the wall (1.5 %); a short one less: the tube beside it carries
    # part of the load
    ki, ko = curved_beam_factors(CART.body_mid_radius, T)
    ring = ki * 6 * w * CART.body_mid_radius / (math.pi * T**2)
    assert float(r.inner_sigma1_max) == pytest.approx(ring, rel=0.03)
    short = contact_stresses(F, 0.0, geometry="parallel", contact_length=0.01)
    assert 0.5 < float(short.inner_sigma1_max) / (ring * L / 0.01) < 0.75
    prof = cl.line_load_profile(CART.body_mid_radius, T, 0.22, L, "opposite", CART.body_length,
                                10.0, 6.0)
    assert float(r.inner_sigma1_max) == pytest.approx(prof["inner_peak"] * F / T**2,
                                                      rel=1e-12)
    assert not bool(r.outer_from_contact)   # the outer peak is the ring's side
    # with friction: 2 μ p0 at the trailing edge (McEwen), on top of the wall's compression
    # under the load: the ring's less the load's spread through the loaded face
    rf = contact_stresses(F, 0.3 * F, geometry="parallel", contact_length=L)
    assert float(rf.outer_contact_Pa) == pytest.approx(0.6 * float(r.p0), rel=1e-12)
    assert float(rf.outer_bending_Pa) == pytest.approx(prof["outer_load"] * F / T**2,
                                                      rel=1e-12)
    assert -ko * 6 * w * CART.body_mid_radius / (math.pi * T**2) < \
        float(rf.outer_bending_Pa) < 0
    # a wall: R* = R (a cylinder on a flat)
    rw = contact_stresses(F, 0.0, geometry="wall", contact_length=L)
    assert float(rw.b) == pytest.approx(math.sqrt(2.0) * b, rel=1e-12)
    # the parallel contact's inner stress is far below the crossed one's
    assert float(r.inner_sigma1_max) < 0.3 * float(contact_stresses(F).inner_sigma1_max)


def test_flaw_depth_lowers_the_contact_tension():
    F = np.array([5.0, 45.0])
    base = contact_stresses(F, 0.1 * F)
    shallow = contact_stresses(F, 0.1 * F, flaw_depth=1e-9)
    deep = contact_stresses(F, 0.1 * F, flaw_depth=30e-6)
    assert shallow.outer_contact_Pa == pytest.approx(base.outer_contact_Pa, rel=0.01)
    assert np.all(deep.outer_contact_Pa < 0.6 * base.outer_contact_Pa)
    # the larger contact (45 N) is less affected by the same flaw
    assert deep.outer_contact_Pa[1] / base.outer_contact_Pa[1] > \
        deep.outer_contact_Pa[0] / base.outer_contact_Pa[0]
    assert deep.inner_sigma1_max == pytest.approx(base.inner_sigma1_max)


def test_material_and_cartridge_are_used():
    thick = dataclasses.replace(CART, wall_thickness=1.5e-3)
    assert float(contact_stresses(20.0, cartridge=thick).inner_sigma1_max) < \
        float(contact_stresses(20.0).inner_sigma1_max)
    stiff = contact_stresses(20.0, material=TYPE_I_TUBING_GLASS)
    assert float(stiff.p0) > float(contact_stresses(20.0).p0)
    steel = dataclasses.replace(PAPER_GLASS, E=200e9, nu=0.3)
    assert float(contact_stresses(20.0, geometry="edge", edge_radius=1e-3,
                                  partner_material=steel).p0) > float(
        contact_stresses(20.0, geometry="edge", edge_radius=1e-3).p0)


@pytest.mark.parametrize("kwargs,args,field", [
    ({}, (0.0,), "normal_force"),
    ({}, (-1.0,), "normal_force"),
    ({}, (math.nan,), "normal_force"),
    ({}, (np.array([1.0, np.inf]),), "normal_force"),
    ({}, (1.0, -0.1), "tangential_force"),
    ({}, (1.0, math.nan), "tangential_force"),
    ({}, (1.0, 1.5), "tangential_force"),                       # Q/F > 1 without a μ
    ({"friction_coefficient": 0.3}, (1.0, 0.5), "tangential_force"),
    ({"friction_coefficient": 2.5}, (1.0, 0.5), "friction_coefficient"),
    ({"geometry": "sphere"}, (1.0,), "geometry"),
    ({"location": "neck"}, (1.0,), "location"),
    ({"location": "rim", "geometry": "parallel", "contact_length": 0.01}, (1.0,), "location"),
    ({"location": "shoulder", "geometry": "wall", "contact_length": 0.01}, (1.0,),
     "location"),
    ({"crossing_angle_deg": 0.0}, (1.0,), "crossing_angle_deg"),
    ({"crossing_angle_deg": 120.0}, (1.0,), "crossing_angle_deg"),
    ({"geometry": "parallel"}, (1.0,), "contact_length"),
    ({"geometry": "wall", "contact_length": 1.0}, (1.0,), "contact_length"),
    ({"contact_length": 0.01}, (1.0,), "contact_length"),
    ({"geometry": "edge"}, (1.0,), "edge_radius"),
    ({"edge_radius": 1e-3}, (1.0,), "edge_radius"),
    ({}, (2e4,), "normal_force"),                               # a > the bending length
    ({"crossing_angle_deg": 3.0}, (50.0,), "normal_force"),     # a long ellipse: a > l
    ({"weibull_modulus_outer": 1.0}, (1.0,), "weibull_modulus_outer"),
    ({"weibull_modulus_inner": 0.5}, (1.0,), "weibull_modulus_inner"),
    ({"flaw_depth": 0.0}, (1.0,), "flaw_depth"),
    ({"sliding_direction": "diagonal"}, (1.0,), "sliding_direction"),
    ({"ring_support": "glue"}, (1.0,), "ring_support"),
    ({"cartridge": "3 mL"}, (1.0,), "cartridge"),
    ({"material": 45e9}, (1.0,), "material"),
    ({}, ("ten",), "normal_force"),
    ({}, (True,), "normal_force"),
    ({}, (1.0, "x"), "tangential_force"),
])
def test_bad_input_names_the_field(kwargs, args, field):
    with pytest.raises(InvalidParameterError, match=field):
        contact_stresses(*args, **kwargs)


def test_bad_input_messages_give_the_range():
    with pytest.raises(InvalidParameterError, match=r"bending length ell = .* normal_force < "):
        contact_stresses(2e4)
    with pytest.raises(InvalidParameterError, match=r"\[0, 1\].*friction_coefficient"):
        contact_stresses(1.0, 1.5)
    # rim and shoulder: point contacts only (their factors come from a point-contact FEM)
    with pytest.raises(InvalidParameterError, match="point contact"):
        contact_stresses(1.0, location="rim", geometry="parallel", contact_length=0.01)
    # the friction limit may be raised
    assert float(contact_stresses(1.0, 1.5, friction_coefficient=1.6).outer_contact_Pa) > 0
