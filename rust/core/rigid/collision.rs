//! Contact geometry of rigid shapes: pure geometry, no forces.
//!
//! Every function appends [`ContactPoint`]s in the world frame to an output vector. The normal
//! points from the first object to the second, the overlap is positive, the point lies midway
//! through the overlap. Bead contacts are computed by hand (they are sphere–sphere and
//! sphere–plane tests); exact shapes go through parry3d-f64's contact manifolds, kept between
//! steps in an [`ExactContactCache`] so parry can match features (persistent manifolds).

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::query::{
    self, ContactManifold, ContactManifoldsWorkspace, DefaultQueryDispatcher,
    PersistentQueryDispatcher, Ray,
};
use parry3d_f64::shape::{Ball, Compound, ConvexPolyhedron, HalfSpace, Shape};

use super::shape::{BeadClump, ExactShape};
use crate::error::{DemfemError, Result};
use crate::geometry::{MeshWall, WallShape};

/// One contact point, world frame, SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPoint {
    /// Contact point, midway through the overlap, m.
    pub point: Vector3<f64>,
    /// Unit normal from the first object to the second.
    pub normal: Vector3<f64>,
    /// Overlap (interpenetration depth) > 0, m.
    pub overlap: f64,
    /// Curvature radius of the first surface at the contact, m (`inf` for a plane).
    pub radius_first: f64,
    /// Curvature radius of the second surface at the contact, m (`inf` for a plane).
    pub radius_second: f64,
    /// Feature of the first object that touches: the bead index for a clump, `piece << 32 |
    /// parry feature id` for an exact shape, 0 for a plane or sphere. Keys friction history.
    pub feature_first: u64,
    /// Feature of the second object, as `feature_first`.
    pub feature_second: u64,
}

/// An infinite plane bounding a solid half-space (the belt, a wall).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// A point of the plane, m.
    pub point: Vector3<f64>,
    /// Unit normal pointing out of the solid, into the free space.
    pub normal: Vector3<f64>,
    /// Velocity of the plane's surface (a belt moves tangentially), m/s.
    pub surface_velocity: Vector3<f64>,
}

impl Plane {
    /// A plane through `point` (m) with outward `normal` (any length > 0) whose surface
    /// moves with `surface_velocity` (m/s).
    pub fn new(
        point: Vector3<f64>,
        normal: Vector3<f64>,
        surface_velocity: Vector3<f64>,
    ) -> Result<Self> {
        let length = normal.norm();
        if length.is_nan()
            || length <= 0.0
            || length.is_infinite()
            || !point
                .iter()
                .chain(surface_velocity.iter())
                .all(|v| v.is_finite())
        {
            return Err(DemfemError::ShapeMismatch {
                field: "plane".into(),
                detail: "point and surface velocity finite, normal finite and non-zero".into(),
            });
        }
        Ok(Self {
            point,
            normal: normal / length,
            surface_velocity,
        })
    }

    /// Signed distance of `x` (m) from the plane, positive on the free side, m.
    pub fn signed_distance(&self, x: &Vector3<f64>) -> f64 {
        self.normal.dot(&(x - self.point))
    }
}

/// Position (m) and orientation (body → world) of a rigid body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyPose {
    /// Centre of mass, world, m.
    pub position: Vector3<f64>,
    /// Orientation, body → world.
    pub orientation: UnitQuaternion<f64>,
}

impl BodyPose {
    fn to_parry(self) -> Pose {
        let (x, q) = (self.position, self.orientation.coords);
        Pose::from_parts(
            Vector::new(x.x, x.y, x.z),
            Rotation::from_xyzw(q[0], q[1], q[2], q[3]),
        )
    }
}

fn to_nalgebra(v: Vector) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

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

/// Persistent parry contact manifolds of one pair of objects, kept from step to step.
#[derive(Default)]
pub struct ExactContactCache {
    manifolds: Vec<ContactManifold<(), ()>>,
    workspace: Option<ContactManifoldsWorkspace>,
    /// Force evaluation that last used this cache (the scene drops caches it did not use).
    pub(crate) last_used: u64,
}

