"""Tilted and lifted hitters in the seven-cartridge cluster: the sign convention, a start
that is clear by exactly the impact gap (on the meshes, not only on the placement's own
samples), the first contact at the intended end of cartridge 1, and bad input."""
from __future__ import annotations

import math

import numpy as np
import pytest

from demfem.cartridge import Cartridge
from demfem.errors import InvalidParameterError
from demfem.fem.cluster_placement import clearance, envelope_points
from demfem.materials import Material
from demfem.scenes import CartridgeCluster

SOFT = Material(1e8, 0.22, 2230.0, name="soft glass")
TUBE = Cartridge.tube(11.6e-3, 1.1e-3, 10e-3, material=SOFT)


def _radial_gap_to_1(nodes: np.ndarray, c: CartridgeCluster) -> float:
    """Smallest horizontal distance of nodes from 1's axis minus 1's outer radius at their
    height (nodes beside 1 only): the exact clearance of the nodes against 1's surface."""
    z = nodes[:, 2] - c.lift
    beside = (z >= 0) & (z <= c.cartridge.length)
    _, ro = c.cartridge.radii_at(z[beside])
    return float(np.min(np.hypot(nodes[beside, 0], nodes[beside, 1]) - ro))


def test_upright_default_is_unchanged():
    c = CartridgeCluster.load_case("max", layers=1)
    assert c.is_upright()
    assert np.array_equal(c.centres(), c.sites())
    for p, (x, y) in zip(c.placements(), c.sites()):
        assert np.array_equal(p.rotation, np.eye(3))
        assert p.translation.tolist() == [x, y, c.lift]


@pytest.mark.parametrize("tilt", [-3.0, 3.0])
def test_sign_convention_and_clear_start_on_the_mesh(tilt):
    """Positive tilt leans the top forward along the heading (2's heading is +x: its axis
    gains +x), negative leans it back. The tilted tet mesh of 2 starts exactly impact_gap
    from 1's surface (its nodes on the exact outer profile), nothing sits below the belt,
    and every pair is apart."""
    c = CartridgeCluster.load_case("max", layers=1, tilt_2_deg=tilt, tilt_3_deg=tilt)
    pl = c.placements()
    axis2 = pl[1].axis
    assert axis2 == pytest.approx([math.sin(math.radians(tilt)), 0.0,
                                   math.cos(math.radians(tilt))], abs=1e-12)
    # 3 heads at -60 degrees: its axis leans along (cos -60, sin -60) for tilt > 0
    h3 = np.array([0.5, -math.sqrt(3) / 2])
    assert np.dot(pl[2].axis[:2], h3) == pytest.approx(math.sin(math.radians(tilt)), abs=1e-12)
    p = c.parts()
    for k in (1, 2):
        nodes = p.meshes[k].nodes
        assert _radial_gap_to_1(nodes, c) == pytest.approx(c.impact_gap, abs=1e-9)
        assert nodes[:, 2].min() == pytest.approx(c.lift, abs=1e-12)
    # every pair apart (the placement's envelope check, both ways)
    pts = envelope_points(c.cartridge, c.n_theta())
    for i in range(7):
        for j in range(i + 1, 7):
            assert clearance(pl[i], pl[j], c.cartridge, c.n_theta(), points=pts) > 0
    # where they touch first: the bottom edge (tilt < 0) or the shoulder edge (tilt > 0)
    first = c.first_contact()
    r = 0.5 * c.diameter
    for k in ("2", "3"):
        z = first[k]["z_m"]
        if tilt < 0:
            assert 0.0 <= z <= 2 * r * math.sin(math.radians(abs(tilt))) + 1e-9
        else:
            body = c.cartridge.body_length
            assert body * math.cos(math.radians(tilt)) - 1e-6 <= z <= body + 1e-9
        assert first[k]["gap_m"] == pytest.approx(c.impact_gap, abs=1e-9)


def test_offset_lifts_and_moves_the_impact_up():
    c = CartridgeCluster.load_case("max", elements="shell", tilt_2_deg=-2.0, offset_2_z=0.01)
    # the lowest glass point of 2 is lift + offset (its placement), 3 stands on the belt
    low2 = c.placements()[1].apply(envelope_points(c.cartridge, c.n_theta()))[:, 2].min()
    assert low2 == pytest.approx(c.lift + 0.01, abs=1e-12)
    assert c.placements()[2].translation[2] == c.lift
    z = c.first_contact()["2"]["z_m"]
    assert 0.01 <= z <= 0.01 + c.diameter * math.sin(math.radians(2.0)) + 1e-9
    # on the shell mesh: the lowest contact surface (half the end thickness below the
    # mid-surface nodes) is at least lift + offset above the belt
    p = c.parts()
    nodes = p.meshes[1].nodes
    bottom = np.unique(p.meshes[1].triangles[np.any(
        nodes[p.meshes[1].triangles][:, :, 2] <= nodes[:, 2].min() + 1e-3, axis=1)])
    half = 0.5 * c.cartridge.wall_thickness
    assert nodes[bottom, 2].min() - half >= c.lift + 0.01 - 1e-5


