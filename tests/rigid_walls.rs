//! Rigid cartridges against the walls the accumulation table needs — convex polygons (finite,
//! two-sided) and a harmonically moving gate — and the outlet, checked against closed forms.
mod rigid_common;

use demfem::geometry::{Vec3, WallMotion, WallShape};
use demfem::rigid::{RigidScene, RigidSceneConfig, RigidWall};
use nalgebra::{UnitQuaternion, Vector3};
use rigid_common::*;

const R_OUT: f64 = 5.8e-3;

/// A vertical square polygon in the plane x = 0, |y| <= half, |z| <= half.
fn vertical_square(half: f64) -> WallShape {
    WallShape::polygon(vec![
        Vec3::new(0.0, -half, -half),
        Vec3::new(0.0, half, -half),
        Vec3::new(0.0, half, half),
        Vec3::new(0.0, -half, half),
    ])
    .unwrap()
}

fn scene(kind: &str, config: RigidSceneConfig) -> (RigidScene, usize) {
    let (shape, mass) = cartridge(kind);
    let mut scene = RigidScene::new(config).unwrap();
    let id = scene.add_shape(shape, mass).unwrap();
    (scene, id)
}

/// Smallest distance from the axis at which a tangent plane parallel to the axis can touch
/// the body, m: the outer radius for the exact shape; for the clump the minimum over
/// azimuth of its support function (its envelope is a cylinder with flutes between beads).
fn side_envelope_min(kind: &str) -> f64 {
    if kind != "clump" {
        return R_OUT;
    }
    let (clump, _) = cartridge_clump();
    (0..3600)
        .map(|k| {
            let t = k as f64 * std::f64::consts::TAU / 3600.0;
            clump
                .centers
                .iter()
                .zip(&clump.radii)
                .map(|(c, r)| c.x * t.cos() + c.y * t.sin() + r)
                .fold(f64::NEG_INFINITY, f64::max)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Gravity along ∓x pulls an upright cartridge onto either face of a vertical polygon: it
/// comes to rest with its side on the polygon, the centre between the body's smallest
/// side envelope and its outer radius from it (less the Hertz overlap of its weight, below
/// 2 µm), upright. A second cartridge beside the polygon's
/// edge falls freely past it: x(t) = x0 − g t²/2.
fn rest_against_polygon(kind: &str) {
    for side in [1.0, -1.0] {
        let g = 9.81;
        let config = RigidSceneConfig {
            gravity: Vector3::new(-side * g, 0.0, 0.0),
            walls: vec![RigidWall {
                shape: vertical_square(0.05),
                motion: WallMotion::Fixed,
                surface_velocity: Vector3::zeros(),
            }],
            max_expected_speed: 1.0,
            ..Default::default()
        };
        let (mut scene, id) = scene(kind, config);
        let x0 = side * (R_OUT + 0.2e-3);
        scene
            .add_body(
                id,
                Vector3::new(x0, 0.0, 0.0),
                UnitQuaternion::identity(),
                Vector3::zeros(),
                Vector3::zeros(),
            )
            .unwrap();
        // beside the polygon: 2 cm past its edge at y = 5 cm
        let free_x0 = side * 0.05;
        scene
            .add_body(
                id,
                Vector3::new(free_x0, 0.09, 0.0),
                UnitQuaternion::identity(),
                Vector3::zeros(),
                Vector3::zeros(),
            )
            .unwrap();
        let t_end = 0.06;
        let steps = (t_end / scene.time_step()).ceil() as u64;
        scene.run(steps).unwrap();
        let b = &scene.bodies;
        let x = b.position[0].x * side;
        let lowest = side_envelope_min(kind) - 2e-6;
        assert!(
            x < R_OUT && x > lowest,
            "{kind} side {side}: x {x}, bounds {lowest} {R_OUT}"
        );
        // at rest normal to the wall; along it a cylinder on its side is in neutral
        // equilibrium (it may roll about its axis), so only the normal speed must vanish
        assert!(b.velocity[0].x.abs() < 1e-3, "{kind}: {:?}", b.velocity[0]);
        let tilt = tilt_degrees(&b.orientation[0]);
        assert!(tilt < 0.05, "{kind}: tilt {tilt}°");
        let t = scene.time();
        let expected = free_x0 - side * 0.5 * g * t * t;
        assert!(
            (b.position[1].x - expected).abs() < 1e-9,
            "{kind}: free body at {} vs {expected}",
            b.position[1].x
        );
        assert_eq!(scene.wall_contacts()[0], 1);
        assert_eq!(scene.wall_contacts()[1], 0);
    }
}

#[test]
fn clump_rests_against_either_face_of_a_vertical_polygon() {
    rest_against_polygon("clump");
}

#[test]
fn exact_cartridge_rests_against_either_face_of_a_vertical_polygon() {
    rest_against_polygon("exact");
}

#[test]
fn revolution_cartridge_rests_against_either_face_of_a_vertical_polygon() {
    rest_against_polygon("revolution");
}

/// A gate polygon oscillating as x = A sin(ωt) hits a cartridge lying along x, bottom end
/// first, `gap` ahead of it (no gravity, no friction, restitution 1). Against an infinitely
/// heavy wall moving at V the elastic rebound leaves the body at 2V, V = Aω cos(ω t_hit)
/// with A sin(ω t_hit) = gap; the push passes through the centre of mass, so no spin. The
/// onset log holds the one wall contact with approach speed V.
fn pushed_by_gate(kind: &str) {
    let (amplitude, period, gap) = (0.01, 0.2, 0.5e-3);
    let omega = 2.0 * std::f64::consts::PI / period;
    let config = RigidSceneConfig {
        gravity: Vector3::zeros(),
        walls: vec![RigidWall {
            shape: vertical_square(0.03),
            motion: WallMotion::harmonic(Vec3::X, amplitude, period, 0.0).unwrap(),
            surface_velocity: Vector3::zeros(),
        }],
        restitution: 1.0,
        friction: 0.0,
        max_expected_speed: 1.0,
        record_onsets: true,
        ..Default::default()
    };
    let (mut scene, id) = scene(kind, config);
    let axis_along_x =
        UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::FRAC_PI_2);
    scene
        .add_body(
            id,
            Vector3::new(com_height() + gap, 0.0, 0.0),
            axis_along_x,
            Vector3::zeros(),
            Vector3::zeros(),
        )
        .unwrap();
    let steps = (0.03 / scene.time_step()).ceil() as u64;
    scene.run(steps).unwrap();
    let t_hit = (gap / amplitude).asin() / omega;
    let v_wall = amplitude * omega * (omega * t_hit).cos();
    let v = scene.bodies.velocity[0];
    assert!(
        (v.x / (2.0 * v_wall) - 1.0).abs() < 0.01,
        "{kind}: {v:?} vs 2 x {v_wall}"
    );
    assert!(v.y.abs() + v.z.abs() < 1e-3 * v.x, "{kind}: {v:?}");
    let spin = scene.bodies.angular_velocity_body[0].norm();
    assert!(spin < 0.05, "{kind}: spin {spin} rad/s");
    let onsets = scene.onsets();
    assert_eq!(onsets.len(), 1, "{kind}: {onsets:?}");
    let o = onsets[0];
    assert!(o.partner_is_wall && o.partner == 0 && o.body == 0);
    assert!(
        (o.time - t_hit).abs() < 1e-4,
        "{kind}: onset at {} vs {t_hit}",
        o.time
    );
    assert!(
        (o.normal_speed / v_wall - 1.0).abs() < 0.01,
        "{kind}: {o:?} vs {v_wall}"
    );
}

#[test]
fn clump_pushed_by_a_moving_gate_leaves_at_twice_the_gate_speed() {
    pushed_by_gate("clump");
}

#[test]
fn exact_cartridge_pushed_by_a_moving_gate_leaves_at_twice_the_gate_speed() {
    pushed_by_gate("exact");
}

#[test]
fn revolution_cartridge_pushed_by_a_moving_gate_leaves_at_twice_the_gate_speed() {
    pushed_by_gate("revolution");
}

/// A cartridge crossing the outlet plane is removed at the step its centre crosses it and
/// stays where it was.
#[test]
fn body_past_the_outlet_is_removed() {
    let config = RigidSceneConfig {
        gravity: Vector3::zeros(),
        removal_plane: Some((Vector3::new(0.01, 0.0, 0.0), Vector3::new(-1.0, 0.0, 0.0))),
        max_expected_speed: 1.0,
        ..Default::default()
    };
    let (mut scene, id) = scene("clump", config);
    let v = 0.5;
    scene
        .add_body(
            id,
            Vector3::zeros(),
            UnitQuaternion::identity(),
            Vector3::new(v, 0.0, 0.0),
            Vector3::zeros(),
        )
        .unwrap();
    let steps = (0.03 / scene.time_step()).ceil() as u64;
    scene.run(steps).unwrap();
    assert!(!scene.alive()[0]);
    let (t, i) = scene.removals()[0];
    assert_eq!(i, 0);
    assert!((t - 0.01 / v).abs() <= 1.01 * scene.time_step(), "{t}");
    let x = scene.bodies.position[0].x;
    assert!(x >= 0.01 && x < 0.01 + 1.01 * v * scene.time_step(), "{x}");
}

#[test]
fn cuboid_walls_are_refused() {
    let config = RigidSceneConfig {
        walls: vec![RigidWall {
            shape: WallShape::cuboid(Vec3::ZERO, Vec3::ONE).unwrap(),
            motion: WallMotion::Fixed,
            surface_velocity: Vector3::zeros(),
        }],
        ..Default::default()
    };
    assert!(RigidScene::new(config).is_err());
}

/// An exact cartridge that bounces off a wall, leaves its reach and comes back touches it
/// again like the first time (the contact cache is reset when a pair drifts apart; a stale
/// parry workspace used to panic here). Dropped upright onto a floor wall, elastic and
/// frictionless, it hits at √(2 g h) both times.
#[test]
fn exact_cartridge_bouncing_off_a_wall_twice() {
    bouncing_twice("exact");
}

#[test]
fn revolution_cartridge_bouncing_off_a_wall_twice() {
    bouncing_twice("revolution");
}

fn bouncing_twice(kind: &str) {
    let g = 9.81;
    let config = RigidSceneConfig {
        gravity: Vector3::new(0.0, 0.0, -g),
        walls: vec![RigidWall {
            shape: WallShape::plane(Vec3::ZERO, Vec3::Z).unwrap(),
            motion: WallMotion::Fixed,
            surface_velocity: Vector3::zeros(),
        }],
        restitution: 1.0,
        friction: 0.0,
        max_expected_speed: 1.0,
        record_onsets: true,
        ..Default::default()
    };
    let (mut scene, id) = scene(kind, config);
    let z0 = 0.04; // the bottom 9 mm above the floor: out of the bounding sphere's reach
    scene
        .add_body(
            id,
            Vector3::new(0.0, 0.0, z0),
            UnitQuaternion::identity(),
            Vector3::zeros(),
            Vector3::zeros(),
        )
        .unwrap();
    let h = z0 - com_height();
    let fall = (2.0 * h / g).sqrt();
    let steps = (3.5 * fall / scene.time_step()).ceil() as u64;
    scene.run(steps).unwrap();
    let onsets = scene.onsets();
    assert_eq!(onsets.len(), 2, "{onsets:?}");
    let v_hit = (2.0 * g * h).sqrt();
    for o in onsets {
        assert!(
            (o.normal_speed / v_hit - 1.0).abs() < 0.01,
            "{o:?} vs {v_hit}"
        );
    }
}

/// The side of a vertical wall as a mesh of 200 triangles (in the plane x = 0, |y|, |z| ≤
/// 5 cm) instead of a polygon: gravity along −x lays the bead-clump cartridge against it as
/// against the polygon, with the same trajectory (the same bead contacts, each counted
/// once where a bead sits over a shared edge or vertex of the mesh) to 1e-9 m.
#[test]
fn clump_rests_against_a_mesh_wall_as_against_the_polygon() {
    rests_against_mesh("clump");
}

/// The same with the body of revolution: the mesh's shared edges and vertices (flat) give no
/// contact of their own.
#[test]
fn revolution_cartridge_rests_against_a_mesh_wall_as_against_the_polygon() {
    rests_against_mesh("revolution");
}

fn rests_against_mesh(kind: &str) {
    use demfem::geometry::MeshWall;
    let n = 10;
    let half = 0.05;
    let mut v = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let s = 2.0 * half / n as f64;
            v.push(Vec3::new(0.0, -half + i as f64 * s, -half + j as f64 * s));
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut t = Vec::new();
    for j in 0..n {
        for i in 0..n {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let mesh = WallShape::Mesh(MeshWall::new(v, t).unwrap());
    let mut ends = Vec::new();
    for shape in [mesh, vertical_square(half)] {
        let config = RigidSceneConfig {
            gravity: Vector3::new(-9.81, 0.0, 0.0),
            walls: vec![RigidWall {
                shape,
                motion: WallMotion::Fixed,
                surface_velocity: Vector3::zeros(),
            }],
            max_expected_speed: 1.0,
            ..Default::default()
        };
        let (mut scene, id) = scene(kind, config);
        scene
            .add_body(
                id,
                Vector3::new(R_OUT + 0.2e-3, 0.003, 0.001),
                UnitQuaternion::identity(),
                Vector3::zeros(),
                Vector3::zeros(),
            )
            .unwrap();
        let steps = (0.06 / scene.time_step()).ceil() as u64;
        scene.run(steps).unwrap();
        ends.push((scene.bodies.position[0], scene.bodies.velocity[0]));
        assert_eq!(scene.wall_contacts()[0], 1);
    }
    let ((x_m, v_m), (x_p, v_p)) = (ends[0], ends[1]);
    println!("mesh {x_m:?} {v_m:?}\npolygon {x_p:?} {v_p:?}");
    assert!((x_m - x_p).norm() < 1e-9, "{x_m:?} vs {x_p:?}");
    assert!((v_m - v_p).norm() < 1e-7, "{v_m:?} vs {v_p:?}");
    assert!(x_m.x < R_OUT && x_m.x > side_envelope_min(kind) - 2e-6);
}

/// A rotating wall is refused by the rigid scene (not implemented there), naming the wall.
#[test]
fn rigid_scene_refuses_a_rotating_wall() {
    let config = RigidSceneConfig {
        walls: vec![RigidWall {
            shape: vertical_square(0.05),
            motion: WallMotion::rotation(Vec3::ZERO, Vec3::Z, 1.0).unwrap(),
            surface_velocity: Vector3::zeros(),
        }],
        ..Default::default()
    };
    let e = RigidScene::new(config).err().expect("refused");
    assert!(format!("{e}").contains("walls[0].motion"), "{e}");
}
