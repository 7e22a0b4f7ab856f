//! Contact points of the force law for bodies of revolution: body–body, body–plane, the
//! faces of polygon walls and beads (spheres, clumps) against a body.
//!
//! Every contact is a [`ContactPoint`] (world frame, normal from the first object to the
//! second, point midway through the overlap) with a *weight* w ∈ (0, 1]: the scene scales
//! the contact's Hertz force and elastic energy by w (see `scene` on how w enters the
//! damping), so that a contact's potential is Σ w · 2/5 k_H δ^{5/2}.
//!
//! * **Bodies.** Each pair of pieces within reach gives its closest features
//!   ([`super::features::piece_pair`]); an overlap there is a point contact (features shared
//!   by two pieces, such as the body–shoulder edge, are counted once). Two cylinders that are
//!   nearly parallel touch along a line, where the deepest point is ill-defined (it jumps
//!   from one end to the other as the axes pass through parallel). Such a *line pair* adds
//!   two samples at the ends α, β of the axial range both cylinders cover: the overlap there
//!   between the axis point of the first and the axis line of the second (r_a + r_b − d).
//!   With σ* the axial position of the deepest point, the end α gets the weight
//!   g h (σ* − α)/ℓ and β the weight g h (β − σ*)/ℓ (ℓ = β − α): the potential
//!   U = U(δ*) + g h [(σ* − α) U(δ_α) + (β − σ*) U(δ_β)]/ℓ is continuous through parallel
//!   (where every δ is equal and U = 2 U(δ): a line contact carries two Hertz points, as a
//!   cylinder lying on a plane) and equals the exact point contact once the ends lift off.
//!   g = 1 − smoothstep(sin θ / [`LINE_ANGLE`]) fades the samples out with the angle θ
//!   between the axes, h = smoothstep(ℓ / ℓ₀) (ℓ₀ a tenth of the shorter piece) as the
//!   cylinders slide off each other's ends. Point contacts that belong to the line (the
//!   features of its two cylinders: sides and end edges) other than the pair's own deepest
//!   point are weighted 1 − g h, so the edge contacts that flicker in and out of their normal
//!   cones at parallel carry no weight there. Not handled: line contacts of cones (a side
//!   against a shoulder at its own slope) keep one point.
//! * **Planes** (the belt, walls): every convex edge circle touches with four points at
//!   quarter turns, anchored at its deepest point (as parry's square approximation of a
//!   cap): the overlaps are δ_c + r s cos(jπ/2) (δ_c of the circle's centre, s the sine of the
//!   angle between axis and plane normal), so a tilted circle touches with its lowest point
//!   only, a flat one (an upright cartridge on the belt) with all four; the set is symmetric
//!   about the deepest point, so its sliding does no work and the normal forces are the
//!   gradient of Σ U(δ_j). Sides and faces need no points of their own: a straight generator
//!   or a flat face touches a plane first at its ends, which lie on edge circles.
//! * **Polygon walls**: the same points where they fall inside the polygon; the polygon's
//!   edges and corners in [`super::wall_edges`].
//! * **Beads**: the bead centre's distance from the outline in its meridian plane, exact.

use nalgebra::Vector3;

use super::features::{
    piece_pair_cached, segment_parameters, CandidateCache, Feature, FeaturePair, Placed,
};
use crate::rigid::collision::ContactPoint;

type V3 = Vector3<f64>;

/// sin θ above which nearly parallel cylinders are no longer a line pair.
pub const LINE_ANGLE: f64 = 0.05;

/// Friction-history key offset of line samples: 1024 + 2 · piece + end.
const LINE_KEY: u64 = 1024;
/// Relative tolerance of the test that a bounded face's point under an anchored point lies
/// within the circle's radius of the axis (plane_contacts): rounding, and a circle tilted by
/// s against the face whose side points overlap by δ lie √(r² + (s δ)²) − r ≈ (s δ)²/2r
/// outside, a few nm at most for a body standing on the face.
const FACE_RADIUS_TOLERANCE: f64 = 1e-6;

/// Friction-history key offset of plane points: 2048 + 4 · circle + j.
const PLANE_KEY: u64 = 2048;
/// Friction-history key offset of outline segments touched by beads.
const OUTLINE_KEY: u64 = 4096;

