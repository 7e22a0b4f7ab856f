"""Analyses on hand-built cases with known answers."""
import math

import numpy as np
import pytest

from demfem.analysis import (
    ONSET_DTYPE,
    bond_order_psi4,
    bond_order_psi6,
    collision_onset_table,
    contact_pairs_from_positions,
    coordination_from_positions,
    coordination_number,
    coordination_series,
    first_line_force,
    force_statistics,
    gentleness_score,
    mean_bond_order,
    mean_coordination,
    middle_mean,
    onset_histogram,
    onset_quantiles,
    particle_contact_force,
    period_of_oscillation,
    rank_setups,
    speed,
    spheres_riding_up,
    tag_mask,
    tagged_speed,
)
from demfem.errors import InvalidParameterError, ShapeError
from demfem.scenes import Tag

R = 0.008  # sphere radius, m


def square_lattice(n=8, spacing=2 * R, angle=0.0):
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    xy = spacing * np.column_stack([i.ravel(), j.ravel()]).astype(float)
    c, s = math.cos(angle), math.sin(angle)
    xy = xy @ np.array([[c, s], [-s, c]])
    return np.column_stack([xy, np.full(len(xy), R)])


def hexagonal_lattice(n=8, spacing=2 * R, angle=0.0):
    rows = []
    for j in range(n):
        for i in range(n):
            rows.append((spacing * (i + 0.5 * (j % 2)), spacing * j * math.sqrt(3) / 2))
    xy = np.array(rows)
    c, s = math.cos(angle), math.sin(angle)
    xy = xy @ np.array([[c, s], [-s, c]])
    return np.column_stack([xy, np.full(len(xy), R)])


def interior(positions, margin):
    """Spheres at least ``margin`` inside the lattice's bounding box."""
    xy = positions[:, :2]
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    return np.all((xy > lo + margin) & (xy < hi - margin), axis=1)


# ---- coordination ----------------------------------------------------------------------------

def test_square_packing_coordination():
    pos = square_lattice(8)
    pairs = contact_pairs_from_positions(pos, np.full(len(pos), R), gap_tolerance=1e-9)
    assert len(pairs) == 2 * 8 * 7  # horizontal + vertical bonds
    z = coordination_number(pairs, len(pos))
    inside = interior(pos, R)
    assert np.all(z[inside] == 4)
    # Corners have 2, other edge spheres 3.
    assert np.sort(z)[:4].tolist() == [2, 2, 2, 2]
    assert np.count_nonzero(z == 3) == 4 * 6
    assert mean_coordination(z, select=inside) == 4.0
    assert mean_coordination(z) == pytest.approx(2 * len(pairs) / len(pos))


def test_hexagonal_packing_coordination():
    pos = hexagonal_lattice(8)
    pairs = contact_pairs_from_positions(pos, np.full(len(pos), R), gap_tolerance=1e-9)
    z = coordination_number(pairs, len(pos))
    inside = interior(pos, 1.5 * R)
    assert inside.sum() == 36
    assert np.all(z[inside] == 6)


def test_coordination_from_positions_over_frames():
    square = square_lattice(3)
    frames = np.stack([square, square * [2.0, 2.0, 1.0]])  # the second frame pulled apart
    z = coordination_from_positions(frames, np.full(9, R), gap_tolerance=1e-9)
    assert z.shape == (2, 9)
    assert z[0].tolist() == [2, 3, 2, 3, 4, 3, 2, 3, 2] and z[1].sum() == 0
    assert coordination_from_positions(square, np.full(9, R), 1e-9)[4] == 4


def test_gap_tolerance_counts_near_contacts_only():
    pos = square_lattice(3, spacing=2 * R * 1.01)  # 1 % gap, as in the table's start packing
    radii = np.full(len(pos), R)
    assert len(contact_pairs_from_positions(pos, radii)) == 0
    assert len(contact_pairs_from_positions(pos, radii, gap_tolerance=0.02 * 2 * R)) == 12


