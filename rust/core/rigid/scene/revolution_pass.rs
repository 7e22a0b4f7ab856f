//! The contact pass of scenes with bodies of revolution ([`crate::rigid::revolution`]), and
//! the beads (one-bead spheres of mixed tables, clumps) that share a table with them.
//!
//! The same gravity, contact law, effective-mass sharing and onset log as the parry and clump
//! pass (`contacts`), organised for speed:
//!
//! * **Broad phase: a Verlet list.** Candidate body pairs are the pairs whose bounding
//!   capsules, inflated by a skin, overlap; the list is rebuilt only when some body has moved
//!   by more than half the skin since the last build (the translation of its centre plus its
//!   rotation angle times its bounding radius bounds the travel of every surface point). The
//!   pairs are kept sorted, so the order of the force sums — and therefore the result, to
//!   the bit — does not depend on when the list was rebuilt.
//! * **Friction springs in slots.** Each body–wall slot and each listed pair keeps the Mindlin
//!   springs of its contacts in one flat array (keyed by the contacts' features and looked
//!   up among the few of that slot), carried over when the list is rebuilt.
//! * **Weights.** A contact of weight w (line pairs, see `revolution::contacts`) carries w
//!   times the force and energy of its Hertz law. Its dashpot uses the mass m*/(n w) with
//!   n = Σ w over the pair's contacts, so that the pair's damping is ζ √(m*/n · Σ w k): the
//!   rule "n contacts of one pair share m*" of the module above, with weights.

use nalgebra::{UnitQuaternion, Vector3};

use super::{PreparedShape, RigidOnset, RigidScene};
use crate::contact::effective_mass;
use crate::error::{DemfemError, Result};
use crate::rigid::collision::{
    clump_clump_contacts, clump_mesh_contacts, clump_plane_contacts, clump_polygon_contacts,
    BodyPose, ClumpPairScratch, ContactPoint, Plane,
};
use crate::rigid::revolution::contacts::{bead_contact, pair_contacts, plane_contacts, PairScratch};
use crate::rigid::revolution::features::Placed;
use crate::rigid::revolution::wall_edges::polygon_edge_contacts;
use crate::rigid::shape::RigidShape;

type V3 = Vector3<f64>;

/// A Mindlin spring of one contact: (feature on the first object, feature on the second, ξ).
type Spring = (u64, u64, V3);

/// State of the pass kept between evaluations.
#[derive(Debug, Default)]
pub(crate) struct RevolutionPass {
    pairs: Vec<(u32, u32)>,
    reference: Vec<(V3, UnitQuaternion<f64>)>,
    built_for: usize,
    skin: f64,
    springs: Vec<Spring>,
    springs_next: Vec<Spring>,
    pair_range: Vec<(u32, u32)>,
    pair_touching: Vec<bool>,
    wall_range: Vec<(u32, u32)>,
    wall_touching: Vec<bool>,
    contacts: Vec<ContactPoint>,
    weights: Vec<f64>,
    pair_scratch: PairScratch,
    clump_scratch: ClumpPairScratch,
    rebuilds: u64,
    /// Each body's axis, x and y in the world for this evaluation.
    frames: Vec<[V3; 3]>,
    /// The deepest overlap of the last evaluation: (body, partner, partner is a boundary,
    /// overlap m).
    deepest: Option<(usize, usize, bool, f64)>,
}

impl RevolutionPass {
    /// Verlet-list rebuilds so far.
    pub(crate) fn rebuilds(&self) -> u64 {
        self.rebuilds
    }
}

fn placed<'a>(shape: &'a crate::rigid::RevolutionShape, pose: &BodyPose) -> Placed<'a> {
    let q = pose.orientation;
    Placed {
        shape,
        origin: pose.position,
        axis: q * Vector3::z(),
        x: q * Vector3::x(),
        y: q * Vector3::y(),
    }
}

/// A body placed with its frame of this evaluation (see `RevolutionPass::frames`).
#[inline]
fn placed_with<'a>(
    shape: &'a crate::rigid::RevolutionShape,
    position: V3,
    frame: &[V3; 3],
) -> Placed<'a> {
    Placed {
        shape,
        origin: position,
        axis: frame[0],
        x: frame[1],
        y: frame[2],
    }
}