/// 3t² − 2t³ on [0, 1], clamped outside.
#[inline]
pub fn smoothstep(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// A straight piece: axis from `start` along the unit `direction` for `length`, radius
/// `radius` (0 for a wall edge), m.
#[derive(Debug, Clone, Copy)]
pub struct Rod {
    /// Start of the axis, m.
    pub start: V3,
    /// Unit direction.
    pub direction: V3,
    /// Axial length, m.
    pub length: f64,
    /// Radius, m.
    pub radius: f64,
}

/// One end sample of a line pair: weight, overlap (m), unit normal from the first rod to
/// the second, contact point (m), end index.
#[derive(Debug, Clone, Copy)]
pub struct LineSample {
    /// Weight of the sample (g h times the end's share).
    pub weight: f64,
    /// Overlap, m (may be ≤ 0: no contact).
    pub overlap: f64,
    /// Unit normal from rod a to rod b.
    pub normal: V3,
    /// Midway point, m.
    pub point: V3,
    /// 0 for the end α, 1 for β.
    pub end: usize,
}

/// The line-pair weight g h of two rods (0 when they are not a line pair) and the axial
/// range [α, β] of `a` they both cover (distances along `a` from its start, m).
pub fn line_pair(a: &Rod, b: &Rod) -> (f64, f64, f64) {
    let sin = a.direction.cross(&b.direction).norm();
    if sin >= LINE_ANGLE {
        return (0.0, 0.0, 0.0);
    }
    let g = 1.0 - smoothstep(sin / LINE_ANGLE);
    let t0 = (b.start - a.start).dot(&a.direction);
    let t1 = t0 + b.length * b.direction.dot(&a.direction);
    let lo = t0.min(t1).max(0.0);
    let hi = t0.max(t1).min(a.length);
    let ell = hi - lo;
    if ell <= 0.0 || ell.is_nan() {
        return (0.0, 0.0, 0.0);
    }
    let ell0 = 0.1 * a.length.min(b.length);
    (g * smoothstep(ell / ell0), lo, hi)
}

/// The two end samples of a line pair of weight `gh` over [α, β] = [`lo`, `hi`] with the
/// deepest point at `sigma` along `a` (`None`: halfway).
pub fn line_samples(
    a: &Rod,
    b: &Rod,
    gh: f64,
    lo: f64,
    hi: f64,
    sigma: Option<f64>,
) -> [LineSample; 2] {
    let ell = hi - lo;
    let s = sigma.unwrap_or(0.5 * (lo + hi)).clamp(lo, hi);
    let shares = [(s - lo) / ell, (hi - s) / ell];
    let mut out = [LineSample {
        weight: 0.0,
        overlap: f64::NEG_INFINITY,
        normal: a.direction,
        point: a.start,
        end: 0,
    }; 2];
    for (end, at) in [lo, hi].into_iter().enumerate() {
        let x = a.start + a.direction * at;
        let y = b.start + b.direction * (x - b.start).dot(&b.direction);
        let gap = y - x;
        let d = gap.norm();
        if d <= 1e-15 {
            continue;
        }
        let normal = gap / d;
        let overlap = a.radius + b.radius - d;
        out[end] = LineSample {
            weight: gh * shares[end],
            overlap,
            normal,
            point: x + normal * (a.radius - 0.5 * overlap),
            end,
        };
    }
    out
}

/// The rod of piece `i` of a placed body.
pub fn piece_rod(x: &Placed, i: usize) -> Rod {
    let f = &x.shape.frustums[i];
    Rod {
        start: x.at(f.z[0]),
        direction: x.axis,
        length: f.length(),
        radius: f.r[0],
    }
}

/// Hertz contact radius of a feature touched at `point`, m: the local radius r(z) of a side
/// at the point's height, an edge circle's radius, a face's outer radius — continuous as a
/// contact slides from one feature onto the next (a jump would do work: the potential
/// 2/5 k_H δ^{5/2} would change at a fixed overlap), constant along a cylinder.
pub fn feature_radius(x: &Placed, feature: Feature, point: &V3) -> f64 {
    match feature {
        Feature::Side(i) => {
            let f = &x.shape.frustums[i];
            f.radius_at((point - x.origin).dot(&x.axis).clamp(f.z[0], f.z[1]))
        }
        Feature::Edge(k) => x.shape.circles[k].r,
        Feature::Face(f) => x.shape.faces[f].contact_radius,
    }
}

/// Whether `feature` is the side or an end edge of piece `i`.
pub fn belongs_to(x: &Placed, feature: Feature, i: usize) -> bool {
    match feature {
        Feature::Side(j) => j == i,
        Feature::Edge(k) => x.shape.frustums[i].circles.contains(&k),
        Feature::Face(_) => false,
    }
}

/// The pieces of `x` (with their rods) whose capsules reach the bounding capsule of `y`.
fn near_pieces(x: &Placed, y: &Placed, out: &mut Vec<(usize, Rod)>) {
    out.clear();
    let capsule = y.shape.bounding_capsule;
    let (c0, c1) = (y.at(capsule.z_min), y.at(capsule.z_max));
    for (i, f) in x.shape.frustums.iter().enumerate() {
        let rod = piece_rod(x, i);
        let (s, t, _) =
            segment_parameters(&rod.start, &(rod.direction * rod.length), &c0, &(c1 - c0));
        let gap = rod.start + rod.direction * (s * rod.length) - c0 - (c1 - c0) * t;
        if gap.norm() < f.reach + capsule.radius {
            out.push((i, rod));
        }
    }
}

/// Reusable buffers of [`pair_contacts`].
#[derive(Debug, Default, Clone)]
pub struct PairScratch {
    cache: CandidateCache,
    near_a: Vec<(usize, Rod)>,
    near_b: Vec<(usize, Rod)>,
    found: Vec<(FeaturePair, usize, usize, bool)>,
    lines: Vec<(usize, usize, f64, f64, f64, Option<f64>)>,
}

/// Contacts between two bodies of revolution (a first, b second), appended to `out` with
/// their weights in `weights` (see the module docs).
pub fn pair_contacts(
    a: &Placed,
    b: &Placed,
    scratch: &mut PairScratch,
    out: &mut Vec<ContactPoint>,
    weights: &mut Vec<f64>,
) {
    scratch.found.clear();
    scratch.lines.clear();
    scratch.cache.clear();
    // the pieces of each body that can reach the other's bounding capsule
    near_pieces(a, b, &mut scratch.near_a);
    near_pieces(b, a, &mut scratch.near_b);
    for &(i, rod_a) in &scratch.near_a {
        let fa = a.shape.frustums[i];
        for &(j, rod_b) in &scratch.near_b {
            let fb = b.shape.frustums[j];
            let (s, t, _) = segment_parameters(
                &rod_a.start,
                &(rod_a.direction * rod_a.length),
                &rod_b.start,
                &(rod_b.direction * rod_b.length),
            );
            let gap = (rod_a.start + rod_a.direction * (s * rod_a.length))
                - (rod_b.start + rod_b.direction * (t * rod_b.length));
            if gap.norm() >= fa.reach + fb.reach {
                continue;
            }
            let found = piece_pair_cached(a, i, b, j, 0.0, &mut scratch.cache);
            let line = if fa.is_cylinder() && fb.is_cylinder() {
                line_pair(&rod_a, &rod_b)
            } else {
                (0.0, 0.0, 0.0)
            };
            if line.0 > 0.0 {
                let sigma = found.map(|f| (f.point_a - rod_a.start).dot(&rod_a.direction));
                scratch.lines.push((i, j, line.0, line.1, line.2, sigma));
            }
            if let Some(f) = found {
                if f.distance < 0.0 {
                    scratch.found.push((f, i, j, line.0 > 0.0));
                }
            }
        }
    }
    // point contacts, each pair of features once
    for k in 0..scratch.found.len() {
        let (f, _, _, own) = scratch.found[k];
        let earlier = scratch.found[..k]
            .iter()
            .any(|e| e.0.feature_a == f.feature_a && e.0.feature_b == f.feature_b);
        if earlier {
            continue;
        }
        let owned = own
            || scratch.found[k + 1..]
                .iter()
                .any(|e| e.3 && e.0.feature_a == f.feature_a && e.0.feature_b == f.feature_b);
        let weight = if owned {
            1.0
        } else {
            1.0 - scratch
                .lines
                .iter()
                .filter(|l| belongs_to(a, f.feature_a, l.0) && belongs_to(b, f.feature_b, l.1))
                .map(|l| l.2)
                .fold(0.0, f64::max)
        };
        if weight <= 0.0 {
            continue;
        }
        match (f.feature_a, f.feature_b) {
            (Feature::Face(face), Feature::Edge(edge)) => {
                face_points(a, face, scratch.found[k].1, b, edge, out);
                weights.resize(out.len(), weight);
            }
            (Feature::Edge(edge), Feature::Face(face)) => {
                let start = out.len();
                face_points(b, face, scratch.found[k].2, a, edge, out);
                for c in &mut out[start..] {
                    c.normal = -c.normal;
                    std::mem::swap(&mut c.radius_first, &mut c.radius_second);
                    std::mem::swap(&mut c.feature_first, &mut c.feature_second);
                }
                weights.resize(out.len(), weight);
            }
            _ => {
                out.push(ContactPoint {
                    point: 0.5 * (f.point_a + f.point_b),
                    normal: f.normal,
                    overlap: -f.distance,
                    radius_first: feature_radius(a, f.feature_a, &f.point_a),
                    radius_second: feature_radius(b, f.feature_b, &f.point_b),
                    feature_first: f.feature_a.key(),
                    feature_second: f.feature_b.key(),
                });
                weights.push(weight);
            }
        }
    }
    for &(i, j, gh, lo, hi, sigma) in &scratch.lines {
        let (rod_a, rod_b) = (piece_rod(a, i), piece_rod(b, j));
        for sample in line_samples(&rod_a, &rod_b, gh, lo, hi, sigma) {
            if sample.overlap > 0.0 && sample.weight > 0.0 {
                out.push(ContactPoint {
                    point: sample.point,
                    normal: sample.normal,
                    overlap: sample.overlap,
                    radius_first: rod_a.radius,
                    radius_second: rod_b.radius,
                    feature_first: LINE_KEY + 2 * i as u64 + sample.end as u64,
                    feature_second: j as u64,
                });
                weights.push(sample.weight);
            }
        }
    }
}

/// Flat face `face` of X (on its piece `piece`) against edge circle `edge` of Y: four points
/// of the circle at quarter turns anchored at its deepest point along the face normal, as on
/// a plane (so that two cartridges end to end press rim on rim evenly), each kept where it
/// overlaps the face, projects onto it and lies in X's piece; appended oriented X → Y.
fn face_points(
    x: &Placed,
    face: usize,
    piece: usize,
    y: &Placed,
    edge: usize,
    out: &mut Vec<ContactPoint>,
) {
    let f = x.shape.faces[face];
    let circle = y.shape.circles[edge];
    let m = x.axis * f.facing;
    let face_centre = x.at(f.z);
    let in_plane = m - y.axis * m.dot(&y.axis);
    let s = in_plane.norm();
    let (u, v) = if s > 1e-14 {
        let u = -in_plane / s;
        (u, y.axis.cross(&u))
    } else {
        (y.x, y.y)
    };
    let centre = y.at(circle.z);
    let tolerance = 1e-6 * f.r[1];
    let radius_y = circle.r;
    let quarter = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)];
    for (j, (c, sn)) in quarter.into_iter().enumerate() {
        let p = centre + (u * c + v * sn) * circle.r;
        let overlap = -m.dot(&(p - face_centre));
        if overlap <= 0.0 {
            continue;
        }
        let (_, _, rho) = x.meridian(&p);
        if rho < f.r[0] - tolerance || rho > f.r[1] + tolerance {
            continue;
        }
        if !super::features::inside_piece(x, piece, &p) {
            continue;
        }
        out.push(ContactPoint {
            point: p + m * (0.5 * overlap),
            normal: m,
            overlap,
            radius_first: f.contact_radius,
            radius_second: radius_y,
            feature_first: Feature::Face(face).key(),
            feature_second: Feature::Edge(edge).key() + ((j as u64) << 12),
        });
    }
}

