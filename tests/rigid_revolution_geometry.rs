//! The fast exact cartridge (`rigid::revolution`) against parry3d-f64 on random poses:
//! distance, normal and closest points between two bodies, against planes and beads.
//!
//! Where parry's shapes are exact: its `Cylinder` is, so two plain tubes (side, rims and caps
//! of a cylinder) are compared with parry's GJK (apart) and EPA (overlapping) on the true
//! cylinders; the cones of the cartridge with GJK on exact support maps of the frustums (the
//! convex hull of two circles, written here). parry's own compound of the cartridge
//! approximates each cone by a 32-gon hull: its deviation is measured and printed.
//!
//! parry's iterations are not exact to 1e-9 m on curved shapes: GJK creeps towards the
//! closest points of two circles (edge against edge) and stops up to ~1e-7 m above the
//! distance; EPA's polytope stays inside the Minkowski difference. Each analytic answer is
//! therefore also certified on its own, with exact support functions h(n) of the pieces:
//! apart, its two closest points are on the surfaces (an upper bound on the distance) and the
//! separation of the supports along its normal, −h_A(n) − h_B(−n), is a lower bound — the two
//! agree to 1e-12 m; overlapping, its depth equals the overlap of the supports along its
//! normal (an upper bound on the minimum translation distance) and is never more than 1e-9 m
//! above parry's EPA depth.

use demfem::rigid::revolution::contacts::{bead_contact, plane_contacts};
use demfem::rigid::revolution::features::{piece_pair_within, FeaturePair, Placed};
use demfem::rigid::{RevolutionProfile, RevolutionShape};
use nalgebra::{UnitQuaternion, Vector3};
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::query::contact::contact_support_map_support_map;
use parry3d_f64::shape::{Ball, Cylinder, SupportMap};

type V3 = Vector3<f64>;

/// A small deterministic generator (64-bit LCG), uniform in [0, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A uniformly random rotation (Shoemake 1992).
    fn rotation(&mut self) -> UnitQuaternion<f64> {
        let (u1, u2, u3) = (self.next(), self.next(), self.next());
        let tau = 2.0 * std::f64::consts::PI;
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            b * (tau * u3).cos(),
            a * (tau * u2).sin(),
            a * (tau * u2).cos(),
            b * (tau * u3).sin(),
        ))
    }

    fn in_ball(&mut self, radius: f64) -> V3 {
        loop {
            let v = V3::new(self.next(), self.next(), self.next()) * 2.0 - V3::repeat(1.0);
            if v.norm() <= 1.0 {
                return v * radius;
            }
        }
    }
}

fn to_parry(v: &V3) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

fn from_parry(v: Vector) -> V3 {
    V3::new(v.x, v.y, v.z)
}

fn pose_of(x: &V3, q: &UnitQuaternion<f64>) -> Pose {
    let c = q.coords;
    Pose::from_parts(to_parry(x), Rotation::from_xyzw(c[0], c[1], c[2], c[3]))
}

fn placed<'a>(shape: &'a RevolutionShape, x: &V3, q: &UnitQuaternion<f64>) -> Placed<'a> {
    Placed {
        shape,
        origin: *x,
        axis: q * V3::z(),
        x: q * V3::x(),
        y: q * V3::y(),
    }
}

/// The solid frustum between (z0, r0) and (z1, r1) about local z: the convex hull of its
/// two circles, as an exact support map.
struct FrustumSupport {
    z: [f64; 2],
    r: [f64; 2],
}

impl SupportMap for FrustumSupport {
    fn local_support_point(&self, dir: Vector) -> Vector {
        let radial = Vector::new(dir.x, dir.y, 0.0);
        let length = radial.length();
        let unit = if length > 0.0 {
            radial / length
        } else {
            Vector::X
        };
        let candidate = |k: usize| unit * self.r[k] + Vector::new(0.0, 0.0, self.z[k]);
        let (a, b) = (candidate(0), candidate(1));
        if a.dot(dir) >= b.dot(dir) {
            a
        } else {
            b
        }
    }
}

