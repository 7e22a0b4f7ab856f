//! No-tension springs from nodes to fixed "ghost" points: a spring of stiffness k and rest
//! length L₀ pushes its node away from the ghost with k (L₀ − l) while its length l is
//! below L₀ and never pulls (the confinement of neighbours that are not meshed).

use crate::error::{check_positive, DemfemError, Result};

use super::vec3::{add, norm, scale, sub};
use super::FemContact;

/// One no-tension spring.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoTensionSpring {
    /// Node index.
    pub node: usize,
    /// The fixed ghost point, m.
    pub anchor: [f64; 3],
    /// Stiffness, N/m (> 0).
    pub stiffness: f64,
    /// Rest length, m (> 0): shorter than this the spring pushes.
    pub rest_length: f64,
}

impl NoTensionSpring {
    /// Check the values against a mesh of `n_nodes` nodes.
    pub fn validate(&self, n_nodes: usize) -> Result<()> {
        if self.node >= n_nodes {
            return Err(DemfemError::ShapeMismatch {
                field: "spring node".into(),
                detail: format!("node {} out of range ({n_nodes} nodes)", self.node),
            });
        }
        if !self.anchor.iter().all(|x| x.is_finite()) {
            return Err(DemfemError::InvalidParameter {
                field: "spring anchor".into(),
                value: format!("{:?}", self.anchor),
                allowed: "finite".into(),
            });
        }
        check_positive("spring stiffness", self.stiffness)?;
        check_positive("spring rest_length", self.rest_length)?;
        Ok(())
    }

    /// Force on the node (N) and stored energy (J) with the node at `x`.
    pub fn force(&self, x: [f64; 3]) -> ([f64; 3], f64) {
        let r = sub(x, self.anchor);
        let l = norm(r);
        if l >= self.rest_length || !(l > 0.0) {
            return ([0.0; 3], 0.0);
        }
        let c = self.rest_length - l;
        (
            scale(r, self.stiffness * c / l),
            0.5 * self.stiffness * c * c,
        )
    }
}

impl FemContact {
    /// Add the forces of the no-tension springs into `force` (N per node), and, when
    /// `check`, their stiffness into the Gershgorin bounds; returns their stored energy, J.
    pub(super) fn spring_forces(&mut self, force: &mut [[f64; 3]], check: bool) -> f64 {
        let mut spring_energy = 0.0;
        for s in &self.springs {
            let (f, e) = s.force(self.x[s.node]);
            force[s.node] = add(force[s.node], f);
            spring_energy += e;
            if check && e > 0.0 {
                self.gershgorin[s.node] += s.stiffness / self.mass[s.node];
            }
        }
        spring_energy
    }
}
