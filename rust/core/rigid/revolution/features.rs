//! Exact closest features of two pieces of bodies of revolution (two frustums), in the
//! world frame.
//!
//! A frustum's boundary is its side, its two edge circles and, at the ends of the body or at
//! a flat step, a flat face. Between two convex pieces the signed distance (positive apart,
//! minus the penetration depth when they overlap) is attained by one pair of features whose
//! closest points satisfy the normal-cone conditions (Lin & Canny 1991; for penetration,
//! the minimum translation distance of the separating-axis theorem). Every candidate pair is
//! solved exactly and checked against those conditions; the valid candidate with the
//! largest signed distance is the answer:
//!
//! * **side–side**: a frustum's side is the envelope of the spheres centred on its axis at σ
//!   with radius R(σ) linear in σ (a cone-sphere), so the distance of two sides is the
//!   minimum of the convex function f(σ, τ) = |c_A(σ) − c_B(τ)| − R_A(σ) − R_B(τ) over a
//!   box: the clamped segment–segment closest points (Ericson 2005, §5.1.9) for two
//!   cylinders (line–line distance minus the radii), projected Newton from there for cones.
//!   Valid when both parameters are inside their pieces.
//! * **edge circle–side**: the signed distance of the circle's point at angle θ from the
//!   side (in the side's meridian plane, (ρ − r(z)) cos α) is minimised over θ (sampled,
//!   then safeguarded Newton); valid when the foot lies on the side and the normal is in the
//!   circle's normal cone.
//! * **edge circle–edge circle**: the distance from a point of one circle to the other
//!   circle is closed form, minimised over the first circle's angle; the normal is the
//!   cross product of the two tangents (edge–edge), so the distance is signed through zero.
//! * **face–edge circle**: the circle's deepest point along the face normal, valid when it
//!   projects onto the face and the normal is in the circle's cone.
//!
//! Lengths in m. Round-off of the solution is ~1e-15 m on centimetre bodies.

use nalgebra::Vector3;

use super::RevolutionShape;

type V3 = Vector3<f64>;

/// Tolerance of the normal-cone tests, rad.
pub const CONE_TOLERANCE: f64 = 1e-9;

/// A body of revolution placed in the world: centre of mass, unit axis (body z) and the
/// body x and y axes, world frame.
#[derive(Debug, Clone, Copy)]
pub struct Placed<'a> {
    /// The shape.
    pub shape: &'a RevolutionShape,
    /// Centre of mass (body origin), m.
    pub origin: V3,
    /// Body z (the axis), unit.
    pub axis: V3,
    /// Body x, unit.
    pub x: V3,
    /// Body y, unit.
    pub y: V3,
}

impl Placed<'_> {
    /// The point of the axis at body height `z`, m.
    #[inline]
    pub fn at(&self, z: f64) -> V3 {
        self.origin + self.axis * z
    }

    /// Height along the axis and unit radial direction of the world point `p` (any unit
    /// direction normal to the axis when `p` is on it), and its distance from the axis.
    #[inline]
    pub fn meridian(&self, p: &V3) -> (f64, V3, f64) {
        let q = p - self.origin;
        let z = q.dot(&self.axis);
        let radial = q - self.axis * z;
        let rho = radial.norm();
        if rho > 1e-300 {
            (z, radial / rho, rho)
        } else {
            (z, self.x, 0.0)
        }
    }
}

/// Which feature of a body touches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Feature {
    /// The side of piece i.
    Side(usize),
    /// Edge circle k.
    Edge(usize),
    /// Flat face f.
    Face(usize),
}

impl Feature {
    /// A key for friction histories: side i → i, edge k → 256 + k, face f → 512 + f.
    pub fn key(self) -> u64 {
        match self {
            Feature::Side(i) => i as u64,
            Feature::Edge(k) => 256 + k as u64,
            Feature::Face(f) => 512 + f as u64,
        }
    }
}

/// The closest features of two pieces (A first, B second).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeaturePair {
    /// Signed distance, m: positive apart, minus the penetration depth in overlap.
    pub distance: f64,
    /// Unit normal from A to B.
    pub normal: V3,
    /// Closest point on A, m.
    pub point_a: V3,
    /// Closest point on B, m.
    pub point_b: V3,
    /// Feature of A.
    pub feature_a: Feature,
    /// Feature of B.
    pub feature_b: Feature,
}