/// A tube (one cylinder piece with solid caps) centred on its centre of mass.
fn tube(radius: f64, length: f64) -> RevolutionShape {
    let profile = RevolutionProfile::new(
        vec![0.0, length],
        vec![0.5 * radius, 0.5 * radius],
        vec![radius, radius],
    )
    .unwrap();
    RevolutionShape::from_profile(&profile, 0.5 * length).unwrap()
}

fn cartridge() -> RevolutionShape {
    let profile = RevolutionProfile::default_cartridge();
    let com = profile.mass_properties(2230.0).unwrap().center_of_mass.z;
    RevolutionShape::from_profile(&profile, com).unwrap()
}

/// Exact support value max over piece `i` of x of n·p (the convex hull of its two circles).
fn support(x: &Placed, i: usize, n: &V3) -> f64 {
    let f = &x.shape.frustums[i];
    let radial = (n - x.axis * n.dot(&x.axis)).norm();
    (0..2)
        .map(|k| n.dot(&x.at(f.z[k])) + f.r[k] * radial)
        .fold(f64::NEG_INFINITY, f64::max)
}

/// Exact support point of piece `i` of x in the direction n.
fn support_point(x: &Placed, i: usize, n: &V3) -> V3 {
    let f = &x.shape.frustums[i];
    let radial = n - x.axis * n.dot(&x.axis);
    let length = radial.norm();
    let unit = if length > 0.0 { radial / length } else { x.x };
    let at = |k: usize| x.at(f.z[k]) + unit * f.r[k];
    if n.dot(&at(0)) >= n.dot(&at(1)) {
        at(0)
    } else {
        at(1)
    }
}

/// The best support separation of two pieces found from `start` by moving the direction to
/// the one between the current support points (the dual of the distance problem), m.
fn best_separation(a: &Placed, i: usize, b: &Placed, j: usize, start: &V3) -> f64 {
    let mut n = start.normalize();
    let mut best = separation(a, i, b, j, &n);
    for _ in 0..200 {
        let gap = support_point(b, j, &(-n)) - support_point(a, i, &n);
        if gap.norm() == 0.0 {
            break;
        }
        n = gap.normalize();
        best = best.max(separation(a, i, b, j, &n));
    }
    best
}

/// Separation of piece i of a and piece j of b along the unit n (from a to b): a lower
/// bound on their distance, minus their overlap along n.
fn separation(a: &Placed, i: usize, b: &Placed, j: usize, n: &V3) -> f64 {
    -support(b, j, &(-n)) - support(a, i, n)
}

/// Distance of a world point from the surface of a body (0 on it), m.
fn off_surface(x: &Placed, p: &V3) -> f64 {
    let (z, _, rho) = x.meridian(p);
    x.shape.meridian_distance(z, rho).0.abs()
}

/// The closest piece pair of two bodies (smallest signed distance) with its indices.
fn body_distance(a: &Placed, b: &Placed) -> Option<(FeaturePair, usize, usize)> {
    let mut best: Option<(FeaturePair, usize, usize)> = None;
    for i in 0..a.shape.frustums.len() {
        for j in 0..b.shape.frustums.len() {
            if let Some(f) = piece_pair_within(a, i, b, j, 1.0) {
                if best.is_none_or(|b| f.distance < b.0.distance) {
                    best = Some((f, i, j));
                }
            }
        }
    }
    best
}

/// Running maxima of the deviations.
#[derive(Default, Debug)]
struct Worst {
    deviations: Vec<f64>,
    distance: f64,
    normal: f64,
    point: f64,
    compared: usize,
    points_compared: usize,
    certificate: f64,
    normal_converged: f64,
    point_converged: f64,
}

