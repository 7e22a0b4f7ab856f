"""Materials and the cartridge geometry, checked against closed forms of a hollow cylinder."""
import math

import numpy as np
import pytest

from demfem.cartridge import Cartridge
from demfem.errors import InvalidParameterError
from demfem.materials import BOROSILICATE_3_3, PAPER_GLASS, TYPE_I_TUBING_GLASS, Material


def test_presets_are_valid_glass():
    assert PAPER_GLASS.E == 45e9
    for m in (PAPER_GLASS, BOROSILICATE_3_3, TYPE_I_TUBING_GLASS):
        assert 2200 <= m.density <= 2400 and 0.15 <= m.nu <= 0.25
    # P-wave speed of glass is about 5 km/s
    assert 4000 < PAPER_GLASS.p_wave_speed < 6000


@pytest.mark.parametrize("kwargs, field", [
    ({"E": -1.0, "nu": 0.2, "density": 2230}, "E"),
    ({"E": 0.0, "nu": 0.2, "density": 2230}, "E"),
    ({"E": float("nan"), "nu": 0.2, "density": 2230}, "E"),
    ({"E": 1e9, "nu": 0.5, "density": 2230}, "nu"),
    ({"E": 1e9, "nu": -1.0, "density": 2230}, "nu"),
    ({"E": 1e9, "nu": 0.2, "density": float("inf")}, "density"),
    ({"E": 1e9, "nu": 0.2, "density": "heavy"}, "density"),
])
def test_material_rejects_bad_values(kwargs, field):
    with pytest.raises(InvalidParameterError, match=field) as exc:
        Material(**kwargs)
    assert isinstance(exc.value, ValueError)


def plain_tube(L=0.06, od=0.0116, t=0.0011):
    return Cartridge(body_outer_diameter=od, wall_thickness=t, length=L, shoulder_length=0.0,
                     neck_length=0.0, flange_length=0.0, flange_chamfer=0.0,
                     neck_outer_diameter=od, flange_outer_diameter=od)


def test_plain_tube_mass_properties_match_hollow_cylinder():
    L, ro, ri = 0.06, 0.0058, 0.0047
    tube = plain_tube(L)
    rho = tube.material.density
    M = rho * math.pi * (ro**2 - ri**2) * L
    mp = tube.mass_properties()
    assert mp.mass == pytest.approx(M, rel=1e-12)
    assert mp.center_of_mass[2] == pytest.approx(L / 2, rel=1e-12)
    assert mp.inertia[2, 2] == pytest.approx(0.5 * M * (ro**2 + ri**2), rel=1e-12)
    assert mp.inertia[0, 0] == pytest.approx(M * (3 * (ro**2 + ri**2) + L**2) / 12, rel=1e-12)


def test_default_cartridge_is_a_3ml_cartridge():
    c = Cartridge()
    z, ri, ro = c.stations()
    assert z[0] == 0 and z[-1] == pytest.approx(0.064)
    assert np.all(ro > ri) and np.all(np.diff(z) >= 0)
    # a 3 mL cartridge weighs about 5 g; the paper's equivalent sphere is about 1.6 cm
    assert 4.5e-3 < c.mass < 5.5e-3
    s = c.equivalent_sphere()
    assert 0.0155 < s.diameter < 0.0170
    assert s.mass == c.mass
    assert 4 / 3 * math.pi * s.radius**3 * c.material.density == pytest.approx(c.mass, rel=1e-12)
    # the centre of mass is below mid-length: the neck and flange are lighter than the body
    assert 0.025 < c.center_of_mass[2] < 0.032


def test_clump_matches_the_cartridge_within_one_percent():
    c = Cartridge()
    clump = c.bead_clump()
    assert clump.n_beads == 632
    mp, cp = c.mass_properties(), clump.mass_properties()
    assert cp.mass == pytest.approx(mp.mass, rel=1e-12)
    # centre of mass: clump centres are relative to the cartridge's
    assert np.linalg.norm(cp.center_of_mass) < 0.01 * c.length
    for i in range(3):
        assert cp.inertia[i, i] == pytest.approx(mp.inertia[i, i], rel=0.01)
    off = cp.inertia - np.diag(np.diag(cp.inertia))
    assert np.abs(off).max() < 1e-3 * cp.inertia[2, 2]
    # the envelope has the cartridge's outer diameter and length
    r_env = np.hypot(clump.centers[:, 0], clump.centers[:, 1]) + clump.radii
    assert r_env.max() == pytest.approx(c.body_outer_diameter / 2, rel=1e-9)
    z_abs = clump.centers[:, 2] + c.center_of_mass[2]
    assert (z_abs - clump.radii).min() == pytest.approx(0.0, abs=1e-12)
    assert (z_abs + clump.radii).max() == pytest.approx(c.length, abs=1e-12)


@pytest.mark.parametrize("n", [100, 632, 2000])
def test_clump_count_is_exact(n):
    assert Cartridge().bead_clump(n).n_beads == n


@pytest.mark.parametrize("kwargs, field", [
    ({"wall_thickness": 0.0}, "wall_thickness"),
    ({"wall_thickness": -1e-3}, "wall_thickness"),
    ({"wall_thickness": 6e-3}, "wall_thickness"),
    ({"length": 0.009}, "length"),
    ({"neck_outer_diameter": 2e-3}, "neck_outer_diameter"),
    ({"flange_outer_diameter": 5e-3}, "flange_outer_diameter"),
    ({"body_outer_diameter": float("nan")}, "body_outer_diameter"),
    ({"shoulder_length": -1e-3}, "shoulder_length"),
])
def test_cartridge_rejects_bad_dimensions(kwargs, field):
    with pytest.raises(InvalidParameterError, match=field):
        Cartridge(**kwargs)


def test_clump_rejects_bad_counts():
    with pytest.raises(InvalidParameterError, match="n_beads"):
        Cartridge().bead_clump(5)
    with pytest.raises(InvalidParameterError, match="n_beads"):
        Cartridge().bead_clump(63.2)
