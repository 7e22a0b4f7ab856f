//! The edges and corners of a convex polygon wall (the table's gate and tilted wall: two-
//! sided plates of zero thickness) against a body of revolution.
//!
//! The polygon's face is a plane restricted to the polygon ([`super::contacts::plane_contacts`]
//! with an inside test). An edge is a cone-sphere of radius 0 (a segment): against a side
//! the closest points come from the same convex minimisation as two sides
//! ([`super::features::sweep_closest`]); against an edge circle it is an edge–edge pair (the
//! distance from the circle's point at θ to the edge's line, minimised over θ; the normal is
//! the cross product of the tangents, signed through zero). A corner is a point, whose signed
//! distance from the body is exact in its meridian plane. A contact counts only where the
//! edge or corner is the polygon's closest feature to the body: the normal from the wall to
//! the body points out of the polygon across the edge (n · e_in < 0 for the edge's inward
//! in-plane normal e_in), or past both edges at a corner. An upright cartridge sliding along
//! the gate's vertical edge meets it along a line: the line-pair rule of
//! [`super::contacts`] applies with the edge as a cylinder of radius 0.
//!
//! Contacts are oriented wall first (normal from the wall to the body). Lengths in m.

use nalgebra::Vector3;

use super::contacts::{belongs_to, feature_radius, line_pair, line_samples, piece_rod, Rod};
use super::features::{
    circle_minimum, circle_point, in_cone, segment_parameters, Feature, Placed, Sweep,
};
use crate::rigid::collision::ContactPoint;

type V3 = Vector3<f64>;

/// Friction-history key of a polygon edge (1 + e) and a corner (1024 + m) on the wall side.
const EDGE_KEY: u64 = 1;
const CORNER_KEY: u64 = 1024;
/// Key offset of a line sample on the body side (as in `contacts`).
const LINE_KEY: u64 = 1024;

/// One candidate of an edge against a piece: signed distance, normal wall → body, point on
/// the wall, point on the body, body feature.
type Candidate = (f64, V3, V3, V3, Feature);

/// Edge circle `k` of the body against the segment `start + u t`, u ∈ (0, length):
/// (distance, normal body → wall, point on the circle, point on the segment), `None` unless
/// the foot is inside the segment and the normal in the circle's cone.
fn circle_segment(
    x: &Placed,
    k: usize,
    start: &V3,
    t: &V3,
    length: f64,
) -> Option<(f64, V3, V3, V3)> {
    let circle = x.shape.circles[k];
    let q0 = x.at(circle.z) - start;
    let r = circle.r;
    let (a0, ac, as_) = (
        q0.norm_squared() + r * r,
        2.0 * r * q0.dot(&x.x),
        2.0 * r * q0.dot(&x.y),
    );
    let (b0, bc, bs) = (q0.dot(t), r * x.x.dot(t), r * x.y.dot(t));
    let eval = |c: f64, s: f64| -> (f64, f64, f64) {
        let av = a0 + ac * c + as_ * s;
        let da = -ac * s + as_ * c;
        let bv = b0 + bc * c + bs * s;
        let db = -bc * s + bs * c;
        (
            av - bv * bv,
            da - 2.0 * bv * db,
            -(av - a0) - 2.0 * (db * db - bv * (bv - b0)),
        )
    };
    // nearly parallel to the axis, the edge faces the circle where it passes nearest
    let centre = x.at(circle.z);
    let guess = if x.axis.dot(t).abs() > 0.95 {
        let w = start + t * (centre - start).dot(t) - centre;
        let (c, s) = (w.dot(&x.x), w.dot(&x.y));
        let n = c.hypot(s);
        (n > 0.5 * r).then(|| (c / n, s / n))
    } else {
        None
    };
    let (u, _) = circle_minimum(guess, eval);
    let (p, _, tangent) = circle_point(x, k, u);
    let u = (p - start).dot(t);
    if !(u > 0.0 && u < length) {
        return None;
    }
    let foot = start + t * u;
    let gap = foot - p;
    let mut normal = super::features::edge_normal(&tangent, t, &gap, r)?;
    let (_, radial, _) = x.meridian(&p);
    let (mz, mr) = circle.cone_middle();
    if normal.dot(&(x.axis * mz + radial * mr)) < 0.0 {
        normal = -normal;
    }
    if !in_cone(x, k, &p, &normal) {
        return None;
    }
    Some((gap.dot(&normal), normal, p, foot))
}

