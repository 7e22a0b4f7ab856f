"""The CalculiX input-deck writer of benches/fem_vs_calculix.py on a tiny mesh."""
import importlib.util
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "benches" / "fem_vs_calculix.py"


def _load():
    spec = importlib.util.spec_from_file_location("fem_vs_calculix", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _tiny_mesh():
    # Two positively oriented tets sharing the face (1, 2, 3) (0-based).
    nodes = np.array([[0, 0, 0], [1e-3, 0, 0], [0, 1e-3, 0], [0, 0, 1e-3], [1e-3, 1e-3, 1e-3]], dtype=float)
    tets = np.array([[0, 1, 2, 3], [1, 2, 3, 4]], dtype=np.int64)
    for t in tets:
        a, b, c, d = nodes[t]
        assert np.dot(b - a, np.cross(c - a, d - a)) > 0
    return {"nodes": nodes, "tets": tets, "kick": np.array([4]), "fixed": np.array([0, 1, 2]), "probe": 4}


def _blocks(deck: str) -> dict:
    """Keyword line -> list of data lines following it."""
    out, key = {}, None
    for line in deck.splitlines():
        if line.startswith("*"):
            key = line
            out.setdefault(key, [])
        elif key is not None and line.strip():
            out[key].append(line)
    return out


def test_deck_counts_types_and_card_limits():
    m = _load()
    mesh = _tiny_mesh()
    deck = m.write_deck(mesh, total_time=1e-6)
    b = _blocks(deck)
    assert len(b["*NODE, NSET=NALL"]) == 5
    assert len(b["*ELEMENT, TYPE=C3D4, ELSET=EALL"]) == 2
    assert b["*ELEMENT, TYPE=C3D4, ELSET=EALL"][1].replace(" ", "") == "2,2,3,4,5"  # 1-based ids
    assert b["*NSET, NSET=NFIX"] == ["1, 2, 3"]
    assert b["*NSET, NSET=NKICK"] == ["5"]
    assert b["*NSET, NSET=NPROBE"] == ["5"]
    assert b["*BOUNDARY"] == ["NFIX, 1, 3"]
    assert b["*INITIAL CONDITIONS, TYPE=VELOCITY"] == ["NKICK, 1, -1.000000e+00"]
    assert b["*DYNAMIC, EXPLICIT"][0].split(",")[1].strip() == "1.000000000000e-06"
    assert deck.rstrip().endswith("*END STEP")
    # CalculiX 2.20 limits found the hard way: cards up to 132 characters, fields up to 20.
    for line in deck.splitlines()[2:]:  # after *HEADING and its free-text title
        assert len(line) <= 132
        assert all(len(f.strip()) <= 20 for f in line.split(",")), line
    # The initial increment never exceeds the step (ccx refuses that).
    tiny = _blocks(m.write_deck(mesh, total_time=1e-15))["*DYNAMIC, EXPLICIT"][0]
    assert float(tiny.split(",")[0]) <= float(tiny.split(",")[1])


def test_mesh_file_round_trip(tmp_path):
    m = _load()
    mesh = _tiny_mesh()
    lines = [f"{len(mesh['nodes'])} {len(mesh['tets'])}"]
    lines += [" ".join(f"{v:.17e}" for v in x) for x in mesh["nodes"]]
    lines += [" ".join(str(i) for i in t) for t in mesh["tets"]]
    lines += ["kick 1", "4", "fixed 3", "0", "1", "2", "probe 4"]
    (tmp_path / "mesh.txt").write_text("\n".join(lines) + "\n")
    r = m.read_mesh(tmp_path / "mesh.txt")
    assert np.array_equal(r["nodes"], mesh["nodes"]) and np.array_equal(r["tets"], mesh["tets"])
    assert list(r["kick"]) == [4] and list(r["fixed"]) == [0, 1, 2] and r["probe"] == 4


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX (ccx) not installed")
def test_ccx_runs_the_tiny_deck(tmp_path):
    m = _load()
    res = m.run_ccx(m.write_deck(_tiny_mesh(), total_time=1e-7), tmp_path, threads=1, timeout=60)
    assert res["courant_dt"] > 0
    assert res["time"] == pytest.approx(1e-7, rel=1e-6)
    assert res["probe_u"][0] < 0 and res["strain_energy"] > 0
    assert re.search(r"C3D4|elements", res["stdout"])


def _central_difference(mesh, dt, n_steps, v0=1.0):
    """Textbook lumped-mass central differences (demfem's scheme) on a small C3D4 mesh."""
    E, nu, rho = 45e9, 0.22, 2230.0
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    D = np.zeros((6, 6))
    D[:3, :3] = lam
    D[np.arange(3), np.arange(3)] += 2 * mu
    D[3:, 3:] = mu * np.eye(3)
    nodes, n = mesh["nodes"], len(mesh["nodes"])
    K, M = np.zeros((3 * n, 3 * n)), np.zeros(3 * n)
    for t in mesh["tets"]:
        X = nodes[t]
        J = np.array([X[1] - X[0], X[2] - X[0], X[3] - X[0]]).T
        V = np.linalg.det(J) / 6
        G = np.linalg.inv(J)
        g = np.vstack([-G.sum(0), G])
        B = np.zeros((6, 12))
        for a in range(4):
            gx, gy, gz = g[a]
            B[:, 3 * a : 3 * a + 3] = [[gx, 0, 0], [0, gy, 0], [0, 0, gz], [gy, gx, 0], [0, gz, gy], [gz, 0, gx]]
        idx = np.array([[3 * i, 3 * i + 1, 3 * i + 2] for i in t]).ravel()
        K[np.ix_(idx, idx)] += V * B.T @ D @ B
        M[idx] += rho * V / 4
    fixed = np.zeros(3 * n, bool)
    for i in mesh["fixed"]:
        fixed[3 * i : 3 * i + 3] = True
    u, v = np.zeros(3 * n), np.zeros(3 * n)
    for i in mesh["kick"]:
        v[3 * i] = -v0
    for k in range(n_steps):
        a = -(K @ u) / M
        a[fixed] = 0.0
        v = v + (0.5 * dt if k == 0 else dt) * a
        u = u + dt * v
    return u, 0.5 * u @ K @ u


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX (ccx) not installed")
def test_ccx_explicit_matches_textbook_central_differences(tmp_path):
    """After 20 increments of CalculiX's own step, ccx and the lumped-mass central-difference
    scheme (demfem's) agree on a 2-tet deck to 2e-3 in displacement and 5e-3 in strain energy;
    the first increments differ more (see the README, FEM section)."""
    m = _load()
    mesh = {**_tiny_mesh(), "nodes": _tiny_mesh()["nodes"] * 1e3}  # 1 m tets: step ≈ 1e-5 s
    probe = m.run_ccx(m.write_deck(mesh, total_time=1e-15), tmp_path / "p", threads=1, timeout=60)
    dt = probe["courant_dt"]
    res = m.run_ccx(m.write_deck(mesh, total_time=20 * dt), tmp_path / "r", threads=1, timeout=60)
    u, energy = _central_difference(mesh, dt, 20)
    assert res["probe_u"][0] == pytest.approx(u[12], rel=2e-3)
    assert res["probe_u"][2] == pytest.approx(u[14], rel=5e-3)
    assert res["strain_energy"] == pytest.approx(energy, rel=5e-3)
