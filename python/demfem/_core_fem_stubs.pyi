# Stubs of the FEM part of demfem._core (rust/bindings/src/fem.rs). This branch has no
# _core.pyi yet: append this file's content below the existing stubs of _core.pyi when
# merging (it expects `import numpy as np` and `import numpy.typing as npt` at the top).
import os
from collections.abc import Callable

import numpy as np
import numpy.typing as npt

def fem_tet_mesh(
    z: npt.NDArray[np.float64],
    r_in: npt.NDArray[np.float64],
    r_out: npt.NDArray[np.float64],
    n_theta: int,
    n_layers: int,
    target_size: float,
    min_dihedral_deg: float = 5.0,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], dict[str, float]]:
    """Revolved linear-tet mesh of the axisymmetric body (stations z, radii in m):
    (nodes (N,3) m, tets (E,4), quality dict). Slivers below min_dihedral_deg are refused."""

def fem_shell_mesh(
    z: npt.NDArray[np.float64],
    r_in: npt.NDArray[np.float64],
    r_out: npt.NDArray[np.float64],
    n_theta: int,
    target_size: float,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], npt.NDArray[np.float64]]:
    """Mid-surface triangle mesh: (nodes (N,3) m, triangles (T,3), thickness (T,) m)."""

def fem_solve_static(
    nodes: npt.NDArray[np.float64],
    tets: npt.NDArray[np.int64],
    youngs_modulus: float,
    poisson_ratio: float,
    loads: npt.NDArray[np.float64],
    fixed_dofs: npt.NDArray[np.int64],
    fixed_values: npt.NDArray[np.float64],
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Sparse Cholesky solve K u = f: (u (N,3) m, reactions (N,3) N). E in Pa."""

def fem_element_stresses(
    nodes: npt.NDArray[np.float64],
    tets: npt.NDArray[np.int64],
    youngs_modulus: float,
    poisson_ratio: float,
    u: npt.NDArray[np.float64],
) -> npt.NDArray[np.float64]:
    """Element stresses (E,6) Pa in the order xx, yy, zz, yz, xz, xy."""

def fem_stress_invariants(
    s: npt.NDArray[np.float64],
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Principal stresses (M,3) Pa (σ1 ≥ σ2 ≥ σ3) and von Mises stress (M,) Pa."""

class FemTetSolver:
    """Explicit central-difference solver for linear tets (SI units)."""

    def __init__(
        self,
        nodes: npt.NDArray[np.float64],
        tets: npt.NDArray[np.int64],
        youngs_modulus: float,
        poisson_ratio: float,
        density: float,
        dt: float | None = None,
        safety_factor: float = 0.9,
        rayleigh_alpha: float = 0.0,
        rayleigh_beta: float = 0.0,
        mass_scaling_dt: float | None = None,
        certified_step: bool = True,
        energy_interval: int = 100,
    ) -> None: ...
    def set_prescribed(
        self,
        dofs: npt.NDArray[np.int64],
        values: npt.NDArray[np.float64],
        kind: str = "displacement",
        rise_time: float = 0.0,
    ) -> None: ...
    def set_loads(self, loads: npt.NDArray[np.float64], rise_time: float = 0.0) -> None: ...
    def set_extra_loads(self, loads: npt.NDArray[np.float64]) -> None: ...
    def set_initial_velocity(self, v: npt.NDArray[np.float64]) -> None: ...
    def set_initial_displacement(self, u: npt.NDArray[np.float64]) -> None: ...
    def run(
        self, n_steps: int, chunk: int = 1000, progress: Callable[[int, float], object] | None = None
    ) -> None: ...
    @property
    def dt(self) -> float: ...
    @property
    def dt_limit(self) -> float: ...
    @property
    def time(self) -> float: ...
    @property
    def steps(self) -> int: ...
    @property
    def added_mass(self) -> float: ...
    def displacement(self) -> npt.NDArray[np.float64]: ...
    def velocity(self) -> npt.NDArray[np.float64]: ...
    def energy(self) -> dict[str, float]: ...
    def element_stresses(self) -> npt.NDArray[np.float64]: ...
    def nodal_stresses(self) -> npt.NDArray[np.float64]: ...
    def write_vtu(self, path: str | os.PathLike[str]) -> None: ...