/// A plane through `point` with unit `normal` (out of the solid) against a body (plane
/// first): four anchored points per convex edge circle, weight 1 (module docs). With
/// `inside`, only points whose projection it accepts count (a polygon's face), and only where
/// the face's point under them lies within the circle's radius of the axis.
pub fn plane_contacts(
    point: &V3,
    normal: &V3,
    body: &Placed,
    inside: Option<&dyn Fn(&V3) -> bool>,
    out: &mut Vec<ContactPoint>,
    weights: &mut Vec<f64>,
) {
    let in_plane = normal - body.axis * normal.dot(&body.axis);
    let s = in_plane.norm();
    let (u, v) = if s > 1e-14 {
        let u = -in_plane / s;
        (u, body.axis.cross(&u))
    } else {
        (body.x, body.y)
    };
    for (k, circle) in body.shape.circles.iter().enumerate() {
        if !circle.convex {
            continue;
        }
        let centre = body.at(circle.z);
        let depth = -normal.dot(&(centre - point));
        if depth + circle.r * s <= 0.0 {
            continue;
        }
        let radius = circle.r;
        let quarter = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)];
        for (j, (c, sn)) in quarter.into_iter().enumerate() {
            let overlap = depth + circle.r * s * c;
            if overlap <= 0.0 {
                continue;
            }
            let x = centre + (u * c + v * sn) * circle.r;
            if let Some(accept) = inside {
                // A bounded face (a polygon's, a triangle's) touches only where its own
                // material is inside the body: the face's point under `x` must lie within the
                // circle's radius of the axis. A quarter point beside the anchor (c = 0)
                // reaches past the plane only once the circle's centre has crossed it, and
                // the face's point under it lies outside the circle by √(r² + (s δ)²) − r:
                // the body passes beside the face's edge (a cartridge whose foot is past the
                // gate's plane, leaving through the gap beside it), where the edge and
                // corner contacts hold it. Counted, such a point switches a contact of the
                // circle centre's depth on within one step as it slides across the outline
                // (a phantom overlap that threw a cartridge at 17 m/s). Standing on a face
                // (s ≈ 0) the four points stay.
                let under = x + normal * overlap - centre;
                let off_axis = under - body.axis * under.dot(&body.axis);
                if off_axis.norm() > circle.r * (1.0 + FACE_RADIUS_TOLERANCE) || !accept(&x) {
                    continue;
                }
            }
            out.push(ContactPoint {
                point: x + normal * (0.5 * overlap),
                normal: *normal,
                overlap,
                radius_first: f64::INFINITY,
                radius_second: radius,
                feature_first: 0,
                feature_second: PLANE_KEY + 4 * k as u64 + j as u64,
            });
            weights.push(1.0);
        }
    }
}

