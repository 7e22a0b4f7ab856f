//! Hard cases that must stay bounded: jammed packings at real glass stiffness, a fast impact
//! on a thin wall, a sphere squeezed by an oscillating gate, and a user step just under the
//! stable limit.

mod dem_support;
use dem_support::*;

use demfem::dem::{Effect, EffectSet, ParticleInit, Scene, Simulation};
use demfem::geometry::{Vec3, Wall, WallMotion, WallShape};
use demfem::DemfemError;

/// Run a jammed box `steps` steps and check the bounds: every step Ok (no NaN), overlap below
/// 1 % of the radius, kinetic energy below that of every sphere moving at the belt speed and
/// spinning with its contact point at belt speed (ω = V/R): the belt is the only energy
/// source and can drive neither faster; 5 % margin for transients.
fn run_jammed(scene: &Scene, steps: u64) {
    let mut sim = Simulation::new(scene).unwrap();
    let r = 0.008;
    let n = sim.len() as f64;
    let ke_cap = 1.05
        * n
        * (0.5 * sim.masses()[0] * 0.2 * 0.2 + 0.5 * sim.inertias()[0] * (0.2 / r) * (0.2 / r));
    let mut max_overlap: f64 = 0.0;
    for _ in 0..steps / 1000 {
        sim.step(1000).unwrap();
        max_overlap = max_overlap.max(sim.max_overlap());
        assert!(
            sim.kinetic_energy() < ke_cap,
            "KE {} > {ke_cap}",
            sim.kinetic_energy()
        );
    }
    assert!(max_overlap < 0.01 * r, "overlap {max_overlap}");
    // the pack really is jammed: a hexagonal monolayer pressed by the belt has Z ≈ 3-4 at the end
    let z: u32 = sim.coordination().iter().sum();
    assert!(z as f64 / n > 2.5, "mean coordination {}", z as f64 / n);
}

#[test]
fn jammed_packing_is_held_at_45_and_73_gpa() {
    for e in [45e9, 73e9] {
        let scene = jammed_box(10, 8, e);
        run_jammed(&scene, 100_000);
    }
}

#[test]
fn user_step_ten_percent_under_the_limit_is_stable() {
    let probe = Simulation::new(&jammed_box(10, 8, 73e9)).unwrap();
    let limit = probe.stable_step().limit;
    let mut scene = jammed_box(10, 8, 73e9);
    scene.time_step = Some(0.9 * limit);
    run_jammed(&scene, 100_000);
    // and a step above the limit is refused
    scene.time_step = Some(1.01 * limit);
    match Simulation::new(&scene) {
        Err(DemfemError::UnstableTimeStep { dt, limit: l, .. }) => assert!(dt > l),
        other => panic!("expected UnstableTimeStep, got {other:?}"),
    }
}

/// 5 m/s head-on on a thin (two-sided) gate leaf at E = 73 GPa with the default step: the
/// sphere bounces back (no tunnelling), the overlap stays within 2 % of the Hertz maximum.
#[test]
fn fast_impact_on_thin_wall_does_not_tunnel() {
    let (r, v, e) = (0.008, 5.0, 73e9);
    let glass = material(e, 0.22, 2230.0, 0.0, 1.0);
    let mut p = ParticleInit::at_rest(vec![Vec3::new(-r - 1e-4, 0.0, 0.0)], vec![r]);
    p.velocity[0] = Vec3::new(v, 0.0, 0.0);
    let leaf = Wall::fixed(
        WallShape::vertical_strip(0.0, -0.05, 0.0, 0.05, -0.05, 0.05).unwrap(),
        0,
    );
    let mut scene = Scene::new(p, vec![glass], vec![leaf], EffectSet::empty());
    scene.gravity = Vec3::ZERO;
    scene.expected_max_speed = v;
    let mut sim = Simulation::new(&scene).unwrap();
    let m = sim.masses()[0];
    let (d_th, _, _) = hertz_impact(e_star(e, 0.22, e, 0.22), r, m, v);
    let mut d_max: f64 = 0.0;
    for _ in 0..20_000 {
        sim.step(1).unwrap();
        d_max = d_max.max(sim.max_overlap());
        assert!(sim.positions()[0].x < 0.0, "centre crossed the wall");
    }
    assert!(
        sim.velocities()[0].x < -0.99 * v,
        "no rebound: {:?}",
        sim.velocities()[0]
    );
    assert!(
        (d_max / d_th - 1.0).abs() < 0.02,
        "overlap {d_max} vs Hertz {d_th}"
    );
}

/// A sphere between a fixed wall (x = 0) and a gate oscillating along x with A = 1 mm,
/// T = 10 ms, whose closest approach squeezes it by 20 µm (0.25 % of r). Over three periods:
/// no NaN, the sphere stays between the walls, the overlap never exceeds the imposed squeeze
/// plus 10 % (Hertz load sharing between two contacts), speeds stay below the gate's
/// 2π A/T ≈ 0.63 m/s by a bounded factor.
#[test]
fn sphere_wedged_by_oscillating_gate_stays_bounded() {
    let r = 0.008;
    let (amp, period, squeeze) = (1e-3, 0.01, 20e-6);
    let gate_x = 2.0 * r + amp - squeeze; // the gate reaches gate_x - amp = 2r - squeeze
    let glass = material(45e9, 0.22, 2230.0, 0.2, 0.5);
    let p = ParticleInit::at_rest(vec![Vec3::new(r, 0.0, 0.0)], vec![r]);
    let fixed = Wall::fixed(WallShape::plane(Vec3::ZERO, Vec3::X).unwrap(), 0);
    let mut gate = Wall::fixed(
        WallShape::vertical_strip(gate_x, -0.05, gate_x, 0.05, -0.05, 0.05).unwrap(),
        0,
    );
    gate.motion = WallMotion::harmonic(-Vec3::X, amp, period, 0.0).unwrap();
    let effects = EffectSet::of(&[
        Effect::MovingWalls,
        Effect::Friction,
        Effect::Rotation,
        Effect::Damping,
    ]);
    let mut scene = Scene::new(p, vec![glass], vec![fixed, gate], effects);
    scene.gravity = Vec3::ZERO;
    scene.expected_max_speed = 2.0;
    let mut sim = Simulation::new(&scene).unwrap();
    let steps = (3.0 * period / sim.dt()) as u64;
    let mut d_max: f64 = 0.0;
    for _ in 0..steps {
        sim.step(1).unwrap();
        d_max = d_max.max(sim.max_overlap());
        let x = sim.positions()[0].x;
        assert!(x > 0.0 && x < gate_x + amp, "escaped: x = {x}");
        assert!(
            sim.velocities()[0].length() < 5.0,
            "speed {:?}",
            sim.velocities()[0]
        );
    }
    assert!(
        d_max > 0.0 && d_max < 1.1 * squeeze,
        "overlap {d_max} vs squeeze {squeeze}"
    );
}
