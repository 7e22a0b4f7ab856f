"""The accumulation-table scene: start packing, tags, walls, gate, scene files and validation."""
import dataclasses
import math
from pathlib import Path

import numpy as np

from demfem.cartridge import Cartridge
import pytest

from demfem.analysis import (
    bond_order_psi4,
    bond_order_psi6,
    contact_pairs_from_positions,
    coordination_number,
)
from demfem.errors import DemfemIOError, InvalidParameterError
from demfem.scenes import AccumulationTable, Tag, wall_displacement, wall_velocity

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def table():
    return AccumulationTable()


@pytest.fixture(scope="module")
def scene(table):
    return table.build()


# ---- start configuration ---------------------------------------------------------------------

def test_default_counts_and_arrays(table, scene):
    assert scene.n_particles == 840
    assert scene.positions.shape == (840, 3)
    sphere = Cartridge().equivalent_sphere()  # the scene's spheres are the default cartridge's
    assert np.all(scene.radii == sphere.radius) and np.all(scene.masses == sphere.mass)
    assert np.all(scene.positions[:, 2] == sphere.radius)  # resting on the belt
    assert scene.tags.shape == (840,) and scene.tags.dtype == np.int32
    assert table.rows_in_rectangle == 20


def test_no_overlaps_and_inside_walls(table, scene):
    pos, r = scene.positions, table.sphere_radius
    pairs = contact_pairs_from_positions(pos, scene.radii, gap_tolerance=0.5 * table.pitch)
    distance = np.linalg.norm(pos[pairs[:, 0]] - pos[pairs[:, 1]], axis=1)
    assert distance.min() == pytest.approx(table.pitch)  # 1 % gap, nothing closer
    x, y = pos[:, 0], pos[:, 1]
    assert np.all((x > r) & (x < table.x_end - r) & (y > r) & (y < table.width - r))
    theta = math.radians(table.tilted_wall_angle_deg)
    beyond = x > table.length
    # Below the tilted wall's line by more than a radius.
    y_wall = table.width - (x[beyond] - table.length) * math.tan(theta)
    assert np.all((y_wall - y[beyond]) * math.cos(theta) > r)
    scene.check_start_positions()


def test_square_packing_upstream_hexagonal_in_triangle(table, scene):
    pos = scene.positions
    pairs = contact_pairs_from_positions(pos, scene.radii,
                                         gap_tolerance=1.5 * table.packing_gap * 2 * table.sphere_radius)
    z = coordination_number(pairs, len(pos))
    square = pos[:, 0] < table.length
    tri = ~square
    # Interior spheres: away from walls and from the interface by more than a pitch.
    p = table.pitch
    inner_square = square & (pos[:, 0] > pos[square, 0].min() + 1.5 * p) & (pos[:, 0] < table.length - p) \
        & (pos[:, 1] > 1.5 * p) & (pos[:, 1] < table.width - 1.5 * p)
    assert inner_square.sum() > 400
    assert np.all(z[inner_square] == 4)
    # Hexagonal spheres with six neighbours: a good share of the triangle, none in the square.
    assert np.count_nonzero(z[tri] == 6) > 0.5 * tri.sum()
    assert np.all(z[square] <= 4)
    psi4 = bond_order_psi4(pos, pairs=pairs)
    psi6 = bond_order_psi6(pos, pairs=pairs)
    assert np.abs(psi4[inner_square]) == pytest.approx(np.ones(inner_square.sum()))
    six = tri & (z == 6)
    assert np.abs(psi6[six]) == pytest.approx(np.ones(six.sum()))


