//! Initial velocity, gravity and contact for the explicit shell solver [`ShellExplicit`].
//!
//! Contact acts on the translational dofs only: the [`FemContact`] (built with
//! [`FemContact::new_shell`], two-sided faces offset by half the thickness) gets the
//! nodes' translations u and velocities v^{n−½} and returns nodal forces, which enter the
//! step as external forces (so the solver's exact discrete balance E_kin + E_int − W_ext =
//! E_0 counts their work). The stable step is certified for the element bound plus the
//! contact's eigenvalue allowance (Weyl's inequality on M^{-½}(K + K_c)M^{-½}, K_c acting
//! on translations with the translational masses); an automatic step is reduced to fit, a
//! fixed one above the new limit is refused, as in [`crate::fem::explicit`].

use crate::error::{DemfemError, Result};
use crate::fem::contact::{ContactEnergy, FemContact};
use crate::fem::stable_step::critical_step_from_eigenvalue;

use super::ShellExplicit;

/// Energies of an explicit shell run with contact, J.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ShellEnergy {
    /// Kinetic energy ½ v^{n−½}·M v^{n+½}, J.
    pub kinetic: f64,
    /// Elastic strain energy of the shells, J.
    pub internal: f64,
    /// Work of the applied loads (gravity included) and of the reactions of fixed dofs, J.
    pub load_work: f64,
    /// Elastic energy stored in the contact penalty and stick springs, J.
    pub contact_elastic: f64,
    /// Energy stored in the no-tension springs, J.
    pub springs: f64,
    /// Work dissipated by friction, J.
    pub friction_work: f64,
    /// Work done on the shells by moving rigid surfaces (the belt), J.
    pub rigid_work: f64,
    /// Kinetic plus internal energy at t = 0, J.
    pub initial: f64,
}

impl ShellEnergy {
    /// |E_kin + E_int + E_contact + E_springs + W_friction − W_rigid − W_loads − E_0|, J.
    pub fn balance_error(&self) -> f64 {
        (self.kinetic + self.internal + self.contact_elastic + self.springs + self.friction_work
            - self.rigid_work
            - self.load_work
            - self.initial)
            .abs()
    }
    /// Balance error relative to the largest of the terms (0 when all vanish).
    pub fn relative_balance_error(&self) -> f64 {
        let scale = [
            self.kinetic,
            self.internal,
            self.load_work,
            self.contact_elastic,
            self.springs,
            self.friction_work,
            self.rigid_work,
            self.initial,
        ]
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()));
        if scale > 0.0 {
            self.balance_error() / scale
        } else {
            0.0
        }
    }
}

impl ShellExplicit {
    fn require_start(&self, what: &str) -> Result<()> {
        if self.steps > 0 {
            return Err(DemfemError::Effect(format!(
                "{what} can only be set before the first step"
            )));
        }
        Ok(())
    }

    /// Initial velocity v^0 (m/s, rad/s), 6 values per node; before the first step only.
    /// Fixed dofs must get 0.
    pub fn set_initial_velocity(&mut self, v: &[f64]) -> Result<()> {
        self.require_start("initial velocity")?;
        if v.len() != self.v.len() || v.iter().any(|x| !x.is_finite()) {
            return Err(DemfemError::ShapeMismatch {
                field: "v0".into(),
                detail: format!("{} finite values expected", self.v.len()),
            });
        }
        if let Some(d) = (0..v.len()).find(|&d| !self.free[d] && v[d] != 0.0) {
            return Err(DemfemError::InvalidParameter {
                field: "v0".into(),
                value: format!("{:e} at fixed dof {} of node {}", v[d], d % 6, d / 6),
                allowed: "0 at fixed dofs".into(),
            });
        }
        self.v.copy_from_slice(v);
        Ok(())
    }

    /// Initial velocity `v` (m/s) of every node's translation (a rigid translation).
    pub fn set_uniform_velocity(&mut self, v: [f64; 3]) -> Result<()> {
        let mut all = vec![0.0; self.v.len()];
        for (d, x) in all.iter_mut().enumerate() {
            if d % 6 < 3 && self.free[d] {
                *x = v[d % 6];
            }
        }
        self.set_initial_velocity(&all)
    }

    /// Add the weight of the lumped masses in the acceleration field `g` (m/s²) to the loads.
    pub fn add_gravity(&mut self, g: [f64; 3]) -> Result<()> {
        if g.iter().any(|x| !x.is_finite()) {
            return Err(DemfemError::InvalidParameter {
                field: "gravity".into(),
                value: format!("{g:?}"),
                allowed: "finite".into(),
            });
        }
        for d in 0..self.loads.len() {
            if d % 6 < 3 {
                self.loads[d] += self.mass[d] * g[d % 6];
            }
        }
        Ok(())
    }

