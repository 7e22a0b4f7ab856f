"""One name for Young's modulus: the FEM bindings take ``young_modulus`` (documented) and
still accept the old ``youngs_modulus`` as an alias, the same solver either way."""
import numpy as np
import pytest

from demfem import _core as c

MM = 1e-3
Z = np.array([0.0, 4.0]) * MM
RI = np.array([4.7, 4.7]) * MM
RO = np.array([5.8, 5.8]) * MM


def test_tet_solver_and_functions_take_young_modulus_and_the_old_name():
    nodes, tets, _ = c.fem_tet_mesh(Z, RI, RO, 12, 1, 1.5 * MM)
    new = c.FemTetSolver(nodes, tets, young_modulus=45e9, poisson_ratio=0.2, density=2230.0)
    old = c.FemTetSolver(nodes, tets, youngs_modulus=45e9, poisson_ratio=0.2, density=2230.0)
    positional = c.FemTetSolver(nodes, tets, 45e9, 0.2, 2230.0)
    assert new.dt == old.dt == positional.dt
    u = np.full_like(nodes, 1e-6)
    assert np.array_equal(c.fem_element_stresses(nodes, tets, young_modulus=45e9,
                                                 poisson_ratio=0.2, u=u),
                          c.fem_element_stresses(nodes, tets, youngs_modulus=45e9,
                                                 poisson_ratio=0.2, u=u))
    with pytest.raises(TypeError, match="not both"):
        c.FemTetSolver(nodes, tets, 45e9, 0.2, 2230.0, youngs_modulus=45e9)
    with pytest.raises(TypeError, match="young_modulus"):
        c.FemTetSolver(nodes, tets, poisson_ratio=0.2, density=2230.0)
    with pytest.raises(TypeError, match="density"):
        c.FemTetSolver(nodes, tets, young_modulus=45e9, poisson_ratio=0.2)


def test_shell_solver_takes_young_modulus_and_the_old_name():
    sn, tri, th = c.fem_shell_mesh(Z, RI, RO, 12, 1.0 * MM)
    new = c.FemShellSolver(sn, tri, th, young_modulus=45e9, poisson_ratio=0.2, density=2230.0)
    old = c.FemShellSolver(sn, tri, th, youngs_modulus=45e9, poisson_ratio=0.2, density=2230.0)
    assert new.dt == old.dt
