//! Contacts of exact shapes through parry3d-f64's contact manifolds, kept between steps in an
//! [`ExactContactCache`] so parry can match features (persistent manifolds): an exact shape
//! against a plane, a sphere, another exact shape and a bead clump, with the local overlap
//! measured along the manifold normal. Lengths in m.

use nalgebra::Vector3;
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query::{
    self, ContactManifold, ContactManifoldsWorkspace, DefaultQueryDispatcher,
    PersistentQueryDispatcher, Ray,
};
use parry3d_f64::shape::{Ball, Compound, HalfSpace, Shape};

use super::primitives::{to_nalgebra, BodyPose, ContactPoint, Plane};
use crate::error::{DemfemError, Result};
use crate::rigid::shape::{BeadClump, ExactShape};

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
pub(super) fn manifold_contacts(
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

/// Contact radius of each piece of `shape` by piece id (`inf` past the list).
pub(super) fn piece_radius(shape: &ExactShape) -> impl Fn(u32) -> f64 + '_ {
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
