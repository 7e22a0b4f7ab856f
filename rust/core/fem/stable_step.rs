//! Critical time step of explicit central differences, bounded from below.
//!
//! The element eigenvalue theorem (Irons; Hughes, *The Finite Element Method*, §9.3) says
//! that the largest eigenvalue of the assembled problem M⁻¹K is no larger than the largest
//! of the element eigenvalues λ_e = λ_max(M_e⁻¹K_e), provided the lumped global mass is the
//! sum of the element masses. Hence dt = 2/√(max_e λ_e) ≤ 2/ω_max is always stable. The
//! popular min-height / c_d estimate carries no such guarantee for tetrahedra.
//!
//! With Rayleigh damping C = αM + βK and the velocity lagged by half a step, the modal
//! recurrence v⁺ = (1 − (α + βω²)dt)v⁻ − ω²dt·u is stable for
//! dt ≤ (2/ω)(√(1+ξ²) − ξ), ξ = (α + βω²)/(2ω) (Jury criterion), a bound that decreases
//! with ω, so evaluating it at the element bound ω̄ ≥ ω_max stays conservative.

use rayon::prelude::*;

use crate::error::{check_non_negative, DemfemError, Result};
use crate::fem::element::Tet4;

/// Largest element eigenvalue max_e λ_max(M_e⁻¹K_e), 1/s², and the element that attains it.
/// `mass_factor[e]` scales the element mass (mass scaling; `None` = 1).
pub fn element_eigenvalue_bound(tets: &[Tet4], lambda: f64, mu: f64, density: f64, mass_factor: Option<&[f64]>) -> (f64, usize) {
    let eigs = element_eigenvalues(tets, lambda, mu, density, mass_factor);
    let mut best = (0.0, 0);
    for (e, &l) in eigs.iter().enumerate() {
        if l > best.0 {
            best = (l, e);
        }
    }
    best
}

/// Every element's λ_max(M_e⁻¹K_e), 1/s² (parallel; each entry is independent, so the
/// result does not depend on the number of threads).
pub fn element_eigenvalues(tets: &[Tet4], lambda: f64, mu: f64, density: f64, mass_factor: Option<&[f64]>) -> Vec<f64> {
    tets.par_iter()
        .enumerate()
        .map(|(e, t)| t.max_eigenvalue(lambda, mu, density, mass_factor.map_or(1.0, |f| f[e])))
        .collect()
}

/// Critical central-difference step (s) for the largest circular frequency squared
/// `omega_sq` (1/s²), with mass- and stiffness-proportional damping `alpha` (1/s) and
/// `beta` (s).
pub fn critical_step_from_eigenvalue(omega_sq: f64, alpha: f64, beta: f64) -> Result<f64> {
    check_non_negative("alpha", alpha)?;
    check_non_negative("beta", beta)?;
    if !(omega_sq > 0.0) || !omega_sq.is_finite() {
        return Err(DemfemError::Numerical(format!("largest eigenvalue {omega_sq:e} is not positive and finite")));
    }
    let w = omega_sq.sqrt();
    let xi = (alpha + beta * omega_sq) / (2.0 * w);
    Ok(2.0 / w * ((1.0 + xi * xi).sqrt() - xi))
}

/// Element mass-scaling factors s_e ≥ 1 such that every element's own stable step is at
/// least `target_dt` (s): s_e = max(1, (target_dt / dt_e)²) with dt_e = 2/√λ_e.
/// Returns the factors and the added mass (kg) Σ (s_e − 1) ρ V_e.
pub fn mass_scaling_factors(tets: &[Tet4], lambda: f64, mu: f64, density: f64, target_dt: f64) -> Result<(Vec<f64>, f64)> {
    crate::error::check_positive("target_dt", target_dt)?;
    let eigs = element_eigenvalues(tets, lambda, mu, density, None);
    let mut added = 0.0;
    let mut f = Vec::with_capacity(tets.len());
    for (t, l) in tets.iter().zip(eigs) {
        let dt_e = 2.0 / l.sqrt();
        // A hair above the exact ratio so rounding cannot leave dt_e' below the target.
        let s = ((target_dt / dt_e).powi(2) * (1.0 + 1e-12)).max(1.0);
        added += (s - 1.0) * density * t.volume;
        f.push(s);
    }
    Ok((f, added))
}
