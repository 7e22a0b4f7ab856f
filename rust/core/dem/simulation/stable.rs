//! The stable time step of a scene ([`stable_time_step`]) and what sets it ([`StableStep`]).

use crate::contact;
use crate::dem::effects::Effect;
use crate::dem::material::{DemContactLaw, PairLaw};
use crate::dem::scene::Scene;
use crate::error::Result;

/// The stable time step of a scene and what sets it.
#[derive(Debug, Clone, PartialEq)]
pub struct StableStep {
    /// Largest accepted step, s.
    pub limit: f64,
    /// Which law or criterion sets it.
    pub reason: String,
}

/// Stable time step of a scene: the smaller of the Rayleigh step of every particle (Hertz
/// laws only, where stiffness comes from E) and half the critical step 2/ω of the stiffest
/// single contact at `expected_max_speed`, normal (ω² = k'_n/m*) and tangential
/// (ω² = k_t/m_t, m_t = 2/7 m* with rotation: a rolling sphere's tangential inertia). The
/// factor 1/2 allows for several simultaneous contacts (a dense lattice raises the highest
/// eigenfrequency by up to about 2).
pub fn stable_time_step(scene: &Scene, mass: &[f64]) -> Result<StableStep> {
    let p = &scene.particles;
    let v = scene.expected_max_speed;
    let friction = scene.effects.has(Effect::Friction);
    let rotation = scene.effects.has(Effect::Rotation);
    let mut best = StableStep {
        limit: f64::INFINITY,
        reason: "no particle".into(),
    };
    let mut consider = |limit: f64, reason: &dyn Fn() -> String| {
        if limit < best.limit {
            best = StableStep {
                limit,
                reason: reason(),
            };
        }
    };
    // distinct (material, radius, mass) classes only: the table is usually monodisperse
    let mut seen: Vec<(usize, u64)> = Vec::new();
    let mut wall_materials: Vec<usize> = scene.walls.iter().map(|w| w.material).collect();
    wall_materials.sort_unstable();
    wall_materials.dedup();
    for i in 0..p.len() {
        let key = (p.material[i], p.radius[i].to_bits());
        if seen.contains(&key) {
            continue;
        }
        seen.push(key);
        let mat = &scene.materials[p.material[i]];
        let r = p.radius[i];
        let m = mass[i];
        if scene.model.is_hertzian() {
            let t =
                contact::rayleigh_time_step(r, mat.density, mat.young_modulus, mat.poisson_ratio)?;
            consider(t, &|| {
                format!(
                    "Rayleigh step of particle {i} (r = {r} m, material {})",
                    p.material[i]
                )
            });
        }
        let mut partners: Vec<(usize, f64, f64, String)> = vec![(
            p.material[i],
            0.5 * m,
            0.5 * r,
            format!("particle {i} against its twin"),
        )];
        for &wm in &wall_materials {
            partners.push((
                wm,
                m,
                r,
                format!("particle {i} against a wall of material {wm}"),
            ));
        }
        for (other, m_star, r_star, what) in partners {
            let law = PairLaw::with_zeta(mat, &scene.materials[other], scene.model, 0.0)?;
            let (k_n, k_t) = match scene.model {
                DemContactLaw::LinearSpringDashpot {
                    normal_stiffness,
                    tangential_stiffness,
                } => (normal_stiffness, tangential_stiffness),
                _ => {
                    // Hertz bounds Hertz–Reissner from above (the shell only softens)
                    let k_h = contact::hertz_stiffness(r_star, law.e_star)?;
                    let d = contact::hertz_max_overlap(k_h, m_star, v);
                    (1.5 * k_h * d.sqrt(), 8.0 * law.g_star * (r_star * d).sqrt())
                }
            };
            let dt_n = 0.5 * 2.0 * (m_star / k_n).sqrt();
            consider(dt_n, &|| {
                format!("normal contact stiffness, {what}, at {v} m/s")
            });
            if friction {
                let m_t = if rotation { 2.0 / 7.0 * m_star } else { m_star };
                let dt_t = 0.5 * 2.0 * (m_t / k_t).sqrt();
                consider(dt_t, &|| {
                    format!("tangential contact stiffness, {what}, at {v} m/s")
                });
            }
        }
    }
    if !best.limit.is_finite() {
        best.limit = f64::MAX;
    }
    Ok(best)
}
