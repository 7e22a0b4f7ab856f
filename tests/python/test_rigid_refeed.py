"""Re-feeding the rigid engine: RigidSimulation.reinsert_body, demfem.dem.refeed_removed_bodies
and run(sim, t, refeed=...) for full-shape cartridges: the population stays whole, bodies
come back upright at the upstream sites, the result is bitwise the same on 1 and 2 threads,
and bad input names the field."""
import numpy as np
import pytest

from demfem import dem, rigid
from demfem.cartridge import Cartridge
from demfem.errors import InvalidParameterError
from demfem.scenes import AccumulationTable

GLASS = dem.material(45e9, 0.22, 2230.0, friction=0.2, restitution=0.5)
EFFECTS = ["gravity", "belt", "friction", "rotation", "damping"]
ZC = float(Cartridge().center_of_mass[2])
PITCH = Cartridge().body_outer_diameter + 2e-4
ROWS = 6


def _belt(columns: int, threads: int = 1) -> tuple[rigid.RigidSimulation, dict]:
    """`columns` x 6 upright cartridges moving with a belt at 0.3 m/s between two side walls
    towards an outlet one pitch downstream of the last column; the re-feed sites are one
    column upstream of the first."""
    y = (np.arange(ROWS) - 2.5) * PITCH
    xx, yy = np.meshgrid(np.arange(columns) * PITCH, y, indexing="ij")
    x = np.column_stack([xx.ravel(), yy.ravel(), np.full(xx.size, ZC + 2e-5)])
    v = np.tile([0.3, 0.0, 0.0], (len(x), 1))
    half = 0.5 * ROWS * PITCH + 1e-3
    walls = [dem.plane((0, 0, 0), (0, 0, 1), surface_velocity=(0.3, 0, 0)),
             dem.plane((0, -half, 0), (0, 1, 0)), dem.plane((0, half, 0), (0, -1, 0))]
    sim = rigid.RigidSimulation(x, rigid.upright(len(x)), rigid.shape_dict("revolution"), GLASS,
                                walls, EFFECTS, velocities=v, expected_max_speed=1.0,
                                removal_plane=((columns * PITCH, 0.0, 0.0), (-1.0, 0.0, 0.0)),
                                threads=threads)
    refeed = {"sites": np.column_stack([np.full(ROWS, -PITCH), y, np.full(ROWS, ZC + 1e-6)]),
              "velocity": np.array([0.3, 0.0, 0.0])}
    return sim, refeed


def test_refed_belt_keeps_its_body_count_and_puts_bodies_back_upstream():
    sim, refeed = _belt(4)
    n = len(sim)
    counts = []
    for t in np.arange(0.01, 0.1001, 0.01):
        dem.run(sim, t, refeed=refeed, chunk_steps=500)
        counts.append(int(sim.alive().sum()))
    removed_t, removed = sim.removals()
    back_t, back = sim.reinsertions()
    # the outlet took whole columns; every one came back in the same chunk
    assert len(removed) >= 2 * ROWS, len(removed)
    assert counts == [n] * len(counts), counts
    np.testing.assert_array_equal(np.sort(back), np.sort(removed))
    assert np.all(back_t >= removed_t.min())
    # each came back upstream of where it left, at a re-feed site's y, and rides the belt
    x = sim.positions()
    assert np.all(x[back, 0] < 4 * PITCH)
    assert np.all(np.min(np.abs(x[back, 1][:, None] - refeed["sites"][None, :, 1]), axis=1)
                  < 0.5 * PITCH)
    assert np.degrees(np.max(sim.tilt_angles())) < 5.0
    assert np.max(np.linalg.norm(sim.velocities(), axis=1)) < 0.5


def test_refeed_puts_a_body_back_upright_at_the_first_free_site():
    sim, refeed = _belt(2)
    sim.remove_body(3)
    sim.remove_body(5)
    assert dem.refeed_removed_bodies(sim, refeed["sites"], (0.3, 0.0, 0.0)) == 2
    x = sim.positions()
    # the lowest index takes the first site, the next the second (the first is taken now)
    np.testing.assert_array_equal(x[3], refeed["sites"][0])
    np.testing.assert_array_equal(x[5], refeed["sites"][1])
    np.testing.assert_array_equal(sim.orientations()[[3, 5]], rigid.upright(2))
    np.testing.assert_array_equal(sim.velocities()[5], [0.3, 0.0, 0.0])
    np.testing.assert_array_equal(sim.angular_velocities()[5], [0.0, 0.0, 0.0])
    assert list(sim.reinsertions()[1]) == [3, 5]
    # a site on top of a body is not free: the engine refuses it and the next is taken
    sim.remove_body(4)
    blocked = np.vstack([x[0], refeed["sites"][2]])
    assert dem.refeed_removed_bodies(sim, blocked) == 1
    np.testing.assert_array_equal(sim.positions()[4], refeed["sites"][2])
    # no free site: the body waits
    sim.remove_body(6)
    assert dem.refeed_removed_bodies(sim, x[:1]) == 0
    assert not sim.alive()[6]


