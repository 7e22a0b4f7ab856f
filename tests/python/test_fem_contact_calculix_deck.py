"""The CalculiX contact deck of benches/fem_contact_vs_calculix.py (text only; no ccx)."""
import importlib.util
from pathlib import Path

import numpy as np
import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "benches" / "fem_contact_vs_calculix.py"


def _load():
    spec = importlib.util.spec_from_file_location("fem_contact_vs_calculix", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


class _Glass:
    E, nu, density, name = 45e9, 0.22, 2230.0, "glass"


def _tiny_problem():
    """Two bodies of one positively oriented tet each; b moves at −0.2 m/s along x."""
    t = np.array([[0, 0, 0], [1e-3, 0, 0], [0, 1e-3, 0], [0, 0, 1e-3]], dtype=float)
    nodes = np.vstack([t, t + [2e-3, 0, 0]])
    tets = np.array([[0, 1, 2, 3], [4, 5, 6, 7]], dtype=np.int64)
    body = np.array([0, 0, 0, 0, 1, 1, 1, 1])
    vel = np.zeros((8, 3))
    vel[4:, 0] = -0.2
    return {"nodes": nodes, "tets": tets, "body": body, "velocity": vel, "outer": np.ones(8, bool)}


def _blocks(deck: str) -> dict:
    out, key = {}, None
    for line in deck.splitlines():
        if line.startswith("*"):
            key = line
            out.setdefault(key, [])
        elif key is not None and line.strip():
            out[key].append(line)
    return out


def test_c3d4_face_numbering_is_consistent():
    """S1 = 1-2-3, S2 = 1-4-2, S3 = 2-4-3, S4 = 3-4-1: on a positive tet every face so
    ordered has the same orientation (its right-hand normal points at the opposite node)."""
    m = _load()
    assert m.C3D4_FACES == ((0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0))
    x = _tiny_problem()["nodes"][:4]
    for loc in m.C3D4_FACES:
        opp = ({0, 1, 2, 3} - set(loc)).pop()
        a, b, c = x[list(loc)]
        assert np.dot(np.cross(b - a, c - a), x[opp] - a) > 0


def test_boundary_faces_drop_shared_faces():
    m = _load()
    nodes = np.array([[0, 0, 0], [1e-3, 0, 0], [0, 1e-3, 0], [0, 0, 1e-3], [1e-3, 1e-3, 1e-3]], float)
    tets = np.array([[0, 1, 2, 3], [1, 2, 3, 4]], dtype=np.int64)
    faces = m.boundary_faces(tets)
    assert len(faces) == 6
    shared = {1, 2, 3}
    assert all(set(m.face_nodes(tets, e, f)) != shared for e, f in faces)
    # tet 0's face opposite node 0 is S3 (2-4-3) and is the shared one
    assert (0, 3) not in faces and set(m.face_nodes(tets, 0, 3)) == shared


def test_penalty_slope_is_k_over_area():
    m = _load()
    p = _tiny_problem()
    faces = [(0, 1)]
    pen = m.penalty_slope(p, faces, 45e9, 0.22)
    K = 45e9 / (3 * (1 - 2 * 0.22))
    A, V = 0.5e-6, 1e-9 / 6
    assert pen["k_face_median_N_per_m"] == pytest.approx(K * A * A / V)
    assert pen["slope_median_N_per_m3"] == pytest.approx(K * A / V)
    assert m.lumped_mass(p["nodes"], p["tets"], 2230.0).sum() == pytest.approx(2 * 2230.0 * V)


def test_deck_text():
    m = _load()
    p = _tiny_problem()
    deck = m.write_deck(p, [(0, 1), (0, 2)], [(1, 3)], 1.5e14, 4e-5, _Glass(), output_every=5,
                        print_velocities=True)
    b = _blocks(deck)
    assert len(b["*NODE, NSET=NALL"]) == 8
    assert [ln.replace(" ", "") for ln in b["*ELEMENT, TYPE=C3D4, ELSET=EA"]] == ["1,1,2,3,4"]
    assert [ln.replace(" ", "") for ln in b["*ELEMENT, TYPE=C3D4, ELSET=EB"]] == ["2,5,6,7,8"]
    assert b["*NSET, NSET=NB"] == ["5, 6, 7, 8"]
    assert b["*SURFACE, NAME=SA, TYPE=ELEMENT"] == ["1, S1", "1, S2"]
    assert b["*SURFACE, NAME=SB, TYPE=ELEMENT"] == ["2, S3"]
    assert b["*CONTACT PAIR, INTERACTION=GLASS2GLASS, TYPE=NODE TO SURFACE"] == ["SB, SA"]
    assert "*SURFACE INTERACTION, NAME=GLASS2GLASS" in b
    assert float(b["*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR"][0]) == pytest.approx(1.5e14)
    assert b["*INITIAL CONDITIONS, TYPE=VELOCITY"] == ["NB, 1, -2.000000e-01"]
    assert float(b["*DYNAMIC, EXPLICIT"][0].split(",")[1]) == pytest.approx(4e-5)
    assert b["*CONTACT PRINT, SLAVE=SB, MASTER=SA, FREQUENCY=5"] == ["CF"]
    assert b["*NODE PRINT, NSET=NB, FREQUENCY=5"] == ["V"]
    assert "*FRICTION" not in b
    assert deck.rstrip().endswith("*END STEP")
    for line in deck.splitlines()[2:]:  # CalculiX 2.20 card limits (fields: data lines)
        assert len(line) <= 132
        if not line.startswith("*"):
            assert all(len(f.strip()) <= 20 for f in line.split(",")), line
    tiny = _blocks(m.write_deck(p, [(0, 1)], [(1, 3)], 1.5e14, 1e-15, _Glass()))
    assert float(tiny["*DYNAMIC, EXPLICIT"][0].split(",")[0]) <= 1e-15
    assert "*NODE PRINT, NSET=NB, FREQUENCY=5" not in tiny


def test_parsers():
    m = _load()
    dat = (" statistics for slave set SB, master set SA and time  0.5000000E-05\n\n"
           "   total surface force (fx,fy,fz) and moment about the origin (mx,my,mz)\n\n"
           "    1.500000E+00  0.000000E+00 -2.000000E-01  0.0E+00  0.0E+00  0.0E+00\n\n"
           " velocities (vx,vy,vz) for set NB and time  0.5000000E-05\n\n"
           "      5 -2.000000E-01  0.000000E+00  0.000000E+00\n"
           "      6 -1.000000E-01  1.000000E-03  0.000000E+00\n\n")
    t, f = m.parse_contact_forces(dat)
    assert t.tolist() == [5e-6] and f.tolist() == [[1.5, 0.0, -0.2]]
    tv, v = m.parse_velocity_blocks(dat, np.array([5, 6]))
    assert tv.tolist() == [5e-6] and v[0, 1].tolist() == [-0.1, 1e-3, 0.0]


def test_two_tube_problem_faces_outer_surface():
    """The benchmark's tubes: outer faces only (2 per quad of the outer surface), a facet
    of each facing the other across the 1.1 µm gap."""
    pytest.importorskip("demfem._core")
    m = _load()
    p = m.build_problem()
    fa, fb = m.outer_faces(p, 0), m.outer_faces(p, 1)
    n_z = len(np.unique(np.round(p["meshes"][0].nodes[:, 2], 9))) - 1
    assert len(fa) == len(fb) == 2 * p["n_theta"] * n_z
    xa = p["nodes"][p["body"] == 0, 0].max()
    xb = p["nodes"][p["body"] == 1, 0].min()
    r_face = 5.8e-3 * np.cos(np.pi / p["n_theta"])
    assert xa == pytest.approx(r_face, rel=1e-9) and xb - xa == pytest.approx(p["gap"], rel=1e-6)
    pen = m.penalty_slope(p, fa, 45e9, 0.22)
    assert pen["slope_min_N_per_m3"] == pytest.approx(pen["slope_max_N_per_m3"], rel=1e-6)