/// A body's bounding capsule inflated by half the skin, and the box around it: (lower x,
/// upper x, lower corner, upper corner, axis start, axis end, radius, body).
type CapsuleBox = (f64, f64, V3, V3, V3, V3, f64, u32);

/// An upper bound of the rotation angle between two orientations, rad: with the nearer
/// of ±b, |a − b| = 2 sin(θ/4) ≥ θ/π·√2 for θ ≤ π, so θ ≤ 2.23 |a − b|.
fn rotation_bound(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>) -> f64 {
    let (qa, qb) = (a.coords, b.coords);
    let d = (qa - qb).norm().min((qa + qb).norm());
    2.23 * d
}

impl RigidScene {
    /// Refuse a start configuration in which two bodies, or a body and a wall, overlap by
    /// more than `tolerance` (m): an error naming `positions`, the bodies and the overlap.
    /// Evaluates the forces at the current time (as the first step would), so it is checked
    /// for scenes with bodies of revolution (others pass).
    pub fn check_start_overlaps(&mut self, tolerance: f64) -> Result<()> {
        if self.revolution.is_none() || self.bodies.is_empty() {
            return Ok(());
        }
        self.compute_forces(self.time)?;
        let deepest = self.revolution.as_ref().and_then(|p| p.deepest);
        match deepest {
            Some((body, partner, wall, overlap)) if overlap > tolerance => {
                let what = if wall {
                    format!("body {body} and wall {partner}")
                } else {
                    format!("bodies {body} and {partner}")
                };
                Err(DemfemError::InvalidParameter {
                    field: "positions".into(),
                    value: format!("{what} overlapping by {overlap:e} m"),
                    allowed: format!("start poses apart (overlaps up to {tolerance:e} m)"),
                })
            }
            _ => Ok(()),
        }
    }