impl Worst {
    fn add(&mut self, mine: &FeaturePair, distance: f64, normal: V3, pa: V3, pb: V3, points: bool) {
        self.compared += 1;
        self.deviations.push((mine.distance - distance).abs());
        self.distance = self.distance.max((mine.distance - distance).abs());
        if points {
            self.points_compared += 1;
            self.normal = self
                .normal
                .max(mine.normal.cross(&normal).norm().asin().abs());
            let angle = mine.normal.cross(&normal).norm().asin().abs();
            let point = (mine.point_a - pa).norm().max((mine.point_b - pb).norm());
            self.point = self.point.max(point);
            if (mine.distance - distance).abs() <= 1e-9 {
                self.normal_converged = self.normal_converged.max(angle);
                self.point_converged = self.point_converged.max(point);
            }
        }
    }
}

impl Worst {
    /// Median, 99th percentile and fraction within 1e-9 m of the distance deviations.
    fn spread(&self) -> String {
        let mut d = self.deviations.clone();
        d.sort_by(f64::total_cmp);
        let at = |q: f64| d[((d.len() - 1) as f64 * q) as usize];
        let within = d.iter().filter(|&&x| x <= 1e-9).count() as f64 / d.len() as f64;
        format!(
            "|Δd| median {:.2e} m, 99 % {:.2e} m, within 1e-9 m in {:.1} % of the poses (there: max normal angle {:.2e} rad, max point distance {:.2e} m)",
            at(0.5),
            at(0.99),
            100.0 * within,
            self.normal_converged,
            self.point_converged
        )
    }
}

/// Whether two random bodies' axes are far enough from parallel (and from perpendicular,
/// where caps lie flat on sides) for closest points to be unique.
fn unique_points(qa: &UnitQuaternion<f64>, qb: &UnitQuaternion<f64>) -> bool {
    let skew = (qa * V3::z()).cross(&(qb * V3::z())).norm();
    skew > 1e-2 && (1.0 - skew * skew).sqrt() > 1e-2
}

