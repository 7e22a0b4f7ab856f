//! The contacts of one force evaluation of a [`RigidScene`]: gravity, contact detection
//! against planes, walls and the other bodies (culled by bounding capsules), the contact
//! forces with their Mindlin springs carried from step to step ([`FrictionHistory`]), the
//! damping shared by the points of a multi-point contact, and the onset log.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use nalgebra::Vector3;

use super::{PreparedShape, RigidOnset, RigidScene};
use crate::contact::effective_mass;
use crate::error::{DemfemError, Result};
use crate::rigid::collision::{
    clump_clump_contacts, clump_exact_contacts, clump_mesh_contacts, clump_plane_contacts,
    clump_polygon_contacts, exact_exact_contacts, exact_plane_contacts, exact_polygon_contacts,
    BodyPose, ContactPoint, Plane,
};
use crate::rigid::forces::RigidContactLaw;
use crate::rigid::shape::{BoundingCapsule, RigidShape};

/// Key of a contact's friction history: (first object << 32 | second object, feature on the
/// first, feature on the second); planes are objects `u32::MAX − plane index`.
pub(super) type ContactKey = (u64, u64, u64);

/// Force (N) and stored elastic energy (J) of one contact point, carrying its Mindlin spring
/// over from the previous step when `history` is given: the spring of `key` is read from the
/// first map (zero for a new contact) and the updated one stored in the second.
#[allow(clippy::too_many_arguments)]
fn force_with_history(
    model: &RigidContactLaw,
    contact: &ContactPoint,
    relative_velocity: &Vector3<f64>,
    effective_mass: f64,
    e_star: f64,
    key: ContactKey,
    history: Option<(&FrictionHistory, &mut FrictionHistory)>,
    dt: f64,
) -> Result<(Vector3<f64>, f64)> {
    let mut xi = history
        .as_ref()
        .and_then(|(previous, _)| previous.get(&key).copied())
        .unwrap_or_else(Vector3::zeros);
    let (f, energy) = model.force_and_energy(
        contact,
        relative_velocity,
        effective_mass,
        e_star,
        &mut xi,
        dt,
    )?;
    if let Some((_, current)) = history {
        current.insert(key, xi);
    }
    Ok((f, energy))
}

/// Multiply–rotate hash for small integer keys (the FxHash scheme): the default SipHash
/// would cost more than the force it looks up.
#[derive(Default, Clone, Copy)]
pub(super) struct ContactKeyHasher(u64);

impl Hasher for ContactKeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_u64(&mut self, value: u64) {
        self.0 = (self.0.rotate_left(5) ^ value).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

pub(super) type FrictionHistory =
    HashMap<ContactKey, Vector3<f64>, BuildHasherDefault<ContactKeyHasher>>;

/// Scenes with bodies of revolution run their own contact pass (`revolution_pass`).
fn revolution_elsewhere() -> DemfemError {
    DemfemError::Effect("bodies of revolution are handled by the revolution pass".into())
}

pub(super) fn plane_object(plane: usize) -> u64 {
    (u32::MAX as u64) - plane as u64
}

impl RigidScene {
    /// Note that bodies (or a body and a boundary) touch under `key`; log an onset when they
    /// did not touch at the previous evaluation. `relative` is the velocity of the second
    /// surface minus the first at the deepest point `point`, whose normal is `normal`;
    /// `logged_normal` is the normal the log keeps (from the wall to the body, or from the
    /// lower body index to the higher).
    #[allow(clippy::too_many_arguments)]
    fn note_touch(
        &mut self,
        key: u64,
        body: usize,
        partner: usize,
        partner_is_wall: bool,
        time: f64,
        relative: &Vector3<f64>,
        normal: &Vector3<f64>,
        point: &Vector3<f64>,
        logged_normal: &Vector3<f64>,
    ) {
        self.touching_next.insert(key);
        if partner_is_wall {
            self.wall_contacts[body] += 1;
        } else {
            self.coordination[body] += 1;
            self.coordination[partner] += 1;
        }
        if self.record_onsets && !self.touching.contains(&key) {
            let v_n = relative.dot(normal);
            let (first, second) = if partner_is_wall {
                (body, partner)
            } else {
                (body.min(partner), body.max(partner))
            };
            self.onsets.push(RigidOnset {
                time,
                body: first as u32,
                partner: second as u32,
                partner_is_wall,
                normal_speed: -v_n,
                tangential_speed: (relative - normal * v_n).norm(),
                point: *point,
                normal: *logged_normal,
                body_pose: self.pose(first),
                partner_pose: (!partner_is_wall).then(|| self.pose(second)),
            });
        }
    }