impl FeaturePair {
    /// The same contact seen from B.
    pub fn reversed(self) -> Self {
        Self {
            distance: self.distance,
            normal: -self.normal,
            point_a: self.point_b,
            point_b: self.point_a,
            feature_a: self.feature_b,
            feature_b: self.feature_a,
        }
    }
}

/// Closest-point parameters (s, t) ∈ [0, 1]² of the segments p0 + s d1 and q0 + t d2, and
/// whether each lies strictly inside (Ericson 2005, §5.1.9).
pub fn segment_parameters(p0: &V3, d1: &V3, q0: &V3, d2: &V3) -> (f64, f64, bool) {
    let r = p0 - q0;
    let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    let (c, b) = (d1.dot(&r), d1.dot(d2));
    let denom = a * e - b * b;
    let tiny = 1e-30;
    if a <= tiny || e <= tiny {
        let s = if a <= tiny {
            0.0
        } else {
            (-c / a).clamp(0.0, 1.0)
        };
        let t = if e <= tiny {
            0.0
        } else {
            (f / e).clamp(0.0, 1.0)
        };
        return (s, t, false);
    }
    let raw_s = if denom > 1e-14 * a * e {
        (b * f - c * e) / denom
    } else {
        0.0
    };
    let mut s = raw_s.clamp(0.0, 1.0);
    let mut interior = raw_s > 0.0 && raw_s < 1.0 && denom > 1e-14 * a * e;
    let mut t = (b * s + f) / e;
    if t <= 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
        interior = false;
    } else if t >= 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
        interior = false;
    }
    (s, t, interior)
}

/// A cone-sphere: spheres centred at `origin + σ axis` for σ ∈ [s0, s1] with radius
/// r0 + k (σ − s0), m. A frustum's side is the envelope of its cone-sphere (a wall edge is
/// one with radius 0).
#[derive(Debug, Clone, Copy)]
pub struct Sweep {
    /// The point σ = 0 of the axis, m.
    pub origin: V3,
    /// Unit axis.
    pub axis: V3,
    /// Range of σ, m.
    pub s: [f64; 2],
    /// Radius at σ = s0, m.
    pub r0: f64,
    /// dR/dσ.
    pub k: f64,
}

impl Sweep {
    /// The cone-sphere of piece `i` of `x`: a side point at height z (radius r(z)) is
    /// tangent to the sphere centred at σ = z + slope · r(z) with radius r(z)/cos α.
    pub fn of_piece(x: &Placed, i: usize) -> Self {
        let f = &x.shape.frustums[i];
        let k = f.slope;
        Self {
            origin: x.origin,
            axis: x.axis,
            s: [f.z[0] + k * f.r[0], f.z[1] + k * f.r[1]],
            r0: f.r[0] / f.cos,
            k: k * f.cos,
        }
    }

    /// Radius at σ, m.
    #[inline]
    pub fn radius(&self, sigma: f64) -> f64 {
        self.r0 + self.k * (sigma - self.s[0])
    }
}