#[test]
fn tubes_match_parry_cylinders_on_random_poses() {
    let (ra, la, rb, lb) = (5.8e-3, 0.0545, 3.65e-3, 0.0127);
    let (a_shape, b_shape) = (tube(ra, la), tube(rb, lb));
    let cyl_a = Cylinder::new(0.5 * la, ra);
    let cyl_b = Cylinder::new(0.5 * lb, rb);
    let y_to_z = UnitQuaternion::from_axis_angle(&V3::x_axis(), std::f64::consts::FRAC_PI_2);
    let mut rng = Lcg(11);
    let mut worst = Worst::default();
    let (mut penetrating, mut separated, mut trials) = (0, 0, 0);
    let (mut above_parry, mut below_epa, mut epa_gap): (f64, f64, f64) = (0.0, 0.0, 0.0);
    while worst.compared < 10_000 {
        trials += 1;
        let (qa, qb) = (rng.rotation(), rng.rotation());
        let xa = rng.in_ball(0.01);
        let xb = xa + rng.in_ball(0.04);
        let (a, b) = (placed(&a_shape, &xa, &qa), placed(&b_shape, &xb, &qb));
        let Some(mine) = piece_pair_within(&a, 0, &b, 0, 1.0) else {
            continue;
        };
        if !(mine.distance > -5e-4 && mine.distance < 2e-3) {
            continue;
        }
        let frame_a = pose_of(&xa, &(qa * y_to_z));
        let frame_b = pose_of(&xb, &(qb * y_to_z));
        let Some(c) =
            contact_support_map_support_map(&frame_a.inv_mul(&frame_b), &cyl_a, &cyl_b, 1.0)
        else {
            panic!("parry found no contact at {xa:?} {xb:?}");
        };
        let pa = from_parry(frame_a * c.point1);
        let pb = from_parry(frame_b * c.point2);
        let normal = from_parry(frame_a.rotation * c.normal1);
        worst.add(&mine, c.dist, normal, pa, pb, unique_points(&qa, &qb));
        // the certificate: supports along the analytic normal
        let lower = separation(&a, 0, &b, 0, &mine.normal);
        let on_surfaces = off_surface(&a, &mine.point_a).max(off_surface(&b, &mine.point_b));
        let gap = if mine.distance >= 0.0 {
            ((mine.point_b - mine.point_a).norm() - lower).abs()
        } else {
            (mine.distance - lower).abs()
        };
        worst.certificate = worst.certificate.max(gap).max(on_surfaces);
        if gap > 1e-12 || on_surfaces > 1e-12 {
            panic!("not certified (gap {gap:e}, off surface {on_surfaces:e}) at xa {xa:?} qa {qa:?} xb {xb:?} qb {qb:?}: {mine:?}");
        }
        if c.dist < 0.0 {
            penetrating += 1;
            // our depth is the overlap along our normal; along parry's normal it must not be
            // smaller (else ours would not be the minimum translation distance)
            let along_parry = -separation(&a, 0, &b, 0, &normal);
            below_epa = below_epa.max(-mine.distance - along_parry);
            epa_gap = epa_gap.max((c.dist - mine.distance).abs());
        } else {
            separated += 1;
            // GJK's distance is that of two surface points: an upper bound
            above_parry = above_parry.max(mine.distance - c.dist);
        }
    }
    println!(
        "tube–tube, {} poses ({penetrating} overlapping, {separated} apart, {trials} drawn): certified to {:.3e} m; max |Δd| against parry {:.3e} m (|Δ depth| against EPA {epa_gap:.3e} m; ours above GJK by at most {above_parry:.3e} m, our depth above the overlap along EPA's normal by at most {below_epa:.3e} m); with unique closest points ({}): max normal angle {:.3e} rad, max point distance {:.3e} m; {}",
        worst.compared, worst.certificate, worst.distance, worst.points_compared, worst.normal, worst.point, worst.spread()
    );
    assert!(
        above_parry <= 1e-12,
        "above GJK's upper bound by {above_parry:e}"
    );
    assert!(
        below_epa <= 1e-12,
        "depth above the overlap along EPA's normal by {below_epa:e}"
    );
    assert!(worst.certificate <= 1e-12);
}

