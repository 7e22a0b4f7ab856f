//! The explicit solver of linear tetrahedra ([`ExplicitSolver`]): the integrator over
//! [`TetElements`], with Rayleigh damping, mass scaling and the certified step of
//! [`ExplicitConfig`]. SI units.

use crate::error::Result;
use crate::fem::mesh::TetMesh;
use crate::fem::tet_elements::TetElements;
use crate::fem::tet_forces::TetForceKernel;

use super::{Explicit, ExplicitConfig};

/// Explicit central-difference solver for a tetrahedral mesh (3 translations per node).
pub type ExplicitSolver = Explicit<TetElements, 3>;

impl Explicit<TetElements, 3> {
    /// Build the solver: precompute elements, lumped masses (with optional mass scaling)
    /// and the time step. Fails on bad input or a `config.dt` above the critical-step bound.
    pub fn new(mesh: &TetMesh, config: ExplicitConfig) -> Result<Self> {
        config.validate()?;
        let elements = TetElements::new(mesh, config.material, config.mass_scaling_dt)?;
        Self::from_elements(elements, config)
    }

    /// Mass added by mass scaling, kg.
    pub fn added_mass(&self) -> f64 {
        self.elements.added_mass()
    }

    /// The element-force kernel (for K·x products, e.g. eigenvalue estimates).
    pub fn kernel_mut(&mut self) -> &mut TetForceKernel {
        self.elements.kernel_mut()
    }
}