/// The minimiser (σ, τ) of f = |c_A(σ) − c_B(τ)| − R_A(σ) − R_B(τ) over the box when it
/// lies strictly inside it (else `None`): closed form for two constant radii, projected
/// Newton on the convex f otherwise.
pub fn sweep_closest(a: &Sweep, b: &Sweep) -> Option<(f64, f64)> {
    let [sa0, sa1] = a.s;
    let [sb0, sb1] = b.s;
    let w = a.origin - b.origin;
    let (ua, ub) = (a.axis, b.axis);
    let p0 = a.origin + ua * sa0;
    let q0 = b.origin + ub * sb0;
    let (s, t, interior) = segment_parameters(&p0, &(ua * (sa1 - sa0)), &q0, &(ub * (sb1 - sb0)));
    let mut sigma = sa0 + s * (sa1 - sa0);
    let mut tau = sb0 + t * (sb1 - sb0);
    if a.k == 0.0 && b.k == 0.0 {
        return interior.then_some((sigma, tau));
    }
    let (ka, kb) = (a.k, b.k);
    let f_of =
        |sg: f64, ta: f64| -> f64 { (w + ua * sg - ub * ta).norm() - a.radius(sg) - b.radius(ta) };
    let scale = (sa1 - sa0).max(sb1 - sb0);
    for _ in 0..40 {
        let d = w + ua * sigma - ub * tau;
        let length = d.norm();
        if length < 1e-15 {
            return None;
        }
        let u = d / length;
        let (da, db, ab) = (u.dot(&ua), u.dot(&ub), ua.dot(&ub));
        let g = [da - ka, -db - kb];
        let h11 = (1.0 - da * da) / length;
        let h22 = (1.0 - db * db) / length;
        let h12 = -(ab - da * db) / length;
        let reg = 1e-12 * (h11 + h22) + 1e-300;
        let free0 = !((sigma <= sa0 && g[0] > 0.0) || (sigma >= sa1 && g[0] < 0.0));
        let free1 = !((tau <= sb0 && g[1] > 0.0) || (tau >= sb1 && g[1] < 0.0));
        let step = match (free0, free1) {
            (true, true) => {
                let (m11, m22) = (h11 + reg, h22 + reg);
                let det = m11 * m22 - h12 * h12;
                [
                    -(m22 * g[0] - h12 * g[1]) / det,
                    -(m11 * g[1] - h12 * g[0]) / det,
                ]
            }
            (true, false) => [-g[0] / (h11 + reg), 0.0],
            (false, true) => [0.0, -g[1] / (h22 + reg)],
            (false, false) => break,
        };
        let f0 = f_of(sigma, tau);
        let mut lambda = 1.0;
        let (mut s1, mut t1);
        loop {
            s1 = (sigma + lambda * step[0]).clamp(sa0, sa1);
            t1 = (tau + lambda * step[1]).clamp(sb0, sb1);
            if f_of(s1, t1) <= f0 || lambda < 1e-8 {
                break;
            }
            lambda *= 0.5;
        }
        let moved = (s1 - sigma).abs().max((t1 - tau).abs());
        sigma = s1;
        tau = t1;
        if moved <= 1e-15 * scale {
            break;
        }
    }
    (sigma > sa0 && sigma < sa1 && tau > sb0 && tau < sb1).then_some((sigma, tau))
}

/// Side of piece `i` of A against side of piece `j` of B: the valid interior solution, or
/// `None`.
pub fn side_side(a: &Placed, i: usize, b: &Placed, j: usize) -> Option<FeaturePair> {
    let (sa, sb) = (Sweep::of_piece(a, i), Sweep::of_piece(b, j));
    let (sigma, tau) = sweep_closest(&sa, &sb)?;
    let (ca, cb) = (a.origin + a.axis * sigma, b.origin + b.axis * tau);
    let d = ca - cb;
    let length = d.norm();
    if length < 1e-15 {
        return None;
    }
    let u = d / length;
    let (ra, rb) = (sa.radius(sigma), sb.radius(tau));
    Some(FeaturePair {
        distance: length - ra - rb,
        normal: -u,
        point_a: ca - u * ra,
        point_b: cb + u * rb,
        feature_a: Feature::Side(i),
        feature_b: Feature::Side(j),
    })
}

/// A direction in a circle's plane as (cos θ, sin θ): the circle searches move along the
/// circle by rotating unit vectors, with no trigonometric function.
pub type Turn = (f64, f64);

#[inline]
fn cross2(a: Turn, b: Turn) -> f64 {
    a.0 * b.1 - a.1 * b.0
}

/// `u` turned by atan(t).
#[inline]
fn rotate(u: Turn, t: f64) -> Turn {
    let n = (1.0 + t * t).sqrt();
    ((u.0 - u.1 * t) / n, (u.1 + u.0 * t) / n)
}

/// The eight sample directions of a circle search, 45° apart.
const SAMPLES: [Turn; 8] = {
    let r = std::f64::consts::FRAC_1_SQRT_2;
    [
        (1.0, 0.0),
        (r, r),
        (0.0, 1.0),
        (-r, r),
        (-1.0, 0.0),
        (-r, -r),
        (0.0, -1.0),
        (r, -r),
    ]
};

