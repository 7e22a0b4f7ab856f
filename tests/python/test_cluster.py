"""The seven-cartridge cluster (paper Figs. 10-13): scene geometry, ghost springs, load-case
picker, TOML files and a tiny run with every output. Small tubes, soft glass, few steps."""
from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from demfem.analysis.collisions import ONSET_DTYPE
from demfem.cartridge import Cartridge
from demfem.errors import InvalidParameterError, SettingsMismatchError
from demfem.fem import FemModel, Body
from demfem.materials import Material
from demfem.scenes import CartridgeCluster
from demfem.scenes.cluster import SITE_ANGLES_DEG

SOFT = Material(1e8, 0.22, 2230.0, name="soft glass")
TUBE = Cartridge.tube(11.6e-3, 1.1e-3, 10e-3, material=SOFT)


def small(**kw) -> CartridgeCluster:
    return CartridgeCluster.load_case("max", layers=1, cartridge=TUBE, **kw)


def test_hexagon_geometry_and_touching_neighbours():
    c = small()
    d = TUBE.body_outer_diameter
    xy = c.centres()
    assert np.allclose(xy[0], 0.0)
    for k, phi in enumerate(SITE_ANGLES_DEG):
        r = np.hypot(*xy[k + 1])
        ang = math.degrees(math.atan2(xy[k + 1, 1], xy[k + 1, 0]))
        assert (ang - phi + 180) % 360 - 180 == pytest.approx(0.0, abs=1e-9)
        gap = r - d
        if k < 2:  # 2 and 3: a small gap, they hit soon
            assert gap == pytest.approx(c.impact_gap)
        else:      # 4-7 touch 1
            assert 0.0 <= gap <= c.touch_tolerance
    # no pair of cartridges overlaps; ring neighbours are hexagon sides apart
    for i in range(7):
        for j in range(i + 1, 7):
            assert np.hypot(*(xy[i] - xy[j])) >= d
    # the meshes: node gap between 1 and each of 4-7 is the touch gap (columns face)
    p = c.parts()
    assert p.n_theta % 6 == 0
    for k in range(3, 7):
        dist = np.linalg.norm(p.meshes[0].nodes[:, None, :2] - p.meshes[k].nodes[None, ::7, :2],
                              axis=2).min()
        assert 0.0 <= dist <= c.touch_tolerance * 1.01
    # velocities: 2 along +x at V2, 3 at -60 degrees at V3, straight at 1
    v = np.asarray(c.velocities())
    assert np.allclose(v[1], (0.18, 0, 0))
    assert np.allclose(v[2, :2], 0.12 * np.array([0.5, -math.sqrt(3) / 2]))
    assert np.allclose(v[[0, 3, 4, 5, 6]], 0.0)
    for k in (1, 2):  # heading points at 1
        assert np.dot(v[k, :2], -xy[k]) == pytest.approx(np.linalg.norm(v[k]) * np.linalg.norm(xy[k]))
    # regions of 1: bottom / top half
    assert set(np.unique(p.regions_1)) == {0, 1}


def test_springs_layout_and_default_stiffness():
    from demfem.contact import ContactBody, k_eq

    c = small(springs=True)
    p = c.parts()
    assert [s.body for s in p.springs] == [3, 4, 5, 6]
    cb = ContactBody.from_cartridge(TUBE)
    assert p.spring_stiffness_per_contact == pytest.approx(k_eq(cb, cb, 0.18))
    for s in p.springs:
        k = s.body
        phi = math.radians(SITE_ANGLES_DEG[k - 1])
        out = np.array([math.cos(phi), math.sin(phi)])
        pos = p.meshes[k].nodes[s.nodes, :2] - p.centres[k]
        # springs sit on the outer side, anchors beyond their nodes, zero force at t = 0
        assert np.all(pos @ out > 0.4 * np.linalg.norm(pos, axis=1))
        arm = s.anchors - p.meshes[k].nodes[s.nodes]
        assert np.allclose(np.linalg.norm(arm, axis=1), s.rest_length)
        assert np.all(np.einsum("ij,ij->i", arm[:, :2], pos) > 0)
        # three ghost contacts of k_eq each, divided over their nodes
        assert np.sum(s.stiffness) == pytest.approx(3 * p.spring_stiffness_per_contact)