impl ExactContactCache {
    /// Forget the manifolds *and* the workspace: parry's workspace indexes into the manifold
    /// list, so clearing one without the other leaves dangling indices (parry then panics
    /// when the pair touches again).
    pub fn reset(&mut self) {
        self.manifolds.clear();
        self.workspace = None;
    }
}

impl std::fmt::Debug for ExactContactCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ExactContactCache")
            .field("manifolds", &self.manifolds.len())
            .finish()
    }
}

/// Contacts of different pieces closer than this angle times the piece radius (one edge of
/// the 32-gon of a cone piece) are one contact, rad.
const HULL_EDGE_ANGLE: f64 = 2.0 * std::f64::consts::PI / 32.0;

/// Radius of the piece `id` of an exact shape; `inf` for a plane, the ball's own for a ball.
type RadiusOf<'a> = &'a dyn Fn(u32) -> f64;

/// Local overlap of two convex pieces at a manifold point, measured along the manifold
/// normal `n` (world, from piece 1 to piece 2), m; `None` when the surfaces do not overlap
/// there. From `p1` (on piece 1) a ray starts `LOCAL_OVERLAP_RAY_START` behind it (outside
/// piece 2 for a valid normal, see [`normal_is_valid`]) and runs along +n to piece 2's
/// surface; the overlap is how far that surface lies behind `p1`. The same from `p2` towards
/// piece 1 along −n; the larger of the two counts (a rim point is measured well from its own
/// side). Frames piece → world.
#[allow(clippy::too_many_arguments)]
fn local_overlap(
    piece1: &dyn Shape,
    frame1: &Pose,
    p1: Vector,
    piece2: &dyn Shape,
    frame2: &Pose,
    p2: Vector,
    n: Vector,
) -> Option<f64> {
    let start = LOCAL_OVERLAP_RAY_START;
    let depth = |piece: &dyn Shape, frame: &Pose, p: Vector, dir: Vector| {
        let origin = frame.inverse_transform_point(p - dir * start);
        let ray = Ray::new(origin, frame.rotation.inverse() * dir);
        piece
            .cast_local_ray(&ray, 2.0 * start, true)
            .map(|t| start - t)
    };
    match (depth(piece1, frame1, p2, -n), depth(piece2, frame2, p1, n)) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    }
}

/// Whether `depth` (m) along the world normal `n` (from piece 1 to piece 2) is the overlap of
/// the two pieces' extents along `n`: max over piece 1 of x·n − min over piece 2 of x·n, from
/// their support maps. For the minimum-translation normal that parry's EPA is meant to find
/// the two agree; EPA occasionally stops on a wrong polytope face (seen between the flat
/// caps of coaxial cylinders: a sideways normal claiming 0.9 mm where the extents overlap by
/// 11.6 mm and the true overlap along the axis is 1 µm), and such a manifold must not become
/// a force. Pieces without a support map are trusted.
fn normal_is_valid(
    piece1: &dyn Shape,
    frame1: &Pose,
    piece2: &dyn Shape,
    frame2: &Pose,
    n: Vector,
    depth: f64,
) -> bool {
    let (Some(s1), Some(s2)) = (piece1.as_support_map(), piece2.as_support_map()) else {
        return true;
    };
    let far1 = frame1 * s1.local_support_point(frame1.rotation.inverse() * n);
    let near2 = frame2 * s2.local_support_point(frame2.rotation.inverse() * -n);
    let extent_overlap = (far1 - near2).dot(n);
    (extent_overlap - depth).abs() <= 0.1 * depth.abs() + NORMAL_CHECK_TOLERANCE
}

/// Absolute tolerance of [`normal_is_valid`], m (far below any contact overlap of interest,
/// far above round-off on centimetre bodies).
const NORMAL_CHECK_TOLERANCE: f64 = 1e-9;

