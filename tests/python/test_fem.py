"""FEM bindings: meshes, explicit solver against the static solve, errors, VTK output."""
import numpy as np
import pytest

from demfem import _core as c
from demfem.errors import InvalidParameterError, ShapeError, UnstableTimeStepError

MM = 1e-3
Z = np.array([0, 54.5, 58.5, 61.0, 61.3, 64.0]) * MM
RI = np.array([4.7, 4.7, 1.9, 1.9, 1.9, 1.9]) * MM
RO = np.array([5.8, 5.8, 3.0, 3.0, 3.65, 3.65]) * MM


def test_cartridge_meshes():
    nodes, tets, q = c.fem_tet_mesh(Z, RI, RO, 24, 2, 1.0 * MM)
    assert nodes.shape[1] == 3 and tets.shape[1] == 4 and tets.max() < len(nodes)
    assert q["min_dihedral_deg"] > 5.0
    sn, tri, th = c.fem_shell_mesh(Z, RI, RO, 24, 1.0 * MM)
    assert tri.shape[1] == 3 and len(th) == len(tri)
    assert th[0] == pytest.approx(1.1 * MM)


def test_explicit_damped_tends_to_static_and_errors(tmp_path):
    nodes, tets, _ = c.fem_tet_mesh(np.array([0, 4 * MM]), RI[:2], RO[:2], 24, 2, 1.0 * MM)
    base = np.where(nodes[:, 2] < 1e-9)[0]
    fixed = np.array([[i, k] for i in base for k in range(3)])
    loads = np.zeros_like(nodes)
    top = nodes[:, 2] > 4 * MM - 1e-9
    loads[top, 2] = 10.0 / top.sum()
    u_static, reac = c.fem_solve_static(nodes, tets, 45e9, 0.2, loads, fixed, np.zeros(len(fixed)))
    assert reac.sum(axis=0)[2] == pytest.approx(-10.0)
    s = c.FemTetSolver(nodes, tets, 45e9, 0.2, 2230.0, rayleigh_alpha=2e6)
    s.set_prescribed(fixed, np.zeros(len(fixed)))
    s.set_loads(loads)
    seen = []
    s.run(3000, chunk=1000, progress=lambda n, t: seen.append((n, t)))
    assert [n for n, _ in seen] == [1000, 2000, 3000]
    # Heavily damped: the axial displacement settles on the static solve (0.1 %).
    top_u = s.displacement()[top, 2].mean()
    assert top_u == pytest.approx(u_static[top, 2].mean(), rel=1e-3)
    assert s.energy()["relative_balance_error"] < 1e-9
    s.write_vtu(tmp_path / "state.vtu")
    assert (tmp_path / "state.vtu").read_text().rstrip().endswith("</VTKFile>")
    with pytest.raises(UnstableTimeStepError):
        c.FemTetSolver(nodes, tets, 45e9, 0.2, 2230.0, dt=1e-3)
    with pytest.raises(ShapeError):
        c.FemTetSolver(nodes, tets[:, :3], 45e9, 0.2, 2230.0)
    with pytest.raises(InvalidParameterError):
        c.FemTetSolver(nodes, tets, 45e9, 0.7, 2230.0)
    p, vm = c.fem_stress_invariants(np.array([[100.0, 0, 0, 0, 0, 0]]))
    assert p[0, 0] == pytest.approx(100.0) and vm[0] == pytest.approx(100.0)
