//! Materials and the per-pair contact parameters derived from them once, at scene build.
//!
//! Pair rules (documented choices): E* and G* combine both materials (Hertz and Mindlin);
//! friction, rolling friction and restitution of a pair are the smaller of the two values
//! (Yade's convention), so a frictionless wall stays frictionless against any particle.

use crate::contact::{self, ForceClamp};
use crate::error::{check_non_negative, check_open, check_positive, DemfemError, Result};

/// Elastic and frictional properties of one material, SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus E, Pa.
    pub young_modulus: f64,
    /// Poisson's ratio ν, in (-1, 0.5).
    pub poisson_ratio: f64,
    /// Density ρ, kg/m³ (used for particle mass; ignored for walls).
    pub density: f64,
    /// Coulomb friction coefficient μ ≥ 0.
    pub friction: f64,
    /// Normal coefficient of restitution e in (0, 1].
    pub restitution: f64,
    /// Rolling friction coefficient μ_r ≥ 0 (dimensionless; torque = μ_r R* F_n).
    pub rolling_friction: f64,
    /// Point-load stiffness of the shell k_R, N/m (Reissner, eq. 6), for the Hertz–Reissner
    /// law; `f64::INFINITY` for a body that does not bend (solid sphere, wall).
    pub shell_stiffness: f64,
}

impl Material {
    /// A material with no shell compliance (`shell_stiffness = ∞`).
    pub fn new(
        young_modulus: f64,
        poisson_ratio: f64,
        density: f64,
        friction: f64,
        restitution: f64,
        rolling_friction: f64,
    ) -> Self {
        Material {
            young_modulus,
            poisson_ratio,
            density,
            friction,
            restitution,
            rolling_friction,
            shell_stiffness: f64::INFINITY,
        }
    }

    /// Check every field; `index` names the material in the error.
    pub fn validate(&self, index: usize) -> Result<()> {
        let f = |s: &str| format!("materials[{index}].{s}");
        check_positive(&f("young_modulus"), self.young_modulus)?;
        check_open(&f("poisson_ratio"), self.poisson_ratio, -1.0, 0.5)?;
        check_positive(&f("density"), self.density)?;
        check_non_negative(&f("friction"), self.friction)?;
        check_non_negative(&f("rolling_friction"), self.rolling_friction)?;
        if !(self.restitution.is_finite() && self.restitution > 0.0 && self.restitution <= 1.0) {
            return Err(DemfemError::invalid(
                &f("restitution"),
                self.restitution,
                "in (0, 1]",
            ));
        }
        if !(self.shell_stiffness > 0.0) || self.shell_stiffness.is_nan() {
            return Err(DemfemError::invalid(
                &f("shell_stiffness"),
                self.shell_stiffness,
                "> 0 (inf: no shell)",
            ));
        }
        Ok(())
    }

    /// Shear modulus G = E / (2 (1 + ν)), Pa.
    pub fn shear_modulus(&self) -> f64 {
        self.young_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }
}

/// Which normal law (and matching tangential spring) the scene uses for every pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DemContactLaw {
    /// Hertz normal force F = 4/3 E* √R* δ^{3/2}, Mindlin tangential spring k_t = 8 G* √(R* δ),
    /// Tsuji restitution damping.
    HertzMindlin,
    /// Hertz indentation in series with the shell stiffness of both bodies (eq. 12), Mindlin
    /// tangential spring on the Hertz part of the overlap, Tsuji-type damping on the tangent
    /// stiffness (realised restitution close to, not exactly, e: see [`PairLaw`]).
    HertzReissnerMindlin,
    /// Linear spring–dashpot: F_n = k_n δ + c_n δ̇, tangential spring k_t; the dashpot gives
    /// restitution e exactly without force clamping.
    LinearSpringDashpot {
        /// Normal stiffness k_n, N/m.
        normal_stiffness: f64,
        /// Tangential stiffness k_t, N/m.
        tangential_stiffness: f64,
    },
}

impl DemContactLaw {
    /// Validate the model's own parameters.
    pub fn validate(&self) -> Result<()> {
        if let DemContactLaw::LinearSpringDashpot {
            normal_stiffness,
            tangential_stiffness,
        } = *self
        {
            check_positive("normal_stiffness", normal_stiffness)?;
            check_positive("tangential_stiffness", tangential_stiffness)?;
        }
        Ok(())
    }

