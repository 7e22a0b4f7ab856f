//! Contact forces between rigid bodies, per contact point.
//!
//! Normal: Hertz, F = k_H δ^{3/2} with k_H = 4/3 √R* E* from the curvature radii of the two
//! surfaces at the contact (bead radii for a clump; a piece's outer radius for an exact
//! shape), plus Tsuji damping ζ √(m* k_H) δ^{1/4} δ̇ with ζ chosen for the requested
//! restitution and the total clamped at ≥ 0 (`ForceClamp::NonNegative`, the clamp ζ was
//! calibrated with). m* is the effective mass of the two whole bodies (infinite for a plane):
//! the usual clump choice; when several beads touch at once or the contact is far from the
//! centre of mass the realised restitution differs from the requested one.
//!
//! Tangential: history-free, viscous-regularised Coulomb friction,
//! F_t = −min(μ F_n, c_t |v_t|) v̂_t with c_t = 2 √(m* · dF_n/dδ) (critical damping of the
//! normal spring). It cannot hold a body at rest on a slope indefinitely (it creeps at
//! v_t = μ F_n / c_t), which is acceptable for impacts and tipping but not for static
//! friction; a Mindlin spring with history is the next step.

use nalgebra::Vector3;

use super::collision::ContactPoint;
use crate::contact::{
    effective_modulus, effective_radius, hertz_stiffness, tsuji_damping_for_restitution,
    ForceClamp, NormalLaw,
};
use crate::error::{check_non_negative, Result};

/// Elastic constants of a contacting material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactMaterial {
    /// Young's modulus, Pa (`inf` for a rigid wall).
    pub young_modulus: f64,
    /// Poisson's ratio.
    pub poisson_ratio: f64,
}

impl ContactMaterial {
    /// The paper's glass: E = 45 GPa, ν = 0.22.
    pub const PAPER_GLASS: ContactMaterial =
        ContactMaterial { young_modulus: 45e9, poisson_ratio: 0.22 };
}

/// Normal and tangential contact model shared by all contacts of a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactModel {
    /// Effective modulus body–body, Pa.
    pub e_star_body_body: f64,
    /// Effective modulus body–plane, Pa.
    pub e_star_body_plane: f64,
    /// Tsuji damping parameter ζ (dimensionless).
    pub damping_zeta: f64,
    /// Coulomb friction coefficient μ.
    pub friction: f64,
}

impl ContactModel {
    /// Build from the body and plane materials, the restitution e ∈ (0, 1] of a Hertz impact
    /// and the friction coefficient μ ≥ 0.
    pub fn new(
        body: ContactMaterial,
        plane: ContactMaterial,
        restitution: f64,
        friction: f64,
    ) -> Result<Self> {
        let e_star_body_body = effective_modulus(
            body.young_modulus,
            body.poisson_ratio,
            body.young_modulus,
            body.poisson_ratio,
        )?;
        let e_star_body_plane = effective_modulus(
            body.young_modulus,
            body.poisson_ratio,
            plane.young_modulus,
            plane.poisson_ratio,
        )?;
        let damping_zeta = tsuji_damping_for_restitution(restitution, ForceClamp::NonNegative)?;
        check_non_negative("friction", friction)?;
        Ok(Self { e_star_body_body, e_star_body_plane, damping_zeta, friction })
    }

    /// Force on the second object of `contact` (the first receives its opposite), N.
    ///
    /// `relative_velocity` is the velocity of the second surface minus the first at the
    /// contact point (m/s), `effective_mass` m* (kg), `e_star` the effective modulus (Pa).
    #[inline]
    pub fn force(
        &self,
        contact: &ContactPoint,
        relative_velocity: &Vector3<f64>,
        effective_mass: f64,
        e_star: f64,
    ) -> Result<Vector3<f64>> {
        // effective_radius takes a plane (inf) only as its second argument
        let (r1, r2) = if contact.radius_first.is_infinite() {
            (contact.radius_second, contact.radius_first)
        } else {
            (contact.radius_first, contact.radius_second)
        };
        let r_star = effective_radius(r1, r2)?;
        let k_h = hertz_stiffness(r_star, e_star)?;
        let (elastic, stiffness) = NormalLaw::Hertz { k_h }.force_and_stiffness(contact.overlap);
        let n = contact.normal;
        let normal_speed = relative_velocity.dot(&n); // < 0 while approaching
        let overlap_rate = -normal_speed;
        let damping =
            self.damping_zeta * (effective_mass * k_h).sqrt() * contact.overlap.sqrt().sqrt();
        let normal_force = (elastic + damping * overlap_rate).max(0.0);
        let mut force = n * normal_force;
        if self.friction > 0.0 {
            let slip = relative_velocity - n * normal_speed;
            let slip_speed = slip.norm();
            if slip_speed > 0.0 {
                let viscous = 2.0 * (effective_mass * stiffness).sqrt() * slip_speed;
                let magnitude = viscous.min(self.friction * normal_force);
                force -= slip * (magnitude / slip_speed);
            }
        }
        Ok(force)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn contact(overlap: f64) -> ContactPoint {
        ContactPoint {
            point: Vector3::zeros(),
            normal: Vector3::z(),
            overlap,
            radius_first: f64::INFINITY,
            radius_second: 1e-3,
            feature_first: 0,
            feature_second: 0,
        }
    }

    #[test]
    fn static_normal_force_is_hertz() {
        let model =
            ContactModel::new(ContactMaterial::PAPER_GLASS, ContactMaterial::PAPER_GLASS, 1.0, 0.0)
                .unwrap();
        let f = model.force(&contact(1e-6), &Vector3::zeros(), 1e-3, 20e9).unwrap();
        let expected = 4.0 / 3.0 * (1e-3_f64).sqrt() * 20e9 * (1e-6_f64).powf(1.5);
        assert!((f.z / expected - 1.0).abs() < 1e-12 && f.x == 0.0 && f.y == 0.0);
    }

    #[test]
    fn friction_is_capped_by_coulomb() {
        let model =
            ContactModel::new(ContactMaterial::PAPER_GLASS, ContactMaterial::PAPER_GLASS, 1.0, 0.3)
                .unwrap();
        let f = model.force(&contact(1e-6), &Vector3::new(10.0, 0.0, 0.0), 1e-3, 20e9).unwrap();
        assert!((f.x + 0.3 * f.z).abs() < 1e-12 * f.z, "{f:?}");
    }
}