/// How far behind a contact point the rays of [`local_overlap`] start, m: far more than any
/// overlap the time step allows, far less than a cartridge.
const LOCAL_OVERLAP_RAY_START: f64 = 1e-3;

/// Contact points of two shapes from parry's manifolds, world frame (see the module docs).
///
/// Three things about parry's manifolds matter for forces and are corrected here (the
/// scene then lets all points of one piece pair share one Hertz law, see
/// `scene::piece_pair_share`):
///
/// * Spatial coherence. Parry reuses a manifold's points from the previous query while the
///   normal has turned less than 1° and the points have slid less than 1 mm (thresholds
///   hard-coded for game-scale bodies): the points are then frozen material points and only
///   their separation along the frozen normal is updated. With micrometre overlaps this
///   makes the force depend on the path (a body spinning or rolling against another is
///   pushed by a point that is no longer where the surfaces touch, then jumps back at the
///   next recomputation): a non-conservative force that pumps energy into lasting contacts.
///   Every manifold is therefore recomputed at every query (`mark_shapes_deformed`).
/// * Wrong EPA normals (compound pairs): a manifold whose normal is not the minimum-
///   translation direction is dropped ([`normal_is_valid`]).
/// * Skew feature clipping (compound pairs only, `pieces` given). Between two cylinders
///   whose axes are not parallel, parry clips the two side generators against each other
///   and reports the clip ends — up to 30 mm from where the surfaces actually touch — each
///   with the full overlap measured along the common normal (the distance between skew
///   lines is the same everywhere along them), plus the deepest point. Forces at those ends
///   triple the stiffness and give torques with wrong lever arms, which is not the gradient
///   of any potential: tilted cartridges resting against each other gained energy until
///   they ran away. Each point's overlap is re-measured in the true geometry
///   along the normal ([`local_overlap`], capped at parry's value) and points out of
///   contact are dropped.
#[allow(clippy::too_many_arguments)]
fn manifold_contacts(
    pose1: &Pose,
    shape1: &dyn Shape,
    radius1: RadiusOf<'_>,
    pose2: &Pose,
    shape2: &dyn Shape,
    radius2: RadiusOf<'_>,
    pieces: Option<(&Compound, &Compound)>,
    cache: &mut ExactContactCache,
    out: &mut Vec<ContactPoint>,
) -> Result<()> {
    let pos12 = pose1.inv_mul(pose2);
    for manifold in cache.manifolds.iter_mut() {
        manifold.mark_shapes_deformed();
    }
    DefaultQueryDispatcher
        .contact_manifolds(
            &pos12,
            shape1,
            shape2,
            0.0,
            &mut cache.manifolds,
            &mut cache.workspace,
        )
        .map_err(|_| {
            DemfemError::Effect("parry3d has no contact manifold for this shape pair".into())
        })?;
    let first_new = out.len();
    for manifold in &cache.manifolds {
        let sub1 = manifold.subshape_pos1().copied().unwrap_or(Pose::IDENTITY);
        let sub2 = manifold.subshape_pos2().copied().unwrap_or(Pose::IDENTITY);
        let frame1 = *pose1 * sub1;
        let frame2 = *pose2 * sub2;
        let normal = to_nalgebra(frame1.rotation * manifold.local_n1);
        let piece_shapes = pieces.and_then(|(c1, c2)| {
            let a = c1.shapes().get(manifold.subshape1 as usize)?;
            let b = c2.shapes().get(manifold.subshape2 as usize)?;
            Some((a.1.as_ref(), b.1.as_ref()))
        });
        let n_world = frame1.rotation * manifold.local_n1;
        if let Some((piece1, piece2)) = piece_shapes {
            let deepest = manifold
                .points
                .iter()
                .map(|c| -c.dist)
                .fold(f64::NEG_INFINITY, f64::max);
            if deepest > 0.0 && !normal_is_valid(piece1, &frame1, piece2, &frame2, n_world, deepest)
            {
                continue;
            }
        }
        for contact in &manifold.points {
            if contact.dist >= 0.0 {
                continue;
            }
            let (w1, w2) = (frame1 * contact.local_p1, frame2 * contact.local_p2);
            let overlap = match piece_shapes {
                Some((piece1, piece2)) => {
                    local_overlap(piece1, &frame1, w1, piece2, &frame2, w2, n_world)
                        .map_or(0.0, |d| d.min(-contact.dist))
                }
                None => -contact.dist,
            };
            if overlap <= 0.0 {
                continue;
            }
            let p1 = to_nalgebra(w1);
            let p2 = to_nalgebra(w2);
            let point = 0.5 * (p1 + p2);
            // Adjacent pieces of a compound share their boundary circle (body cylinder and
            // shoulder cone): both report the same physical contact there, up to one edge of
            // the cone's polygon; parry may also report the deepest point of a piece pair
            // next to a clipped feature point. Count such a contact once, keeping the deeper
            // report.
            let (r1, r2) = (radius1(manifold.subshape1), radius2(manifold.subshape2));
            let reach = HULL_EDGE_ANGLE
                * [r1, r2]
                    .into_iter()
                    .filter(|r| r.is_finite())
                    .fold(0.0, f64::max);
            let feature_first = piece_feature(manifold.subshape1, contact.fid1.0);
            let feature_second = piece_feature(manifold.subshape2, contact.fid2.0);
            let same_contact = out[first_new..]
                .iter()
                .position(|c| (c.point - point).norm() < reach && c.normal.dot(&normal) > 0.999);
            let found = ContactPoint {
                point,
                normal,
                overlap,
                radius_first: r1,
                radius_second: r2,
                feature_first,
                feature_second,
            };
            match same_contact {
                // the same touch reported twice: keep the deeper report
                Some(k) => {
                    let existing = &mut out[first_new + k];
                    if overlap > existing.overlap * (1.0 + 1e-9) {
                        *existing = found;
                    }
                }
                None => out.push(found),
            }
        }
    }
    Ok(())
}