/// Minimum over the circle of a smooth function of the direction u = (cos θ, sin θ), given
/// with its first two derivatives in θ: from `start` when given (a guess close to the
/// minimum), else from the best of eight samples, by Newton steps safeguarded by bisection
/// on the derivative within ±45°; a search from a guess that ends on that bracket's edge is
/// redone from the samples. Returns (u, value).
pub fn circle_minimum(start: Option<Turn>, f: impl Fn(f64, f64) -> (f64, f64, f64)) -> (Turn, f64) {
    let sampled = || {
        let mut best = (SAMPLES[0], f64::INFINITY);
        for u in SAMPLES {
            let v = f(u.0, u.1).0;
            if v < best.1 {
                best = (u, v);
            }
        }
        best.0
    };
    let refine = |begin: Turn| -> (Turn, bool) {
        let (mut lo, mut hi) = (rotate(begin, -1.0), rotate(begin, 1.0));
        let mut u = begin;
        for _ in 0..60 {
            let (_, d1, d2) = f(u.0, u.1);
            // the bracket keeps the minimum: f' < 0 before it, > 0 after it
            if d1 > 0.0 {
                hi = u;
            } else if d1 < 0.0 {
                lo = u;
            } else {
                break;
            }
            let inside = |w: Turn| cross2(lo, w) > 0.0 && cross2(w, hi) > 0.0;
            let newton = if d2 > 0.0 {
                Some(rotate(u, -d1 / d2))
            } else {
                None
            };
            let next = match newton {
                Some(w) if inside(w) => w,
                _ => {
                    let (c, s) = (lo.0 + hi.0, lo.1 + hi.1);
                    let n = c.hypot(s);
                    (c / n, s / n)
                }
            };
            let moved = cross2(u, next).abs();
            u = next;
            if moved <= 1e-15 || cross2(lo, hi) <= 1e-15 {
                break;
            }
        }
        let edge = |w: Turn| cross2(w, u).abs() <= 1e-12 && w.0 * u.0 + w.1 * u.1 > 0.0;
        let on_edge = edge(rotate(begin, -1.0)) || edge(rotate(begin, 1.0));
        (u, on_edge)
    };
    let u = match start {
        Some(guess) => match refine(guess) {
            (u, false) => u,
            _ => refine(sampled()).0,
        },
        None => refine(sampled()).0,
    };
    (u, f(u.0, u.1).0)
}

/// A point of edge circle `k` of `x` in the direction u = (cos θ, sin θ) (from body x
/// towards body y), its centre and the derivative of the point in θ.
#[inline]
pub(crate) fn circle_point(x: &Placed, k: usize, u: Turn) -> (V3, V3, V3) {
    let c = &x.shape.circles[k];
    let centre = x.at(c.z);
    (
        centre + (x.x * u.0 + x.y * u.1) * c.r,
        centre,
        (x.y * u.0 - x.x * u.1) * c.r,
    )
}

/// The direction in the plane of circle `k` of `x` towards the world point `target`, when
/// the circle's axis is within 18° of `axis` (the other piece's) and the target lies off
/// the middle of the disc: a guess for the circle searches of nearly parallel bodies (where
/// the closest point faces the other axis), else `None` (sample).
#[inline]
fn facing(x: &Placed, k: usize, axis: &V3, target: &V3) -> Option<Turn> {
    if x.axis.dot(axis).abs() < 0.95 {
        return None;
    }
    let w = target - x.at(x.shape.circles[k].z);
    let (c, s) = (w.dot(&x.x), w.dot(&x.y));
    let n = c.hypot(s);
    (n > 0.5 * x.shape.circles[k].r).then(|| (c / n, s / n))
}

/// Whether the world direction `n` (pointing out of body `x` at its point `p`) lies in the
/// normal cone of edge circle `k`.
#[inline]
pub(crate) fn in_cone(x: &Placed, k: usize, p: &V3, n: &V3) -> bool {
    let (_, radial, _) = x.meridian(p);
    x.shape.circles[k].cone_holds(n.dot(&x.axis), n.dot(&radial), CONE_TOLERANCE)
}