def test_tags_present_and_in_their_regions(table, scene):
    pos, tags = scene.positions, scene.tags
    p, L, W = table.pitch, table.length, table.width
    counts = {t: int(np.count_nonzero(tags == t)) for t in Tag}
    assert counts[Tag.TRIANGULAR_CENTRE] == counts[Tag.RECTANGULAR_CENTRE] == 1
    assert counts[Tag.UPPER_VERTEX] == counts[Tag.LOWER_VERTEX] == 1
    assert counts[Tag.FIRST_LINE] == table.rows_in_rectangle
    first = pos[tags == Tag.FIRST_LINE]
    assert np.allclose(first[:, 0], L - p / 2)  # the square column at the interface
    (tri,) = pos[tags == Tag.TRIANGULAR_CENTRE]
    (rect,) = pos[tags == Tag.RECTANGULAR_CENTRE]
    (upper,) = pos[tags == Tag.UPPER_VERTEX]
    (lower,) = pos[tags == Tag.LOWER_VERTEX]
    hexagonal = pos[pos[:, 0] > L]
    square = pos[pos[:, 0] < L]
    assert tri[0] > L and np.linalg.norm(tri[:2] - hexagonal[:, :2].mean(axis=0)) < p
    assert rect[0] < L - p and np.linalg.norm(rect[:2] - square[:, :2].mean(axis=0)) < p
    assert upper[0] > L and upper[1] > W - 2 * p and upper[0] < L + p
    assert lower[0] > L and lower[1] < p and lower[0] < L + p


# ---- walls, gate, effects --------------------------------------------------------------------

def test_effects_follow_parameters(table):
    assert table.effects == ("gravity", "belt", "moving_walls", "friction", "rotation", "damping")
    more = dataclasses.replace(table, planar=True, rolling_resistance=0.01)
    assert more.effects[-2:] == ("planar", "rolling_resistance")
    still = dataclasses.replace(table, gate_amplitude=0.0)
    assert "moving_walls" not in still.effects
    assert still.build().wall("gate")["motion"] == {"kind": "fixed"}


def test_walls_belt_and_gate(table, scene):
    names = [w["name"] for w in scene.walls]
    assert names == ["belt", "back", "lower_side", "upper_side", "tilted", "gate"]
    belt = scene.wall("belt")
    assert belt["kind"] == "plane" and belt["surface_velocity"].tolist() == [0.2, 0.0, 0.0]
    assert [w["name"] for w in scene.walls if w["motion"]["kind"] != "fixed"] == ["gate"]
    gate = scene.wall("gate")
    motion = gate["motion"]
    assert motion["direction"].tolist() == [0.0, 1.0, 0.0]
    assert motion["amplitude"] == 0.02 and motion["period"] == 2.0
    # The opening is w0 at t = 0, w0 + A at T/4, w0 - A at 3T/4.
    assert gate["vertices"][:, 1].min() == pytest.approx(table.opening_width)
    for t, expected in ((0.0, 0.04), (0.5, 0.06), (1.5, 0.02)):
        edge = gate["vertices"][:, 1].min() + wall_displacement(motion, t)[1]
        assert edge == pytest.approx(expected)
        assert table.opening_width_at(t) == pytest.approx(expected)
    assert wall_velocity(motion, 0.0)[1] == pytest.approx(0.02 * 2 * math.pi / 2.0)
    # Even at its lowest the gate still reaches past the tilted wall's tip: no gap.
    lowest_top = gate["vertices"][:, 1].max() - motion["amplitude"]
    assert lowest_top >= table.tilted_wall_gap
    tilted = scene.wall("tilted")
    assert tilted["vertices"][1, :2].tolist() == pytest.approx([table.x_end, table.tilted_wall_gap])
    assert table.x_end == pytest.approx(0.70 + 0.36 * math.cos(math.radians(45)))
    assert scene.removal["point"][0] == pytest.approx(table.x_end + table.sphere_radius)
    assert scene.gravity.tolist() == [0.0, 0.0, -9.81]
    assert scene.materials["glass"]["young_modulus"] == 45e9
    assert scene.materials["glass"]["poisson_ratio"] == 0.22
    assert scene.materials["glass"]["density"] == 2230.0
    assert scene.materials["glass"]["friction"] == 0.2
    assert scene.materials["glass"]["restitution"] == 0.5


def test_harmonic_motion_with_phase():
    motion = {"kind": "harmonic", "direction": np.array([0.0, 1.0, 0.0]), "amplitude": 0.02,
              "period": 2.0, "phase": math.pi / 2}
    assert wall_displacement(motion, 0.0).tolist() == pytest.approx([0.0, 0.02, 0.0])
    assert wall_displacement(motion, 1.0).tolist() == pytest.approx([0.0, -0.02, 0.0])
    assert wall_velocity(motion, 0.5)[1] == pytest.approx(-0.02 * math.pi)
    assert wall_displacement({"kind": "fixed"}, 3.0).tolist() == [0.0, 0.0, 0.0]
    t = AccumulationTable(gate_phase=math.pi / 2)
    assert t.opening_width_at([0.0, 1.0]).tolist() == pytest.approx([0.06, 0.02])