@pytest.mark.parametrize("tilt, region", [(-5.0, 0), (5.0, 1)])
def test_first_contact_is_at_the_leading_end(tilt, region):
    """A short soft tube tilted back (bottom leads) touches 1 first in its bottom half
    (region 0), tilted forward (top leads) in its top half; the other half stays free
    through the first impact."""
    c = CartridgeCluster.load_case("max", cartridge=TUBE, elements="shell", tilt_2_deg=tilt,
                                   v3=0.0)
    m = c.build_model(c.parts())
    r = m.run(3e-4, progress=False)
    f_lead, _ = r.pair_force("1", "2", regions=(region,))
    f_other, _ = r.pair_force("1", "2", regions=(1 - region,))
    assert f_lead.max() > 0.05  # N; it hit
    on = np.flatnonzero(f_lead > 0)
    # at the expected time: the gap closed at 0.18 m/s (20 um in 0.11 ms), within 20 us
    assert abs(r.time[on[0]] - c.impact_gap / c.v2) < 2e-5
    assert f_other.max() == 0.0


def test_bad_tilt_and_offset_are_refused(tmp_path):
    with pytest.raises(InvalidParameterError, match=r"tilt_2_deg = nan.*\[-10, 10\]"):
        CartridgeCluster(tilt_2_deg=float("nan"))
    with pytest.raises(InvalidParameterError, match=r"tilt_3_deg = 11.0.*\[-10, 10\]"):
        CartridgeCluster(tilt_3_deg=11.0)
    with pytest.raises(InvalidParameterError, match=r"offset_2_z = -0.001.*belt"):
        CartridgeCluster(offset_2_z=-1e-3)
    with pytest.raises(InvalidParameterError, match=r"offset_3_z = 0.05.*\[0, 0.032\]"):
        CartridgeCluster(offset_3_z=0.05)
    with pytest.raises(InvalidParameterError, match="offset_2_z"):
        CartridgeCluster(offset_2_z=float("inf"))
    # both leaning forward by 10 degrees: their tops meet in front of 1
    with pytest.raises(InvalidParameterError, match=r"tilt_2_deg = 10.0.*cartridges 2 and 3 "
                                                    r"would overlap"):
        CartridgeCluster(tilt_2_deg=10.0, tilt_3_deg=10.0)
    # a scene file carries the fields; a bad one names the field
    c = CartridgeCluster(tilt_2_deg=-2.0, offset_3_z=0.004, elements="shell")
    path = c.to_toml(tmp_path / "tilted.toml")
    assert CartridgeCluster.from_toml(path) == c
    bad = tmp_path / "bad.toml"
    bad.write_text('scene = "cartridge_cluster"\ntilt_3_deg = -12.5\n')
    with pytest.raises(InvalidParameterError, match="tilt_3_deg"):
        CartridgeCluster.from_toml(bad)


def test_cli_reads_tilt_from_a_scene_file(tmp_path, capsys):
    from demfem.cli import main

    bad = tmp_path / "bad.toml"
    bad.write_text('scene = "cartridge_cluster"\ntilt_2_deg = "steep"\n')
    assert main(["cluster", "--case", str(bad), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "tilt_2_deg" in err and err.count("\n") == 1


def test_cli_runs_a_tilted_scene_file(tmp_path, capsys):
    """demfem cluster --case SCENE.toml with a tilt: the run is of the tilted scene (its
    settings record it) and 2's force is on 1's bottom half only."""
    from demfem.cli import main

    c = CartridgeCluster.load_case("max", cartridge=TUBE, elements="shell", tilt_2_deg=-5.0,
                                   v3=0.0)
    scene = c.to_toml(tmp_path / "tilted.toml")
    out = tmp_path / "out"
    assert main(["cluster", "--case", str(scene), "--duration", "3e-4", "--snapshots", "2",
                 "--out", str(out)]) == 0
    capsys.readouterr()
    import json

    record = json.loads((out / "settings.json").read_text())
    assert record["settings"]["cluster"]["tilt_2_deg"] == -5.0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["force_peaks"]["1-2_bottom"]["normal_N"] > 0
    assert summary["force_peaks"]["1-2_top"]["normal_N"] == 0.0
    assert summary["submodel"]["pairs"]["1-2_bottom"]["geometry"] == "crossed"
