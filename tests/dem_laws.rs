//! The other contact laws and rolling resistance inside the DEM, against closed forms:
//! Hertz–Reissner series law (energy balance, eq. 12 of the paper), linear spring–dashpot
//! (damped oscillator), constant rolling torque (rigid-body rolling deceleration 5/7 μ_r g).

mod dem_support;
use dem_support::*;

use demfem::dem::{ContactModel, Effect, EffectSet, Simulation};
use demfem::geometry::Vec3;

fn impact(sim: &mut Simulation) -> (f64, f64) {
    let (mut f_max, mut steps, mut started) = (0.0_f64, 0u64, false);
    for _ in 0..1_000_000 {
        sim.step(1).unwrap();
        match sim.contacts().first() {
            Some(c) => {
                started = true;
                steps += 1;
                f_max = f_max.max(c.normal_force);
            }
            None if started => break,
            None => {}
        }
    }
    (f_max, steps as f64 * sim.dt())
}

/// Hertz in series with a shell of stiffness k_R on a rigid plane: the maximum force solves
/// m v² = F²/k_R + 4/5 F^{5/3}/k_H^{2/3} (energy stored in both springs at rest, eq. 12).
/// Solved here by bisection; tolerance 0.3 % (dt = t/1000 sampling).
#[test]
fn hertz_reissner_impact_force_matches_energy_balance() {
    let (e, nu, rho, r, v) = (64e9, 0.2, 2300.0, 0.008, 0.2);
    let k_r = 3.0e6;
    let m = sphere_mass(rho, r);
    let k_h = k_hertz(e_star(e, nu, 1e21, nu), r);
    let g = |f: f64| f * f / k_r + 0.8 * f.powf(5.0 / 3.0) / k_h.powf(2.0 / 3.0) - m * v * v;
    let (mut lo, mut hi) = (0.0, 1e6);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(mid) > 0.0 {
            hi = mid
        } else {
            lo = mid
        }
    }
    let f_th = 0.5 * (lo + hi);
    let mut mat = material(e, nu, rho, 0.0, 1.0);
    mat.shell_stiffness = k_r;
    let mut scene = sphere_on_floor(
        r,
        r + 1e-7,
        Vec3::new(0.0, 0.0, -v),
        Vec3::ZERO,
        vec![mat, rigid(nu, 0.0, 1.0)],
        EffectSet::empty(),
    );
    scene.model = ContactModel::HertzReissnerMindlin;
    // the soft shell dominates: contact time ≈ π √(m/k_R)
    scene.time_step = Some(std::f64::consts::PI * (m / k_r).sqrt() / 1000.0);
    let mut sim = Simulation::new(&scene).unwrap();
    let (f, _) = impact(&mut sim);
    assert!((f / f_th - 1.0).abs() < 3e-3, "F_max {f} vs {f_th}");
    assert!(
        (sim.velocities()[0].z / v - 1.0).abs() < 1e-6,
        "elastic rebound"
    );
}

/// Linear spring–dashpot on a rigid plane: contact time π/ω_d with ω_d = ω₀ √(1−β²) and
/// restitution e exactly when the force is not clamped (tolerance 0.5 %: dt = t_c/2000 and
/// the half-step velocity lag of the dashpot).
#[test]
fn linear_spring_dashpot_matches_damped_oscillator() {
    let (rho, r, v, k_n, e): (f64, f64, f64, f64, f64) = (2230.0, 0.008, 0.3, 2.0e6, 0.6);
    let m = sphere_mass(rho, r);
    let beta = -e.ln() / (std::f64::consts::PI.powi(2) + e.ln().powi(2)).sqrt();
    let t_c = std::f64::consts::PI / ((k_n / m).sqrt() * (1.0 - beta * beta).sqrt());
    let mut scene = sphere_on_floor(
        r,
        r + 1e-7,
        Vec3::new(0.0, 0.0, -v),
        Vec3::ZERO,
        vec![material(45e9, 0.22, rho, 0.0, e), rigid(0.22, 0.0, e)],
        EffectSet::of(&[Effect::Damping]),
    );
    scene.model = ContactModel::LinearSpringDashpot {
        normal_stiffness: k_n,
        tangential_stiffness: 0.8 * k_n,
    };
    scene.clamp_normal_force = false;
    scene.time_step = Some(t_c / 2000.0);
    let mut sim = Simulation::new(&scene).unwrap();
    let (_, t) = impact(&mut sim);
    assert!((t / t_c - 1.0).abs() < 5e-3, "duration {t} vs {t_c}");
    let e_real = sim.velocities()[0].z / v;
    assert!(
        (e_real / e - 1.0).abs() < 5e-3,
        "restitution {e_real} vs {e}"
    );
}

/// A sphere rolling on a plane against a constant rolling torque μ_r R m g decelerates at
/// 5/7 μ_r g (rigid-body rolling: (m + I/R²) dv/dt = −M/R). After 0.05 s the speed must be
/// v₀ − 5/7 μ_r g t within 1 %.
#[test]
fn rolling_resistance_decelerates_at_five_sevenths_mu_r_g() {
    let (r, v0, mu_r) = (0.008, 0.3, 0.05);
    let mut mat = material(45e9, 0.22, 2230.0, 0.5, 0.5);
    mat.rolling_friction = mu_r;
    let effects = EffectSet::of(&[
        Effect::Gravity,
        Effect::Friction,
        Effect::Rotation,
        Effect::Damping,
        Effect::RollingResistance,
    ]);
    // start rolling without slip: ω_y = v/R for motion along +x on a floor below
    let mut scene = sphere_on_floor(
        r,
        r,
        Vec3::new(v0, 0.0, 0.0),
        Vec3::new(0.0, v0 / r, 0.0),
        vec![mat, mat],
        effects,
    );
    scene.gravity = Vec3::new(0.0, 0.0, -9.81);
    let mut sim = Simulation::new(&scene).unwrap();
    sim.run_until(0.05).unwrap();
    let expected = v0 - 5.0 / 7.0 * mu_r * 9.81 * sim.time();
    let v = sim.velocities()[0].x;
    assert!(
        (v / expected - 1.0).abs() < 0.01,
        "v = {v}, expected {expected}"
    );
}