def test_coordination_counts_each_contact_once_and_skips_removed():
    z = coordination_number(np.array([[0, 1], [1, 0], [1, 2]]), 4)
    assert z.tolist() == [1, 2, 1, 0]
    pos = square_lattice(2)
    pos[3] = np.nan  # a sphere that has left the table
    pairs = contact_pairs_from_positions(pos, np.full(4, R), gap_tolerance=1e-9)
    assert pairs.tolist() == [[0, 1], [0, 2]]
    series = coordination_series([pairs, np.zeros((0, 2), int)], 4)
    assert series.tolist() == [[2, 1, 1, 0], [0, 0, 0, 0]]
    present = np.array([True, True, True, False])
    assert mean_coordination(series, present=present).tolist() == pytest.approx([4 / 3, 0.0])


def test_mean_coordination_over_a_tag():
    tags = np.array([Tag.FIRST_LINE, Tag.NONE, Tag.FIRST_LINE, Tag.RECTANGULAR_CENTRE])
    z = np.array([[1, 5, 3, 4], [2, 6, 2, 6]])
    first = tag_mask(tags, Tag.FIRST_LINE)
    assert mean_coordination(z, select=first).tolist() == [2.0, 2.0]
    assert mean_coordination(z, select=np.array([3])).tolist() == [4.0, 6.0]
    assert math.isnan(mean_coordination(z[0], select=tag_mask(tags, Tag.UPPER_VERTEX)))


def test_bad_pairs_are_rejected():
    with pytest.raises(InvalidParameterError, match="cannot touch itself"):
        coordination_number(np.array([[0, 0]]), 2)
    with pytest.raises(InvalidParameterError, match=r"must be in \[0, 1\]"):
        coordination_number(np.array([[0, 2]]), 2)
    with pytest.raises(ShapeError):
        coordination_number(np.array([0, 1, 2]), 3)


# ---- packing order ---------------------------------------------------------------------------

@pytest.mark.parametrize("angle", [0.0, 0.3])
def test_psi4_is_one_on_square_and_psi6_zero(angle):
    pos = square_lattice(8, angle=angle)
    inside = interior(square_lattice(8), R)  # interior in lattice coordinates
    psi4 = bond_order_psi4(pos, cutoff=2 * R * 1.2)
    psi6 = bond_order_psi6(pos, cutoff=2 * R * 1.2)
    assert np.abs(psi4[inside]) == pytest.approx(np.ones(inside.sum()))
    assert np.abs(psi6[inside]) == pytest.approx(np.zeros(inside.sum()), abs=1e-12)
    # psi_4 of a lattice turned by a has the phase 4a.
    assert np.angle(psi4[inside][0]) == pytest.approx(4 * angle)
    assert mean_bond_order(psi4, select=inside) == pytest.approx(1.0)


def test_psi6_is_one_on_hexagonal_and_psi4_zero():
    pos = hexagonal_lattice(8)
    pairs = contact_pairs_from_positions(pos, np.full(len(pos), R), gap_tolerance=1e-9)
    inside = interior(pos, 1.5 * R)
    psi6 = bond_order_psi6(pos, pairs=pairs)
    psi4 = bond_order_psi4(pos, pairs=pairs)
    assert psi6[inside] == pytest.approx(np.ones(inside.sum()))
    assert np.abs(psi4[inside]) == pytest.approx(np.zeros(inside.sum()), abs=1e-12)
    # Every bond of a perfect hexagonal patch is a multiple of 60 deg, so even the edge spheres
    # (fewer bonds) have |psi_6| = 1; psi_4 of an edge sphere is not zero.
    assert mean_bond_order(psi6) == pytest.approx(1.0)
    assert mean_bond_order(psi4) > 0.05


def test_bond_order_of_isolated_sphere_is_nan():
    pos = np.array([[0.0, 0.0, R], [1.0, 0.0, R], [1.0 + 2 * R, 0.0, R]])
    psi = bond_order_psi6(pos, cutoff=2.5 * R)
    assert np.isnan(psi[0])
    assert psi[1] == pytest.approx(1.0) and psi[2] == pytest.approx(1.0)  # one bond along x
    with pytest.raises(InvalidParameterError, match="exactly one of pairs and cutoff"):
        bond_order_psi6(pos)


# ---- speeds and middle means -----------------------------------------------------------------

