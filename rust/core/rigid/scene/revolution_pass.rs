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

use super::revolution_geometry::{frames, Block};
use super::{RigidOnset, RigidScene};
use crate::contact::effective_mass;
use crate::error::{DemfemError, Result};
use crate::rigid::collision::{BodyPose, ContactPoint};

type V3 = Vector3<f64>;

/// Bodies below which the contact geometry stays on one thread (a block would be too small
/// to pay for the hand-over).
const PARALLEL_MIN_BODIES: usize = 64;

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
    wall_blocks: Vec<Block>,
    pair_blocks: Vec<Block>,
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

    /// Drop every trace of body `i` kept between evaluations — the Mindlin springs and the
    /// touching flags of its body–boundary slots (`n_boundaries` per body) and of the listed
    /// pairs it belongs to — and force a rebuild of the pair list at the next evaluation
    /// (a body put back elsewhere: [`RigidScene::reinsert_body`]).
    pub(crate) fn forget_body(&mut self, i: usize, n_boundaries: usize) {
        for slot in i * n_boundaries..(i + 1) * n_boundaries {
            if let Some(range) = self.wall_range.get_mut(slot) {
                *range = (0, 0);
            }
            if let Some(touching) = self.wall_touching.get_mut(slot) {
                *touching = false;
            }
        }
        let body = i as u32;
        for (k, &(a, b)) in self.pairs.iter().enumerate() {
            if a == body || b == body {
                if let Some(range) = self.pair_range.get_mut(k) {
                    *range = (0, 0);
                }
                if let Some(touching) = self.pair_touching.get_mut(k) {
                    *touching = false;
                }
            }
        }
        self.built_for = usize::MAX;
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
        let n_boundaries = self.planes.len() + self.walls.len();
        let offsets = self.wall_offsets(time);
        frames(&self.bodies.orientation, &mut pass.frames);
        // the geometry, in blocks of bodies and of pairs (on the scene's threads)
        let blocks = match &self.pool {
            Some(pool) if n >= PARALLEL_MIN_BODIES => pool.current_num_threads(),
            _ => 1,
        };
        pass.wall_blocks.resize_with(blocks, Block::default);
        pass.pair_blocks.resize_with(blocks, Block::default);
        let view = self.view();
        let pairs = &pass.pairs;
        let frames_now = &pass.frames;
        let cut = |count: usize, b: usize| (count * b / blocks)..(count * (b + 1) / blocks);
        let run = |(b, (walls, pair)): (usize, (&mut Block, &mut Block))| -> Result<()> {
            walls.clear();
            pair.clear();
            view.wall_geometry(cut(n, b), frames_now, &offsets, walls)?;
            view.pair_geometry(pairs, cut(pairs.len(), b), frames_now, pair)
        };
        let jobs = pass
            .wall_blocks
            .iter_mut()
            .zip(pass.pair_blocks.iter_mut())
            .enumerate();
        match (&self.pool, blocks) {
            (Some(pool), b) if b > 1 => pool.install(|| {
                use rayon::prelude::*;
                jobs.collect::<Vec<_>>()
                    .into_par_iter()
                    .map(run)
                    .collect::<Result<Vec<()>>>()
            })?,
            _ => jobs.map(run).collect::<Result<Vec<()>>>()?,
        };
        // the forces, slot by slot in a fixed order
        let old_wall_range = std::mem::take(&mut pass.wall_range);
        let was_touching_wall = std::mem::take(&mut pass.wall_touching);
        pass.wall_range = vec![(0, 0); n * n_boundaries];
        pass.wall_touching = vec![false; n * n_boundaries];
        let old_pair_range = std::mem::take(&mut pass.pair_range);
        let was_touching_pair = std::mem::take(&mut pass.pair_touching);
        pass.pair_range = vec![(0, 0); pass.pairs.len()];
        pass.pair_touching = vec![false; pass.pairs.len()];
        pass.springs_next.clear();
        pass.deepest = None;
        self.coordination.iter_mut().for_each(|c| *c = 0);
        self.wall_contacts.iter_mut().for_each(|c| *c = 0);
        let mut count = 0;
        let mut max_overlap: f64 = 0.0;
        let mut elastic_energy = 0.0;
        let wall_blocks = std::mem::take(&mut pass.wall_blocks);
        for block in &wall_blocks {
            for touch in &block.touches {
                let (i, p) = (touch.slot / n_boundaries, touch.slot % n_boundaries);
                let contacts = &block.contacts[touch.range.0..touch.range.1];
                let weights = &block.weights[touch.range.0..touch.range.1];
                let old = old_wall_range.get(touch.slot).copied().unwrap_or((0, 0));
                let start = pass.springs_next.len() as u32;
                count += contacts.len();
                self.wall_contacts[i] += 1;
                let m_star = self.bodies.mass[i] / contacts.len() as f64;
                let deepest = deepest_of(contacts);
                let c0 = contacts[deepest];
                let touched = was_touching_wall.get(touch.slot).copied().unwrap_or(false);
                if !touched && self.record_onsets {
                    let relative =
                        self.bodies.point_velocity(i, &c0.point) - touch.surface_velocity;
                    let mut o = onset(time, i, p, true, &relative, &c0.normal);
                    o.point = c0.point;
                    o.normal = c0.normal;
                    o.body_pose = self.pose(i);
                    self.onsets.push(o);
                }
                pass.wall_touching[touch.slot] = true;
                if pass.deepest.is_none_or(|d| c0.overlap > d.3) {
                    pass.deepest = Some((i, p, true, c0.overlap));
                }
                for (c, &w) in contacts.iter().zip(weights) {
                    max_overlap = max_overlap.max(c.overlap);
                    let relative = self.bodies.point_velocity(i, &c.point) - touch.surface_velocity;
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
                pass.wall_range[touch.slot] = (start, pass.springs_next.len() as u32);
            }
        }
        pass.wall_blocks = wall_blocks;
        let pair_blocks = std::mem::take(&mut pass.pair_blocks);
        for block in &pair_blocks {
            for touch in &block.touches {
                let k = touch.slot;
                let (a, b) = (pass.pairs[k].0 as usize, pass.pairs[k].1 as usize);
                let contacts = &block.contacts[touch.range.0..touch.range.1];
                let weights = &block.weights[touch.range.0..touch.range.1];
                let old = old_pair_range.get(k).copied().unwrap_or((0, 0));
                let start = pass.springs_next.len() as u32;
                let (first, second) = if touch.flipped { (b, a) } else { (a, b) };
                let sharing: f64 = weights.iter().sum();
                let m_star =
                    effective_mass(self.bodies.mass[first], self.bodies.mass[second])? / sharing;
                let c0 = contacts[deepest_of(contacts)];
                let touched = was_touching_pair.get(k).copied().unwrap_or(false);
                if !touched && self.record_onsets {
                    let relative = self.bodies.point_velocity(second, &c0.point)
                        - self.bodies.point_velocity(first, &c0.point);
                    let mut o = onset(time, a, b, false, &relative, &c0.normal);
                    o.point = c0.point;
                    // logged from the lower index (a) to the higher
                    o.normal = if first == a { c0.normal } else { -c0.normal };
                    o.body_pose = self.pose(a);
                    o.partner_pose = Some(self.pose(b));
                    self.onsets.push(o);
                }
                pass.pair_touching[k] = true;
                if pass.deepest.is_none_or(|d| c0.overlap > d.3) {
                    pass.deepest = Some((a, b, false, c0.overlap));
                }
                self.coordination[a] += 1;
                self.coordination[b] += 1;
                count += contacts.len();
                for (c, &w) in contacts.iter().zip(weights) {
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
        }
        pass.pair_blocks = pair_blocks;
        std::mem::swap(&mut pass.springs, &mut pass.springs_next);
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
            pass.springs_next
                .push((c.feature_first, c.feature_second, xi));
        }
        Ok(out)
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

fn onset(
    time: f64,
    body: usize,
    partner: usize,
    wall: bool,
    relative: &V3,
    normal: &V3,
) -> RigidOnset {
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