/// Whether the normal `n` (wall → body) leaves every face holding an edge across it: the
/// edge is then those faces' closest feature (`inward`: each face's in-plane normal pointing
/// into it from the edge).
/// (A margin of 1e-9 keeps the shared edges of flat meshes out.)
#[inline]
fn off_every_face(n: &V3, inward: &[V3]) -> bool {
    inward.iter().all(|e| n.dot(e) < -1e-9)
}

/// The best valid candidate of the edge `rod` (inward in-plane normals of the faces holding
/// it: `inward`) against piece `i` of the body.
fn edge_piece(body: &Placed, i: usize, rod: &Rod, inward: &[V3]) -> Option<Candidate> {
    let mut best: Option<Candidate> = None;
    let mut consider = |c: Candidate| {
        // an overlap is real only where the edge's point lies in the piece
        let real = c.0 >= 0.0 || super::features::inside_piece(body, i, &c.2);
        if real && off_every_face(&c.1, inward) && best.is_none_or(|b| c.0 > b.0) {
            best = Some(c);
        }
    };
    let sweep = Sweep::of_piece(body, i);
    let edge = Sweep {
        origin: rod.start,
        axis: rod.direction,
        s: [0.0, rod.length],
        r0: 0.0,
        k: 0.0,
    };
    if let Some((sigma, tau)) = super::features::sweep_closest(&sweep, &edge) {
        let centre = body.origin + body.axis * sigma;
        let on_edge = rod.start + rod.direction * tau;
        let d = centre - on_edge;
        let length = d.norm();
        if length > 1e-15 {
            let u = d / length;
            let radius = sweep.radius(sigma);
            consider((
                length - radius,
                u,
                on_edge,
                centre - u * radius,
                Feature::Side(i),
            ));
        }
    }
    for &k in &body.shape.frustums[i].circles {
        if !body.shape.circles[k].convex {
            continue;
        }
        if let Some((distance, n, p, foot)) =
            circle_segment(body, k, &rod.start, &rod.direction, rod.length)
        {
            consider((distance, -n, foot, p, Feature::Edge(k)));
        }
    }
    best
}

/// Contacts of the wall edge from `va` to `vb` (world, m) with a body, wall first, appended
/// to `out` with weights: the best valid candidate of each piece within reach, each body
/// feature once, and the line pair of a nearly parallel cylinder. `inward` holds the
/// in-plane normals of the faces holding the edge (one for a polygon's edge, two for a
/// mesh's); `key` is the wall-side key of the edge's contacts.
#[allow(clippy::too_many_arguments)]
pub fn edge_contacts(
    va: &V3,
    vb: &V3,
    inward: &[V3],
    key: u64,
    body: &Placed,
    out: &mut Vec<ContactPoint>,
    weights: &mut Vec<f64>,
) {
    let length = (vb - va).norm();
    if length <= 0.0 {
        return;
    }
    let capsule = body.shape.bounding_capsule;
    let (c0, c1) = (body.at(capsule.z_min), body.at(capsule.z_max));
    let (s, t, _) = segment_parameters(&c0, &(c1 - c0), va, &(vb - va));
    if (c0 + (c1 - c0) * s - va - (vb - va) * t).norm() >= capsule.radius {
        return;
    }
    let rod = Rod {
        start: *va,
        direction: (vb - va) / length,
        length,
        radius: 0.0,
    };
    let mut found: Vec<(Candidate, bool)> = Vec::new();
    let mut lines: Vec<(usize, f64, f64, f64, Option<f64>)> = Vec::new();
    for i in 0..body.shape.frustums.len() {
        let piece = piece_rod(body, i);
        let (s, t, _) = segment_parameters(
            &piece.start,
            &(piece.direction * piece.length),
            va,
            &(vb - va),
        );
        let gap = piece.start + piece.direction * (s * piece.length) - va - (vb - va) * t;
        if gap.norm() >= body.shape.frustums[i].reach {
            continue;
        }
        let candidate = edge_piece(body, i, &rod, inward);
        let line = if body.shape.frustums[i].is_cylinder() {
            line_pair(&piece, &rod)
        } else {
            (0.0, 0.0, 0.0)
        };
        if line.0 > 0.0 {
            let sigma = candidate.map(|c| (c.3 - piece.start).dot(&piece.direction));
            lines.push((i, line.0, line.1, line.2, sigma));
        }
        if let Some(c) = candidate {
            if c.0 < 0.0 {
                found.push((c, line.0 > 0.0));
            }
        }
    }
    for k in 0..found.len() {
        let (c, own) = found[k];
        if found[..k].iter().any(|f| f.0 .4 == c.4) {
            continue;
        }
        let owned = own || found[k + 1..].iter().any(|f| f.1 && f.0 .4 == c.4);
        let weight = if owned {
            1.0
        } else {
            1.0 - lines
                .iter()
                .filter(|l| belongs_to(body, c.4, l.0))
                .map(|l| l.1)
                .fold(0.0, f64::max)
        };
        if weight <= 0.0 {
            continue;
        }
        out.push(ContactPoint {
            point: 0.5 * (c.2 + c.3),
            normal: c.1,
            overlap: -c.0,
            radius_first: f64::INFINITY,
            radius_second: feature_radius(body, c.4, &c.3),
            feature_first: key,
            feature_second: c.4.key(),
        });
        weights.push(weight);
    }
    for &(i, gh, lo, hi, sigma) in &lines {
        let piece = piece_rod(body, i);
        for sample in line_samples(&piece, &rod, gh, lo, hi, sigma) {
            // the sample's normal runs from the body to the edge
            if sample.overlap > 0.0
                && sample.weight > 0.0
                && off_every_face(&(-sample.normal), inward)
            {
                out.push(ContactPoint {
                    point: sample.point,
                    normal: -sample.normal,
                    overlap: sample.overlap,
                    radius_first: f64::INFINITY,
                    radius_second: piece.radius,
                    feature_first: key,
                    feature_second: LINE_KEY + 2 * i as u64 + sample.end as u64,
                });
                weights.push(sample.weight);
            }
        }
    }
}

