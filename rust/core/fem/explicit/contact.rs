//! Contact in an explicit run: a [`FemContact`] gets the nodes' translations u and
//! velocities v^{n−½} each step and returns nodal forces, which enter the step as external
//! forces (so the integrator's exact discrete balance counts their work). The stable step
//! is certified for the element bound plus the contact's eigenvalue allowance (Weyl:
//! λ_max(A + B) ≤ λ_max(A) + λ_max(B), the contact acting on translations with the
//! translational masses); an automatic step is reduced to fit, a fixed one above the new
//! limit is refused. Energies in J.

use crate::error::{DemfemError, Result};
use crate::fem::contact::{ContactEnergy, FemContact};
use crate::fem::element_set::ElementSet;
use crate::fem::stable_step::critical_step_from_eigenvalue;

use super::Explicit;

/// Every term of an explicit run's energy balance, contact included, J.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnergyBalance {
    /// Kinetic energy ½ v^{n−½}·M v^{n+½}, J.
    pub kinetic: f64,
    /// Elastic strain energy of the elements, J.
    pub internal: f64,
    /// Work of the applied loads (gravity included) and of the reactions of prescribed and
    /// held dofs, J.
    pub load_work: f64,
    /// Energy dissipated by Rayleigh damping, J.
    pub damping_work: f64,
    /// Elastic energy stored in the contact penalty and stick springs, J.
    pub contact_elastic: f64,
    /// Energy stored in the no-tension springs, J.
    pub springs: f64,
    /// Work dissipated by friction, J.
    pub friction_work: f64,
    /// Work done on the bodies by moving rigid surfaces (the belt), J.
    pub rigid_work: f64,
    /// Kinetic plus internal energy at t = 0, J.
    pub initial: f64,
}

impl EnergyBalance {
    /// |E_kin + E_int + W_damp + E_contact + E_springs + W_friction − W_rigid − W_loads − E_0|, J.
    pub fn balance_error(&self) -> f64 {
        (self.kinetic
            + self.internal
            + self.damping_work
            + self.contact_elastic
            + self.springs
            + self.friction_work
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
            self.damping_work,
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

impl<E: ElementSet<D>, const D: usize> Explicit<E, D> {
    /// Attach a contact model built on the same mesh (before the first step; a shell
    /// solver takes a model from [`FemContact::new_shell`], a solid one from
    /// [`FemContact::new`]). The stable step is re-certified with the contact's allowance;
    /// bodies overlapping at the start are refused.
    pub fn set_contact(&mut self, mut contact: FemContact) -> Result<()> {
        self.require_start("contact")?;
        if contact.is_shell() != E::SHELL {
            let (value, allowed) = if E::SHELL {
                (
                    "a contact model of a solid mesh",
                    "a model from FemContact::new_shell",
                )
            } else {
                (
                    "a contact model of a shell mesh",
                    "a model from FemContact::new",
                )
            };
            return Err(DemfemError::InvalidParameter {
                field: "contact".into(),
                value: value.into(),
                allowed: allowed.into(),
            });
        }
        let allowance = contact.eigenvalue_allowance(&self.mass)?;
        let u = E::translations(&self.u, &mut self.u3);
        contact.check_initial_overlap(u)?;
        let limit = critical_step_from_eigenvalue(
            self.eigen.bound + allowance,
            self.config.rayleigh_alpha,
            self.config.rayleigh_beta,
        )?;
        let dt = match self.config.dt {
            Some(dt) if dt > limit => {
                return Err(DemfemError::UnstableTimeStep {
                    dt,
                    limit,
                    reason: format!(
                        "{} element bound {:e} 1/s² plus contact allowance {allowance:e} 1/s²",
                        E::NAME,
                        self.eigen.bound
                    ),
                })
            }
            Some(dt) => dt,
            None => self.config.safety_factor * limit,
        };
        self.dt = dt;
        self.dt_limit = limit;
        self.f_contact = vec![[0.0; 3]; self.mass.len()];
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
    /// Stable step bound without the contact's allowance, s.
    pub fn dt_limit_without_contact(&self) -> f64 {
        self.dt_limit_without_contact
    }
    /// Contact forces of the last step, N per node (empty without contact).
    pub fn contact_force(&self) -> &[[f64; 3]] {
        &self.f_contact
    }

    /// Energies at the start of the last step, contact included: the load work is the
    /// integrator's external work less the contact's.
    pub fn energy_balance(&self) -> EnergyBalance {
        let e = self.energy;
        let c = self.contact_energy();
        EnergyBalance {
            kinetic: e.kinetic,
            internal: e.internal,
            load_work: e.external_work - c.contact_work,
            damping_work: e.damping_work,
            contact_elastic: c.elastic,
            springs: c.springs,
            friction_work: c.friction_work,
            rigid_work: c.rigid_work,
            initial: e.initial,
        }
    }
}