/// Edge circle `k` of X against the side of piece `j` of Y, oriented X → Y; `None` unless
/// valid.
pub fn circle_side(x: &Placed, k: usize, y: &Placed, j: usize) -> Option<FeaturePair> {
    let circle = x.shape.circles[k];
    let piece = y.shape.frustums[j];
    let centre = x.at(circle.z);
    let q0 = centre - y.origin;
    let b = y.axis;
    let rho = circle.r;
    let (z0, zc, zs) = (b.dot(&q0), rho * b.dot(&x.x), rho * b.dot(&x.y));
    let n0 = q0.norm_squared() + rho * rho;
    let (nc, ns) = (2.0 * rho * q0.dot(&x.x), 2.0 * rho * q0.dot(&x.y));
    let (k_slope, cos) = (piece.slope, piece.cos);
    let offset = piece.r[0] - k_slope * piece.z[0];
    let eval = |c: f64, s: f64| -> (f64, f64, f64) {
        let z = z0 + zc * c + zs * s;
        let dz = -zc * s + zs * c;
        let ddz = -(z - z0);
        let n = n0 + nc * c + ns * s;
        let dn = -nc * s + ns * c;
        let ddn = -(n - n0);
        let q = (n - z * z).max(1e-300);
        let dq = dn - 2.0 * z * dz;
        let ddq = ddn - 2.0 * (dz * dz + z * ddz);
        let r = q.sqrt();
        let dr = dq / (2.0 * r);
        let ddr = (ddq - 2.0 * dr * dr) / (2.0 * r);
        (
            cos * (r - k_slope * z - offset),
            cos * (dr - k_slope * dz),
            cos * (ddr - k_slope * ddz),
        )
    };
    let towards = y.origin + b * (centre - y.origin).dot(&b);
    let (u, distance) = circle_minimum(facing(x, k, &b, &towards), eval);
    let (p, _, _) = circle_point(x, k, u);
    let (zp, radial, rho_y) = y.meridian(&p);
    if rho_y <= 1e-15 {
        return None;
    }
    let outward = (radial - b * k_slope) * cos;
    let foot_z = zp + distance * k_slope * cos;
    if !(foot_z > piece.z[0] && foot_z < piece.z[1]) {
        return None;
    }
    let normal = -outward;
    if !in_cone(x, k, &p, &normal) {
        return None;
    }
    Some(FeaturePair {
        distance,
        normal,
        point_a: p,
        point_b: p - outward * distance,
        feature_a: Feature::Edge(k),
        feature_b: Feature::Side(j),
    })
}

/// The normal of two edges (unit tangents, up to sign) whose closest points are `gap`
/// apart: along the gap where it is long enough to have a direction (the distance is then a
/// true point-to-point distance), else the cross product of the tangents (edges crossing);
/// the sign is left to the caller. `size` sets the scale of "long enough", m.
pub(crate) fn edge_normal(tangent_a: &V3, tangent_b: &V3, gap: &V3, size: f64) -> Option<V3> {
    let length = gap.norm();
    if length > 1e-12 * size {
        return Some(gap / length);
    }
    let cross = tangent_a.cross(tangent_b);
    let c = cross.norm();
    (c > 1e-9 * tangent_a.norm() * tangent_b.norm()).then(|| cross / c)
}

/// Edge circle `k` of A against edge circle `l` of B; `None` unless valid.
pub fn circle_circle(a: &Placed, k: usize, b: &Placed, l: usize) -> Option<FeaturePair> {
    let (ca, cb) = (a.shape.circles[k], b.shape.circles[l]);
    let (centre_a, centre_b) = (a.at(ca.z), b.at(cb.z));
    let q0 = centre_a - centre_b;
    let eb = b.axis;
    let r1 = ca.r;
    let r2 = cb.r;
    let (a0, ac, as_) = (
        q0.norm_squared() + r1 * r1,
        2.0 * r1 * q0.dot(&a.x),
        2.0 * r1 * q0.dot(&a.y),
    );
    let (b0, bc, bs) = (eb.dot(&q0), r1 * eb.dot(&a.x), r1 * eb.dot(&a.y));
    let eval = |c: f64, s: f64| -> (f64, f64, f64) {
        let av = a0 + ac * c + as_ * s;
        let da = -ac * s + as_ * c;
        let dda = -(av - a0);
        let bv = b0 + bc * c + bs * s;
        let db = -bc * s + bs * c;
        let ddb = -(bv - b0);
        let p1 = da - 2.0 * bv * db;
        let p2 = dda - 2.0 * (db * db + bv * ddb);
        let rho = (av - bv * bv).max(1e-300).sqrt();
        let drho = p1 / (2.0 * rho);
        let ddrho = (p2 - 2.0 * drho * drho) / (2.0 * rho);
        (
            av - 2.0 * r2 * rho + r2 * r2,
            da - 2.0 * r2 * drho,
            dda - 2.0 * r2 * ddrho,
        )
    };
    let (u, _) = circle_minimum(facing(a, k, &eb, &centre_b), eval);
    let (p, _, tangent_a) = circle_point(a, k, u);
    let (_, radial_b, rho) = b.meridian(&p);
    if rho <= 1e-15 {
        return None;
    }
    let q = b.at(cb.z) + radial_b * r2;
    let tangent_b = eb.cross(&radial_b);
    let gap = q - p;
    let normal = edge_normal(&tangent_a, &tangent_b, &gap, r1)?;
    let (_, radial_a, _) = a.meridian(&p);
    let (mz, mr) = ca.cone_middle();
    let normal = if normal.dot(&(a.axis * mz + radial_a * mr)) < 0.0 {
        -normal
    } else {
        normal
    };
    if !in_cone(a, k, &p, &normal) || !in_cone(b, l, &q, &(-normal)) {
        return None;
    }
    Some(FeaturePair {
        distance: gap.dot(&normal),
        normal,
        point_a: p,
        point_b: q,
        feature_a: Feature::Edge(k),
        feature_b: Feature::Edge(l),
    })
}