def test_small_table_refeed_sites_take_cartridges():
    table = AccumulationTable(n_spheres=36, length=0.12, width=0.12, tilted_wall_length=0.1,
                              opening_width=0.03, gate_amplitude=0.01, wall_height=0.07,
                              particle="revolution", refeed=True)
    description = table.build()
    sim = rigid.from_scene(description)
    refeed = rigid.refeed_of(description)
    np.testing.assert_allclose(refeed["sites"][:, 2], ZC + 1e-6)
    np.testing.assert_array_equal(refeed["sites"][:, :2], description.refeed["sites"][:, :2])
    sim.remove_body(0)
    rigid.run(sim, 5e-3, refeed=refeed)
    assert sim.alive().all()
    assert list(sim.reinsertions()[1]) == [0]
    assert sim.positions()[0, 0] == pytest.approx(refeed["sites"][0, 0], abs=1e-4)
    assert np.degrees(sim.tilt_angles()[0]) < 0.5
    assert rigid.refeed_of(AccumulationTable(**{**description.parameters,
                                                "refeed": False}).build()) is None


def _refed_state(threads: int) -> bytes:
    sim, refeed = _belt(11, threads)
    dem.run(sim, 0.045, refeed=refeed, chunk_steps=500)
    assert len(sim.reinsertions()[1]) >= ROWS
    return b"".join(np.ascontiguousarray(a).tobytes() for a in (
        sim.positions(), sim.velocities(), sim.orientations(), sim.angular_velocities(),
        sim.alive(), *sim.reinsertions()))


def test_refed_belt_is_bitwise_the_same_on_1_and_2_threads():
    # 66 bodies: the contact geometry runs in blocks on 2 threads (64 bodies or more)
    assert _refed_state(1) == _refed_state(2)


def test_reinsert_body_refuses_bad_input_naming_the_field():
    sim, refeed = _belt(2)
    free, up, still = tuple(refeed["sites"][0]), (1.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    with pytest.raises(InvalidParameterError, match=r"invalid i = 0 \(alive\)"):
        sim.reinsert_body(0, free, up, still)
    with pytest.raises(InvalidParameterError, match="invalid i = 99"):
        sim.reinsert_body(99, free, up, still)
    with pytest.raises(InvalidParameterError, match="invalid i = -1"):
        sim.reinsert_body(-1, free, up, still)
    sim.remove_body(1)
    for args, field in [((free, up, (np.nan, 0.0, 0.0)), "velocity"),
                        (((np.inf, 0.0, 0.0), up, still), "position"),
                        ((free, (2.0, 0.0, 0.0, 0.0), still), "orientation"),
                        ((free, (np.nan, 0.0, 0.0, 0.0), still), "orientation")]:
        with pytest.raises(InvalidParameterError, match=f"invalid {field}"):
            sim.reinsert_body(1, *args)
    # on top of body 0: refused naming the position and the body in the way
    with pytest.raises(InvalidParameterError, match="invalid position.*overlap body 0"):
        sim.reinsert_body(1, tuple(sim.positions()[0]), up, still)
    assert sim.reinsert_body(1, tuple(sim.positions()[0]), up, still, if_free=True) is False
    # through the belt: the wall is named
    with pytest.raises(InvalidParameterError, match="overlap wall 0"):
        sim.reinsert_body(1, (free[0], free[1], ZC - 1e-4), up, still)
    assert not sim.alive()[1]
    with pytest.raises(InvalidParameterError, match="sites"):
        dem.refeed_removed_bodies(sim, [[0.0, np.nan, 0.0]])
    with pytest.raises(InvalidParameterError, match="velocity"):
        dem.refeed_removed_bodies(sim, refeed["sites"], (0.0, 0.0))
    assert sim.reinsert_body(1, free, up, still) is True
