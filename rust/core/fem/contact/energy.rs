//! The contact's energies: the elastic energy stored in the normal and stick springs and in
//! the no-tension springs, the work dissipated by friction, the work of the moving rigid
//! surfaces, and the work of all contact forces on the nodes, counted as the solvers count
//! external work (trapezoidal rule in displacement), so that the bookkeeping closes. J.

use rayon::prelude::*;

use super::{FemContact, NODE_CHUNK};

/// Energies of the contact model, J.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactEnergy {
    /// Elastic energy now stored in the normal and stick springs, J.
    pub elastic: f64,
    /// Energy now stored in the no-tension springs, J.
    pub springs: f64,
    /// Work dissipated by friction slip so far, J.
    pub friction_work: f64,
    /// Work done on the bodies by the moving rigid surfaces through contact so far, J.
    pub rigid_work: f64,
    /// Work done by all contact and spring forces on the nodes so far (trapezoidal rule in
    /// displacement, as the solver counts external work), J.
    pub contact_work: f64,
}

impl ContactEnergy {
    /// Closure of the contact bookkeeping: contact_work + rigid_work... rearranged as
    /// |W_c + E_el + E_springs + W_fric − W_rigid| (0 for exact time integration), J.
    pub fn bookkeeping_error(&self) -> f64 {
        (self.contact_work + self.elastic + self.springs + self.friction_work - self.rigid_work)
            .abs()
    }
}

impl FemContact {
    /// Add the work of the contact forces `force` (N per node) over the step that reached
    /// the displacement `u` (m), summed per fixed chunk (other nodes carry no force and add
    /// nothing); remember `u` and `force` for the next step.
    pub(super) fn account_work(&mut self, u: &[[f64; 3]], force: &[[f64; 3]]) {
        let partial: Vec<f64> = self
            .u_prev
            .par_chunks_mut(NODE_CHUNK)
            .zip(self.f_prev.par_chunks_mut(NODE_CHUNK))
            .zip(u.par_chunks(NODE_CHUNK))
            .zip(force.par_chunks(NODE_CHUNK))
            .map(|(((up, fp), u), f)| {
                let mut w = 0.0;
                for (((up, fp), u), f) in up.iter_mut().zip(fp.iter_mut()).zip(u).zip(f) {
                    for d in 0..3 {
                        w += 0.5 * (u[d] - up[d]) * (fp[d] + f[d]);
                    }
                    *up = *u;
                    *fp = *f;
                }
                w
            })
            .collect();
        let w: f64 = partial.iter().sum();
        if self.steps > 0 {
            self.energy.contact_work += w;
        }
    }
}