/// Feature key of an exact-shape contact: piece in the high half, parry feature id below.
#[inline]
fn piece_feature(piece: u32, feature: u32) -> u64 {
    ((piece as u64) << 32) | feature as u64
}

fn piece_radius(shape: &ExactShape) -> impl Fn(u32) -> f64 + '_ {
    move |id| {
        shape
            .piece_contact_radius
            .get(id as usize)
            .copied()
            .unwrap_or(f64::INFINITY)
    }
}

/// An exact shape against a plane (plane first), through parry's half-space manifolds
/// (a cylinder cap gives four rim points, its side a segment's two ends).
pub fn exact_plane_contacts(
    plane: &Plane,
    shape: &ExactShape,
    pose: &BodyPose,
    cache: &mut ExactContactCache,
    out: &mut Vec<ContactPoint>,
) -> Result<()> {
    if plane.signed_distance(&pose.position) >= shape.bounding_radius {
        cache.reset();
        return Ok(());
    }
    let n = plane.normal;
    let half_space = HalfSpace::new(Vector::new(n.x, n.y, n.z));
    let p = plane.point;
    let plane_pose = Pose::from_translation(Vector::new(p.x, p.y, p.z));
    let flat = |_: u32| f64::INFINITY;
    manifold_contacts(
        &plane_pose,
        &half_space,
        &flat,
        &pose.to_parry(),
        &shape.compound,
        &piece_radius(shape),
        None,
        cache,
        out,
    )
}

