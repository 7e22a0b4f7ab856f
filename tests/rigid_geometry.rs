//! Mass properties and contact geometry of the two cartridge representations, against the
//! exact geometry and hand-computed overlaps.
mod rigid_common;

use demfem::rigid::collision::{
    clump_clump_contacts, clump_exact_contacts, clump_plane_contacts, clump_sphere_contacts,
    exact_exact_contacts, exact_plane_contacts, exact_sphere_contacts, ClumpPairScratch,
    ExactContactCache,
};
use demfem::rigid::{BodyPose, Plane, RigidScene, RigidSceneConfig};
use demfem::DemfemError;
use nalgebra::{UnitQuaternion, Vector3};
use rigid_common::*;

fn upright(x: f64, y: f64, z: f64) -> BodyPose {
    BodyPose {
        position: Vector3::new(x, y, z),
        orientation: UnitQuaternion::identity(),
    }
}

fn floor() -> Plane {
    Plane::new(Vector3::zeros(), Vector3::z(), Vector3::zeros()).unwrap()
}

#[test]
fn clump_mass_properties_agree_with_exact_geometry() {
    let (clump, from_beads) = cartridge_clump();
    let exact = rigid_common::cartridge_exact().1;
    assert_eq!(clump.len(), 632);
    assert!((from_beads.mass / CARTRIDGE_MASS - 1.0).abs() < 0.01);
    assert!((exact.mass / CARTRIDGE_MASS - 1.0).abs() < 1e-12);
    for k in 0..3 {
        let rel = from_beads.principal_inertia[k] / exact.principal_inertia[k] - 1.0;
        assert!(rel.abs() < 0.01, "inertia {k}: {rel:e}");
    }
    // fixture centres are relative to the exact centre of mass
    assert!(
        from_beads.center_of_mass.norm() < 1e-5,
        "{:?}",
        from_beads.center_of_mass
    );
    // the clump spans the cartridge: 64 mm long, 11.6 mm across
    assert!((clump.aabb_max.x - clump.aabb_min.x - 11.6e-3).abs() < 1e-6);
    assert!((clump.aabb_max.z - clump.aabb_min.z - 64e-3).abs() < 1e-6);
}

#[test]
fn upright_clump_sinking_into_the_floor_touches_with_its_bottom_ring() {
    let (clump, _) = cartridge_clump();
    let sink = 1e-5;
    let bottom = clump
        .centers
        .iter()
        .zip(&clump.radii)
        .map(|(c, r)| c.z - r)
        .fold(f64::INFINITY, f64::min);
    let pose = upright(0.0, 0.0, -bottom - sink);
    let mut out = Vec::new();
    clump_plane_contacts(&floor(), &clump, &pose, &mut out);
    let ring = clump
        .centers
        .iter()
        .zip(&clump.radii)
        .filter(|(c, r)| (c.z - *r - bottom).abs() < 1e-12)
        .count();
    assert_eq!(out.len(), ring);
    for c in &out {
        assert!((c.overlap - sink).abs() < 1e-12);
        assert_eq!(c.normal, Vector3::z());
        assert!(c.point.z.abs() <= sink);
    }
    out.clear();
    clump_plane_contacts(
        &floor(),
        &clump,
        &upright(0.0, 0.0, -bottom + 1e-6),
        &mut out,
    );
    assert!(out.is_empty());
}

#[test]
fn side_by_side_clumps_touch_along_their_sides() {
    let (clump, _) = cartridge_clump();
    let gap = -2e-5; // overlap of the envelopes
    let pose_b = upright(clump.aabb_max.x - clump.aabb_min.x + gap, 0.0, 0.0);
    let mut out = Vec::new();
    let mut scratch = ClumpPairScratch::default();
    clump_clump_contacts(
        &clump,
        &upright(0.0, 0.0, 0.0),
        &clump,
        &pose_b,
        &mut scratch,
        &mut out,
    );
    assert!(!out.is_empty());
    for c in &out {
        assert!(
            c.overlap > 0.0 && c.overlap <= -gap + 1e-12,
            "{}",
            c.overlap
        );
        assert!(c.normal.x > 0.95, "{:?}", c.normal);
    }
    // brute force gives the same pairs
    let mut brute = 0;
    for ca in &clump.centers {
        for cb in &clump.centers {
            if (cb + pose_b.position - ca).norm() < 2.0 * clump.max_bead_radius {
                brute += 1;
            }
        }
    }
    assert_eq!(out.len(), brute);
}