/// Flat face `f` of X against edge circle `l` of Y, oriented X → Y; `None` unless valid.
pub fn face_circle(x: &Placed, f: usize, y: &Placed, l: usize) -> Option<FeaturePair> {
    let face = x.shape.faces[f];
    let circle = y.shape.circles[l];
    let m = x.axis * face.facing;
    let face_centre = x.at(face.z);
    let in_plane = m - y.axis * m.dot(&y.axis);
    let length = in_plane.norm();
    let direction = if length > 1e-12 {
        in_plane / length
    } else {
        y.x
    };
    let p = y.at(circle.z) - direction * circle.r;
    let distance = m.dot(&(p - face_centre));
    let (_, _, rho) = x.meridian(&p);
    if !(rho >= face.r[0] && rho <= face.r[1]) {
        return None;
    }
    if !in_cone(y, l, &p, &(-m)) {
        return None;
    }
    Some(FeaturePair {
        distance,
        normal: m,
        point_a: p - m * distance,
        point_b: p,
        feature_a: Feature::Face(f),
        feature_b: Feature::Edge(l),
    })
}

/// Whether the world point `p` lies in the solid piece `i` of `x`, up to a round-off margin
/// of 1e-6 of the piece's radius.
pub fn inside_piece(x: &Placed, i: usize, p: &V3) -> bool {
    let f = &x.shape.frustums[i];
    let tolerance = 1e-6 * f.reach;
    let (z, _, rho) = x.meridian(p);
    z >= f.z[0] - tolerance
        && z <= f.z[1] + tolerance
        && rho <= f.radius_at(z.clamp(f.z[0], f.z[1])) + tolerance
}

/// Distance from `p` to the axis segment of piece `i` of `x`, m.
#[inline]
fn distance_to_piece_axis(x: &Placed, i: usize, p: &V3) -> f64 {
    let f = &x.shape.frustums[i];
    let z = (p - x.origin).dot(&x.axis).clamp(f.z[0], f.z[1]);
    (p - x.at(z)).norm()
}

/// The closest features of piece `i` of A and piece `j` of B when they overlap: the valid
/// candidate with the largest signed distance; `None` when none is valid (apart pieces may
/// return `None`: candidates that cannot overlap are skipped).
pub fn piece_pair(a: &Placed, i: usize, b: &Placed, j: usize) -> Option<FeaturePair> {
    piece_pair_within(a, i, b, j, 0.0)
}

/// As [`piece_pair`], with every candidate that can come within `margin` (m) solved: the
/// closest features of apart pieces too, for `margin` above their distance.
pub fn piece_pair_within(
    a: &Placed,
    i: usize,
    b: &Placed,
    j: usize,
    margin: f64,
) -> Option<FeaturePair> {
    piece_pair_cached(a, i, b, j, margin, &mut CandidateCache::default())
}

/// Candidate feature pairs already solved for one pair of bodies (an edge circle belongs to
/// two pieces, a flat step's face too: their candidates are solved once per body pair).
#[derive(Debug, Default, Clone)]
pub struct CandidateCache {
    solved: Vec<(Feature, Feature, Option<FeaturePair>)>,
}

