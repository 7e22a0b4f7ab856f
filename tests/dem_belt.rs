//! A free sphere dropped on a belt: it slides, then rolls without slip at 2/7 of the belt
//! speed (angular momentum about the contact point: m v R + I ω = const = 0 from rest, and
//! rolling v − ω_y R = V with I = 2/5 m R² give v = 2/7 V). With `planar` (upright cartridge:
//! no rolling) it slides until it moves with the belt.

mod dem_support;
use dem_support::*;

use demfem::dem::{Effect, EffectSet, Simulation};
use demfem::geometry::Vec3;

fn belt_scene(planar: bool) -> Simulation {
    let r = 0.008;
    let glass = material(45e9, 0.22, 2230.0, 0.2, 0.5);
    let mut effects = EffectSet::of(&[
        Effect::Gravity,
        Effect::Belt,
        Effect::Friction,
        Effect::Rotation,
        Effect::Damping,
    ]);
    if planar {
        effects = effects.with(Effect::Planar);
    }
    let mut scene = sphere_on_floor(r, r, Vec3::ZERO, Vec3::ZERO, vec![glass, glass], effects);
    scene.gravity = Vec3::new(0.0, 0.0, -9.81);
    scene.walls[0].surface_velocity = Vec3::new(0.2, 0.0, 0.0);
    scene.time_step_safety = 0.5;
    Simulation::new(&scene).unwrap()
}

/// The sliding phase lasts V / (7/2 μ g) = 29 ms; after 80 ms the sphere must roll at
/// 2/7 V. Tolerance 1 % (issue requirement); the lever arm R − δ differs from R by 1e-5.
#[test]
fn free_sphere_on_belt_rolls_at_two_sevenths_of_belt_speed() {
    let mut sim = belt_scene(false);
    sim.run_until(0.08).unwrap();
    let v = sim.velocities()[0];
    let w = sim.angular_velocities()[0];
    let target = 2.0 / 7.0 * 0.2;
    assert!((v.x / target - 1.0).abs() < 0.01, "v = {} vs {target}", v.x);
    // rolling without slip: the contact point (at −R ẑ) moves with the belt, v − ω_y R = V
    let slip = v.x - w.y * 0.008 - 0.2;
    assert!(slip.abs() < 0.002 * 0.2, "slip {slip}");
    assert!(v.y.abs() < 1e-9 && v.z.abs() < 1e-3, "{v:?}");
}

/// With `planar` the sphere cannot roll (rotation about z only): it slides at μ g until it
/// moves with the belt (after V/(μ g) = 0.1 s). Checked at 0.2 s within 1 %.
#[test]
fn planar_sphere_slides_to_belt_speed() {
    let mut sim = belt_scene(true);
    sim.run_until(0.2).unwrap();
    let v = sim.velocities()[0];
    assert!((v.x / 0.2 - 1.0).abs() < 0.01, "v = {}", v.x);
    assert_eq!(sim.angular_velocities()[0].x, 0.0);
    assert_eq!(sim.angular_velocities()[0].y, 0.0);
}