#[test]
fn cartridges_apart_match_exact_frustums_on_random_poses() {
    let shape = cartridge();
    let supports: Vec<FrustumSupport> = shape
        .frustums
        .iter()
        .map(|f| FrustumSupport { z: f.z, r: f.r })
        .collect();
    // every piece alone, in the body frame of the cartridge, caps included
    let pieces: Vec<RevolutionShape> = shape
        .frustums
        .iter()
        .map(|f| {
            let p = RevolutionProfile::new(f.z.to_vec(), vec![0.0; 2], f.r.to_vec()).unwrap();
            RevolutionShape::from_profile(&p, 0.0).unwrap()
        })
        .collect();
    let mut rng = Lcg(23);
    let mut worst = Worst::default();
    let (mut trials, mut above_parry) = (0, 0.0_f64);
    let n = shape.frustums.len();
    while worst.compared < 10_000 {
        trials += 1;
        let (qa, qb) = (rng.rotation(), rng.rotation());
        let xa = rng.in_ball(0.01);
        let xb = xa + rng.in_ball(0.07);
        let (a, b) = (placed(&shape, &xa, &qa), placed(&shape, &xb, &qb));
        let Some((mine, _, _)) = body_distance(&a, &b) else {
            continue;
        };
        if !(mine.distance > 1e-6 && mine.distance < 3e-3) {
            continue;
        }
        let (fa, fb) = (pose_of(&xa, &qa), pose_of(&xb, &qb));
        let pos12 = fa.inv_mul(&fb);
        let mut reference: Option<(f64, V3, V3, V3)> = None;
        // lower bound of the bodies' distance: the smallest over piece pairs of the best
        // support separation along the analytic and parry's normals
        let mut lower = f64::INFINITY;
        let mut overlapping = false;
        for i in 0..n {
            for j in 0..n {
                let mut bound = f64::NEG_INFINITY;
                if let Some(c) =
                    contact_support_map_support_map(&pos12, &supports[i], &supports[j], 1.0)
                {
                    let normal = from_parry(fa.rotation * c.normal1);
                    if c.dist <= 0.0 {
                        overlapping = true;
                    }
                    bound = bound.max(best_separation(&a, i, &b, j, &normal));
                    if reference.is_none_or(|r| c.dist < r.0) {
                        reference = Some((
                            c.dist,
                            normal,
                            from_parry(fa * c.point1),
                            from_parry(fb * c.point2),
                        ));
                    }
                }
                if let Some(f) = piece_pair_within(&a, i, &b, j, 1.0) {
                    bound = bound.max(separation(&a, i, &b, j, &f.normal));
                }
                // the solid pieces (internal caps included) as stand-alone frusta
                let (pi, pj) = (&pieces[i], &pieces[j]);
                let (si, sj) = (placed(pi, &xa, &qa), placed(pj, &xb, &qb));
                if let Some(f) = piece_pair_within(&si, 0, &sj, 0, 1.0) {
                    bound = bound.max(separation(&a, i, &b, j, &f.normal));
                }
                lower = lower.min(bound);
            }
        }
        if overlapping {
            // another piece pair overlaps deeply (the analytic minimum above is of others)
            continue;
        }
        let Some((d, normal, pa, pb)) = reference else {
            panic!("no reference distance");
        };
        worst.add(&mine, d, normal, pa, pb, unique_points(&qa, &qb));
        above_parry = above_parry.max(mine.distance - d);
        let on_surfaces = off_surface(&a, &mine.point_a).max(off_surface(&b, &mine.point_b));
        let upper = (mine.point_b - mine.point_a).norm();
        let gap = upper - lower;
        worst.certificate = worst.certificate.max(gap.abs()).max(on_surfaces);
        if gap > 1e-12 || on_surfaces > 1e-12 {
            panic!(
                "not certified: upper {upper:e} lower {lower:e} (parry {d:e}), off surface {on_surfaces:e} at xa {xa:?} qa {qa:?} xb {xb:?} qb {qb:?}: {mine:?}"
            );
        }
    }
    println!(
        "cartridge–cartridge apart, {} poses ({trials} drawn): certified to {:.3e} m; max |Δd| against GJK on exact frustums {:.3e} m (ours above it by at most {above_parry:.3e} m); with unique closest points ({}): max normal angle {:.3e} rad, max point distance {:.3e} m; {}",
        worst.compared, worst.certificate, worst.distance, worst.points_compared, worst.normal, worst.point, worst.spread()
    );
    assert!(above_parry <= 1e-12);
}