/// Two exact shapes (a first, b second) through parry's compound–compound manifolds.
pub fn exact_exact_contacts(
    a: &ExactShape,
    pose_a: &BodyPose,
    b: &ExactShape,
    pose_b: &BodyPose,
    cache: &mut ExactContactCache,
    out: &mut Vec<ContactPoint>,
) -> Result<()> {
    if (pose_b.position - pose_a.position).norm() >= a.bounding_radius + b.bounding_radius {
        cache.reset();
        return Ok(());
    }
    manifold_contacts(
        &pose_a.to_parry(),
        &a.compound,
        &piece_radius(a),
        &pose_b.to_parry(),
        &b.compound,
        &piece_radius(b),
        Some((&a.compound, &b.compound)),
        cache,
        out,
    )
}

/// An exact shape against a free sphere (shape first, sphere second).
pub fn exact_sphere_contacts(
    shape: &ExactShape,
    pose: &BodyPose,
    sphere_center: &Vector3<f64>,
    sphere_radius: f64,
    cache: &mut ExactContactCache,
    out: &mut Vec<ContactPoint>,
) -> Result<()> {
    if (sphere_center - pose.position).norm() >= shape.bounding_radius + sphere_radius {
        cache.reset();
        return Ok(());
    }
    let ball = Ball::new(sphere_radius);
    let c = sphere_center;
    let ball_pose = Pose::from_translation(Vector::new(c.x, c.y, c.z));
    let own = move |_: u32| sphere_radius;
    manifold_contacts(
        &pose.to_parry(),
        &shape.compound,
        &piece_radius(shape),
        &ball_pose,
        &ball,
        &own,
        None,
        cache,
        out,
    )
}

/// Beads of a clump against an exact shape (clump first): each bead within reach of the
/// shape's bounding sphere is a parry ball queried against the compound.
pub fn clump_exact_contacts(
    clump: &BeadClump,
    pose_clump: &BodyPose,
    shape: &ExactShape,
    pose_shape: &BodyPose,
    out: &mut Vec<ContactPoint>,
) -> Result<()> {
    let between = pose_shape.position - pose_clump.position;
    if between.norm() >= clump.bounding_radius + shape.bounding_radius {
        return Ok(());
    }
    let local_shape_centre = pose_clump.orientation.inverse_transform_vector(&between);
    let shape_pose = pose_shape.to_parry();
    for (i, (c, &r)) in clump.centers.iter().zip(&clump.radii).enumerate() {
        if (c - local_shape_centre).norm() >= shape.bounding_radius + r {
            continue;
        }
        let centre = pose_clump.position + pose_clump.orientation * c;
        let ball_pose = Pose::from_translation(Vector::new(centre.x, centre.y, centre.z));
        let found = query::contact(&ball_pose, &Ball::new(r), &shape_pose, &shape.compound, 0.0)
            .map_err(|_| DemfemError::Effect("parry3d has no ball–compound contact".into()))?;
        if let Some(contact) = found {
            if contact.dist < 0.0 {
                let p1 = to_nalgebra(contact.point1);
                let p2 = to_nalgebra(contact.point2);
                out.push(ContactPoint {
                    point: 0.5 * (p1 + p2),
                    normal: to_nalgebra(contact.normal1),
                    overlap: -contact.dist,
                    radius_first: r,
                    radius_second: piece_radius(shape)(contact.subshape2),
                    feature_first: i as u64,
                    feature_second: piece_feature(contact.subshape2, 0),
                });
            }
        }
    }
    Ok(())
}

/// Half thickness of the parry plate that stands for a polygon wall against exact shapes, m.
/// Overlaps are measured from the polygon's own plane (the plate's mid-plane): a contact
/// counts only where a body reaches past the plate's face by more than this, so the wall
/// acts at zero thickness; the plate only gives parry a solid with one face per side (a fan
/// of triangles would split a flat cap contact at the diagonals).
pub const POLYGON_PLATE_HALF_THICKNESS: f64 = 1e-4;

