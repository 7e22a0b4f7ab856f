"""Where full-shape cartridges touch: every contact onset of the rigid engine records the
contact point on each body (height along the axis, the place: rim, body, shoulder, neck,
flange), the angle between the axes (or between an axis and a wall) and the partner kind."""
import math

import numpy as np
import pytest

from demfem import dem, rigid
from demfem.cartridge import Cartridge
from demfem.errors import InvalidParameterError

GLASS = dem.material(45e9, 0.22, 2230.0, friction=0.2, restitution=0.5)
BELT = dem.plane((0, 0, 0), (0, 0, 1))
EFFECTS = ["gravity", "friction", "rotation", "damping"]


def about(axis, angle):
    """Quaternion (w, x, y, z) of a rotation by ``angle`` (rad) about the unit ``axis``."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    return np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * a])


def qmul(p, q):
    w1, x1, y1, z1 = p
    w2, x2, y2, z2 = q
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def test_place_names_follow_the_cartridge():
    c = Cartridge()
    h = [0.0, 0.5e-3, 10e-3, c.body_length, c.body_length + 1e-3,
         c.body_length + c.shoulder_length + 1e-3, c.length, float("nan")]
    assert list(rigid.place_of(h, c)) == ["rim", "rim", "body", "shoulder", "shoulder", "neck",
                                          "flange", ""]
    with pytest.raises(InvalidParameterError, match="place"):
        rigid.at_place({"place_body": np.array(["rim"], dtype=object)}, "lip")
    with pytest.raises(InvalidParameterError, match="side"):
        rigid.at_place({"place_body": np.array(["rim"], dtype=object)}, "rim", side="left")


@pytest.mark.parametrize("particle", ["revolution", "cylinder", "clump"])
def test_upright_drop_touches_the_belt_with_the_rim_standing(particle):
    c = Cartridge()
    zc = float(c.center_of_mass[2])
    sim = rigid.RigidSimulation(np.array([[0.0, 0.0, zc + 1e-3]]), rigid.upright(1),
                                rigid.shape_dict(particle), GLASS, [BELT], EFFECTS,
                                record_onsets=True)
    sim.run_until(0.02)
    ev = rigid.contact_places(sim, c, walls=[{"name": "belt"}])
    assert list(ev["place_body"][:1]) == ["rim"]
    assert ev["partner_kind"][0] == "wall" and ev["partner_name"][0] == "belt"
    assert ev["axis_angle_deg"][0] == pytest.approx(90.0, abs=0.1)
    assert ev["height_body"][0] == pytest.approx(0.0, abs=c.wall_thickness)
    assert np.isnan(ev["height_partner"][0]) and ev["place_partner"][0] == ""
    assert rigid.at_place(ev, "rim")[0]


@pytest.mark.parametrize("particle", ["revolution", "cylinder"])
def test_crossed_cartridges_meet_body_on_body_at_their_angle(particle):
    # A lies along x on the belt; B, turned 60° in plan, falls across A's body
    c = Cartridge()
    r = 0.5 * c.body_outer_diameter
    lying = about([0, 1, 0], math.pi / 2)
    turned = qmul(about([0, 0, 1], math.radians(60)), lying)
    x = np.array([[0.0, 0.0, r + 1e-6], [0.005, 0.0, 3 * r + 1e-4]])
    sim = rigid.RigidSimulation(x, np.array([lying, turned]), rigid.shape_dict(particle), GLASS,
                                [BELT], EFFECTS, record_onsets=True)
    sim.run_until(0.02)
    ev = rigid.contact_places(sim, c, walls=["belt"])
    pair = np.flatnonzero(ev["partner_kind"] == "cartridge")
    assert len(pair) >= 1
    k = pair[0]
    assert ev["axis_angle_deg"][k] == pytest.approx(60.0, abs=0.5)
    assert ev["place_body"][k] == "body" and ev["place_partner"][k] == "body"
    # A's onset with the belt: lying, its axis along the belt's surface
    belt = np.flatnonzero((ev["partner_kind"] == "wall") & (ev["body"] == 0))
    assert ev["axis_angle_deg"][belt[0]] == pytest.approx(0.0, abs=0.1)


def test_flange_and_sphere_partners_are_named():
    # a cartridge lying along x with its top towards a wall at x = 0.04; a sphere falls on its body
    c = Cartridge()
    r_s = c.equivalent_sphere().radius
    r = 0.5 * c.body_outer_diameter
    zc = float(c.center_of_mass[2])
    head_first = about([0, 1, 0], math.pi / 2)  # axis (bottom to top) along +x
    wall = dem.plane((0.04, 0, 0), (-1, 0, 0))
    x = np.array([[0.04 - (c.length - zc) - 2e-4, 0.0, r + 1e-6], [-0.01, 0.0, r + 2 * r_s]])
    v = np.array([[0.2, 0.0, 0.0], [0.0, 0.0, 0.0]])
    sim = rigid.RigidSimulation(x, np.array([head_first, [1.0, 0, 0, 0]]),
                                rigid.shape_dict("revolution"), GLASS, [BELT, wall], EFFECTS,
                                velocities=v, record_onsets=True,
                                spheres=np.array([False, True]), sphere_radius=r_s)
    sim.run_until(0.03)
    ev = rigid.contact_places(sim, c, walls=["belt", "wall"])
    hit = np.flatnonzero(ev["partner_name"] == "wall")
    assert len(hit) and ev["place_body"][hit[0]] == "flange"
    assert ev["axis_angle_deg"][hit[0]] == pytest.approx(90.0, abs=1.0)
    sphere = np.flatnonzero(ev["partner_kind"] == "sphere")
    assert len(sphere)
    k = sphere[0]
    assert ev["place_body"][k] == "body" and ev["place_partner"][k] == ""
    assert np.isnan(ev["axis_angle"][k])
