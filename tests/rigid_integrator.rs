//! Torque-free rigid-body rotation against closed forms: conservation of angular momentum
//! (space frame) and kinetic energy, the precession rate of a symmetric top, and the
//! intermediate-axis (tennis racket) flip.
use demfem::rigid::{RigidBodies, RigidBodyInit};
use nalgebra::{UnitQuaternion, Vector3};

fn one_body(inertia: Vector3<f64>, omega: Vector3<f64>) -> RigidBodies {
    let mut bodies = RigidBodies::new();
    bodies
        .push(RigidBodyInit {
            position: Vector3::zeros(),
            orientation: UnitQuaternion::from_euler_angles(0.3, -0.2, 0.7),
            velocity: Vector3::zeros(),
            angular_velocity_body: omega,
            mass: 1.0,
            principal_inertia: inertia,
        })
        .unwrap();
    bodies
}

fn free_step(bodies: &mut RigidBodies, h: f64) {
    bodies.kick(0.5 * h);
    bodies.drift(h);
    bodies.kick(0.5 * h);
}

#[test]
fn free_asymmetric_body_conserves_momentum_and_energy() {
    let mut bodies = one_body(Vector3::new(1.0, 2.0, 3.0), Vector3::new(3.0, 1.0, 2.0));
    let l0 = bodies.angular_momentum_world(0);
    let e0 = bodies.kinetic_energy(0);
    let h = 1e-3; // |ω| h ≈ 4e-3, a DEM-like resolution of the rotation
    let mut worst_energy: f64 = 0.0;
    for _ in 0..100_000 {
        free_step(&mut bodies, h);
        worst_energy = worst_energy.max((bodies.kinetic_energy(0) / e0 - 1.0).abs());
    }
    let l = bodies.angular_momentum_world(0);
    assert!(
        (l - l0).norm() <= 1e-12 * l0.norm(),
        "L drift {:e}",
        (l - l0).norm() / l0.norm()
    );
    assert!(worst_energy < 1e-5, "energy error {worst_energy:e}");
    assert!((bodies.orientation[0].quaternion().norm() - 1.0).abs() < 1e-14);
}

#[test]
fn symmetric_top_precesses_at_closed_form_rate() {
    // the cartridge's own inertia (I1 = I2 transverse, I3 axial), spinning fast about its axis
    let (i1, i3) = (1.645_943_63e-6, 1.292_061_47e-7);
    let omega3 = 40.0;
    let mut bodies = one_body(Vector3::new(i1, i1, i3), Vector3::new(0.5, 0.0, omega3));
    let expected = (i3 - i1) / i1 * omega3; // Ω = (I3 − I1)/I1 ω3, rad/s, body frame
    let h = 1e-5;
    let steps = 200_000;
    let mut angle = 0.0;
    let mut previous = 0.0_f64;
    for _ in 0..steps {
        free_step(&mut bodies, h);
        let w = bodies.angular_velocity_body[0];
        let now = w.y.atan2(w.x);
        let mut d = now - previous;
        d -= (d / std::f64::consts::TAU).round() * std::f64::consts::TAU;
        angle += d;
        previous = now;
        assert!(
            (w.z - omega3).abs() < 1e-9,
            "ω3 must stay constant for a symmetric top"
        );
    }
    let rate = angle / (h * steps as f64);
    assert!(
        (rate / expected - 1.0).abs() < 1e-4,
        "rate {rate} vs {expected}"
    );
}

#[test]
fn intermediate_axis_flips_but_conserves_momentum_and_energy() {
    let mut bodies = one_body(Vector3::new(1.0, 2.0, 3.0), Vector3::new(1e-3, 5.0, 1e-3));
    let l0 = bodies.angular_momentum_world(0);
    let e0 = bodies.kinetic_energy(0);
    let (mut seen_negative, mut min_wy, mut max_transverse) = (false, f64::INFINITY, 0.0_f64);
    for _ in 0..100_000 {
        free_step(&mut bodies, 1e-4);
        let w = bodies.angular_velocity_body[0];
        min_wy = min_wy.min(w.y);
        max_transverse = max_transverse.max(w.x.abs().max(w.z.abs()));
        seen_negative |= w.y < -4.0;
    }
    // the spin about the intermediate axis reverses (body flips) and the perturbation grows
    // from 1e-3 to order |ω|
    assert!(seen_negative, "no flip: min ω_y = {min_wy}");
    assert!(
        max_transverse > 1.0,
        "perturbation did not grow: {max_transverse}"
    );
    let l = bodies.angular_momentum_world(0);
    assert!((l - l0).norm() <= 1e-12 * l0.norm());
    assert!((bodies.kinetic_energy(0) / e0 - 1.0).abs() < 1e-6);
}
