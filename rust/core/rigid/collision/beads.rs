//! Contacts of bead clumps, computed by hand (sphere–plane and sphere–sphere tests in the
//! body frame): a clump against a plane, a sphere and another clump. Lengths in m.

use nalgebra::{Matrix3, Vector3};

use super::primitives::{BodyPose, ContactPoint, Plane};
use crate::rigid::shape::BeadClump;

/// Beads of a clump against a plane (plane first, clump second). One dot product per bead:
/// the plane normal is taken into the body frame once; the bounding sphere culls the rest.
pub fn clump_plane_contacts(
    plane: &Plane,
    clump: &BeadClump,
    pose: &BodyPose,
    out: &mut Vec<ContactPoint>,
) {
    let centre_distance = plane.signed_distance(&pose.position);
    if centre_distance >= clump.bounding_radius {
        return;
    }
    let normal_body = pose.orientation.inverse_transform_vector(&plane.normal);
    // the lowest a bead can reach is the support of the box in the normal direction
    for (i, (c, &r)) in clump.centers.iter().zip(&clump.radii).enumerate() {
        let distance = centre_distance + normal_body.dot(c);
        let overlap = r - distance;
        if overlap > 0.0 {
            let centre = pose.position + pose.orientation * c;
            out.push(ContactPoint {
                point: centre - plane.normal * (0.5 * (r + distance)),
                normal: plane.normal,
                overlap,
                radius_first: f64::INFINITY,
                radius_second: r,
                feature_first: 0,
                feature_second: i as u64,
            });
        }
    }
}

/// Beads of a clump against a free sphere (clump first, sphere second).
pub fn clump_sphere_contacts(
    clump: &BeadClump,
    pose: &BodyPose,
    sphere_center: &Vector3<f64>,
    sphere_radius: f64,
    out: &mut Vec<ContactPoint>,
) {
    let rel = sphere_center - pose.position;
    if rel.norm() >= clump.bounding_radius + sphere_radius {
        return;
    }
    let local = pose.orientation.inverse_transform_vector(&rel);
    for (i, (c, &r)) in clump.centers.iter().zip(&clump.radii).enumerate() {
        let d = local - c;
        let reach = r + sphere_radius;
        let d2 = d.norm_squared();
        if d2 < reach * reach && d2 > 0.0 {
            let dist = d2.sqrt();
            let n_local = d / dist;
            let overlap = reach - dist;
            let p_local = c + n_local * (r - 0.5 * overlap);
            out.push(ContactPoint {
                point: pose.position + pose.orientation * p_local,
                normal: pose.orientation * n_local,
                overlap,
                radius_first: r,
                radius_second: sphere_radius,
                feature_first: i as u64,
                feature_second: 0,
            });
        }
    }
}

/// Reusable buffers for [`clump_clump_contacts`] (no allocation per step once warm).
#[derive(Debug, Default, Clone)]
pub struct ClumpPairScratch {
    first: Vec<(u32, Vector3<f64>)>,
    second: Vec<(f64, u32, Vector3<f64>)>,
}

/// Bead pairs of two clumps (a first, b second).
///
/// Bounding spheres cull the pair; then each clump keeps only the beads that lie inside the
/// other's body-frame box (inflated by a bead radius), all expressed in a's body frame; the
/// survivors of b are sorted along the axis where they spread most and each survivor of a
/// scans only the window it can reach (sort and sweep): cost O(n log n + contacts) instead
/// of 632².
pub fn clump_clump_contacts(
    a: &BeadClump,
    pose_a: &BodyPose,
    b: &BeadClump,
    pose_b: &BodyPose,
    scratch: &mut ClumpPairScratch,
    out: &mut Vec<ContactPoint>,
) {
    let between = pose_b.position - pose_a.position;
    if between.norm() >= a.bounding_radius + b.bounding_radius {
        return;
    }
    let rot_a: Matrix3<f64> = pose_a.orientation.to_rotation_matrix().into_inner();
    let rot_ab: Matrix3<f64> = (pose_a.orientation.inverse() * pose_b.orientation)
        .to_rotation_matrix()
        .into_inner();
    let t = rot_a.transpose() * between; // b's origin in a's frame
    let inside = |p: &Vector3<f64>, clump: &BeadClump, pad: f64| {
        (0..3).all(|k| p[k] >= clump.aabb_min[k] - pad && p[k] <= clump.aabb_max[k] + pad)
    };
    scratch.first.clear();
    scratch.second.clear();
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    // only the bead groups whose spheres reach the other body's box are opened
    for chunk in &b.chunks {
        if !inside(&(t + rot_ab * chunk.center), a, chunk.radius) {
            continue;
        }
        for &j in &b.chunk_members[chunk.members.clone()] {
            let in_a = t + rot_ab * b.centers[j as usize];
            if inside(&in_a, a, b.radii[j as usize]) {
                lo = lo.inf(&in_a);
                hi = hi.sup(&in_a);
                scratch.second.push((0.0, j, in_a));
            }
        }
    }
    if scratch.second.is_empty() {
        return;
    }
    let rot_ba = rot_ab.transpose();
    for chunk in &a.chunks {
        if !inside(&(rot_ba * (chunk.center - t)), b, chunk.radius) {
            continue;
        }
        for &i in &a.chunk_members[chunk.members.clone()] {
            let c = a.centers[i as usize];
            if inside(&(rot_ba * (c - t)), b, a.radii[i as usize]) {
                scratch.first.push((i, c));
            }
        }
    }
    let spread = hi - lo;
    let axis = spread.imax();
    for entry in scratch.second.iter_mut() {
        entry.0 = entry.2[axis];
    }
    scratch.second.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    let reach_max = a.max_bead_radius + b.max_bead_radius;
    for &(i, ca) in &scratch.first {
        let ra = a.radii[i as usize];
        let key = ca[axis];
        let start = scratch.second.partition_point(|e| e.0 < key - reach_max);
        for &(kb, j, cb) in &scratch.second[start..] {
            if kb > key + reach_max {
                break;
            }
            let rb = b.radii[j as usize];
            let d = cb - ca;
            let d2 = d.norm_squared();
            let reach = ra + rb;
            if d2 < reach * reach && d2 > 0.0 {
                let dist = d2.sqrt();
                let n_local = d / dist;
                let overlap = reach - dist;
                let p_local = ca + n_local * (ra - 0.5 * overlap);
                out.push(ContactPoint {
                    point: pose_a.position + rot_a * p_local,
                    normal: rot_a * n_local,
                    overlap,
                    radius_first: ra,
                    radius_second: rb,
                    feature_first: i as u64,
                    feature_second: j as u64,
                });
            }
        }
    }
}