def test_refeed_sites_are_free_and_upstream(table):
    scene = dataclasses.replace(table, refeed=True).build()
    sites = scene.refeed["sites"]
    assert sites.shape == (table.rows_in_rectangle, 3)
    gaps = np.linalg.norm(sites[:, None, :] - scene.positions[None, :, :], axis=2)
    assert gaps.min() >= 2 * table.sphere_radius
    assert np.all(sites[:, 0] < scene.positions[:, 0].min())
    assert table.build().refeed is None


def test_clogging_allowed_and_reported(table):
    narrow = dataclasses.replace(table, gate_amplitude=0.03)  # opening 1 cm at its narrowest
    assert narrow.min_opening_width == pytest.approx(0.01)
    assert narrow.clogging_possible and not table.clogging_possible
    assert narrow.build().n_particles == 840


@pytest.mark.parametrize("amplitude", [0.01, 0.02, 0.05, 0.075])
def test_paper_amplitude_sweep_fits_one_geometry(amplitude):
    # The recipe of the module docstring: narrowest opening 2 cm, tilted wall 0.24 m at 45 deg.
    t = AccumulationTable(gate_amplitude=amplitude, opening_width=amplitude + 0.02,
                          tilted_wall_length=0.24)
    assert t.min_opening_width == pytest.approx(0.02)
    assert t.max_opening_width <= t.tilted_wall_gap
    assert t.build().n_particles == 840


def test_description_save_load_round_trip(tmp_path, table):
    scene = dataclasses.replace(table, refeed=True).build()
    path = scene.save(tmp_path / "scene.npz")
    back = type(scene).load(path)
    assert np.array_equal(back.positions, scene.positions)
    assert np.array_equal(back.tags, scene.tags) and back.tags.dtype == np.int32
    assert back.effects == scene.effects and back.tag_names == scene.tag_names
    assert back.materials == scene.materials and back.planar is False
    gate, gate_back = scene.wall("gate"), back.wall("gate")
    assert np.array_equal(gate_back["vertices"], gate["vertices"])
    assert np.array_equal(gate_back["motion"]["direction"], gate["motion"]["direction"])
    assert gate_back["motion"]["period"] == 2.0
    assert back.wall("belt")["top_view"] is None
    assert np.array_equal(back.refeed["sites"], scene.refeed["sites"])
    assert np.array_equal(back.removal["normal"], [1.0, 0.0, 0.0])
    assert AccumulationTable(**back.parameters) == dataclasses.replace(table, refeed=True)
    back.check_start_positions()
    assert [p.name for p in tmp_path.iterdir()] == ["scene.npz"]


def test_overlapping_start_positions_are_refused(scene):
    pos = scene.positions.copy()
    pos[1] = pos[0] + [0.001, 0, 0]
    with pytest.raises(InvalidParameterError, match=r"invalid positions: spheres 0 and 1 overlap"):
        dataclasses.replace(scene, positions=pos).check_start_positions()
    pos = scene.positions.copy()
    # The lowest sphere of the first line, pushed halfway into the lower side wall (it stays
    # clear of its neighbours).
    k = int(np.flatnonzero(scene.tags == Tag.FIRST_LINE)[0])
    pos[k, 1] = 0.006
    with pytest.raises(InvalidParameterError, match=rf"positions\[{k}\].*'lower_side'"):
        dataclasses.replace(scene, positions=pos).check_start_positions()


# ---- scene files -----------------------------------------------------------------------------

def test_toml_round_trip(tmp_path, table):
    custom = dataclasses.replace(table, gate_amplitude=0.015, gate_period=1.0, belt_velocity=0.3,
                                 young_modulus=1e7, planar=True, refeed=True, n_spheres=700)
    path = custom.to_toml(tmp_path / "scene.toml")
    assert AccumulationTable.from_toml(path) == custom
    assert AccumulationTable.from_toml(EXAMPLES / "table_default.toml") == dataclasses.replace(
        table, refeed=True)
    assert not list(tmp_path.glob(".*tmp"))  # the atomic write left no temporary file