    /// Gravity and every contact force and torque of the configuration at time `time` (s).
    pub(super) fn compute_forces(&mut self, time: f64) -> Result<()> {
        if self.revolution.is_some() {
            return self.compute_forces_revolution(time);
        }
        self.bodies.clear_forces();
        self.evaluations += 1;
        let evaluation = self.evaluations;
        let dt = self.time_step;
        // friction history: springs of contacts that persist carry over, the rest are dropped
        let with_history = self.model.friction > 0.0;
        let previous = std::mem::take(&mut self.friction_history);
        let mut current = std::mem::take(&mut self.friction_history_next);
        current.clear();
        for i in 0..self.bodies.len() {
            self.bodies.force[i] = if self.alive[i] {
                self.gravity * self.bodies.mass[i]
            } else {
                Vector3::zeros()
            };
        }
        std::mem::swap(&mut self.touching, &mut self.touching_next);
        self.touching_next.clear();
        self.coordination.iter_mut().for_each(|c| *c = 0);
        self.wall_contacts.iter_mut().for_each(|c| *c = 0);
        let mut contacts = std::mem::take(&mut self.contacts);
        let mut count = 0;
        let mut max_overlap: f64 = 0.0;
        let mut elastic_energy = 0.0;
        let n_planes = self.planes.len();
        let n_boundaries = n_planes + self.walls.len();
        // boundaries at this time: planes as given, walls displaced by their motion
        let offsets = self.wall_offsets(time);
        for i in 0..self.bodies.len() {
            if !self.alive[i] {
                continue;
            }
            let pose = self.pose(i);
            for p in 0..n_boundaries {
                contacts.clear();
                let shape_i = &self.shapes[self.body_shape[i]].0;
                let surface_velocity = if p < n_planes {
                    let plane = self.planes[p];
                    match shape_i {
                        RigidShape::Clump(clump) => {
                            clump_plane_contacts(&plane, clump, &pose, &mut contacts)
                        }
                        RigidShape::Exact(shape) => {
                            let cache = self.exact_caches.entry((i, usize::MAX - p)).or_default();
                            cache.last_used = evaluation;
                            exact_plane_contacts(&plane, shape, &pose, cache, &mut contacts)?
                        }
                        RigidShape::Revolution(_) => return Err(revolution_elsewhere()),
                    }
                    plane.surface_velocity
                } else {
                    let wall = &self.walls[p - n_planes];
                    let (offset, velocity) = offsets[p - n_planes];
                    match (&wall.shape, shape_i) {
                        (PreparedShape::Plane { point, normal }, _) => {
                            let plane = Plane {
                                point: point + offset,
                                normal: *normal,
                                surface_velocity: Vector3::zeros(),
                            };
                            match shape_i {
                                RigidShape::Clump(clump) => {
                                    clump_plane_contacts(&plane, clump, &pose, &mut contacts)
                                }
                                RigidShape::Exact(shape) => {
                                    let cache =
                                        self.exact_caches.entry((i, usize::MAX - p)).or_default();
                                    cache.last_used = evaluation;
                                    exact_plane_contacts(
                                        &plane,
                                        shape,
                                        &pose,
                                        cache,
                                        &mut contacts,
                                    )?
                                }
                                RigidShape::Revolution(_) => return Err(revolution_elsewhere()),
                            }
                        }
                        (_, RigidShape::Revolution(_)) => return Err(revolution_elsewhere()),
                        (PreparedShape::Mesh(mesh), RigidShape::Clump(clump)) => {
                            clump_mesh_contacts(mesh, &offset, clump, &pose, &mut contacts)
                        }
                        (PreparedShape::Mesh(_), RigidShape::Exact(_)) => {
                            return Err(DemfemError::ShapeMismatch {
                                field: format!("walls[{}]", p - n_planes),
                                detail: "a mesh wall takes bead clumps and spheres, not exact \
                                         shapes (yet)"
                                    .into(),
                            });
                        }
                        (PreparedShape::Polygon(polygon), RigidShape::Clump(clump)) => {
                            clump_polygon_contacts(polygon, &offset, clump, &pose, &mut contacts)
                        }
                        (PreparedShape::Polygon(polygon), RigidShape::Exact(shape)) => {
                            let cache = self.exact_caches.entry((i, usize::MAX - p)).or_default();
                            cache.last_used = evaluation;
                            exact_polygon_contacts(
                                polygon,
                                &offset,
                                shape,
                                &pose,
                                cache,
                                &mut contacts,
                            )?
                        }
                    }
                    wall.surface_velocity + velocity
                };
                if contacts.is_empty() {
                    continue;
                }
                count += contacts.len();
                let m_star = self.bodies.mass[i] / contacts.len() as f64;
                let mut deepest = 0;
                for (k, c) in contacts.iter().enumerate() {
                    if c.overlap > contacts[deepest].overlap {
                        deepest = k;
                    }
                }
                let c0 = contacts[deepest];
                let relative0 = self.bodies.point_velocity(i, &c0.point) - surface_velocity;
                self.note_touch(
                    plane_object(p) << 32 | i as u64,
                    i,
                    p,
                    true,
                    time,
                    &relative0,
                    &c0.normal,
                    &c0.point,
                    &c0.normal,
                );
                for c in &contacts {
                    max_overlap = max_overlap.max(c.overlap);
                    let relative = self.bodies.point_velocity(i, &c.point) - surface_velocity;
                    let key = (
                        plane_object(p) << 32 | i as u64,
                        c.feature_first,
                        c.feature_second,
                    );
                    let (f, energy) = force_with_history(
                        &self.model,
                        c,
                        &relative,
                        m_star,
                        self.model.e_star_body_plane,
                        key,
                        with_history.then_some((&previous, &mut current)),
                        dt,
                    )?;
                    elastic_energy += energy;
                    self.apply(i, &c.point, &f);
                }
            }
        }
        // broad phase: sort and sweep the bounding spheres along x (O(N log N) pairs)
        let mut order = std::mem::take(&mut self.sweep_order);
        order.clear();
        for i in 0..self.bodies.len() {
            if !self.alive[i] {
                continue;
            }
            let r = self.shapes[self.body_shape[i]].0.bounding_radius();
            order.push((
                self.bodies.position[i].x - r,
                self.bodies.position[i].x + r,
                i,
            ));
        }
        order.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
        for (k, &(_, upper, first_index)) in order.iter().enumerate() {
            for &(lower, _, second_index) in &order[k + 1..] {
                if lower >= upper {
                    break;
                }
                let (a, b) = (first_index.min(second_index), first_index.max(second_index));
                let (pa, pb) = (self.pose(a), self.pose(b));
                let (shape_a, shape_b) = (
                    &self.shapes[self.body_shape[a]].0,
                    &self.shapes[self.body_shape[b]].0,
                );
                let reach = shape_a.bounding_radius() + shape_b.bounding_radius();
                let apart = (pb.position - pa.position).norm() >= reach
                    || !capsules_overlap(
                        &shape_a.bounding_capsule(),
                        &pa,
                        &shape_b.bounding_capsule(),
                        &pb,
                    );
                if apart {
                    continue;
                }
                contacts.clear();
                // the clump–exact pair is always computed with the clump first
                let mut flipped = false;
                match (
                    &self.shapes[self.body_shape[a]].0,
                    &self.shapes[self.body_shape[b]].0,
                ) {
                    (RigidShape::Clump(ca), RigidShape::Clump(cb)) => clump_clump_contacts(
                        ca,
                        &pa,
                        cb,
                        &pb,
                        &mut self.clump_scratch,
                        &mut contacts,
                    ),
                    (RigidShape::Exact(ea), RigidShape::Exact(eb)) => {
                        let cache = self.exact_caches.entry((a, b)).or_default();
                        cache.last_used = evaluation;
                        exact_exact_contacts(ea, &pa, eb, &pb, cache, &mut contacts)?
                    }
                    (RigidShape::Clump(ca), RigidShape::Exact(eb)) => {
                        clump_exact_contacts(ca, &pa, eb, &pb, &mut contacts)?
                    }
                    (RigidShape::Exact(ea), RigidShape::Clump(cb)) => {
                        flipped = true;
                        clump_exact_contacts(cb, &pb, ea, &pa, &mut contacts)?
                    }
                    (RigidShape::Revolution(_), _) | (_, RigidShape::Revolution(_)) => {
                        return Err(revolution_elsewhere())
                    }
                }
                if contacts.is_empty() {
                    continue;
                }
                let (first, second) = if flipped { (b, a) } else { (a, b) };
                let both_exact = matches!(
                    (
                        &self.shapes[self.body_shape[a]].0,
                        &self.shapes[self.body_shape[b]].0
                    ),
                    (RigidShape::Exact(_), RigidShape::Exact(_))
                );
                // the pair's m* is shared by its contacts (module docs); between exact shapes
                // a contact is a piece pair, whose points share one force law
                let sharing = if both_exact {
                    distinct_piece_pairs(&contacts)
                } else {
                    contacts.len()
                };
                let m_star = effective_mass(self.bodies.mass[first], self.bodies.mass[second])?
                    / sharing as f64;
                let mut deepest = 0;
                for (k, c) in contacts.iter().enumerate() {
                    if c.overlap > contacts[deepest].overlap {
                        deepest = k;
                    }
                }
                let c0 = contacts[deepest];
                let relative0 = self.bodies.point_velocity(second, &c0.point)
                    - self.bodies.point_velocity(first, &c0.point);
                // the normal of `first` → `second`, as `a` → `b` for the log
                let normal0 = if first == a { c0.normal } else { -c0.normal };
                self.note_touch(
                    (a as u64) << 32 | b as u64,
                    a,
                    b,
                    false,
                    time,
                    &relative0,
                    &c0.normal,
                    &c0.point,
                    &normal0,
                );
                count += contacts.len();
                for c in &contacts {
                    max_overlap = max_overlap.max(c.overlap);
                    let relative = self.bodies.point_velocity(second, &c.point)
                        - self.bodies.point_velocity(first, &c.point);
                    let key = (
                        (first as u64) << 32 | second as u64,
                        c.feature_first,
                        c.feature_second,
                    );
                    let (f, energy) = force_with_history(
                        &self.model,
                        c,
                        &relative,
                        m_star,
                        self.model.e_star_body_body,
                        key,
                        with_history.then_some((&previous, &mut current)),
                        dt,
                    )?;
                    // between two exact shapes each piece pair is one contact, however many
                    // points parry reports for it (see `piece_pair_share`)
                    let share = if both_exact {
                        piece_pair_share(&contacts, c)
                    } else {
                        1.0
                    };
                    let f = f * share;
                    elastic_energy += energy * share;
                    self.apply(second, &c.point, &f);
                    self.apply(first, &c.point, &(-f));
                }
            }
        }
        // manifolds of pairs that drifted apart are stale: forget them
        if !self.exact_caches.is_empty() {
            self.exact_caches
                .retain(|_, cache| cache.last_used == evaluation);
        }
        self.contacts = contacts;
        self.sweep_order = order;
        self.friction_history = current;
        self.friction_history_next = previous;
        self.contacts_last_step = count;
        self.max_overlap_last_step = max_overlap;
        self.elastic_energy_last_step = elastic_energy;
        self.forces_current = true;
        Ok(())
    }

