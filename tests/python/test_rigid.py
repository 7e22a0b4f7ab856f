"""Full-shape cartridges through Python: the RigidSimulation binding, demfem.rigid.from_scene
and the table's ``particle`` option, checked against physics and for field-naming errors."""
import math
from pathlib import Path

import numpy as np
import pytest

from demfem import dem, rigid
from demfem.cartridge import Cartridge
from demfem.errors import EffectError, InvalidParameterError, ShapeError
from demfem.scenes import AccumulationTable

GLASS = dem.material(45e9, 0.22, 2230.0, friction=0.2, restitution=0.5)
BELT = dem.plane((0, 0, 0), (0, 0, 1))
EFFECTS = ["gravity", "friction", "rotation", "damping"]


@pytest.mark.parametrize("particle", ["clump", "cylinder"])
def test_dropped_cartridge_comes_to_rest_upright(particle):
    c = Cartridge()
    zc = float(c.center_of_mass[2])
    # dropped upright from 1 mm (a tilted drop rocks on the bottom rim for long: Housner)
    q = rigid.upright(1)
    sim = rigid.RigidSimulation(np.array([[0.0, 0.0, zc + 1e-3]]), q, rigid.shape_dict(particle),
                                GLASS, [BELT], EFFECTS)
    assert sim.body_mass == pytest.approx(c.mass, rel=1e-9)
    sim.run_until(0.1)
    # standing on its flat bottom end: upright, centre of mass zc above the belt (less the
    # micron-size Hertz overlap of its weight), at rest
    assert math.degrees(sim.tilt_angles()[0]) < 0.1
    assert sim.positions()[0, 2] == pytest.approx(zc, abs=5e-6)
    assert np.linalg.norm(sim.velocities()[0]) < 1e-3
    np.testing.assert_allclose(sim.axes()[0], [0, 0, 1], atol=2e-3)
    o = sim.orientations()[0]
    assert np.linalg.norm(o) == pytest.approx(1.0, abs=1e-12)
    assert sim.wall_contacts()[0] == 1 and sim.coordination()[0] == 0


def test_cartridge_tilted_past_its_base_falls():
    c = Cartridge()
    zc = float(c.center_of_mass[2])
    # the centre of mass is outside the base once tan(tilt) > r_out / zc
    tilt = math.atan(0.5 * c.body_outer_diameter / zc) + math.radians(8)
    q = np.array([[math.cos(tilt / 2), math.sin(tilt / 2), 0.0, 0.0]])
    z = zc * math.cos(tilt) + 0.5 * c.body_outer_diameter * math.sin(tilt) + 1e-4
    sim = rigid.RigidSimulation(np.array([[0.0, 0.0, z]]), q, rigid.shape_dict("clump"),
                                GLASS, [BELT], EFFECTS)
    sim.run_until(0.4)
    assert math.degrees(sim.tilt_angles()[0]) > 80.0


def test_validation_errors_name_the_field():
    x = np.zeros((1, 3))
    q = rigid.upright(1)
    shape = rigid.shape_dict("cylinder")
    with pytest.raises(InvalidParameterError, match="shape.kind"):
        rigid.RigidSimulation(x, q, {"kind": "blob"}, GLASS, [BELT], EFFECTS)
    with pytest.raises(ShapeError, match="orientations"):
        rigid.RigidSimulation(x, np.ones((1, 3)), shape, GLASS, [BELT], EFFECTS)
    with pytest.raises(InvalidParameterError, match="material.young_modulus"):
        rigid.RigidSimulation(x, q, shape, {"poisson_ratio": 0.2, "density": 2230.0}, [BELT],
                              EFFECTS)
    with pytest.raises(InvalidParameterError, match=r"orientations\[0\]"):
        rigid.RigidSimulation(x, np.zeros((1, 4)), shape, GLASS, [BELT], EFFECTS)
    with pytest.raises(EffectError, match="planar"):
        rigid.RigidSimulation(x, q, shape, GLASS, [BELT], EFFECTS + ["planar"])
    with pytest.raises(InvalidParameterError, match="r_in"):
        rigid.RigidSimulation(x, q, {"kind": "exact", "z": [0, 1e-2], "r_in": [2e-3, 2e-3],
                                     "r_out": [1e-3, 1e-3]}, GLASS, [BELT], EFFECTS)
    with pytest.raises(InvalidParameterError, match="walls"):
        rigid.RigidSimulation(x, q, shape, GLASS, [{"type": "torus"}], EFFECTS)


def _small_table(**kw):
    return AccumulationTable(n_spheres=36, length=0.12, width=0.12, tilted_wall_length=0.1,
                             opening_width=0.03, gate_amplitude=0.01, wall_height=0.07, **kw)


@pytest.mark.parametrize("particle", ["clump", "cylinder"])
def test_table_particle_builds_without_overlaps_and_runs(particle):
    description = _small_table(particle=particle).build()
    assert description.parameters["particle"] == particle
    xy = description.positions[:, :2]
    d = np.linalg.norm(xy[:, None] - xy[None], axis=2) + np.eye(len(xy))
    assert d.min() > Cartridge().body_outer_diameter
    sim = rigid.from_scene(description)
    assert len(sim) == description.n_particles
    np.testing.assert_allclose(sim.positions()[:, :2], xy)
    sim.run_until(0.01)
    # nothing overlapped at the start: no body was thrown, everything still stands
    assert np.max(np.linalg.norm(sim.velocities(), axis=1)) < 0.3
    assert math.degrees(np.max(sim.tilt_angles())) < 1.0


def test_table_particle_validation(tmp_path: Path):
    with pytest.raises(InvalidParameterError, match="particle"):
        _small_table(particle="cube")
    with pytest.raises(InvalidParameterError, match="wall_height"):
        AccumulationTable(particle="clump")  # default walls are lower than a cartridge
    with pytest.raises(InvalidParameterError, match="planar"):
        _small_table(particle="clump", planar=True)
    with pytest.raises(InvalidParameterError, match="particle"):
        rigid.from_scene(_small_table().build())  # spheres go through demfem.dem
    table = _small_table(particle="cylinder")
    path = table.to_toml(tmp_path / "t.toml")
    assert 'particle = "cylinder"' in path.read_text()
    assert AccumulationTable.from_toml(path) == table


@pytest.mark.parametrize("particle", ["clump", "cylinder"])
def test_belt_friction_topples_a_cartridge_only_above_r_over_zc(particle):
    # A belt starting under an upright cartridge drags its bottom with mu m g while it slips;
    # the weight can resist that torque about the centre of mass only up to m g r_out, so
    # the cartridge tips over when mu > r_out / z_c (0.19 for the default cartridge).
    c = Cartridge()
    zc = float(c.center_of_mass[2])
    critical = 0.5 * c.body_outer_diameter / zc
    belt = dem.plane((0, 0, 0), (0, 0, 1), surface_velocity=(0.2, 0, 0))
    tilt = {}
    for mu in (0.7 * critical, 1.5 * critical):
        mat = dem.material(45e9, 0.22, 2230.0, friction=mu, restitution=0.5)
        sim = rigid.RigidSimulation(np.array([[0.0, 0.0, zc]]), rigid.upright(1),
                                    rigid.shape_dict(particle), mat, [belt], EFFECTS + ["belt"])
        sim.run_until(0.3)
        tilt[mu] = math.degrees(sim.tilt_angles()[0])
    low, high = tilt[0.7 * critical], tilt[1.5 * critical]
    assert low < 2.0, tilt
    assert high > 45.0, tilt