    /// Rebuild the candidate pairs when needed (see the module docs).
    fn refresh_pairs(&mut self) {
        let n = self.bodies.len();
        let Some(pass) = self.revolution.as_mut() else {
            return;
        };
        let stale = pass.built_for != n
            || (0..n).any(|i| {
                let (x0, q0) = pass.reference[i];
                let r = self.shapes[self.body_shape[i]].0.bounding_radius();
                (self.bodies.position[i] - x0).norm()
                    + r * rotation_bound(&q0, &self.bodies.orientation[i])
                    > 0.5 * pass.skin
            });
        if !stale {
            return;
        }
        pass.rebuilds += 1;
        if pass.skin == 0.0 {
            pass.skin = 0.1
                * self
                    .shapes
                    .iter()
                    .map(|(s, _)| s.bounding_capsule().radius)
                    .fold(f64::INFINITY, f64::min);
        }
        let margin = 0.5 * pass.skin;
        // boxes around the capsules, swept along x
        let mut boxes: Vec<CapsuleBox> = Vec::with_capacity(n);
        for i in 0..n {
            if !self.alive[i] {
                continue;
            }
            let capsule = self.shapes[self.body_shape[i]].0.bounding_capsule();
            let axis = self.bodies.orientation[i] * Vector3::z();
            let c0 = self.bodies.position[i] + axis * capsule.z_min;
            let c1 = self.bodies.position[i] + axis * capsule.z_max;
            let reach = capsule.radius + margin;
            let lo = c0.inf(&c1).add_scalar(-reach);
            let hi = c0.sup(&c1).add_scalar(reach);
            boxes.push((lo.x, hi.x, lo, hi, c0, c1, reach, i as u32));
        }
        boxes.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.7.cmp(&b.7)));
        let mut pairs = Vec::new();
        for (k, a) in boxes.iter().enumerate() {
            for b in &boxes[k + 1..] {
                if b.0 > a.1 {
                    break;
                }
                if a.2.y > b.3.y || b.2.y > a.3.y || a.2.z > b.3.z || b.2.z > a.3.z {
                    continue;
                }
                let (s, t, _) = crate::rigid::revolution::features::segment_parameters(
                    &a.4,
                    &(a.5 - a.4),
                    &b.4,
                    &(b.5 - b.4),
                );
                let gap = a.4 + (a.5 - a.4) * s - b.4 - (b.5 - b.4) * t;
                if gap.norm() < a.6 + b.6 {
                    pairs.push((a.7.min(b.7), a.7.max(b.7)));
                }
            }
        }
        pairs.sort_unstable();
        // carry the springs' ranges and the touching flags of pairs listed before
        let mut range = vec![(0, 0); pairs.len()];
        let mut touching = vec![false; pairs.len()];
        let mut old = 0;
        for (k, p) in pairs.iter().enumerate() {
            while old < pass.pairs.len() && pass.pairs[old] < *p {
                old += 1;
            }
            if old < pass.pairs.len() && pass.pairs[old] == *p {
                range[k] = pass.pair_range[old];
                touching[k] = pass.pair_touching[old];
            }
        }
        pass.pairs = pairs;
        pass.pair_range = range;
        pass.pair_touching = touching;
        pass.reference = (0..n)
            .map(|i| (self.bodies.position[i], self.bodies.orientation[i]))
            .collect();
        pass.built_for = n;
    }

    /// Gravity and every contact force and torque at time `time` (s), for scenes with bodies
    /// of revolution.
    pub(super) fn compute_forces_revolution(&mut self, time: f64) -> Result<()> {
        self.bodies.clear_forces();
        self.evaluations += 1;
        let n = self.bodies.len();
        for i in 0..n {
            self.bodies.force[i] = if self.alive[i] {
                self.gravity * self.bodies.mass[i]
            } else {
                Vector3::zeros()
            };
        }
        self.refresh_pairs();
        let Some(mut pass) = self.revolution.take() else {
            return Ok(());
        };
        let result = self.revolution_contacts(&mut pass, time);
        self.revolution = Some(pass);
        result
    }

    fn revolution_contacts(&mut self, pass: &mut RevolutionPass, time: f64) -> Result<()> {
        let n = self.bodies.len();
        let dt = self.time_step;
        let n_planes = self.planes.len();
        let n_boundaries = n_planes + self.walls.len();
        let offsets: Vec<(V3, V3)> = self
            .walls
            .iter()
            .map(|w| {
                let (x, v) = w.motion.offset_and_velocity(time);
                (Vector3::new(x.x, x.y, x.z), Vector3::new(v.x, v.y, v.z))
            })
            .collect();
        if pass.wall_range.len() != n * n_boundaries {
            pass.wall_range.resize(n * n_boundaries, (0, 0));
            pass.wall_touching.resize(n * n_boundaries, false);
        }
        pass.springs_next.clear();
        pass.deepest = None;
        self.coordination.iter_mut().for_each(|c| *c = 0);
        self.wall_contacts.iter_mut().for_each(|c| *c = 0);
        let mut count = 0;
        let mut max_overlap: f64 = 0.0;
        let mut elastic_energy = 0.0;
        let mut contacts = std::mem::take(&mut pass.contacts);
        let mut weights = std::mem::take(&mut pass.weights);
        pass.frames.clear();
        pass.frames.extend(self.bodies.orientation.iter().map(|q| {
            let r = q.to_rotation_matrix();
            let m = r.matrix();
            [m.column(2).into_owned(), m.column(0).into_owned(), m.column(1).into_owned()]
        }));
        for i in 0..n {
            if !self.alive[i] {
                continue;
            }
            let pose = self.pose(i);
            for p in 0..n_boundaries {
                contacts.clear();
                weights.clear();
                let shape = &self.shapes[self.body_shape[i]].0;
                let (plane_point, plane_normal, surface_velocity, prepared) = if p < n_planes {
                    let plane = self.planes[p];
                    (plane.point, plane.normal, plane.surface_velocity, None)
                } else {
                    let wall = &self.walls[p - n_planes];
                    let (offset, velocity) = offsets[p - n_planes];
                    let (point, normal) = match &wall.shape {
                        PreparedShape::Plane { point, normal } => (point + offset, *normal),
                        _ => (offset, Vector3::z()),
                    };
                    (point, normal, wall.surface_velocity + velocity, Some((wall, offset)))
                };
                match (prepared.map(|(w, o)| (&w.shape, o)), shape) {
                    (None | Some((PreparedShape::Plane { .. }, _)), RigidShape::Clump(clump)) => {
                        let plane = Plane {
                            point: plane_point,
                            normal: plane_normal,
                            surface_velocity: Vector3::zeros(),
                        };
                        clump_plane_contacts(&plane, clump, &pose, &mut contacts);
                    }
                    (None | Some((PreparedShape::Plane { .. }, _)), RigidShape::Revolution(r)) => {
                        let body = placed_with(r, pose.position, &pass.frames[i]);
                        if plane_normal.dot(&(pose.position - plane_point)) < r.bounding_radius {
                            plane_contacts(
                                &plane_point,
                                &plane_normal,
                                &body,
                                None,
                                &mut contacts,
                                &mut weights,
                            );
                        }
                    }
                    (Some((PreparedShape::Polygon(polygon), offset)), RigidShape::Clump(clump)) => {
                        clump_polygon_contacts(polygon, &offset, clump, &pose, &mut contacts)
                    }
                    (Some((PreparedShape::Polygon(polygon), offset)), RigidShape::Revolution(r)) => {
                        polygon_contacts(polygon, &offset, r, &pose, &mut contacts, &mut weights);
                    }
                    (Some((PreparedShape::Mesh(mesh), offset)), RigidShape::Clump(clump)) => {
                        clump_mesh_contacts(mesh, &offset, clump, &pose, &mut contacts)
                    }
                    (Some((PreparedShape::Mesh(mesh), offset)), RigidShape::Revolution(r)) => {
                        crate::rigid::revolution::mesh_walls::mesh_contacts(
                            mesh,
                            &offset,
                            &placed(r, &pose),
                            &mut contacts,
                            &mut weights,
                        )
                    }
                    (_, RigidShape::Exact(_)) => return Err(mixed_exact()),
                }
                weights.resize(contacts.len(), 1.0);
                let slot = i * n_boundaries + p;
                let old = pass.wall_range[slot];
                let start = pass.springs_next.len() as u32;
                if contacts.is_empty() {
                    pass.wall_range[slot] = (start, start);
                    pass.wall_touching[slot] = false;
                    continue;
                }
                count += contacts.len();
                self.wall_contacts[i] += 1;
                let m_star = self.bodies.mass[i] / contacts.len() as f64;
                let deepest = deepest_of(&contacts);
                if !pass.wall_touching[slot] && self.record_onsets {
                    let c0 = contacts[deepest];
                    let relative = self.bodies.point_velocity(i, &c0.point) - surface_velocity;
                    let mut o = onset(time, i, p, true, &relative, &c0.normal);
                    o.point = c0.point;
                    o.normal = c0.normal;
                    o.body_pose = pose;
                    self.onsets.push(o);
                }
                pass.wall_touching[slot] = true;
                let overlap = contacts[deepest].overlap;
                if pass.deepest.is_none_or(|d| overlap > d.3) {
                    pass.deepest = Some((i, p, true, overlap));
                }
                for (c, &w) in contacts.iter().zip(&weights) {
                    max_overlap = max_overlap.max(c.overlap);
                    let relative = self.bodies.point_velocity(i, &c.point) - surface_velocity;
                    let (f, energy) = self.spring_force(
                        pass,
                        old,
                        c,
                        &relative,
                        m_star / w,
                        self.model.e_star_body_plane,
                        dt,
                    )?;
                    elastic_energy += w * energy;
                    let f = f * w;
                    self.bodies.force[i] += f;
                    self.bodies.torque[i] += (c.point - self.bodies.position[i]).cross(&f);
                }
                pass.wall_range[slot] = (start, pass.springs_next.len() as u32);
            }
        }
        for k in 0..pass.pairs.len() {
            let (a, b) = (pass.pairs[k].0 as usize, pass.pairs[k].1 as usize);
            let old = pass.pair_range[k];
            let start = pass.springs_next.len() as u32;
            pass.pair_range[k] = (start, start);
            if !(self.alive[a] && self.alive[b]) {
                pass.pair_touching[k] = false;
                continue;
            }
            contacts.clear();
            weights.clear();
            let (pa, pb) = (self.pose(a), self.pose(b));
            let (shape_a, shape_b) = (
                &self.shapes[self.body_shape[a]].0,
                &self.shapes[self.body_shape[b]].0,
            );
            let reach = shape_a.bounding_radius() + shape_b.bounding_radius();
            let mut flipped = false;
            if (pb.position - pa.position).norm() < reach
                && super::contacts::capsules_overlap(
                    &shape_a.bounding_capsule(),
                    &pa,
                    &shape_b.bounding_capsule(),
                    &pb,
                )
            {
                match (shape_a, shape_b) {
                    (RigidShape::Revolution(ra), RigidShape::Revolution(rb)) => pair_contacts(
                        &placed_with(ra, pa.position, &pass.frames[a]),
                        &placed_with(rb, pb.position, &pass.frames[b]),
                        &mut pass.pair_scratch,
                        &mut contacts,
                        &mut weights,
                    ),
                    (RigidShape::Clump(ca), RigidShape::Revolution(rb)) => {
                        beads_against(ca, &pa, &placed(rb, &pb), &mut contacts)
                    }
                    (RigidShape::Revolution(ra), RigidShape::Clump(cb)) => {
                        flipped = true;
                        beads_against(cb, &pb, &placed(ra, &pa), &mut contacts)
                    }
                    (RigidShape::Clump(ca), RigidShape::Clump(cb)) => clump_clump_contacts(
                        ca,
                        &pa,
                        cb,
                        &pb,
                        &mut pass.clump_scratch,
                        &mut contacts,
                    ),
                    _ => return Err(mixed_exact()),
                }
            }
            if contacts.is_empty() {
                pass.pair_touching[k] = false;
                continue;
            }
            weights.resize(contacts.len(), 1.0);
            let (first, second) = if flipped { (b, a) } else { (a, b) };
            let sharing: f64 = weights.iter().sum();
            let m_star = effective_mass(self.bodies.mass[first], self.bodies.mass[second])? / sharing;
            let deepest = deepest_of(&contacts);
            if !pass.pair_touching[k] && self.record_onsets {
                let c0 = contacts[deepest];
                let relative = self.bodies.point_velocity(second, &c0.point)
                    - self.bodies.point_velocity(first, &c0.point);
                let mut o = onset(time, a, b, false, &relative, &c0.normal);
                o.point = c0.point;
                // logged from the lower index (a) to the higher
                o.normal = if first == a { c0.normal } else { -c0.normal };
                o.body_pose = pa;
                o.partner_pose = Some(pb);
                self.onsets.push(o);
            }
            pass.pair_touching[k] = true;
            let overlap = contacts[deepest].overlap;
            if pass.deepest.is_none_or(|d| overlap > d.3) {
                pass.deepest = Some((a, b, false, overlap));
            }
            self.coordination[a] += 1;
            self.coordination[b] += 1;
            count += contacts.len();
            for (c, &w) in contacts.iter().zip(&weights) {
                max_overlap = max_overlap.max(c.overlap);
                let relative = self.bodies.point_velocity(second, &c.point)
                    - self.bodies.point_velocity(first, &c.point);
                let (f, energy) = self.spring_force(
                    pass,
                    old,
                    c,
                    &relative,
                    m_star / w,
                    self.model.e_star_body_body,
                    dt,
                )?;
                elastic_energy += w * energy;
                let f = f * w;
                let arm_second = c.point - self.bodies.position[second];
                let arm_first = c.point - self.bodies.position[first];
                self.bodies.force[second] += f;
                self.bodies.torque[second] += arm_second.cross(&f);
                self.bodies.force[first] -= f;
                self.bodies.torque[first] -= arm_first.cross(&f);
            }
            pass.pair_range[k] = (start, pass.springs_next.len() as u32);
        }
        std::mem::swap(&mut pass.springs, &mut pass.springs_next);
        pass.contacts = contacts;
        pass.weights = weights;
        self.contacts_last_step = count;
        self.max_overlap_last_step = max_overlap;
        self.elastic_energy_last_step = elastic_energy;
        self.forces_current = true;
        Ok(())
    }

    /// The force of one contact with its Mindlin spring carried over from the slot's springs
    /// of the last evaluation (`old`, a range of `pass.springs`); the updated spring goes to
    /// `pass.springs_next`.
    #[allow(clippy::too_many_arguments)]
    fn spring_force(
        &self,
        pass: &mut RevolutionPass,
        old: (u32, u32),
        c: &ContactPoint,
        relative: &V3,
        m_star: f64,
        e_star: f64,
        dt: f64,
    ) -> Result<(V3, f64)> {
        let with_history = self.model.friction > 0.0;
        let mut xi = if with_history {
            pass.springs[old.0 as usize..old.1 as usize]
                .iter()
                .find(|s| s.0 == c.feature_first && s.1 == c.feature_second)
                .map_or_else(Vector3::zeros, |s| s.2)
        } else {
            Vector3::zeros()
        };
        let out = self
            .model
            .force_and_energy(c, relative, m_star, e_star, &mut xi, dt)?;
        if with_history {
            pass.springs_next.push((c.feature_first, c.feature_second, xi));
        }
        Ok(out)
    }
}

