//! Chung & Ooi (2011), "Benchmark tests for verifying discrete element modelling codes at
//! particle impact level", Granular Matter 13:643–656, tests 1–4, checked against the closed
//! forms they compare with (Hertz impact, restitution, rigid-body oblique impact theory), plus
//! energy conservation of undamped impacts.
//!
//! Step sizes are chosen per test as a fraction of the Hertz contact time so the time
//! discretisation error is far below the asserted tolerance; each tolerance says why.

mod dem_support;
use dem_support::*;

use demfem::dem::{Effect, EffectSet, ParticleInit, Scene, Simulation};
use demfem::geometry::Vec3;

/// Run until the contact with the partner ends; return (max overlap, max normal force,
/// contact duration, steps).
fn track_contact(sim: &mut Simulation, max_steps: u64) -> (f64, f64, f64, u64) {
    let (mut d_max, mut f_max, mut active_steps) = (0.0_f64, 0.0_f64, 0u64);
    let mut started = false;
    for k in 0..max_steps {
        sim.step(1).unwrap();
        let c = sim.contacts();
        if let Some(c) = c.first() {
            started = true;
            active_steps += 1;
            d_max = d_max.max(c.overlap);
            f_max = f_max.max(c.normal_force);
        } else if started {
            return (d_max, f_max, active_steps as f64 * sim.dt(), k);
        }
    }
    panic!("contact did not end within {max_steps} steps");
}

/// Test 1: elastic normal impact of two identical glass spheres (E = 48 GPa, ν = 0.20,
/// ρ = 2800 kg/m³, R = 10 mm, each at 10 m/s). Max overlap, max force and duration against
/// Hertz. dt = t_c/1000: the sampled maximum is within (π/1000)²/8 ≈ 1e-6 of the true one,
/// the duration within one step (0.1 %); tolerance 0.3 %.
#[test]
fn test1_elastic_sphere_sphere_matches_hertz() {
    let (e, nu, rho, r, v) = (4.8e10, 0.20, 2800.0, 0.010, 10.0);
    let m = sphere_mass(rho, r);
    let (d_th, f_th, t_th) = hertz_impact(e_star(e, nu, e, nu), r / 2.0, m / 2.0, 2.0 * v);
    let mut p = ParticleInit::at_rest(
        vec![
            Vec3::new(-r - 1e-5, 0.0, 0.0),
            Vec3::new(r + 1e-5, 0.0, 0.0),
        ],
        vec![r, r],
    );
    p.velocity = vec![Vec3::new(v, 0.0, 0.0), Vec3::new(-v, 0.0, 0.0)];
    let mut scene = Scene::new(
        p,
        vec![material(e, nu, rho, 0.0, 1.0)],
        vec![],
        EffectSet::empty(),
    );
    scene.gravity = Vec3::ZERO;
    scene.expected_max_speed = 2.0 * v;
    scene.time_step = Some(t_th / 1000.0);
    let mut sim = Simulation::new(&scene).unwrap();
    let (d, f, t, _) = track_contact(&mut sim, 10_000);
    assert!((d / d_th - 1.0).abs() < 3e-3, "overlap {d} vs Hertz {d_th}");
    assert!((f / f_th - 1.0).abs() < 3e-3, "force {f} vs Hertz {f_th}");
    assert!(
        (t / t_th - 1.0).abs() < 3e-3,
        "duration {t} vs Hertz {t_th}"
    );
}

/// Test 2: elastic normal impact of a sphere (R = 0.1 m) on a rigid plane at 0.2 m/s, for
/// aluminium alloy (E = 70 GPa, ν = 0.33, ρ = 2700) and magnesium alloy (E = 45 GPa, ν = 0.35,
/// ρ = 1800). Same tolerances as test 1.
#[test]
fn test2_elastic_sphere_wall_matches_hertz() {
    for (e, nu, rho) in [(7.0e10, 0.33, 2700.0), (4.5e10, 0.35, 1800.0)] {
        let (r, v) = (0.1, 0.2);
        let m = sphere_mass(rho, r);
        let (d_th, f_th, t_th) = hertz_impact(e_star(e, nu, 1e21, nu), r, m, v);
        let mats = vec![material(e, nu, rho, 0.0, 1.0), rigid(nu, 0.0, 1.0)];
        let mut scene = sphere_on_floor(
            r,
            r + 1e-7,
            Vec3::new(0.0, 0.0, -v),
            Vec3::ZERO,
            mats,
            EffectSet::empty(),
        );
        scene.time_step = Some(t_th / 1000.0);
        let mut sim = Simulation::new(&scene).unwrap();
        let (d, f, t, _) = track_contact(&mut sim, 10_000);
        assert!(
            (d / d_th - 1.0).abs() < 3e-3,
            "E={e}: overlap {d} vs {d_th}"
        );
        assert!((f / f_th - 1.0).abs() < 3e-3, "E={e}: force {f} vs {f_th}");
        assert!(
            (t / t_th - 1.0).abs() < 3e-3,
            "E={e}: duration {t} vs {t_th}"
        );
        // undamped and frictionless: the rebound speed equals the impact speed
        let v_out = sim.velocities()[0].z;
        assert!((v_out / v - 1.0).abs() < 1e-6, "E={e}: rebound {v_out}");
    }
}