def test_speed_and_tagged_speed():
    v = np.array([[[3.0, 4.0, 0.0], [0.0, 0.0, 1.0], [1.0, 2.0, 2.0]],
                  [[0.0, 0.0, 0.0], [np.nan] * 3, [0.0, 0.6, 0.8]]])
    assert speed(v).tolist()[0] == [5.0, 1.0, 3.0]
    tags = np.array([Tag.FIRST_LINE, Tag.FIRST_LINE, Tag.TRIANGULAR_CENTRE])
    assert tagged_speed(v, tags, Tag.FIRST_LINE).tolist() == [3.0, 0.0]  # NaN sphere left out
    assert tagged_speed(v, tags, Tag.TRIANGULAR_CENTRE).tolist() == pytest.approx([3.0, 1.0])
    assert np.isnan(tagged_speed(v, tags, Tag.UPPER_VERTEX)).all()


def test_middle_mean_drops_extremes():
    values = np.array([100.0, 1, 2, 3, 4, 5, 6, 7, 8, -50])
    assert middle_mean(values, drop=0.1) == pytest.approx(4.5)  # mean of 1..8
    assert middle_mean(values, drop=0.0) == pytest.approx(np.mean(values))
    assert middle_mean(values, drop=0.25) == pytest.approx(np.mean([2, 3, 4, 5, 6, 7]))
    frames = np.array([[1.0, 2.0, 3.0, 4.0, 1000.0], [np.nan, 5.0, 5.0, 5.0, 5.0]])
    assert middle_mean(frames, drop=0.2).tolist() == [3.0, 5.0]
    assert middle_mean(frames, drop=0.2, axis=0)[1:4].tolist() == [3.5, 4.0, 4.5]
    with pytest.raises(InvalidParameterError, match=r"drop = 0.5: must be finite and in \[0, 0.5\)"):
        middle_mean(values, drop=0.5)


def test_spheres_riding_up():
    pos = np.array([[[0, 0, R], [0, 0, R + 0.001], [0, 0, 2.5 * R], [np.nan] * 3]])
    assert spheres_riding_up(pos, np.full(4, R)).tolist() == [1]
    assert spheres_riding_up(pos[0], np.full(4, R), tolerance=0.0005) == 2


# ---- forces and the gentlest set-up ----------------------------------------------------------

def test_particle_contact_force_net_and_sum():
    pairs = np.array([[0, 1], [1, 2]])
    f = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    net = particle_contact_force(pairs, f, 3, kind="net")
    assert net.tolist() == [[1, 0, 0], [-1, 2, 0], [0, -2, 0]]
    assert particle_contact_force(pairs, f, 3, kind="sum").tolist() == [1.0, 3.0, 2.0]
    with pytest.raises(InvalidParameterError, match="'net' or 'sum'"):
        particle_contact_force(pairs, f, 3, kind="max")


def test_first_line_force_averages_present_first_line_spheres():
    tags = np.array([Tag.FIRST_LINE, Tag.NONE, Tag.FIRST_LINE])
    forces = np.array([[[3.0, 4.0, 0.0], [100.0, 0, 0], [1.0, 0.0, 0.0]],
                       [[np.nan] * 3, [100.0, 0, 0], [0.0, 2.0, 0.0]]])
    assert first_line_force(forces, tags).tolist() == [3.0, 2.0]
    assert first_line_force(np.linalg.norm(forces, axis=2), tags).tolist() == [3.0, 2.0]


def test_gentleness_score_by_hand():
    stats = np.array([[1.0, 1.0, 1.0], [2.0, 4.0, 4.0], [4.0, 2.0, 2.0]])
    # Medians (2, 2, 2): scores (1/2+1/2+1/2)/3, (1+2+2)/3, (2+1+1)/3.
    assert gentleness_score(stats).tolist() == pytest.approx([0.5, 5 / 3, 4 / 3])
    assert gentleness_score(stats, weights=(0, 1, 0)).tolist() == pytest.approx([0.5, 2.0, 1.0])
    with pytest.raises(InvalidParameterError, match="not all zero"):
        gentleness_score(stats, weights=(0, 0, 0))