    #[inline]
    fn apply(&mut self, body: usize, point: &Vector3<f64>, force: &Vector3<f64>) {
        self.bodies.force[body] += force;
        self.bodies.torque[body] += (point - self.bodies.position[body]).cross(force);
    }
}

/// Share of the force law a contact point of two exact shapes carries: 1 / (points reported
/// for its piece pair). Parry describes one piece–piece contact by a varying number of
/// points — the deepest point alone, or with the clipped corners of a flat cap (5 or 9 for
/// two caps pressed together, chosen by round-off from one step to the next) or the ends of
/// a line contact — each at (about) the full overlap. Counting every point as a Hertz
/// contact makes the stiffness jump with that number between steps, which does work (an
/// undamped head-on cap impact gained 0.3 % of its energy); sharing one Hertz law among
/// the points keeps the total force a function of the overlap and lets the points only
/// place it.
fn piece_pair_share(contacts: &[ContactPoint], c: &ContactPoint) -> f64 {
    let pieces = |x: &ContactPoint| (x.feature_first >> 32, x.feature_second >> 32);
    let key = pieces(c);
    let count = contacts.iter().filter(|x| pieces(x) == key).count();
    1.0 / count.max(1) as f64
}

/// Number of distinct piece pairs among the contacts of two exact shapes.
fn distinct_piece_pairs(contacts: &[ContactPoint]) -> usize {
    let pieces = |x: &ContactPoint| (x.feature_first >> 32, x.feature_second >> 32);
    let mut count = 0;
    for (k, c) in contacts.iter().enumerate() {
        if !contacts[..k].iter().any(|x| pieces(x) == pieces(c)) {
            count += 1;
        }
    }
    count.max(1)
}

/// True when the bounding capsules of two bodies overlap (a cheap, tight cull for long
/// bodies: two upright cartridges 2 cm apart have overlapping bounding spheres, not capsules).
pub(super) fn capsules_overlap(
    a: &BoundingCapsule,
    pose_a: &BodyPose,
    b: &BoundingCapsule,
    pose_b: &BodyPose,
) -> bool {
    let axis_a = pose_a.orientation * Vector3::z();
    let axis_b = pose_b.orientation * Vector3::z();
    let (a0, a1) = (
        pose_a.position + axis_a * a.z_min,
        pose_a.position + axis_a * a.z_max,
    );
    let (b0, b1) = (
        pose_b.position + axis_b * b.z_min,
        pose_b.position + axis_b * b.z_max,
    );
    let reach = a.radius + b.radius;
    segment_distance_squared(&a0, &a1, &b0, &b1) < reach * reach
}

/// Squared distance between segments [p0, p1] and [q0, q1], m² (Ericson, *Real-Time
/// Collision Detection*, §5.1.9).
pub(super) fn segment_distance_squared(
    p0: &Vector3<f64>,
    p1: &Vector3<f64>,
    q0: &Vector3<f64>,
    q1: &Vector3<f64>,
) -> f64 {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    let tiny = 1e-30;
    let (s, t) = if a <= tiny && e <= tiny {
        (0.0, 0.0)
    } else if a <= tiny {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= tiny {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s = if denom > tiny {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    (p0 + d1 * s - (q0 + d2 * t)).norm_squared()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_distance_matches_hand_cases() {
        let z = Vector3::zeros();
        let ex = Vector3::x();
        // parallel segments 2 apart
        let d = segment_distance_squared(
            &z,
            &ex,
            &Vector3::new(0.0, 2.0, 0.0),
            &Vector3::new(1.0, 2.0, 0.0),
        );
        assert!((d - 4.0).abs() < 1e-15);
        // crossing skew segments 3 apart in z
        let d = segment_distance_squared(
            &Vector3::new(-1.0, 0.0, 0.0),
            &ex,
            &Vector3::new(0.0, -1.0, 3.0),
            &Vector3::new(0.0, 1.0, 3.0),
        );
        assert!((d - 9.0).abs() < 1e-15);
        // end to end along a line
        let d = segment_distance_squared(
            &z,
            &ex,
            &Vector3::new(3.0, 0.0, 0.0),
            &Vector3::new(4.0, 0.0, 0.0),
        );
        assert!((d - 4.0).abs() < 1e-15);
    }
}
