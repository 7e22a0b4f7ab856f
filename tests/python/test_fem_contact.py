"""demfem.fem: meshes from cartridges, bodies in contact, the belt, ghost springs, the
two-cartridge collision, and clear errors for bad input."""
import numpy as np
import pytest

from demfem.cartridge import Cartridge
from demfem.errors import DemfemError, InvalidParameterError
from demfem.fem import (Body, ContactOptions, FemModel, GhostSprings, RigidPlane,
                        ball_tet_mesh, cartridge_tet_mesh, collide_cartridges,
                        estimated_tet_count, rotation_about)
from demfem.materials import Material

SOFT = Material(1e7, 0.3, 1000.0, "soft")


def test_tube_and_cartridge_meshes():
    tube = Cartridge.tube(11.6e-3, 1.1e-3, 20e-3)
    z, ri, ro = tube.stations()
    assert list(z) == [0.0, 20e-3] and ri[0] == pytest.approx(4.7e-3) and ro[0] == pytest.approx(5.8e-3)
    m = cartridge_tet_mesh(tube, layers=2)
    r = np.hypot(m.nodes[:, 0], m.nodes[:, 1])
    assert r.min() == pytest.approx(4.7e-3, rel=1e-9) and r.max() == pytest.approx(5.8e-3, rel=1e-9)
    est = estimated_tet_count(tube, layers=2)
    assert 0.5 < m.n_elements / est < 2.0
    with pytest.raises(InvalidParameterError, match="max_elements"):
        cartridge_tet_mesh(Cartridge(), layers=4, target_size=1e-5)
    with pytest.raises(InvalidParameterError, match="layers"):
        cartridge_tet_mesh(tube, layers=0)


def test_ball_resting_on_belt_is_carried_and_springs_push():
    ball = ball_tet_mesh(0.01, 3).placed(None, (0.0, 0.0, 0.01 + 1e-7))
    belt = RigidPlane(surface_velocity=(0.1, 0.0, 0.0), friction=0.5)
    model = FemModel([Body(ball, name="ball")], SOFT, rigid=[belt], gravity=(0, 0, -9.81),
                     rayleigh_beta=2e-5, mass_scaling_dt=1e-6)
    res = model.run(0.02)
    assert res.channels[0][:2] == ("ball", "belt")
    assert res.normal_force[-1, 0] > 0.0
    assert model.body_velocity(0)[0] > 0.0  # friction drags it along the belt
    assert np.isfinite(res.energy).all()
    assert res.step["dt_s"] <= res.step["dt_limit_s"]
    # A ghost spring on the +x side pushes the body towards −x and never pulls.
    ball2 = ball_tet_mesh(0.01, 2)
    far = int(np.argmax(ball2.nodes[:, 0]))
    springs = GhostSprings(0, np.array([far]), np.array([[0.0125, 0.0, 0.0]]), 50.0, 0.003)
    m2 = FemModel([Body(ball2)], SOFT, springs=[springs])
    m2.run(1e-3)
    assert m2.body_velocity(0)[0] < 0.0


def test_collision_of_two_soft_cartridges_conserves_energy():
    tube = Cartridge.tube(11.6e-3, 1.1e-3, 16e-3, material=SOFT)
    r = collide_cartridges(tube, tube, v_rel=0.2, tilt_deg=90.0, layers=1)
    assert r.max_force > 0.0 and r.raw_max_force >= r.max_force
    assert 0.0 < r.restitution <= 1.0
    assert r.contact_duration > 0.0
    assert r.energy_balance_error < 0.01
    assert r.result.step["reduced_for_contact"] in (True, False)