    /// Lumped masses per dof (kg, kg·m²), 6 per node.
    pub fn mass(&self) -> &[f64] {
        &self.mass
    }
    /// Translational lumped mass of each node, kg.
    pub fn node_mass(&self) -> Vec<f64> {
        self.mass.chunks_exact(6).map(|m| m[0]).collect()
    }
    /// Velocity v^{n−½} (m/s, rad/s), 6 per node.
    pub fn velocity(&self) -> &[f64] {
        &self.v
    }
    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }
    /// Total linear momentum Σ m v of the translations, kg·m/s.
    pub fn momentum(&self) -> [f64; 3] {
        let mut p = [0.0; 3];
        for d in 0..self.v.len() {
            if d % 6 < 3 {
                p[d % 6] += self.mass[d] * self.v[d];
            }
        }
        p
    }

    /// Attach a contact model built on the same mesh (before the first step). The stable
    /// step is re-certified with the contact's allowance; an automatic step is reduced to
    /// fit, a fixed step above the new limit is refused; shells overlapping at the start
    /// are refused.
    pub fn set_contact(&mut self, mut contact: FemContact) -> Result<()> {
        self.require_start("contact")?;
        if !contact.is_shell() {
            return Err(DemfemError::InvalidParameter {
                field: "contact".into(),
                value: "a contact model of a solid mesh".into(),
                allowed: "a model from FemContact::new_shell".into(),
            });
        }
        let mass = self.node_mass();
        let allowance = contact.eigenvalue_allowance(&mass)?;
        self.fill_positions();
        contact.check_initial_overlap(&self.u3)?;
        let limit = critical_step_from_eigenvalue(self.lam_max + allowance, 0.0, 0.0)?;
        let dt = match self.dt_requested {
            Some(dt) if dt > limit => {
                return Err(DemfemError::UnstableTimeStep {
                    dt,
                    limit,
                    reason: format!(
                        "shell element bound {:e} 1/s² plus contact allowance {allowance:e} 1/s²",
                        self.lam_max
                    ),
                })
            }
            Some(dt) => dt,
            None => 0.9 * limit,
        };
        self.dt = dt;
        self.dt_limit = limit;
        self.f_contact = vec![[0.0; 3]; mass.len()];
        self.contact = Some(contact);
        Ok(())
    }

    /// The attached contact model.
    pub fn contact(&self) -> Option<&FemContact> {
        self.contact.as_ref()
    }
    /// Contact energies (zero without contact).
    pub fn contact_energy(&self) -> ContactEnergy {
        self.contact
            .as_ref()
            .map(|c| c.energy())
            .unwrap_or_default()
    }
    /// Contact forces of the last step, N per node (empty without contact).
    pub fn contact_force(&self) -> &[[f64; 3]] {
        &self.f_contact
    }
    /// Step bound of the shell elements alone, s.
    pub fn dt_limit_without_contact(&self) -> f64 {
        self.dt_limit_without_contact
    }
    /// Translation of each node u^n, m.
    pub fn node_displacement(&self) -> Vec<[f64; 3]> {
        self.u.chunks_exact(6).map(|u| [u[0], u[1], u[2]]).collect()
    }

    /// Energies at the start of the last step, contact included.
    pub fn energy_report(&self) -> ShellEnergy {
        let [k, i, w, e0] = self.energy;
        let c = self.contact_energy();
        ShellEnergy {
            kinetic: k,
            internal: i,
            load_work: w - c.contact_work,
            contact_elastic: c.elastic,
            springs: c.springs,
            friction_work: c.friction_work,
            rigid_work: c.rigid_work,
            initial: e0,
        }
    }

    fn fill_positions(&mut self) {
        let n = self.u.len() / 6;
        self.u3.resize(n, [0.0; 3]);
        self.v3.resize(n, [0.0; 3]);
        for i in 0..n {
            self.u3[i] = [self.u[6 * i], self.u[6 * i + 1], self.u[6 * i + 2]];
            self.v3[i] = [self.v[6 * i], self.v[6 * i + 1], self.v[6 * i + 2]];
        }
    }

    /// Contact forces at t^n into `f_contact`; whether there is a contact model.
    pub(super) fn contact_forces(&mut self) -> bool {
        if self.contact.is_none() {
            return false;
        }
        self.fill_positions();
        let (t, dt) = (self.time(), self.dt);
        if let Some(c) = self.contact.as_mut() {
            c.compute(&self.u3, &self.v3, t, dt, &mut self.f_contact);
        }
        true
    }
}