/// A polygon wall displaced by `offset` against a body of revolution: the face (anchored
/// points of the edge circles inside the polygon, on the side of the body's centre), then
/// the edges and corners.
fn polygon_contacts(
    polygon: &crate::rigid::PolygonWall,
    offset: &V3,
    shape: &crate::rigid::RevolutionShape,
    pose: &BodyPose,
    contacts: &mut Vec<ContactPoint>,
    weights: &mut Vec<f64>,
) {
    let (vertices, normal, edge_normals) = polygon.parts();
    if vertices.is_empty() {
        return;
    }
    let to_na = |v: &crate::geometry::Vec3| Vector3::new(v.x, v.y, v.z);
    let first = to_na(&vertices[0]) + offset;
    let mut n = to_na(&normal);
    let side = n.dot(&(pose.position - first));
    if side.abs() >= shape.bounding_radius {
        return;
    }
    if side < 0.0 {
        n = -n;
    }
    let body = placed(shape, pose);
    let inside = |x: &V3| {
        vertices
            .iter()
            .zip(edge_normals)
            .all(|(v, e)| to_na(e).dot(&(x - to_na(v) - offset)) >= 0.0)
    };
    plane_contacts(&first, &n, &body, Some(&inside), contacts, weights);
    let world: Vec<V3> = vertices.iter().map(|v| to_na(v) + offset).collect();
    let inward: Vec<V3> = edge_normals.iter().map(to_na).collect();
    polygon_edge_contacts(&world, &inward, &body, contacts, weights);
}