def test_toml_missing_keys_take_defaults(tmp_path):
    path = tmp_path / "short.toml"
    path.write_text("gate_amplitude = 0.01\ngate_period = 1\n")
    t = AccumulationTable.from_toml(path)
    assert (t.gate_amplitude, t.gate_period, t.n_spheres) == (0.01, 1.0, 840)


def write(tmp_path, text):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("text, pattern", [
    ("gate_amplitude = -0.01",
     r"invalid gate_amplitude = -0.01: must be finite and in \[0, 0.04\)"),
    ("gate_period = 0.0", r"invalid gate_period = 0.0: must be finite and in \(0, inf\)"),
    ("gate_period = -2", r"invalid gate_period = -2.0: must be finite and in \(0, inf\)"),
    ("belt_velocity = nan", r"invalid belt_velocity = nan: must be finite and in \[0, inf\)"),
    ("young_modulus = inf", r"invalid young_modulus = inf: must be finite"),
    ("gate_amplitude = 0.04",
     r"invalid gate_amplitude = 0.04: must be finite and in \[0, 0.04\) .*never close"),
    ("opening_width = 0.07",
     r"invalid gate_amplitude = 0.02: must be finite and in \[0, 0.0154\d*\] .*tilted wall"),
    ("opening_width = 0.1", r"invalid opening_width = 0.1: must be finite and in \(0, 0.0854"),
    ("tilted_wall_length = 0.5", r"invalid tilted_wall_length = 0.5: must be finite and in "
                                 r"\(0, 0.48\d*\) .*end above the lower side wall"),
    ("n_spheres = 5000", r"invalid n_spheres = 5000: must be in \[252, 1052\]"),
    ("n_spheres = 840.5", r"invalid n_spheres = 840.5: must be a whole number"),
    ("friction = \"high\"", r"invalid friction = 'high': must be a real number"),
    ("planar = 1", r"invalid planar = 1: must be true or false"),
    ("restitution = 1.5", r"invalid restitution = 1.5: must be finite and in \(0, 1\]"),
    ("poisson_ratio = 0.5", r"invalid poisson_ratio = 0.5: must be finite and in \(-1, 0.5\)"),
    ("tilted_wall_angle_deg = 90", r"invalid tilted_wall_angle_deg = 90.0: must be finite and "
                                   r"in \(0, 90\)"),
    ("wall_height = 0.01", r"invalid wall_height = 0.01: must be finite and in \[0.0161749, inf\)"),
    ("scene = \"hopper\"", r"invalid scene = 'hopper' in .*bad.toml: must be 'accumulation_table'"),
])
def test_validation_errors_name_field_value_and_range(tmp_path, text, pattern):
    with pytest.raises(InvalidParameterError, match=pattern):
        AccumulationTable.from_toml(write(tmp_path, text))


def test_unknown_key_is_named_with_the_allowed_ones(tmp_path):
    with pytest.raises(InvalidParameterError) as info:
        AccumulationTable.from_toml(write(tmp_path, "gate_amplitude = 0.02\namplitude = 0.02\n"))
    message = str(info.value)
    assert "unknown key 'amplitude'" in message and "bad.toml" in message
    assert "allowed keys: scene, n_spheres, sphere_radius" in message
    assert "gate_amplitude" in message and "packing_gap" in message


def test_file_errors(tmp_path):
    with pytest.raises(InvalidParameterError, match="invalid TOML in"):
        AccumulationTable.from_toml(write(tmp_path, "gate_period = = 2"))
    with pytest.raises(InvalidParameterError, match=r"invalid \[gate\] .*flat"):
        AccumulationTable.from_toml(write(tmp_path, "[gate]\namplitude = 0.02"))
    with pytest.raises(DemfemIOError, match="missing.toml"):
        AccumulationTable.from_toml(tmp_path / "missing.toml")


def test_constructor_validates_too():
    with pytest.raises(InvalidParameterError, match="gate_period"):
        AccumulationTable(gate_period=float("nan"))
    with pytest.raises(InvalidParameterError, match="sphere_radius"):
        AccumulationTable(sphere_radius=-0.008)
    with pytest.raises(dataclasses.FrozenInstanceError):
        AccumulationTable().gate_period = 1.0
