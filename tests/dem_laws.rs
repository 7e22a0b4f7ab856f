//! The other contact laws and rolling resistance inside the DEM, against closed forms:
//! Hertz–Reissner series law (energy balance, eq. 12 of the paper), linear spring–dashpot
//! (damped oscillator), constant rolling torque (rigid-body rolling deceleration 5/7 μ_r g).

mod dem_support;
use dem_support::*;

use demfem::dem::{DemContactLaw, Effect, EffectSet, Simulation};
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
    scene.model = DemContactLaw::HertzReissnerMindlin;
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
    scene.model = DemContactLaw::LinearSpringDashpot {
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

/// Velocity samples of one sphere resting on a rigid floor under gravity after a small kick
/// `kick` (m/s) from its Hertz–Reissner equilibrium, with the given effects and step.
fn hr_oscillation(
    k_r: f64,
    kick: Vec3,
    effects: EffectSet,
    dt: f64,
    steps: usize,
) -> (f64, Vec<Vec3>, Simulation) {
    let (e, nu, rho, r, g) = (45e9, 0.22, 2230.0, 0.008, 9.81);
    let m = sphere_mass(rho, r);
    let k_h = k_hertz(e_star(e, nu, 1e21, nu), r);
    let f0 = m * g;
    let delta0 = (f0 / k_h).powf(2.0 / 3.0) + f0 / k_r; // eq. 12 at rest
                                                        // the scene refuses friction or restitution < 1 without the effect that uses it
    let mu = if effects.has(Effect::Friction) {
        0.5
    } else {
        0.0
    };
    let rest = if effects.has(Effect::Damping) {
        0.5
    } else {
        1.0
    };
    let mut mat = material(e, nu, rho, mu, rest);
    mat.shell_stiffness = k_r;
    let floor = rigid(nu, mu, rest);
    let mut scene = sphere_on_floor(r, r - delta0, kick, Vec3::ZERO, vec![mat, floor], effects);
    scene.model = DemContactLaw::HertzReissnerMindlin;
    scene.gravity = Vec3::new(0.0, 0.0, -g);
    scene.time_step = Some(dt);
    let mut sim = Simulation::new(&scene).unwrap();
    let mut v = Vec::with_capacity(steps);
    for _ in 0..steps {
        sim.step(1).unwrap();
        v.push(sim.velocities()[0]);
    }
    (m, v, sim)
}

/// Mean spacing of the downward zero crossings of `x` (linear interpolation), in samples.
fn mean_period(x: &[f64]) -> f64 {
    let crossings: Vec<f64> = (1..x.len())
        .filter(|&i| x[i - 1] > 0.0 && x[i] <= 0.0)
        .map(|i| (i - 1) as f64 + x[i - 1] / (x[i - 1] - x[i]))
        .collect();
    assert!(crossings.len() >= 4, "too few periods: {}", crossings.len());
    (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64
}

/// Small oscillations of a sphere resting on a rigid floor under the Hertz–Reissner–Mindlin
/// law, against the linearised law at F₀ = m g (shell chosen so Hertz and shell overlaps are
/// comparable, s ≈ 1): normal period 2π √(m/k_n) with k_n = dF/dδ =
/// 1/((2/3) F₀^{-1/3} k_H^{-2/3} + 1/k_R); tangential period 2π √(m/k_t) with the Mindlin
/// k_t = 8 G* √(R δ_H), δ_H = (F₀/k_H)^{2/3} (rotation off, far below the Coulomb cap); and
/// with damping the decay of the normal velocity over one damped period, exp(−γ T_d),
/// γ = c_n/(2m), c_n = ζ √(2/3 m k_n) (Tsuji, ζ of the scene's restitution 0.5 with the force
/// clamp). Amplitudes are 1e-3 of the static overlap, so the nonlinearity is ~1e-6; dt is
/// 1/2000 of a period (1/8000 for the decay). Tolerances: periods 1e-4; decay rate 1.5e-3,
/// because the dashpot reads the half-step velocity, an O(γ dt) error (2.5e-3 at T/2000,
/// 6.5e-4 at T/8000).
#[test]
fn hertz_reissner_mindlin_small_oscillations_match_linearised_law() {
    let (e, nu, r, g, k_r) = (45e9, 0.22_f64, 0.008, 9.81, 1.0e6);
    let k_h = k_hertz(e_star(e, nu, 1e21, nu), r);
    let m = sphere_mass(2230.0, r);
    let f0 = m * g;
    let d_h = (f0 / k_h).powf(2.0 / 3.0);
    let delta0 = d_h + f0 / k_r;
    let k_n = 1.0 / (2.0 / 3.0 / (f0 * k_h * k_h).cbrt() + 1.0 / k_r);
    let shear = |e: f64, nu: f64| e / (2.0 * (1.0 + nu));
    let g_star = 1.0 / ((2.0 - nu) / shear(e, nu) + (2.0 - nu) / shear(1e21, nu));
    let k_t = 8.0 * g_star * (r * d_h).sqrt();
    let (t_n, t_t) = (
        2.0 * std::f64::consts::PI * (m / k_n).sqrt(),
        2.0 * std::f64::consts::PI * (m / k_t).sqrt(),
    );

    // normal, undamped
    let omega_n = 2.0 * std::f64::consts::PI / t_n;
    let kick = Vec3::new(0.0, 0.0, -1e-3 * delta0 * omega_n);
    let dt = t_n / 2000.0;
    let (_, v, _) = hr_oscillation(k_r, kick, EffectSet::of(&[Effect::Gravity]), dt, 20_000);
    let vz: Vec<f64> = v.iter().map(|v| v.z).collect();
    let period = mean_period(&vz) * dt;
    assert!(
        (period / t_n - 1.0).abs() < 1e-4,
        "normal period {period} vs {t_n}"
    );

    // tangential, undamped, no rotation
    let omega_t = 2.0 * std::f64::consts::PI / t_t;
    let kick = Vec3::new(1e-3 * delta0 * omega_t, 0.0, 0.0);
    let dt = t_t / 2000.0;
    let effects = EffectSet::of(&[Effect::Gravity, Effect::Friction]);
    let (_, v, _) = hr_oscillation(k_r, kick, effects, dt, 20_000);
    let vx: Vec<f64> = v.iter().map(|v| v.x).collect();
    let period = mean_period(&vx) * dt;
    assert!(
        (period / t_t - 1.0).abs() < 1e-4,
        "tangential period {period} vs {t_t}"
    );

    // normal, damped: v(t + T_d) = v(t) exp(−γ T_d)
    let zeta = demfem::contact::tsuji_damping_for_restitution(
        0.5,
        demfem::contact::ForceClamp::NonNegative,
    )
    .unwrap();
    let c_n = zeta * (2.0 / 3.0 * m * k_n).sqrt();
    let gamma = c_n / (2.0 * m);
    let t_d = 2.0 * std::f64::consts::PI / (omega_n * omega_n - gamma * gamma).sqrt();
    let dt = t_d / 8000.0;
    let kick = Vec3::new(0.0, 0.0, -1e-3 * delta0 * omega_n);
    let effects = EffectSet::of(&[Effect::Gravity, Effect::Damping]);
    let (_, v, _) = hr_oscillation(k_r, kick, effects, dt, 10_000);
    let measured = (v[8_800].z / v[800].z).ln() / -t_d;
    assert!(
        (measured / gamma - 1.0).abs() < 1.5e-3,
        "decay rate {measured} vs {gamma}"
    );
}