/// The beads of a clump against a body of revolution (clump first).
fn beads_against(
    clump: &crate::rigid::BeadClump,
    pose: &BodyPose,
    body: &Placed,
    contacts: &mut Vec<ContactPoint>,
) {
    let local = pose.orientation.inverse_transform_vector(&(body.origin - pose.position));
    for (k, (c, &r)) in clump.centers.iter().zip(&clump.radii).enumerate() {
        if (c - local).norm() >= body.shape.bounding_radius + r {
            continue;
        }
        let centre = pose.position + pose.orientation * c;
        if let Some(mut contact) = bead_contact(&centre, r, body) {
            contact.feature_first = k as u64;
            contacts.push(contact);
        }
    }
}

fn deepest_of(contacts: &[ContactPoint]) -> usize {
    let mut deepest = 0;
    for (k, c) in contacts.iter().enumerate() {
        if c.overlap > contacts[deepest].overlap {
            deepest = k;
        }
    }
    deepest
}

fn onset(time: f64, body: usize, partner: usize, wall: bool, relative: &V3, normal: &V3) -> RigidOnset {
    let v_n = relative.dot(normal);
    RigidOnset {
        time,
        body: body as u32,
        partner: partner as u32,
        partner_is_wall: wall,
        normal_speed: -v_n,
        tangential_speed: (relative - normal * v_n).norm(),
        point: Vector3::zeros(),
        normal: *normal,
        body_pose: BodyPose {
            position: Vector3::zeros(),
            orientation: UnitQuaternion::identity(),
        },
        partner_pose: None,
    }
}

fn mixed_exact() -> DemfemError {
    DemfemError::ShapeMismatch {
        field: "shape".into(),
        detail: "bodies of revolution share a scene with bead clumps and spheres, not with \
                 parry exact shapes"
            .into(),
    }
}