    /// Whether the normal law derives from E (Hertz-type), which brings in the Rayleigh limit.
    pub fn is_hertzian(&self) -> bool {
        !matches!(self, DemContactLaw::LinearSpringDashpot { .. })
    }
}

/// Contact parameters of one (material a, material b) pair, precomputed at scene build.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairLaw {
    /// Effective modulus E*, Pa.
    pub e_star: f64,
    /// Mindlin effective shear modulus G*, 1/G* = (2−ν₁)/G₁ + (2−ν₂)/G₂, Pa.
    pub g_star: f64,
    /// Series shell stiffness 1/k_R = 1/k_R1 + 1/k_R2, N/m (∞ for solid bodies).
    pub shell_stiffness: f64,
    /// Coulomb friction μ of the pair.
    pub friction: f64,
    /// Rolling friction μ_r of the pair.
    pub rolling_friction: f64,
    /// Restitution e of the pair.
    pub restitution: f64,
    /// Tsuji damping parameter ζ (Hertz laws): c_n = ζ √(2/3 m* k'_n), k'_n = dF/dδ. For pure
    /// Hertz this is exactly F_d = ζ √(m* k_H) δ^{1/4} δ̇ of `contact.rs`.
    pub zeta: f64,
    /// Linear dashpot: c_n = linear_damping √(m* k_n) with linear_damping = 2β.
    pub linear_damping: f64,
    /// c_t / c_n: the tangential dashpot has the normal one's damping ratio,
    /// c_t = c_n √(k_t / k'_n); for Hertz–Mindlin k_t/k'_n = 4 G*/E* is constant.
    pub tangential_damping_ratio: f64,
}

impl PairLaw {
    /// Derive the pair parameters of materials `a` and `b` under `model`.
    pub fn new(
        a: &Material,
        b: &Material,
        model: DemContactLaw,
        clamp: ForceClamp,
    ) -> Result<Self> {
        let restitution = a.restitution.min(b.restitution);
        let zeta = if model.is_hertzian() {
            contact::tsuji_damping_for_restitution(restitution, clamp)?
        } else {
            0.0
        };
        Self::with_zeta(a, b, model, zeta)
    }

    /// As [`PairLaw::new`] with the Tsuji parameter ζ already known (it costs a bisection
    /// over an ODE solve, so a scene computes it once per distinct restitution).
    pub fn with_zeta(a: &Material, b: &Material, model: DemContactLaw, zeta: f64) -> Result<Self> {
        let e_star = contact::effective_modulus(
            a.young_modulus,
            a.poisson_ratio,
            b.young_modulus,
            b.poisson_ratio,
        )?;
        let g_star = 1.0
            / ((2.0 - a.poisson_ratio) / a.shear_modulus()
                + (2.0 - b.poisson_ratio) / b.shear_modulus());
        let shell_stiffness = if a.shell_stiffness.is_infinite() {
            b.shell_stiffness
        } else if b.shell_stiffness.is_infinite() {
            a.shell_stiffness
        } else {
            contact::series(a.shell_stiffness, b.shell_stiffness)
        };
        let restitution = a.restitution.min(b.restitution);
        let (zeta, linear_damping, tangential_damping_ratio) = match model {
            DemContactLaw::HertzMindlin | DemContactLaw::HertzReissnerMindlin => {
                (zeta, 0.0, (4.0 * g_star / e_star).sqrt())
            }
            DemContactLaw::LinearSpringDashpot {
                normal_stiffness,
                tangential_stiffness,
            } => {
                // damped oscillator: e = exp(-β π / √(1-β²)) ⇔ β = -ln e / √(π² + ln² e)
                let ln_e = restitution.ln();
                let beta = -ln_e / (std::f64::consts::PI.powi(2) + ln_e * ln_e).sqrt();
                (
                    0.0,
                    2.0 * beta,
                    (tangential_stiffness / normal_stiffness).sqrt(),
                )
            }
        };
        Ok(PairLaw {
            e_star,
            g_star,
            shell_stiffness,
            friction: a.friction.min(b.friction),
            rolling_friction: a.rolling_friction.min(b.rolling_friction),
            restitution,
            zeta,
            linear_damping,
            tangential_damping_ratio,
        })
    }
}
