"""The cartridge travels with the scene: a table scene's ``[cartridge]`` table sets the
equivalent sphere, the DEM's Reissner stiffness and the assessment's contact law."""
import dataclasses
import math

import pytest

from demfem.cartridge import CARTRIDGE_PRESETS, Cartridge
from demfem.errors import InvalidParameterError
from demfem.scenes.table import AccumulationTable

THIN = {"body_outer_diameter": 10.0e-3, "wall_thickness": 0.8e-3}
SMALL = dict(width=0.1, length=0.1, tilted_wall_length=0.05, n_spheres=30)


def test_default_table_carries_the_default_cartridge():
    t = AccumulationTable()
    sphere = Cartridge().equivalent_sphere()
    assert t.cartridge.geometry_dict() == CARTRIDGE_PRESETS["iso13926_3ml"]
    assert t.sphere_radius == sphere.radius and t.sphere_mass == sphere.mass


def test_scene_file_cartridge_sets_the_equivalent_sphere(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text('scene = "accumulation_table"\nn_spheres = 30\nwidth = 0.1\nlength = 0.1\ntilted_wall_length = 0.05\ndensity = 2340.0\n'
                    '[cartridge]\npreset = "iso13926_3ml"\nbody_outer_diameter = 0.010\n'
                    'wall_thickness = 0.0008\n')
    t = AccumulationTable.from_toml(path)
    c = Cartridge(**{**CARTRIDGE_PRESETS["iso13926_3ml"], **THIN})
    # the glass volume at the scene's density: m = rho V, r = (3 V / 4 pi)^(1/3)
    assert t.sphere_mass == pytest.approx(2340.0 * c.glass_volume, rel=1e-12)
    assert t.sphere_radius == pytest.approx((3 * c.glass_volume / (4 * math.pi)) ** (1 / 3),
                                            rel=1e-12)
    assert t.cartridge.wall_thickness == 0.8e-3 and t.cartridge.material.density == 2340.0
    # written back and read again: the same table
    again = tmp_path / "again.toml"
    t.to_toml(again)
    assert AccumulationTable.from_toml(again) == t
    # and through the JSON-able settings of a run
    assert AccumulationTable.from_dict(dataclasses.asdict(t)) == t


def test_the_dem_uses_the_scene_cartridge_wall():
    """The Reissner stiffness of the DEM law comes from the scene's cartridge: the run is
    bitwise the one with its wall given explicitly, and not the one with the default wall."""
    import numpy as np

    from demfem.dem import from_scene

    t = AccumulationTable(**SMALL, cartridge=Cartridge(**THIN))
    scene = t.build()
    c = t.cartridge

    def state(**kw):
        sim = from_scene(scene, **kw)
        sim.run_until(0.05)
        return np.asarray(sim.positions()), np.asarray(sim.velocities())

    own = state()
    explicit = state(shell_thickness=c.wall_thickness, shell_radius=c.body_mid_radius)
    default = state(shell_thickness=1.1e-3, shell_radius=Cartridge().body_mid_radius)
    assert all(np.array_equal(a, b) for a, b in zip(own, explicit))
    assert not np.array_equal(own[1], default[1])


def test_assess_calibrates_the_scene_cartridge(tmp_path):
    import json

    from demfem.assess import assess

    t = AccumulationTable(**SMALL, cartridge=Cartridge(**THIN))
    assess(t, out=tmp_path, quick=True, stop_after="calibration", log=lambda s: None)
    cal = json.loads((tmp_path / "calibration.json").read_text())
    assert cal["shell_thickness_m"] == 0.8e-3
    assert cal["mass_kg"] == pytest.approx(t.sphere_mass, rel=1e-12)


@pytest.mark.parametrize("values, match", [
    ({"sphere_radius": 0.009}, "sphere_radius"),
    ({"sphere_mass": 0.004}, "sphere_mass"),
    ({"cartridge": {"preset": "20ml"}}, "preset"),
    ({"cartridge": {"wall_thicknes": 1e-3}}, "wall_thicknes"),
    ({"cartridge": {"wall_thickness": "thin"}}, "wall_thickness"),
    ({"cartridge": {"wall_thickness": 7e-3}}, "wall_thickness"),
    ({"cartridge": 3}, "cartridge"),
])
def test_bad_cartridges_name_the_field(values, match):
    with pytest.raises(InvalidParameterError, match=match):
        AccumulationTable.from_dict(values)


def test_cluster_from_a_dem_run_takes_its_cartridge_and_load_case(tmp_path):
    """``demfem cluster --from RUN``: the load case from the run's onsets
    (CartridgeCluster.from_collisions) with the run's cartridge and friction."""
    from demfem.scenes.cluster import CartridgeCluster, cluster_from_run
    from demfem.dem.table_run import run_table

    t = AccumulationTable(**SMALL, cartridge=Cartridge(**THIN), friction=0.3)
    run = run_table(t, 0.3, 0.01)
    run.save(tmp_path / "table_run.npz")
    c = cluster_from_run(tmp_path, "max", springs=True)
    ref = CartridgeCluster.from_collisions(run.onsets, which="max")
    assert (c.v2, c.v3, c.direction_2_deg, c.direction_3_deg) == (
        ref.v2, ref.v3, ref.direction_2_deg, ref.direction_3_deg)
    assert c.cartridge.geometry_dict() == t.cartridge.geometry_dict()
    assert c.friction == 0.3 and c.springs
    with pytest.raises(Exception, match="no table run"):
        cluster_from_run(tmp_path / "nowhere")
