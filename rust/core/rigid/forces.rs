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
//! Tangential: a Mindlin spring with Coulomb cap (the design's choice), history kept per
//! contact by the caller (the scene keys it by body, body, feature, feature). The spring
//! displacement ξ is turned into the current tangent plane and grows by v_t Δt; the force is
//! F_t = −k_t ξ − c_t v_t with k_t = 2(1−ν)/(2−ν) · dF_n/dδ (Mindlin's no-slip stiffness
//! relative to the Hertz tangent stiffness, same material) and c_t = the normal dashpot
//! coefficient. When |F_t| > μ F_n the force is capped and ξ reset to −F_t/k_t, so the spring
//! holds the contact at the sliding limit (static friction: a body on a slope below atan μ
//! stays put). Without friction (μ = 0) no history is kept or needed.

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
    pub const PAPER_GLASS: ContactMaterial = ContactMaterial {
        young_modulus: 45e9,
        poisson_ratio: 0.22,
    };
}

/// Normal and tangential contact model shared by all contacts of a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidContactLaw {
    /// Effective modulus body–body, Pa.
    pub e_star_body_body: f64,
    /// Effective modulus body–plane, Pa.
    pub e_star_body_plane: f64,
    /// Tsuji damping parameter ζ (dimensionless).
    pub damping_zeta: f64,
    /// Coulomb friction coefficient μ.
    pub friction: f64,
    /// Mindlin tangential to Hertz normal tangent-stiffness ratio, 2(1−ν)/(2−ν).
    pub tangential_stiffness_ratio: f64,
}

impl RigidContactLaw {
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
        let nu = body.poisson_ratio;
        let tangential_stiffness_ratio = 2.0 * (1.0 - nu) / (2.0 - nu);
        Ok(Self {
            e_star_body_body,
            e_star_body_plane,
            damping_zeta,
            friction,
            tangential_stiffness_ratio,
        })
    }

    /// Force on the second object of `contact` (the first receives its opposite), N.
    ///
    /// `relative_velocity` is the velocity of the second surface minus the first at the
    /// contact point (m/s), `effective_mass` m* (kg), `e_star` the effective modulus (Pa),
    /// `tangential_displacement` the contact's Mindlin spring ξ (m, zero for a new contact;
    /// updated in place) and `dt` the time step (s).
    #[inline]
    pub fn force(
        &self,
        contact: &ContactPoint,
        relative_velocity: &Vector3<f64>,
        effective_mass: f64,
        e_star: f64,
        tangential_displacement: &mut Vector3<f64>,
        dt: f64,
    ) -> Result<Vector3<f64>> {
        self.force_and_energy(
            contact,
            relative_velocity,
            effective_mass,
            e_star,
            tangential_displacement,
            dt,
        )
        .map(|(force, _)| force)
    }

    /// As [`RigidContactLaw::force`], with the elastic energy stored in the contact after the
    /// update (J): the Hertz potential 2/5 k_H δ^{5/2} plus the Mindlin spring ½ k_t |ξ|².
    #[inline]
    pub fn force_and_energy(
        &self,
        contact: &ContactPoint,
        relative_velocity: &Vector3<f64>,
        effective_mass: f64,
        e_star: f64,
        tangential_displacement: &mut Vector3<f64>,
        dt: f64,
    ) -> Result<(Vector3<f64>, f64)> {
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
        let dashpot =
            self.damping_zeta * (effective_mass * k_h).sqrt() * contact.overlap.sqrt().sqrt();
        let normal_force = (elastic - dashpot * normal_speed).max(0.0);
        let mut force = n * normal_force;
        let mut energy = 0.4 * elastic * contact.overlap;
        if self.friction > 0.0 {
            let slip = relative_velocity - n * normal_speed;
            // turn the old spring into the current tangent plane, keeping its length
            let xi = *tangential_displacement;
            let length = xi.norm();
            let mut turned = xi - n * n.dot(&xi);
            let turned_length = turned.norm();
            if turned_length > 0.0 {
                turned *= length / turned_length;
            }
            turned += slip * dt;
            let k_t = self.tangential_stiffness_ratio * stiffness;
            let mut tangential = -turned * k_t - slip * dashpot;
            let cap = self.friction * normal_force;
            let magnitude = tangential.norm();
            if magnitude > cap {
                tangential *= cap / magnitude;
                turned = if k_t > 0.0 {
                    -tangential / k_t
                } else {
                    Vector3::zeros()
                };
            }
            *tangential_displacement = turned;
            energy += 0.5 * k_t * turned.norm_squared();
            force += tangential;
        }
        Ok((force, energy))
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
        let model = RigidContactLaw::new(
            ContactMaterial::PAPER_GLASS,
            ContactMaterial::PAPER_GLASS,
            1.0,
            0.0,
        )
        .unwrap();
        let f = model
            .force(
                &contact(1e-6),
                &Vector3::zeros(),
                1e-3,
                20e9,
                &mut Vector3::zeros(),
                1e-6,
            )
            .unwrap();
        let expected = 4.0 / 3.0 * (1e-3_f64).sqrt() * 20e9 * (1e-6_f64).powf(1.5);
        assert!((f.z / expected - 1.0).abs() < 1e-12 && f.x == 0.0 && f.y == 0.0);
    }

    #[test]
    fn friction_is_capped_by_coulomb_and_sticks_below_it() {
        let model = RigidContactLaw::new(
            ContactMaterial::PAPER_GLASS,
            ContactMaterial::PAPER_GLASS,
            1.0,
            0.3,
        )
        .unwrap();
        let mut xi = Vector3::zeros();
        let f = model
            .force(
                &contact(1e-6),
                &Vector3::new(10.0, 0.0, 0.0),
                1e-3,
                20e9,
                &mut xi,
                1e-6,
            )
            .unwrap();
        assert!((f.x + 0.3 * f.z).abs() < 1e-12 * f.z, "{f:?}");
        // at the cap the spring holds exactly the Coulomb force
        let k_t =
            model.tangential_stiffness_ratio * 1.5 * 4.0 / 3.0 * (1e-3_f64).sqrt() * 20e9 * 1e-3;
        assert!((xi.x * k_t - 0.3 * f.z).abs() < 1e-9 * f.z, "{xi:?}");
        // a small displacement below the cap: the spring force −k_t ξ, no sliding
        let mut xi = Vector3::new(1e-9, 0.0, 0.0);
        let f = model
            .force(&contact(1e-6), &Vector3::zeros(), 1e-3, 20e9, &mut xi, 1e-6)
            .unwrap();
        assert!((f.x + k_t * 1e-9).abs() < 1e-9 * k_t * 1e-9, "{f:?}");
        assert_eq!(xi, Vector3::new(1e-9, 0.0, 0.0));
    }
}