/// A bead (sphere of `radius` at `centre`, m) against a body: the closest point of the
/// body's outline in the bead centre's meridian plane. Returns (contact, bead first) or
/// `None` apart.
pub fn bead_contact(centre: &V3, radius: f64, body: &Placed) -> Option<ContactPoint> {
    let (z, radial, rho) = body.meridian(centre);
    let (distance, q, n, contact_radius) = body.shape.meridian_distance(z, rho);
    let overlap = radius - distance;
    if overlap <= 0.0 {
        return None;
    }
    let outward = body.axis * n.0 + radial * n.1;
    let surface = body.origin + body.axis * q.0 + radial * q.1;
    let segment = body
        .shape
        .outline
        .windows(2)
        .position(|w| {
            let (ez, er) = (w[1].0 - w[0].0, w[1].1 - w[0].1);
            let (dz, dr) = (q.0 - w[0].0, q.1 - w[0].1);
            (ez * dr - er * dz).abs() <= 1e-12 * (ez.abs() + er.abs()) && dz * ez + dr * er >= 0.0
        })
        .unwrap_or(0);
    Some(ContactPoint {
        point: 0.5 * (surface + centre - outward * radius),
        normal: -outward,
        overlap,
        radius_first: radius,
        radius_second: contact_radius,
        feature_first: 0,
        feature_second: OUTLINE_KEY + segment as u64,
    })
}