@pytest.mark.parametrize("direction, pushes", [(-1.0, False), (1.0, True)])
def test_ghost_springs_never_pull(direction, pushes):
    """Cartridge 5 alone with its ghost springs: moving inwards (away from the ghosts) the
    springs stay slack, moving outwards they push it back."""
    c = small(springs=True)
    p = c.parts()
    k = 4  # cartridge 5, on the +x side
    s = p.springs[1]
    assert s.body == k
    spring = dataclasses.replace(s, body=0)
    v = (0.05 * direction, 0.0, 0.0)
    m = FemModel([Body(p.meshes[k], velocity=v, name="5")], SOFT, springs=[spring])
    energy, vx = [], []
    for _ in range(12):
        m.run(60 * m.dt_step)
        energy.append(m.solver.contact_info()["spring_energy"])
        vx.append(m.body_velocity(0)[0])
    if pushes:
        # compressed, then pushed back out, and once free never pulled back
        assert max(energy) > 0 and energy[-1] == 0.0
        assert vx[-1] < -0.04
        assert vx[-1] == pytest.approx(vx[-2], rel=1e-9)
    else:
        assert max(energy) == 0.0
        assert vx[-1] == pytest.approx(-0.05, rel=1e-6)


def test_load_cases_and_bad_fields():
    mx, avg = CartridgeCluster.load_case("max"), CartridgeCluster.load_case("avg")
    assert (mx.v2, mx.v3) == (0.18, 0.12) and (avg.v2, avg.v3) == (0.05, 0.025)
    assert mx.belt_speed == 0.2 and mx.layers == 2 and mx.elements == "tet"
    bad = [({"v2": -0.1}, "v2"), ({"v3": 11.0}, "v3"), ({"belt_speed": 20.0}, "belt_speed"),
           ({"layers": 0}, "layers"), ({"layers": 5}, "layers"), ({"touch_gap": -1e-6}, "overlap"),
           ({"touch_gap": 1e-3}, "touch_gap"), ({"impact_gap": 0.0}, "impact_gap"),
           ({"elements": "hex"}, "elements"),
           ({"elements": "shell", "mass_scaling_dt": 1e-7}, "mass_scaling_dt"),
           ({"springs": "yes"}, "springs")]
    for kw, word in bad:
        with pytest.raises(InvalidParameterError, match=word):
            CartridgeCluster(**kw)
    with pytest.raises(InvalidParameterError, match="case"):
        CartridgeCluster.load_case("worst")


def _onsets(rows):
    t = np.zeros(len(rows), ONSET_DTYPE)
    for k, (i, j, time, vn, ang, zi, zj) in enumerate(rows):
        t[k] = (i, j, time, vn, vn * math.tan(ang), ang, zi, zj)
    return t


def test_from_collisions_picks_two_near_simultaneous_impacts():
    rows = [
        (0, 1, 0.100, 0.30, 0.0, 4, 3),     # sphere 0 hit hard ...
        (5, 6, 0.101, 0.90, 0.0, 2, 2),     # a strong impact, alone on both spheres
        (2, 0, 0.1005, 0.20, 0.2, 5, 5),    # ... and again by 2 within the window: candidate
        (3, 4, 0.200, 0.05, 0.1, 6, 6),
        (4, 7, 0.2008, 0.04, 0.3, 6, 6),    # sphere 4: a weak candidate
        (8, 9, 0.300, 0.50, 0.0, 1, 1),
        (8, 9, 0.3001, 0.40, 0.0, 1, 1),    # same partner twice: not a candidate
        (10, 11, 0.4, 0.6, 0.0, 3, 3),
        (10, 12, 0.5, 0.6, 0.0, 3, 3),      # outside the window
    ]
    t = _onsets(rows)
    c = CartridgeCluster.from_collisions(t, "max", window=2e-3)
    assert (c.v2, c.v3) == pytest.approx((0.30, 0.20))
    assert c.direction_2_deg == pytest.approx(0.0)
    assert c.direction_3_deg == pytest.approx(-60.0 + math.degrees(0.2))
    assert c.coordination == 5 and c.case == "dem_max"
    typ = CartridgeCluster.from_collisions(t, "typical", window=2e-3, layers=1)
    assert typ.v2 == pytest.approx(np.median([0.30, 0.05]))
    assert typ.v3 == pytest.approx(np.median([0.20, 0.04]))
    assert typ.layers == 1
    with pytest.raises(InvalidParameterError, match="no sphere"):
        CartridgeCluster.from_collisions(t[:2], "max")
    with pytest.raises(InvalidParameterError, match="which"):
        CartridgeCluster.from_collisions(t, "median")


