//! Isotropic linear elastic material (small strain), SI units.

use crate::error::{check_open, check_positive, Result};

/// Isotropic linear elastic material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearElastic {
    /// Young's modulus E, Pa.
    pub young_modulus: f64,
    /// Poisson's ratio ν, dimensionless, in (-1, 0.5).
    pub poisson_ratio: f64,
    /// Mass density ρ, kg/m³.
    pub density: f64,
}

impl LinearElastic {
    /// A checked material: E > 0 Pa, −1 < ν < 0.5, ρ > 0 kg/m³.
    pub fn new(young_modulus: f64, poisson_ratio: f64, density: f64) -> Result<Self> {
        check_positive("young_modulus", young_modulus)?;
        check_open("poisson_ratio", poisson_ratio, -1.0, 0.5)?;
        check_positive("density", density)?;
        Ok(Self {
            young_modulus,
            poisson_ratio,
            density,
        })
    }

    /// The paper's glass: E = 45 GPa, ν = 0.2, ρ = 2230 kg/m³ (DESIGN.md §4).
    pub fn paper_glass() -> Self {
        Self {
            young_modulus: 45e9,
            poisson_ratio: 0.2,
            density: 2230.0,
        }
    }

    /// Re-check a material built by struct literal.
    pub fn validate(&self) -> Result<()> {
        Self::new(self.young_modulus, self.poisson_ratio, self.density).map(|_| ())
    }

    /// Lamé constants (λ, μ), Pa.
    pub fn lame(&self) -> (f64, f64) {
        let e = self.young_modulus;
        let nu = self.poisson_ratio;
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = e / (2.0 * (1.0 + nu));
        (lambda, mu)
    }

    /// Dilatational (P-) wave speed c_d = √((λ+2μ)/ρ), m/s.
    pub fn dilatational_wave_speed(&self) -> f64 {
        let (l, m) = self.lame();
        ((l + 2.0 * m) / self.density).sqrt()
    }
}
