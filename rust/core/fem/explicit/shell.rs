//! The explicit solver of thin shells ([`ShellExplicit`]): the integrator over the CST + DKT
//! triangles of a [`ShellModel`] ([`ShellElements`], 6 dofs per node: translations in m,
//! rotations in rad), undamped, at 0.9 × the element eigenvalue bound or a given step, with
//! fixed dofs held where they are. SI units.

use crate::error::Result;
use crate::fem::shell::{ShellElements, ShellModel};
use crate::fem::stable_step::StepBound;

use super::{Explicit, ExplicitConfig};

/// Explicit central-difference solver for a shell model (6 dofs per node).
pub type ShellExplicit = Explicit<ShellElements, 6>;

impl Explicit<ShellElements, 6> {
    /// Build from a model, the fixed dofs (node, dof 0–5; held at their value) and the time
    /// step `dt` (s; `None` = 0.9 × the element eigenvalue bound 2/√(max_e λ_max(M_e⁻¹K_e));
    /// a larger value is refused with [`crate::error::DemfemError::UnstableTimeStep`]).
    pub fn new(model: &ShellModel, fixed: &[(usize, usize)], dt: Option<f64>) -> Result<Self> {
        let mut config = ExplicitConfig::new(model.material);
        config.dt = dt;
        config.step_bound = StepBound::ElementEigenvalue;
        let mut s = Self::from_elements(ShellElements::new(model)?, config)?;
        s.hold(fixed)?;
        Ok(s)
    }
}