def test_toml_round_trip_and_bad_files(tmp_path):
    c = small(springs=True, v2=0.15, direction_3_deg=-45.0, spring_stiffness=1e5)
    path = c.to_toml(tmp_path / "c.toml")
    back = CartridgeCluster.from_toml(path)
    assert back == c
    assert CartridgeCluster.from_toml(CartridgeCluster().to_toml(tmp_path / "d.toml")) == CartridgeCluster()
    for text, word in [("v2 = -1.0\n", "v2"), ("v3 = 12.0\n", "v3"), ("layers = 7\n", "layers"),
                       ("speed = 1.0\n", "unknown key 'speed'"),
                       ("[cartridge]\ncolour = 1\n", "unknown key 'colour'"),
                       ("[material]\nE = -1.0\n", "E"), ("touch_gap = -1e-5\n", "overlap"),
                       ("v2 = \n", "invalid TOML")]:
        p = tmp_path / "bad.toml"
        p.write_text(text)
        with pytest.raises(InvalidParameterError, match=word):
            CartridgeCluster.from_toml(p)


def test_tiny_run_writes_every_output(tmp_path):
    from demfem.fem.cluster_run import run_cluster

    c = small(springs=True)
    out = tmp_path / "run"
    s = run_cluster(c, duration=3e-4, out=out, progress=False, n_snapshots=4)
    for name in ("forces.csv", "cluster_forces.png", "cluster_sigma1.png",
                 "cluster_sigma1_through_wall.png", "cluster_sigma1_map_1-2_bottom.png",
                 "cluster_sigma1_map_1-3_top.png", "cluster.pvd", "summary.json", "run.npz",
                 "vtk/cluster_0000.vtu", "vtk/cluster_0003.vtu"):
        assert (out / name).exists(), name
    summary = json.loads((out / "summary.json").read_text())  # strict JSON
    assert summary["steps"] > 0 and summary["force_peaks"]["1-2_bottom"]["normal_N"] > 0
    header = (out / "forces.csv").read_text().splitlines()[0]
    assert header.startswith("time_s,fn_12_bottom_N,fn_12_top_N,ft_12_bottom_N")
    # the through-wall line runs from the local inner to the outer surface, also where the
    # contact sits on the shoulder (the element centroids lie strictly inside the wall)
    for pair in ("1-2", "1-3"):
        depth = summary["through_wall"][pair]["depth_fraction"]
        assert 0.0 < min(depth) and max(depth) < 1.0, (pair, depth)
        # taken at the pair's own force peak (the snapshot nearest it), never before it touched
        tw = summary["through_wall"][pair]
        peak_t = summary["force_peaks"][f"{pair}_{tw['region']}"]["time_s"]
        step = 3e-4 / 3
        assert abs(tw["time_s"] - peak_t) <= 0.5 * step + 1e-12, (pair, tw["time_s"], peak_t)
        raw = summary["force_peaks"][f"{pair}_{tw['region']}"]["raw_normal_N"]
        assert raw >= summary["force_peaks"][f"{pair}_{tw['region']}"]["normal_N"]
    assert summary["layers"] == c.layers
    # a rerun reuses the FEM run; other settings are refused
    (out / "cluster_sigma1.png").unlink()
    s2 = run_cluster(c, duration=3e-4, out=out, progress=False, n_snapshots=4)
    assert (out / "cluster_sigma1.png").exists() and s2["steps"] == s["steps"]
    with pytest.raises(SettingsMismatchError, match="v2"):
        run_cluster(dataclasses.replace(c, v2=0.1), duration=3e-4, out=out, progress=False,
                    n_snapshots=4)


