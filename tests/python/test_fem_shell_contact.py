"""demfem.fem with shell bodies: a shell tube on the belt under gravity carries its weight
and is dragged by friction, ghost springs on shell nodes push, two shell cartridges collide
(momentum, energy balance, agreement with the tet run), checkpoints restore bitwise, and
bad input is refused."""
import numpy as np
import pytest

from demfem.cartridge import Cartridge
from demfem.errors import DemfemError, InvalidParameterError
from demfem.fem import (Body, ContactOptions, FemModel, GhostSprings, RigidPlane,
                        ShellMesh, ball_tet_mesh, cartridge_shell_mesh, collide_cartridges)
from demfem.materials import Material

GLASS = Material(7.3e10, 0.2, 2500.0, "glass")


def tube_on_belt(mu=0.3, belt=1.0, springs=()):
    tube = Cartridge.tube(11.6e-3, 1.1e-3, 20e-3)
    m = cartridge_shell_mesh(tube)
    # Lay the tube along x, its outer surface 1e-9 m above the belt (z = 0).
    rot = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
    m = m.placed(rot)
    r_out = 5.8e-3
    m = m.placed(None, (0.0, 0.0, -(m.nodes[:, 2].min() - 0.55e-3) + 1e-9))
    return FemModel([Body(m, name="tube")], GLASS,
                    rigid=[RigidPlane(surface_velocity=(belt, 0.0, 0.0), friction=mu)],
                    springs=springs, gravity=(0.0, 0.0, -9.81),
                    contact=ContactOptions(friction=mu, output_interval=1)), r_out


def test_shell_tube_on_the_belt_carries_its_weight_and_is_dragged_at_mu_n():
    model, _ = tube_on_belt()
    assert model.elements == "shell"
    m = float(np.sum(model.solver.mass()))
    res = model.run(4e-4)
    fn, ft = res.pair_force("tube", "belt")
    late = res.time > 1e-4
    # The tube rings on the belt; over many periods the belt carries its weight.
    assert fn[late].mean() == pytest.approx(m * 9.81, rel=0.02)
    assert ft[late].mean() == pytest.approx(0.3 * m * 9.81, rel=0.02)
    # Slipping all the time: the belt's drag is μ times the normal impulse.
    impulse = float(np.sum(fn) * model.dt_step)
    assert model.body_velocity(0)[0] == pytest.approx(0.3 * impulse / m, rel=0.01)
    assert res.energy_balance_error() < 0.01
    snap = res.final
    assert snap.sigma1_surfaces.shape == (model.mesh.n_elements, 3)
    assert np.all(np.isfinite(snap.sigma1_surfaces))


def test_ghost_springs_on_shell_nodes_push_and_checkpoint_restores(tmp_path):
    model, _ = tube_on_belt(mu=0.0, belt=0.0)
    n = model.mesh.n_nodes
    top = np.nonzero(model.mesh.nodes[:, 2] > model.mesh.nodes[:, 2].max() - 1e-6)[0]
    anchors = model.mesh.nodes[top] + np.array([0.0, 0.0, 1e-3 - 1e-6])
    springs = [GhostSprings(0, top, anchors, 1e5, 1e-3)]
    model, _ = tube_on_belt(mu=0.0, belt=0.0, springs=springs)
    model.run(5e-5)
    path = model.save_state(tmp_path / "state.bin")
    info = model.solver.contact_info()
    assert info["spring_energy"] >= 0.0
    model.run(5e-5)
    again, _ = tube_on_belt(mu=0.0, belt=0.0, springs=springs)
    again.restore_state(path)
    again.run(5e-5)
    assert np.array_equal(np.asarray(again.solver.displacement()),
                          np.asarray(model.solver.displacement()))
    assert n == again.mesh.n_nodes


def test_two_shell_cartridges_collide_like_the_tet_ones():
    r = collide_cartridges(v_rel=0.2, tilt_deg=90.0, elements="shell", stress_samples=8)
    assert r.result.channels[0][:2] == ("a", "b")
    assert r.energy_balance_error < 0.01
    assert 0.5 < r.restitution <= 1.0
    # The tet run of the same case (2 layers): 18.9 N over 80 µs (measured).
    assert r.max_force == pytest.approx(18.9, rel=0.2)
    assert r.contact_duration == pytest.approx(80e-6, rel=0.2)
    assert r.peak_sigma1_inner > 0 and r.peak_sigma1_outer > 0


def test_bad_shell_input_is_refused():
    tube = Cartridge.tube(11.6e-3, 1.1e-3, 20e-3)
    m = cartridge_shell_mesh(tube)
    bad = ShellMesh(m.nodes, m.triangles, np.where(np.arange(m.n_elements) == 3, 0.0, m.thickness))
    with pytest.raises(DemfemError, match="thickness"):
        FemModel([Body(bad)], GLASS)
    with pytest.raises(InvalidParameterError, match="mixed"):
        FemModel([Body(m), Body(ball_tet_mesh(0.01, 2).placed(None, (0.1, 0, 0)))], GLASS)
    with pytest.raises(InvalidParameterError, match="tet bodies only"):
        FemModel([Body(m)], GLASS, rayleigh_beta=1e-6)
    # Two copies 0.5 mm apart: the walls (1.1 mm) overlap by 0.6 mm.
    other = m.placed(None, (2 * 5.25e-3 + 0.5e-3, 0.0, 0.0))
    with pytest.raises(DemfemError, match="body 0 overlaps body 1|body 1 overlaps body 0"):
        FemModel([Body(m), Body(other)], GLASS)
    with pytest.raises(InvalidParameterError, match="elements"):
        collide_cartridges(elements="hex")