#[test]
fn sphere_against_clump_and_exact_side() {
    let (clump, _) = cartridge_clump();
    let (exact, _) = cartridge_exact();
    let radius = 8e-3;
    // beads sit in rings ~1 mm apart: an overlap of the envelopes of 0.1 mm reaches them
    let sink = 1e-4;
    let centre = Vector3::new(5.8e-3 + radius - sink, 0.0, 0.0);
    let mut out = Vec::new();
    clump_sphere_contacts(&clump, &upright(0.0, 0.0, 0.0), &centre, radius, &mut out);
    assert!(
        !out.is_empty()
            && out
                .iter()
                .all(|c| c.normal.x > 0.9 && c.overlap <= sink + 1e-12)
    );
    out.clear();
    let mut cache = ExactContactCache::default();
    exact_sphere_contacts(
        &exact,
        &upright(0.0, 0.0, 0.0),
        &centre,
        radius,
        &mut cache,
        &mut out,
    )
    .unwrap();
    assert_eq!(out.len(), 1);
    assert!((out[0].overlap - sink).abs() < 1e-9, "{}", out[0].overlap);
    assert!((out[0].normal - Vector3::x()).norm() < 1e-9);
    assert_eq!(out[0].radius_first, 5.8e-3);
}

#[test]
fn exact_cartridge_on_the_floor_upright_and_lying() {
    let (exact, mass) = cartridge_exact();
    let zc = mass.center_of_mass.z;
    let sink = 1e-5;
    let mut out = Vec::new();
    let mut cache = ExactContactCache::default();
    exact_plane_contacts(
        &floor(),
        &exact,
        &upright(0.0, 0.0, zc - sink),
        &mut cache,
        &mut out,
    )
    .unwrap();
    // parry stands the cylinder's cap on four rim points
    assert_eq!(out.len(), 4);
    for c in &out {
        assert!((c.overlap - sink).abs() < 1e-9);
        assert!(((c.point.x.powi(2) + c.point.y.powi(2)).sqrt() - 5.8e-3).abs() < 1e-9);
    }
    // lying on its side: the body cylinder touches along a line (two end points)
    out.clear();
    let lying = BodyPose {
        position: Vector3::new(0.0, 0.0, 5.8e-3 - sink),
        orientation: UnitQuaternion::from_axis_angle(
            &Vector3::y_axis(),
            std::f64::consts::FRAC_PI_2,
        ),
    };
    let mut cache = ExactContactCache::default();
    exact_plane_contacts(&floor(), &exact, &lying, &mut cache, &mut out).unwrap();
    assert!(out.len() >= 2);
    assert!(out
        .iter()
        .all(|c| (c.overlap - sink).abs() < 1e-9 && c.radius_second == 5.8e-3));
}

#[test]
fn exact_cartridges_side_by_side_and_bead_against_exact() {
    let (exact, _) = cartridge_exact();
    let (clump, _) = cartridge_clump();
    let overlap = 2e-5;
    let b = upright(11.6e-3 - overlap, 0.0, 0.0);
    let mut out = Vec::new();
    let mut cache = ExactContactCache::default();
    exact_exact_contacts(
        &exact,
        &upright(0.0, 0.0, 0.0),
        &exact,
        &b,
        &mut cache,
        &mut out,
    )
    .unwrap();
    assert!(!out.is_empty());
    for c in &out {
        assert!((c.overlap - overlap).abs() < 1e-9, "{}", c.overlap);
        // parry's cylinder–cylinder normal is exact to its azimuth resolution (~4e-4 rad)
        assert!((c.normal - Vector3::x()).norm() < 1e-3, "{:?}", c.normal);
    }
    out.clear();
    clump_exact_contacts(&clump, &upright(0.0, 0.0, 0.0), &exact, &b, &mut out).unwrap();
    assert!(!out.is_empty());
    assert!(out
        .iter()
        .all(|c| c.overlap > 0.0 && c.overlap <= overlap + 1e-9 && c.normal.x > 0.9));
}

#[test]
fn skew_exact_cartridges_touch_only_where_their_sides_cross() {
    // two cylinder bodies side by side along x, b's axis tilted by θ about x: the sides of
    // two skew cylinders overlap by r_a + r_b − d (d the distance between the axes, here the
    // x offset) only around the point where the axes pass closest (here z = 0 of a's axis).
    // Parry's clipped side generators also report their ends, up to 30 mm away, with that
    // full overlap; those must not become contacts (they did before the fix).
    let (exact, _) = cartridge_exact();
    let overlap = 1.5e-5;
    let r = 5.8e-3;
    for tilt in [1.0_f64, 7.0, 20.0, 40.0] {
        let b = BodyPose {
            position: Vector3::new(2.0 * r - overlap, 0.0, 0.0),
            orientation: UnitQuaternion::from_axis_angle(&Vector3::x_axis(), tilt.to_radians()),
        };
        let mut out = Vec::new();
        let mut cache = ExactContactCache::default();
        exact_exact_contacts(
            &exact,
            &upright(0.0, 0.0, 0.0),
            &exact,
            &b,
            &mut cache,
            &mut out,
        )
        .unwrap();
        let deepest = out
            .iter()
            .max_by(|x, y| x.overlap.total_cmp(&y.overlap))
            .unwrap();
        assert!((deepest.overlap - overlap).abs() < 1e-9, "{tilt}°: {out:?}");
        assert!(
            (deepest.normal - Vector3::x()).norm() < 1e-3,
            "{tilt}°: {out:?}"
        );
        // Hertz contact ellipse of two crossed cylinders: semi-axes ~ √(R δ) ≈ 0.3 mm; away
        // from the crossing the sides part as (s sin θ)² / 4R, so at 1° contact may extend
        // along the line to where that reaches δ (s = √(4 R δ) / sin θ ≈ 34 mm), at 7° to 5 mm
        let reach = (4.0 * r * overlap).sqrt() / tilt.to_radians().sin();
        for c in &out {
            let s = c.point.z.hypot(c.point.y);
            assert!(
                s < reach.max(0.3e-3) + 1e-6,
                "{tilt}°: contact {} mm from the crossing (reach {} mm): {c:?}",
                s * 1e3,
                reach * 1e3
            );
            assert!(c.overlap > 0.0 && c.overlap <= overlap + 1e-9);
        }
        println!("{tilt}°: {} contact point(s)", out.len());
    }
}