/// The contact of the wall corner `v` (world, m) with a body, wall first, when the corner is
/// the wall's closest feature to the body (the normal points away from every edge leaving
/// it: `neighbours` are the other ends of those edges); `key` is its wall-side key.
pub fn corner_contact(
    v: &V3,
    neighbours: &[V3],
    key: u64,
    body: &Placed,
    out: &mut Vec<ContactPoint>,
    weights: &mut Vec<f64>,
) {
    let capsule = body.shape.bounding_capsule;
    let (z, radial, rho) = body.meridian(v);
    if z < capsule.z_min - capsule.radius
        || z > capsule.z_max + capsule.radius
        || rho > capsule.radius
    {
        return;
    }
    let (distance, q, normal, radius) = body.shape.meridian_distance(z, rho);
    if distance >= 0.0 {
        return;
    }
    let outward = body.axis * normal.0 + radial * normal.1;
    let to_body = -outward;
    // (strictly: a corner inside a flat mesh is no corner)
    if neighbours
        .iter()
        .any(|w| to_body.dot(&(w - v)) > -1e-9 * (w - v).norm())
    {
        return;
    }
    let surface = body.origin + body.axis * q.0 + radial * q.1;
    out.push(ContactPoint {
        point: 0.5 * (v + surface),
        normal: to_body,
        overlap: -distance,
        radius_first: f64::INFINITY,
        radius_second: radius,
        feature_first: key,
        feature_second: 0,
    });
    weights.push(1.0);
}

/// Contacts of the edges and corners of a convex polygon (world vertices in boundary order,
/// inward in-plane edge normals) with a body, wall first, appended to `out` with weights.
pub fn polygon_edge_contacts(
    vertices: &[V3],
    edge_normals: &[V3],
    body: &Placed,
    out: &mut Vec<ContactPoint>,
    weights: &mut Vec<f64>,
) {
    let n = vertices.len();
    for e in 0..n {
        let (va, vb) = (vertices[e], vertices[(e + 1) % n]);
        edge_contacts(
            &va,
            &vb,
            &edge_normals[e..e + 1],
            EDGE_KEY + e as u64,
            body,
            out,
            weights,
        );
    }
    for m in 0..n {
        let neighbours = [vertices[(m + 1) % n], vertices[(m + n - 1) % n]];
        corner_contact(
            &vertices[m],
            &neighbours,
            CORNER_KEY + m as u64,
            body,
            out,
            weights,
        );
    }
}