impl CandidateCache {
    /// Forget the solutions (for a new pair of bodies or a new configuration).
    pub fn clear(&mut self) {
        self.solved.clear();
    }

    fn solve(
        &mut self,
        fa: Feature,
        fb: Feature,
        compute: impl FnOnce() -> Option<FeaturePair>,
    ) -> Option<FeaturePair> {
        if let Some(e) = self.solved.iter().find(|e| e.0 == fa && e.1 == fb) {
            return e.2;
        }
        let found = compute();
        self.solved.push((fa, fb, found));
        found
    }
}

/// As [`piece_pair_within`], reusing the solutions of `cache` (same bodies, same poses).
pub fn piece_pair_cached(
    a: &Placed,
    i: usize,
    b: &Placed,
    j: usize,
    margin: f64,
    cache: &mut CandidateCache,
) -> Option<FeaturePair> {
    if let Some(found) = side_side(a, i, b, j) {
        if found.distance >= 0.0
            || (inside_piece(b, j, &found.point_a) && inside_piece(a, i, &found.point_b))
        {
            return Some(found);
        }
    }
    let (fa, fb) = (a.shape.frustums[i], b.shape.frustums[j]);
    let mut best: Option<FeaturePair> = None;
    // in contact mode (margin 0) the first valid overlap ends the search: between shallowly
    // overlapping convex pieces one feature pair is valid (two only where a contact passes
    // from one to the next, at the same point)
    let settled =
        |best: &Option<FeaturePair>| margin <= 0.0 && best.is_some_and(|b| b.distance < 0.0);
    let consider = |c: Option<FeaturePair>, best: &mut Option<FeaturePair>| {
        if let Some(c) = c {
            // an overlap is real only where each closest point lies in the other piece (a
            // face's half-space or an edge's cone alone would accept points far beyond it)
            let real = c.distance >= 0.0
                || (inside_piece(b, j, &c.point_a) && inside_piece(a, i, &c.point_b));
            if real && best.is_none_or(|b| c.distance > b.distance) {
                *best = Some(c);
            }
        }
    };
    let convex_a = |k: &usize| a.shape.circles[*k].convex;
    let convex_b = |l: &usize| b.shape.circles[*l].convex;
    use Feature::{Edge, Face, Side};
    for &k in fa.circles.iter().filter(|k| convex_a(k)) {
        let c = a.shape.circles[k];
        if !settled(&best) && distance_to_piece_axis(b, j, &a.at(c.z)) < c.r + fb.reach + margin {
            consider(
                cache.solve(Edge(k), Side(j), || circle_side(a, k, b, j)),
                &mut best,
            );
        }
    }
    for &l in fb.circles.iter().filter(|l| convex_b(l)) {
        let c = b.shape.circles[l];
        if !settled(&best) && distance_to_piece_axis(a, i, &b.at(c.z)) < c.r + fa.reach + margin {
            let found = cache.solve(Side(i), Edge(l), || {
                circle_side(b, l, a, i).map(FeaturePair::reversed)
            });
            consider(found, &mut best);
        }
    }
    for &k in fa.circles.iter().filter(|k| convex_a(k)) {
        for &l in fb.circles.iter().filter(|l| convex_b(l)) {
            let (ck, cl) = (a.shape.circles[k], b.shape.circles[l]);
            if !settled(&best) && (a.at(ck.z) - b.at(cl.z)).norm() < ck.r + cl.r + margin {
                consider(
                    cache.solve(Edge(k), Edge(l), || circle_circle(a, k, b, l)),
                    &mut best,
                );
            }
        }
    }
    for &f in fa.faces.iter().flatten() {
        for &l in fb.circles.iter().filter(|l| convex_b(l)) {
            if !settled(&best) {
                consider(
                    cache.solve(Face(f), Edge(l), || face_circle(a, f, b, l)),
                    &mut best,
                );
            }
        }
    }
    for &f in fb.faces.iter().flatten() {
        for &k in fa.circles.iter().filter(|k| convex_a(k)) {
            if !settled(&best) {
                let found = cache.solve(Edge(k), Face(f), || {
                    face_circle(b, f, a, k).map(FeaturePair::reversed)
                });
                consider(found, &mut best);
            }
        }
    }
    best
}