#[test]
fn cartridge_deviates_from_parrys_compound_by_its_polygon_cones() {
    use demfem::rigid::revolution::features::Feature;
    use demfem::rigid::ExactShape;
    let profile = RevolutionProfile::default_cartridge();
    let com = profile.mass_properties(2230.0).unwrap().center_of_mass.z;
    let shape = RevolutionShape::from_profile(&profile, com).unwrap();
    let exact = ExactShape::from_profile(&profile, com).unwrap();
    let mut rng = Lcg(5);
    let (mut worst, mut worst_cylinders, mut compared) = (0.0_f64, 0.0_f64, 0);
    while compared < 2000 {
        let (qa, qb) = (rng.rotation(), rng.rotation());
        let xa = rng.in_ball(0.01);
        let xb = xa + rng.in_ball(0.07);
        let (a, b) = (placed(&shape, &xa, &qa), placed(&shape, &xb, &qb));
        let Some((mine, i, j)) = body_distance(&a, &b) else {
            continue;
        };
        if !(mine.distance > 1e-6 && mine.distance < 3e-3) {
            continue;
        }
        let d = parry3d_f64::query::distance(
            &pose_of(&xa, &qa),
            &exact.compound,
            &pose_of(&xb, &qb),
            &exact.compound,
        )
        .unwrap()
        .distance;
        if d <= 0.0 {
            // other pieces overlap deeply: not the apart bodies this test is about
            continue;
        }
        compared += 1;
        worst = worst.max((mine.distance - d).abs());
        let sides = matches!(
            (mine.feature_a, mine.feature_b),
            (Feature::Side(_), Feature::Side(_))
        );
        if sides && shape.frustums[i].is_cylinder() && shape.frustums[j].is_cylinder() {
            worst_cylinders = worst_cylinders.max((mine.distance - d).abs());
        }
    }
    // a 32-gon inscribed in a circle of radius r falls short of it by r (1 − cos(π/32))
    let sag = 5.8e-3 * (1.0 - (std::f64::consts::PI / 32.0).cos());
    println!(
        "against parry's compound (cones as 32-gon hulls), {compared} poses apart: max |Δd| = {worst:.3e} m (a 32-gon's sag on the body radius: {sag:.3e} m); where two cylinder sides are closest: {worst_cylinders:.3e} m"
    );
    assert!(worst <= 2.0 * sag && worst_cylinders <= 1e-6);
}

#[test]
fn tube_on_a_plane_and_beads_match_parry() {
    let (r, l) = (5.8e-3, 0.0545);
    let shape = tube(r, l);
    let cyl = Cylinder::new(0.5 * l, r);
    let y_to_z = UnitQuaternion::from_axis_angle(&V3::x_axis(), std::f64::consts::FRAC_PI_2);
    let mut rng = Lcg(3);
    let (mut worst_plane, mut worst_bead, mut compared) = (0.0_f64, 0.0_f64, 0);
    let floor_normal = V3::z();
    while compared < 10_000 {
        let q = rng.rotation();
        let x = V3::new(0.0, 0.0, rng.next() * 0.03);
        let body = placed(&shape, &x, &q);
        let (mut out, mut weights) = (Vec::new(), Vec::new());
        plane_contacts(
            &V3::zeros(),
            &floor_normal,
            &body,
            None,
            &mut out,
            &mut weights,
        );
        // the deepest point of the body below z = 0: the lowest support point
        let lowest = {
            let frame = pose_of(&x, &(q * y_to_z));
            let support =
                cyl.local_support_point(frame.rotation.inverse() * Vector::new(0.0, 0.0, -1.0));
            from_parry(frame * support).z
        };
        let deepest = out.iter().map(|c| c.overlap).fold(0.0, f64::max);
        if lowest < 0.0 {
            worst_plane = worst_plane.max((deepest + lowest).abs());
        } else {
            assert!(out.is_empty());
        }
        // a bead of 2 mm near the body
        let centre = x + rng.in_ball(0.035);
        let ball = Ball::new(2e-3);
        let pos12 =
            pose_of(&centre, &UnitQuaternion::identity()).inv_mul(&pose_of(&x, &(q * y_to_z)));
        let reference = contact_support_map_support_map(&pos12, &ball, &cyl, 1.0);
        let mine = bead_contact(&centre, 2e-3, &body);
        match (reference, mine) {
            (Some(c), Some(m)) if c.dist < 0.0 => {
                worst_bead = worst_bead.max((m.overlap + c.dist).abs());
            }
            (Some(c), None) => assert!(c.dist >= -1e-12, "missed a bead overlap {}", c.dist),
            (Some(c), Some(m)) => panic!(
                "bead overlap {} where parry has distance {}",
                m.overlap, c.dist
            ),
            _ => {}
        }
        compared += 1;
    }
    println!(
        "tube on a plane, {compared} poses: max |Δδ| deepest point {worst_plane:.3e} m; bead overlaps: max |Δδ| {worst_bead:.3e} m"
    );
    assert!(worst_plane <= 1e-12 && worst_bead <= 1e-9);
}