/// A convex polygon wall (two-sided, zero thickness, like the sphere DEM's) prepared for
/// rigid shapes: the closest-point geometry of [`WallShape::Polygon`] for beads, and the same
/// polygon as a thin parry plate (convex hull of the polygon shifted ± half a thickness along
/// its normal) for exact shapes, with overlaps measured from the mid-plane.
#[derive(Clone)]
pub struct PolygonWall {
    shape: WallShape,
    plate: ConvexPolyhedron,
    /// Largest distance of a vertex from the first vertex, m (a cheap cull radius).
    extent: f64,
    first_vertex: Vector3<f64>,
}

impl std::fmt::Debug for PolygonWall {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PolygonWall")
            .field("shape", &self.shape)
            .finish()
    }
}

impl PolygonWall {
    /// Prepare a [`WallShape::Polygon`] (vertices in m); other shapes are refused.
    pub fn new(shape: &WallShape) -> Result<Self> {
        let WallShape::Polygon {
            vertices, normal, ..
        } = shape
        else {
            return Err(DemfemError::ShapeMismatch {
                field: "wall".into(),
                detail: "PolygonWall needs a polygon".into(),
            });
        };
        let v0 = vertices[0];
        let h = *normal * POLYGON_PLATE_HALF_THICKNESS;
        let points: Vec<Vector> = vertices.iter().flat_map(|v| [*v + h, *v - h]).collect();
        let plate = ConvexPolyhedron::from_convex_hull(&points).ok_or_else(|| {
            DemfemError::Numerical("convex hull of a polygon wall's plate failed".into())
        })?;
        let extent = vertices
            .iter()
            .map(|v| (*v - v0).length())
            .fold(0.0, f64::max);
        Ok(Self {
            shape: shape.clone(),
            plate,
            extent,
            first_vertex: Vector3::new(v0.x, v0.y, v0.z),
        })
    }

    /// The polygon at its reference position: vertices (m, boundary order), unit normal and
    /// inward in-plane edge normals.
    pub fn parts(
        &self,
    ) -> (
        &[crate::geometry::Vec3],
        crate::geometry::Vec3,
        &[crate::geometry::Vec3],
    ) {
        match &self.shape {
            WallShape::Polygon {
                vertices,
                normal,
                edge_normals,
            } => (vertices, *normal, edge_normals),
            _ => (&[], crate::geometry::Vec3::ZERO, &[]),
        }
    }

    /// Closest point (m), unit normal from the wall towards `p` and distance (m) of the
    /// world point `p` from the wall displaced by `offset` (m).
    fn closest(
        &self,
        p: &Vector3<f64>,
        offset: &Vector3<f64>,
    ) -> Option<(Vector3<f64>, Vector3<f64>, f64)> {
        let local = p - offset;
        self.shape
            .closest(Vector::new(local.x, local.y, local.z))
            .map(|(q, n, d)| (to_nalgebra(q) + offset, to_nalgebra(n), d))
    }

    /// True when nothing within `reach` (m) of `p` can touch the wall displaced by `offset`.
    fn out_of_reach(&self, p: &Vector3<f64>, offset: &Vector3<f64>, reach: f64) -> bool {
        if (p - offset - self.first_vertex).norm() >= self.extent + reach {
            return true;
        }
        matches!(self.closest(p, offset), Some((_, _, d)) if d >= reach)
    }
}