def test_bad_input_names_the_field():
    ball = ball_tet_mesh(0.01, 2)
    with pytest.raises(InvalidParameterError, match="friction"):
        FemModel([Body(ball)], SOFT, contact=ContactOptions(friction=-0.1))
    with pytest.raises(DemfemError, match="penalty_scale"):
        FemModel([Body(ball)], SOFT, contact=ContactOptions(penalty_scale=0.0))
    with pytest.raises(DemfemError, match="overlap"):
        FemModel([Body(ball), Body(ball.placed(None, (0.005, 0, 0)))], SOFT)
    with pytest.raises(DemfemError, match="stiffness"):
        FemModel([Body(ball)], SOFT, springs=[GhostSprings(0, np.array([0]), np.zeros((1, 3)) + 1, -1.0, 0.01)])
    with pytest.raises(InvalidParameterError, match="rotation"):
        ball.placed(np.ones((3, 3)))
    with pytest.raises(InvalidParameterError, match="v_rel"):
        collide_cartridges(v_rel=-1.0)
    r = rotation_about((1, 0, 0), 90.0)
    assert np.allclose(r @ [0, 0, 1], [0, -1, 0])


def test_fem_calibrated_line_law_reproduces_the_stored_fem_and_runs_in_the_dem():
    from demfem import dem
    from demfem.fem import fig3
    from demfem.fem.line_law import line_contact_stiffness
    from demfem.scenes import AccumulationTable

    data = fig3.load_stored()
    row = next(r for r in data["runs"] if r["tilt_deg"] == 0.0 and r["E_Pa"] == 1e10)
    m_star = 0.5 * Cartridge().mass
    k_n, k_t = line_contact_stiffness(1e10, 0.22)
    # the linear spring's peak force at the FEM's speed is the FEM's peak force
    v = data["v_rel_m_per_s"]
    assert v * np.sqrt(k_n * m_star) == pytest.approx(row["max_force_N"], rel=1e-9)
    assert k_t / k_n == pytest.approx(2 * (1 - 0.22) / (2 - 0.22))
    k2, _ = line_contact_stiffness(2e10, 0.22)
    assert 1.5 < k2 / k_n < 2.5  # k ∝ E between the stored moduli
    scene = AccumulationTable(n_spheres=252).build()
    sim = dem.from_scene(scene, model="fem_line")
    dem.run(sim, 0.002)
    assert np.isfinite(sim.positions()).all()
    with pytest.raises(InvalidParameterError, match="linear_stiffness"):
        dem.from_scene(scene, model="linear")
    with pytest.raises(InvalidParameterError, match="young_modulus"):
        line_contact_stiffness(-1.0, 0.2)


def test_the_fem_line_law_is_named_in_scene_files_and_refused_by_assess(tmp_path):
    """`contact_model = "fem_line"` in a table scene file runs the DEM on the FEM-fitted line
    law (run_table and demfem run take it from the scene); an unknown law is refused naming
    the allowed ones; demfem assess refuses the line law (its stress model is for point
    loads)."""
    from demfem.assess import assess
    from demfem.scenes import AccumulationTable
    from demfem.dem.table_run import run_table

    small = AccumulationTable(width=0.1, length=0.1, tilted_wall_length=0.05, n_spheres=30,
                              contact_model="fem_line")
    path = small.to_toml(tmp_path / "line.toml")
    assert 'contact_model = "fem_line"' in path.read_text()
    back = AccumulationTable.from_toml(path)
    assert back == small
    run = run_table(back, 0.01, sample_interval=0.005)
    assert run.info["model"] == "fem_line" and run.parameters["contact_model"] == "fem_line"
    # an explicit model replaces the scene's and is recorded in the run's parameters
    other = run_table(back, 0.01, sample_interval=0.005, model="hertz_mindlin")
    assert other.parameters["contact_model"] == "hertz_mindlin"
    with pytest.raises(InvalidParameterError, match="contact_model.*hertz_reissner_mindlin"):
        AccumulationTable(contact_model="hertz")
    with pytest.raises(InvalidParameterError, match="point load"):
        assess(path, out=tmp_path / "a", duration=0.01, log=lambda _: None)