/// Test 3: normal impact on a rigid plane with restitution e = 0.1 … 0.9 (Tsuji damping),
/// with and without clamping the normal force at ≥ 0: the rebound/impact speed ratio must
/// realise e within 1 % (the requirement). dt = t_c/2000: the half-step velocity lag of
/// the dashpot shifts e by O(dt/t_c) ≈ 5e-4.
#[test]
fn test3_restitution_is_realised_with_and_without_clamp() {
    let (e_mod, nu, rho, r, v) = (4.5e10, 0.22, 2230.0, 0.008, 0.5);
    let m = sphere_mass(rho, r);
    let (_, _, t_th) = hertz_impact(e_star(e_mod, nu, 1e21, nu), r, m, v);
    for clamp in [true, false] {
        for k in 1..=9 {
            let e = k as f64 / 10.0;
            let mats = vec![material(e_mod, nu, rho, 0.0, e), rigid(nu, 0.0, e)];
            let mut scene = sphere_on_floor(
                r,
                r + 1e-7,
                Vec3::new(0.0, 0.0, -v),
                Vec3::ZERO,
                mats,
                EffectSet::of(&[Effect::Damping]),
            );
            scene.clamp_normal_force = clamp;
            scene.time_step = Some(t_th / 2000.0);
            let mut sim = Simulation::new(&scene).unwrap();
            let mut started = false;
            for _ in 0..200_000 {
                sim.step(1).unwrap();
                let touching = sim.wall_contact_counts()[0] > 0;
                if touching {
                    started = true;
                } else if started {
                    break;
                }
            }
            let e_real = sim.velocities()[0].z / v;
            assert!(
                (e_real / e - 1.0).abs() < 0.01,
                "clamp={clamp}: e = {e}, realised {e_real}"
            );
        }
    }
}