def test_cli_errors(tmp_path, capsys):
    from demfem.cli import main

    assert main(["cluster", "--layers", "9", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("demfem: error:") and "layers" in err and err.count("\n") == 1
    assert main(["cluster", "--case", "worst", "--out", str(tmp_path)]) == 2
    bad = tmp_path / "bad.toml"
    bad.write_text("v2 = 20.0\n")
    assert main(["cluster", "--case", str(bad), "--out", str(tmp_path)]) == 2
    assert "v2" in capsys.readouterr().err


def test_energy_balance_through_the_impacts_with_springs():
    """The paper's cartridges, max case, ghost springs, 1 layer: through both impacts
    (about 0.11-0.14 ms) the energy balance closes within 0.5 % of the largest energy term.
    A node sliding onto a neighbouring facet deeper than it was used to take the new depth
    at once (1.0 % here, all of it one kick at t = 0.139 ms); the contact now carries the
    depth across the switch."""
    c = CartridgeCluster.load_case("max", layers=1, springs=True)
    m = c.build_model(c.parts())
    r = m.run(2.5e-4, progress=False)
    e = r.energy
    assert e[-1, 5] > 0 or np.max(e[:, 5]) > 0  # contact was active
    assert np.max(e[:, 6]) > 0  # the springs were loaded
    err = r.energy_balance_error()
    assert 0 <= err < 5e-3, err


def test_shell_cluster_geometry_and_tiny_run(tmp_path):
    """Shells: mid-surface columns face each other with the touch gap between the contact
    surfaces (the mid-surfaces are t + gap apart), the shells sit half their end thickness
    up, springs sit on the mid-surface columns, and a tiny run writes the outputs (σ1 on
    the inner and outer faces; no VTK files)."""
    from demfem.fem.cluster_run import run_cluster

    c = small(springs=True, elements="shell")
    p = c.parts()
    t = TUBE.wall_thickness
    for k in range(3, 7):
        dist = np.linalg.norm(p.meshes[0].nodes[:, None, :2] - p.meshes[k].nodes[None, :, :2],
                              axis=2).min()
        assert t <= dist <= t + c.touch_tolerance * 1.01
    assert p.meshes[0].nodes[:, 2].min() == pytest.approx(c.lift + 0.5 * t)
    assert [s.body for s in p.springs] == [3, 4, 5, 6]
    out = tmp_path / "shell"
    s = run_cluster(c, duration=3e-4, out=out, progress=False, n_snapshots=4)
    for name in ("forces.csv", "cluster_forces.png", "cluster_sigma1.png",
                 "cluster_sigma1_through_wall.png", "cluster_sigma1_map_1-2_bottom.png",
                 "summary.json", "run.npz"):
        assert (out / name).exists(), name
    assert s["elements"] == "shell" and s["steps"] > 0 and "layers" not in s
    assert s["force_peaks"]["1-2_bottom"]["normal_N"] > 0
    assert s["through_wall"]["1-2"]["depth_fraction"][0] == pytest.approx(0.0)
    assert s["through_wall"]["1-2"]["depth_fraction"][-1] == pytest.approx(1.0)
    # the VTK series for ParaView: the mid-surface triangles with σ1 on both faces
    import xml.etree.ElementTree as ET

    assert (out / "cluster.pvd").exists() and (out / "vtk" / "cluster_0003.vtu").exists()
    piece = ET.parse(out / "vtk" / "cluster_0003.vtu").getroot().find("UnstructuredGrid/Piece")
    assert int(piece.get("NumberOfCells")) == sum(len(m.triangles) for m in p.meshes)
    cells = [a.get("Name") for a in piece.find("CellData")]
    assert {"sigma1_bottom", "sigma1_top", "thickness"} <= set(cells)
    assert [a.get("Name") for a in piece.find("PointData")] == ["displacement",
                                                                 "contact_pressure"]
    top = piece.find("CellData/DataArray[@Name='sigma1_top']").text.split()
    assert len(top) == int(piece.get("NumberOfCells")) and max(map(float, top)) > 0


def test_shell_energy_balance_through_the_impacts_with_springs():
    """The paper's cartridges as shells, max case, ghost springs: through both impacts
    (about 0.11-0.14 ms) the energy balance closes within 1 % of the largest energy term."""
    c = CartridgeCluster.load_case("max", springs=True, elements="shell")
    m = c.build_model(c.parts())
    r = m.run(2.5e-4, progress=False)
    e = r.energy
    assert np.max(e[:, 5]) > 0  # contact was active
    assert np.max(e[:, 6]) > 0  # the springs were loaded
    fn, _ = r.pair_force("1", "2", regions=(0, 1))
    assert fn.max() > 1.0
    err = r.energy_balance_error()
    assert 0 <= err < 1e-2, err