#[test]
fn time_step_above_the_limit_is_refused() {
    let (shape, mass) = cartridge("clump");
    let limit = time_step_limit_of(RigidSceneConfig::default(), "clump");
    assert!(limit > 1e-7 && limit < 1e-5, "{limit}");
    let config = RigidSceneConfig {
        time_step: Some(2.0 * limit),
        ..Default::default()
    };
    let mut scene = RigidScene::new(config).unwrap();
    let id = scene.add_shape(shape, mass).unwrap();
    let err = scene
        .add_body(
            id,
            Vector3::zeros(),
            UnitQuaternion::identity(),
            Vector3::zeros(),
            Vector3::zeros(),
        )
        .unwrap_err();
    assert!(matches!(err, DemfemError::UnstableTimeStep { .. }), "{err}");
}

#[test]
fn culled_clump_pairs_find_every_bead_pair_at_any_orientation() {
    let (clump, _) = cartridge_clump();
    let pose_a = BodyPose {
        position: Vector3::new(0.001, -0.002, 0.003),
        orientation: UnitQuaternion::from_euler_angles(0.4, -1.1, 0.3),
    };
    let mut scratch = ClumpPairScratch::default();
    for (k, angles) in [
        (0.0, 0.7, 0.2),
        (1.2, 0.1, -0.8),
        (2.0, 1.5, 0.9),
        (0.3, 3.0, 0.0),
    ]
    .iter()
    .enumerate()
    {
        let orientation = UnitQuaternion::from_euler_angles(angles.0, angles.1, angles.2);
        // move b toward a along a fixed direction until their beads just interpenetrate
        let dir = Vector3::new(1.0, 0.5 - k as f64 * 0.3, 0.2).normalize();
        let beads = |pose: &BodyPose| -> Vec<Vector3<f64>> {
            clump
                .centers
                .iter()
                .map(|c| pose.position + pose.orientation * c)
                .collect()
        };
        let world_a = beads(&pose_a);
        let mut distance = 0.068; // just beyond the two bounding spheres
        let (pose_b, brute) = loop {
            let pose_b = BodyPose {
                position: pose_a.position + dir * distance,
                orientation,
            };
            let world_b = beads(&pose_b);
            let mut n = 0;
            for pa in &world_a {
                for pb in &world_b {
                    if (pb - pa).norm() < 2.0 * clump.max_bead_radius {
                        n += 1;
                    }
                }
            }
            if n >= 3 || distance < 0.0 {
                break (pose_b, n);
            }
            distance -= 1e-4;
        };
        let mut out = Vec::new();
        clump_clump_contacts(&clump, &pose_a, &clump, &pose_b, &mut scratch, &mut out);
        assert_eq!(out.len(), brute, "orientation {k}");
        assert!(brute >= 3);
    }
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    assert!(Plane::new(Vector3::zeros(), Vector3::zeros(), Vector3::zeros()).is_err());
    assert!(Plane::new(
        Vector3::new(f64::NAN, 0.0, 0.0),
        Vector3::z(),
        Vector3::zeros()
    )
    .is_err());
    let mut scene = RigidScene::new(RigidSceneConfig::default()).unwrap();
    let (shape, mass) = cartridge("exact");
    let id = scene.add_shape(shape, mass).unwrap();
    let q = UnitQuaternion::identity();
    let z = Vector3::zeros();
    assert!(scene.add_body(id + 1, z, q, z, z).is_err());
    assert!(scene
        .add_body(id, Vector3::new(f64::NAN, 0.0, 0.0), q, z, z)
        .is_err());
    let bad = RigidSceneConfig {
        restitution: 1.5,
        ..Default::default()
    };
    assert!(RigidScene::new(bad).is_err());
    let bad = RigidSceneConfig {
        friction: -0.1,
        ..Default::default()
    };
    assert!(RigidScene::new(bad).is_err());
    let bad = RigidSceneConfig {
        time_step: Some(0.0),
        ..Default::default()
    };
    assert!(RigidScene::new(bad).is_err());
    assert!(demfem::rigid::BeadClump::from_beads(&[Vector3::zeros()], &[0.0], &[1.0]).is_err());
    assert!(demfem::rigid::BeadClump::from_beads(&[Vector3::zeros()], &[1.0], &[]).is_err());
}