/// Test 4: oblique impact of an alumina sphere (R = 2.5 mm, E = 380 GPa, ν = 0.23, ρ = 4000,
/// μ = 0.092, e = 0.98) on a rigid plane at 3.9 m/s for several incidence angles (Kharaz,
/// Gorham & Salman 2001, as used by Chung & Ooi). Rigid-body theory: while the contact
/// slides throughout (tan θ > 7/2 μ (1+e)), the tangential velocity drops by μ (1+e) v_n and
/// the spin becomes 5/2 μ (1+e) v_n / R. At every angle the tangential impulse respects the
/// Coulomb bound and angular momentum about the contact point is conserved. Tolerance 1 %: the elastic tangential
/// loading at onset covers a few steps of a 1500-step contact.
#[test]
fn test4_oblique_impact_matches_rigid_body_theory_when_sliding() {
    let (e_mod, nu, rho, r, speed, mu, e) = (3.8e11, 0.23, 4000.0, 0.0025, 3.9, 0.092, 0.98);
    let m = sphere_mass(rho, r);
    let (_, _, t_th) = hertz_impact(e_star(e_mod, nu, 1e21, nu), r, m, speed);
    let limit_tan = 3.5 * mu * (1.0 + e);
    let effects = EffectSet::of(&[Effect::Damping, Effect::Friction, Effect::Rotation]);
    for deg in [5.0_f64, 10.0, 20.0, 30.0, 45.0, 60.0, 80.0] {
        let th = deg.to_radians();
        let (vt, vn) = (speed * th.sin(), speed * th.cos());
        let mats = vec![material(e_mod, nu, rho, mu, e), rigid(nu, mu, e)];
        let mut scene = sphere_on_floor(
            r,
            r + 1e-8,
            Vec3::new(vt, 0.0, -vn),
            Vec3::ZERO,
            mats,
            effects,
        );
        scene.expected_max_speed = speed;
        scene.time_step = Some(t_th / 1500.0);
        let mut sim = Simulation::new(&scene).unwrap();
        let ke0 = sim.kinetic_energy();
        let mut started = false;
        for _ in 0..100_000 {
            sim.step(1).unwrap();
            if sim.wall_contact_counts()[0] > 0 {
                started = true;
            } else if started {
                break;
            }
        }
        let v_out = sim.velocities()[0];
        let w_out = sim.angular_velocities()[0];
        let vn_out = v_out.z;
        assert!(
            (vn_out / (e * vn) - 1.0).abs() < 0.01,
            "{deg}°: normal rebound {vn_out} vs {}",
            e * vn
        );
        assert!(sim.kinetic_energy() <= ke0, "{deg}°: energy gained");
        if th.tan() > 1.1 * limit_tan {
            let vt_th = vt - mu * (1.0 + e) * vn;
            let w_th = 2.5 * mu * (1.0 + e) * vn / r;
            assert!(
                (v_out.x / vt_th - 1.0).abs() < 0.01,
                "{deg}°: v_t {} vs {vt_th}",
                v_out.x
            );
            // a sphere sliding in +x on a floor below spins about +y
            assert!(
                (w_out.y / w_th - 1.0).abs() < 0.01,
                "{deg}°: ω {} vs {w_th}",
                w_out.y
            );
        }
        // any regime: the Coulomb bound on the tangential impulse, |Δv_t| ≤ μ (1+e) v_n
        // (1 % for the realised e), and angular momentum about the contact point is conserved,
        // so I Δω = m R Δv_t, i.e. ω = 5/2 Δv_t / R (the lever arm R − δ differs by δ/R < 1e-3)
        let dvt = vt - v_out.x;
        assert!(
            dvt <= 1.01 * mu * (1.0 + e) * vn && dvt >= 0.0,
            "{deg}°: Δv_t {dvt}"
        );
        assert!(
            (w_out.y / (2.5 * dvt / r) - 1.0).abs() < 1e-2,
            "{deg}°: ω {} vs {}",
            w_out.y,
            2.5 * dvt / r
        );
        // the contact point's tangential velocity never grows in magnitude (no energy gain)
        let slip_out = v_out.x - w_out.y * r;
        assert!(
            slip_out.abs() <= vt * 1.0001,
            "{deg}°: contact-point velocity {slip_out} vs incident {vt}"
        );
    }
}

/// Undamped, frictionless impacts conserve energy: after the contact the kinetic energy equals
/// the initial one to 1e-6 relative (leapfrog is time-reversible; dt = t_c/2000).
#[test]
fn undamped_impacts_conserve_energy() {
    let (e, nu, rho, r) = (4.5e10, 0.22, 2230.0, 0.008);
    let m = sphere_mass(rho, r);
    for v in [0.05, 0.5, 5.0] {
        let (_, _, t_th) = hertz_impact(e_star(e, nu, e, nu), r / 2.0, m / 2.0, v);
        // oblique: offset 3 mm across, 1 mm up, initial gap 1 µm
        let x2 = ((2.0 * r + 1e-6_f64).powi(2) - 0.003_f64.powi(2) - 0.001_f64.powi(2)).sqrt();
        let mut p = ParticleInit::at_rest(
            vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(x2, 0.003, 0.001)],
            vec![r, r],
        );
        p.velocity = vec![Vec3::new(v, 0.0, 0.0), Vec3::ZERO];
        let mut scene = Scene::new(
            p,
            vec![material(e, nu, rho, 0.0, 1.0)],
            vec![],
            EffectSet::empty(),
        );
        scene.gravity = Vec3::ZERO;
        scene.expected_max_speed = v;
        scene.time_step = Some(t_th / 2000.0);
        let mut sim = Simulation::new(&scene).unwrap();
        let ke0 = sim.kinetic_energy();
        track_contact(&mut sim, 100_000);
        let ke1 = sim.kinetic_energy();
        assert!((ke1 / ke0 - 1.0).abs() < 1e-6, "v={v}: KE {ke0} -> {ke1}");
    }
}