def test_rank_setups_prefers_neither_clogging_nor_spikes():
    t = np.linspace(0.0, 10.0, 1001)
    gentle = np.full_like(t, 1.0)
    clogging = 0.5 + 0.4 * t  # keeps growing, like the paper's A = 1 cm
    spiky = np.full_like(t, 0.8)
    spiky[::100] = 30.0  # rare violent events, like A = 7.5 cm
    table = rank_setups([t, t, t], [clogging, spiky, gentle], ["A=1cm", "A=7.5cm", "A=2cm"],
                        discard_before=1.0)
    assert table["label"].tolist()[0] == "A=2cm"
    assert table["rank"].tolist() == [1, 2, 3]
    assert np.all(np.diff(table["score"]) >= 0)
    gentle_row = table[table["label"] == "A=2cm"][0]
    assert gentle_row["mean"] == 1.0 and gentle_row["peak"] == 1.0
    stats = force_statistics(clogging[t >= 1.0], quantile=0.95)
    assert stats["peak"] == pytest.approx(4.5)
    assert stats["mean"] == pytest.approx(0.5 + 0.4 * 5.5)


# ---- collision onsets ------------------------------------------------------------------------

def test_collision_onset_table_by_hand():
    pairs = np.array([[0, 1], [2, 3], [4, 5]])
    times = np.array([0.3, 0.1, 0.2])
    v_rel = np.array([[1.0, 1.0, 0.0],          # 45 deg: v_n = 1, v_t = 1
                      [0.0, 0.5, 0.0],          # head on along an unnormalised normal
                      [0.1 * math.sqrt(3), 0.0, 0.1]])  # 30 deg: v_n = 0.1 sqrt3, v_t = 0.1
    normals = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [1.0, 0.0, 0.0]])
    z = np.array([[4, 5], [6, 6], [1, 2]])
    table = collision_onset_table(pairs, times, v_rel, normals, z)
    assert table.dtype == ONSET_DTYPE
    assert table["time"].tolist() == [0.1, 0.2, 0.3]
    assert table["i"].tolist() == [2, 4, 0]
    assert table["normal_speed"] == pytest.approx([0.5, 0.1 * math.sqrt(3), 1.0])
    assert table["tangential_speed"] == pytest.approx([0.0, 0.1, 1.0])
    assert np.degrees(table["impact_angle"]) == pytest.approx([0.0, 30.0, 45.0])
    assert table["coordination_j"].tolist() == [6, 2, 5]
    counts, edges = onset_histogram(table, "impact_angle", bins=2, value_range=(0, math.pi / 2))
    assert counts.tolist() == [2, 1] and edges[1] == pytest.approx(math.pi / 4)
    assert onset_quantiles(table, "normal_speed", q=(0.5,))[0] == pytest.approx(0.5)
    with pytest.raises(InvalidParameterError, match="must be one of"):
        onset_quantiles(table, "speed")
    with pytest.raises(InvalidParameterError, match="non-zero"):
        collision_onset_table(pairs, times, v_rel, np.zeros((3, 3)), z)


# ---- period ----------------------------------------------------------------------------------

@pytest.mark.parametrize("method", ["autocorrelation", "fft"])
def test_period_of_a_sine(method):
    t = np.arange(0.0, 20.0, 0.01)
    noise = np.random.default_rng(1).normal(scale=0.2, size=t.size)
    assert period_of_oscillation(t, np.sin(2 * np.pi * t / 2.0) + noise, method) == \
        pytest.approx(2.0, rel=0.01)
    assert period_of_oscillation(t, 5 + np.cos(2 * np.pi * t / 0.5), method) == \
        pytest.approx(0.5, rel=0.01)


def test_period_of_a_coordination_like_signal():
    # Coordination switching between 4 (square) and 6 (hexagonal) every half period T = 2 s.
    t = np.arange(0.0, 30.0, 0.02)
    z = np.where(np.sin(2 * np.pi * t / 2.0) > 0, 6.0, 4.0)
    assert period_of_oscillation(t, z) == pytest.approx(2.0, rel=0.01)


def test_period_of_constant_is_nan_and_bad_times_fail():
    t = np.arange(0.0, 5.0, 0.1)
    assert math.isnan(period_of_oscillation(t, np.full_like(t, 4.0)))
    with pytest.raises(InvalidParameterError, match="uniformly"):
        period_of_oscillation(t ** 2, np.sin(t))