/// Beads of a clump against a polygon wall displaced by `offset` (m) (wall first, clump
/// second): a bead touches when its centre is closer than its radius to the polygon (face,
/// edge or corner). Beads farther than their radius from the polygon's plane are skipped with
/// one dot product each.
pub fn clump_polygon_contacts(
    wall: &PolygonWall,
    offset: &Vector3<f64>,
    clump: &BeadClump,
    pose: &BodyPose,
    out: &mut Vec<ContactPoint>,
) {
    if wall.out_of_reach(&pose.position, offset, clump.bounding_radius) {
        return;
    }
    let WallShape::Polygon { normal, .. } = &wall.shape else {
        return;
    };
    let n = Vector3::new(normal.x, normal.y, normal.z);
    let s0 = n.dot(&(pose.position - offset - wall.first_vertex));
    let n_body = pose.orientation.inverse_transform_vector(&n);
    for (i, (c, &r)) in clump.centers.iter().zip(&clump.radii).enumerate() {
        if (s0 + n_body.dot(c)).abs() >= r {
            continue;
        }
        let centre = pose.position + pose.orientation * c;
        if let Some((_, normal, distance)) = wall.closest(&centre, offset) {
            let overlap = r - distance;
            if overlap > 0.0 {
                out.push(ContactPoint {
                    point: centre - normal * (0.5 * (r + distance)),
                    normal,
                    overlap,
                    radius_first: f64::INFINITY,
                    radius_second: r,
                    feature_first: 0,
                    feature_second: i as u64,
                });
            }
        }
    }
}

/// Beads of a clump against a mesh wall displaced by `offset` (m) (wall first, clump
/// second): the triangles within the clump's bounding sphere through the mesh's BVH, then
/// each bead against each of them within its radius under the rule of
/// [`crate::geometry::mesh`] (each touching face, edge and vertex once). The contact's
/// `feature_first` is the triangle, so each (bead, triangle) keeps its own friction history.
pub fn clump_mesh_contacts(
    mesh: &MeshWall,
    offset: &Vector3<f64>,
    clump: &BeadClump,
    pose: &BodyPose,
    out: &mut Vec<ContactPoint>,
) {
    let local = pose.position - offset;
    let mut near = Vec::new();
    mesh.triangles_within(
        Vector::new(local.x, local.y, local.z),
        clump.bounding_radius,
        &mut near,
    );
    if near.is_empty() {
        return;
    }
    for (i, (c, &r)) in clump.centers.iter().zip(&clump.radii).enumerate() {
        let centre = pose.position + pose.orientation * c;
        let p = centre - offset;
        let p = Vector::new(p.x, p.y, p.z);
        for &t in &near {
            if let Some((_, normal, distance)) = mesh.contact(t, p, r) {
                let normal = to_nalgebra(normal);
                out.push(ContactPoint {
                    point: centre - normal * (0.5 * (r + distance)),
                    normal,
                    overlap: r - distance,
                    radius_first: f64::INFINITY,
                    radius_second: r,
                    feature_first: u64::from(t),
                    feature_second: i as u64,
                });
            }
        }
    }
}

/// An exact shape against a polygon wall displaced by `offset` (m) (wall first), through
/// parry's manifolds of the compound against the wall's thin plate; overlaps are measured
/// from the polygon's plane (see [`POLYGON_PLATE_HALF_THICKNESS`]).
pub fn exact_polygon_contacts(
    wall: &PolygonWall,
    offset: &Vector3<f64>,
    shape: &ExactShape,
    pose: &BodyPose,
    cache: &mut ExactContactCache,
    out: &mut Vec<ContactPoint>,
) -> Result<()> {
    if wall.out_of_reach(&pose.position, offset, shape.bounding_radius) {
        cache.reset();
        return Ok(());
    }
    let wall_pose = Pose::from_translation(Vector::new(offset.x, offset.y, offset.z));
    let flat = |_: u32| f64::INFINITY;
    let first_new = out.len();
    manifold_contacts(
        &wall_pose,
        &wall.plate,
        &flat,
        &pose.to_parry(),
        &shape.compound,
        &piece_radius(shape),
        None,
        cache,
        out,
    )?;
    // from the plate's face to the polygon's plane: half a thickness less overlap, and the
    // midpoint of the true overlap half of that further towards the wall
    let h = POLYGON_PLATE_HALF_THICKNESS;
    let mut k = first_new;
    while k < out.len() {
        if out[k].overlap > h {
            out[k].overlap -= h;
            let shift = out[k].normal * (0.5 * h);
            out[k].point -= shift;
            k += 1;
        } else {
            out.swap_remove(k);
        }
    }
    Ok(())
}
