//! The neighbour lists, rebuilt when a particle or a wall moved more than half the skin:
//! the candidate pairs and wall slots with their carried contact state
//! (`Simulation::rebuild`), the gather lists of the pairs in contact and their update after
//! each force phase, the contact constants, and the wall slots of the batched kernels
//! ([`WallLists`]).

use super::events::EventAcc;
use super::law::{ContactConst, LawKind};
use super::state::{PairContact, PairDetail, PairOut, WallContact, WallDetail, WallOut, WallState};
use super::{Simulation, NO_WALL, PAIR_CHUNK};
use crate::dem::effects::Effect;
use crate::dem::record::Partner;
use crate::geometry::{Vec3, WallShape};

/// The wall slots the batched wall kernel evaluates, listed when the neighbour lists (or the
/// step's mode) change rather than found by scanning every slot each step. Per block of the
/// force phase (`cuts`: the block boundaries in both lists).
#[derive(Debug, Default)]
pub(super) struct WallLists {
    /// Groups of the AVX2 plane pass: (first particle relative to the block's first, slot
    /// column); the four particles from there hold the same plane in that column, with the
    /// constants of a Hertz law, or with those of a Hertz–Reissner law where
    /// `plane_reissner`, and are alive.
    pub(super) planes: Vec<(u32, u32)>,
    /// Every group's law is Hertz–Reissner (else every group's is Hertz): the law of the
    /// first group taken, which the others must share.
    pub(super) plane_reissner: bool,
    /// Every other slot holding a wall, of alive particles: (particle, slot), both relative
    /// to the block's first.
    pub(super) rest: Vec<(u32, u32)>,
    /// Block b's groups are `planes[cuts[b].0..cuts[b + 1].0]`, its slots
    /// `rest[cuts[b].1..cuts[b + 1].1]`.
    pub(super) cuts: Vec<(usize, usize)>,
    /// The entry of the contact table every slot of every group indexes, if they all index
    /// one: the plane pass then writes the constants into its batch once, not per group.
    pub(super) plane_const: Option<u32>,
    /// The (parallel, AVX2, batched) mode the lists were made for; `None` once the neighbour
    /// lists change.
    pub(super) mode: Option<(bool, bool, bool)>,
}

impl Simulation {
    pub(crate) fn refresh_wall_state(&mut self) {
        let moving = self.effects.has(Effect::MovingWalls);
        for (k, w) in self.walls.iter().enumerate() {
            let (offset, velocity, angle) = if moving {
                let (o, v) = w.motion.offset_and_velocity(self.time);
                (o, v, w.motion.angle_at(self.time))
            } else {
                (Vec3::ZERO, Vec3::ZERO, 0.0)
            };
            self.wall_state[k] = WallState {
                offset,
                velocity,
                angle,
            };
        }
    }

    /// The lists derived from the pair list and `pair_active`: the range of pairs where
    /// each particle is i (`pair_start`; the pair list is sorted by (i, j)), the threads'
    /// cuts, and the gather lists of the pairs in contact (see [`Simulation::active_entry`]),
    /// in increasing pair index; every pair is tested at the next step (`pair_wake`).
    pub(crate) fn build_gather_lists(&mut self) {
        let n = self.position.len();
        self.pair_out.clear();
        self.pair_out.resize(self.pairs.len(), PairOut::default());
        self.pair_detail.clear();
        self.pair_detail
            .resize(self.pairs.len(), PairDetail::default());
        self.pair_rolling.clear();
        self.pair_rolling.resize(self.pairs.len(), Vec3::ZERO);
        self.active_base.clear();
        self.active_base.resize(n + 1, 0);
        self.pair_start.clear();
        self.pair_start.resize(n + 1, 0);
        for p in &self.pairs {
            self.pair_start[p.i as usize + 1] += 1;
            self.active_base[p.i as usize + 1] += 1;
            self.active_base[p.j as usize + 1] += 1;
        }
        for i in 0..n {
            self.pair_start[i + 1] += self.pair_start[i];
            self.active_base[i + 1] += self.active_base[i];
        }
        // the gather lists of the pairs in contact, in increasing pair order
        self.active_entry.clear();
        self.active_entry.resize(self.active_base[n] as usize, 0);
        self.active_len.clear();
        self.active_len.resize(n, 0);
        for (e, (p, &on)) in self.pairs.iter().zip(&self.pair_active).enumerate() {
            if on {
                for (k, side) in [(p.i as usize, 0), (p.j as usize, 1)] {
                    let at = (self.active_base[k] + self.active_len[k]) as usize;
                    self.active_entry[at] = 2 * e as u32 + side;
                    self.active_len[k] += 1;
                }
            }
        }
        self.pair_listed.clone_from(&self.pair_active);
        // every pair is tested at the next force evaluation; the travel starts again
        self.pair_wake.clear();
        self.pair_wake.resize(self.pairs.len(), f64::NEG_INFINITY);
        self.travel = 0.0;
        // x + v Δt rounds each coordinate by at most ε |x|; particles stay within half a
        // skin of where they are now until the next rebuild: 2ε (|x|max + skin) bounds the
        // rounding of one step's move (√3 < 2)
        let extent = self
            .position
            .iter()
            .map(|x| x.abs().max_element())
            .filter(|m| m.is_finite())
            .fold(0.0, f64::max);
        self.travel_slack = 2.0 * f64::EPSILON * (extent + self.skin);
    }

    /// Bring the gather lists in step with `pair_active` after a force phase: only the
    /// chunks of pairs in which a contact began or ended are looked at, and each such pair
    /// is inserted into (or removed from) the sorted lists of its two particles.
    pub(super) fn sync_active_lists(&mut self) {
        for (c, flips) in self.chunk_flips.iter().enumerate() {
            if flips.onsets == 0 && flips.ends == 0 {
                continue;
            }
            let end = ((c + 1) * PAIR_CHUNK).min(self.pairs.len());
            for e in c * PAIR_CHUNK..end {
                let on = self.pair_active[e];
                if on == self.pair_listed[e] {
                    continue;
                }
                self.pair_listed[e] = on;
                let p = &self.pairs[e];
                for (k, side) in [(p.i as usize, 0), (p.j as usize, 1)] {
                    let entry = 2 * e as u32 + side;
                    let base = self.active_base[k] as usize;
                    let len = self.active_len[k] as usize;
                    if on {
                        // insertion into the sorted list (its room is every candidate of k)
                        let list = &mut self.active_entry[base..=base + len];
                        let mut at = len;
                        while at > 0 && list[at - 1] > entry {
                            list[at] = list[at - 1];
                            at -= 1;
                        }
                        list[at] = entry;
                        self.active_len[k] += 1;
                    } else {
                        let list = &mut self.active_entry[base..base + len];
                        if let Some(at) = list.iter().position(|&x| x == entry) {
                            list.copy_within(at + 1.., at);
                            self.active_len[k] -= 1;
                        }
                    }
                }
            }
        }
    }

    /// Derived per-contact data: r_i + r_j of each pair, the law constants of every pair
    /// and wall slot, the wall slots' output arrays, and the derived cut positions of the
    /// threads' blocks. A pure function of the lists and the static data (run after a
    /// rebuild and a restore).
    pub(crate) fn refresh_contact_constants(&mut self) {
        self.cut_blocks();
        self.derive_cut_lists();
        self.wall_lists.mode = None;
        let n_slots = self.wall_slots.len();
        self.wall_out.clear();
        self.wall_out.resize(n_slots, WallOut::default());
        self.wall_detail.clear();
        self.wall_detail.resize(n_slots, WallDetail::default());
        let nm = self.n_materials;
        // ContactConst::new is a function of (law, R*, m*) for the scene's model: one table
        // entry per distinct triple
        let (model, laws) = (self.model, &self.laws);
        let table = &mut self.contact_table;
        table.clear();
        table.push(ContactConst::default());
        let mut index: std::collections::HashMap<(usize, u64, u64), u32> =
            std::collections::HashMap::new();
        let mut entry = |law: usize, r_star: f64, m_star: f64| -> u32 {
            *index
                .entry((law, r_star.to_bits(), m_star.to_bits()))
                .or_insert_with(|| {
                    table.push(ContactConst::new(model, laws, law, r_star, m_star));
                    (table.len() - 1) as u32
                })
        };
        self.pair_const.clear();
        for p in self.pairs.iter_mut() {
            let (i, j) = (p.i as usize, p.j as usize);
            let r_sum = self.radius[i] + self.radius[j];
            let r_star = self.radius[i] * self.radius[j] / r_sum;
            let m_star = self.mass[i] * self.mass[j] / (self.mass[i] + self.mass[j]);
            let law = self.material[i] as usize * nm + self.material[j] as usize;
            self.pair_const.push(entry(law, r_star, m_star));
        }
        let stride = self.wall_stride;
        for (k, s) in self.wall_slots.iter_mut().enumerate() {
            if s.wall == NO_WALL {
                continue;
            }
            let i = k / stride;
            let law = self.material[i] as usize * nm + self.walls[s.wall as usize].material;
            s.k = entry(law, self.radius[i], self.mass[i]);
        }
        let table = &self.contact_table;
        self.pairs_hertz = self
            .pair_const
            .iter()
            .all(|&k| table[k as usize].kind == LawKind::Hertz);
        let first_k = self.pair_const.first().copied();
        let r0 = self.radius.first().copied();
        self.pairs_uniform = match (first_k, r0) {
            (Some(k0), Some(r0))
                if matches!(
                    table.get(k0 as usize).map(|c| c.kind),
                    Some(LawKind::Hertz | LawKind::HertzReissner)
                ) && self.pair_const.iter().all(|&k| k == k0)
                    && self.radius.iter().all(|&r| r.to_bits() == r0.to_bits()) =>
            {
                Some((k0, r0))
            }
            _ => None,
        };
    }

    /// The [`WallLists`] for the step's mode: per block of the force phase (`parallel`: the
    /// blocks of `cut_lists`, else one), the groups of the AVX2 plane pass (four
    /// consecutive alive particles from the block's start, a slot column whose four slots
    /// hold the same plane wall with Hertz constants; marked `planar_pass`) and every other
    /// slot of an alive particle. Without AVX2 there are no groups. A pure function of the
    /// lists, `alive` and the mode, so the kernels find in it exactly the slots a scan of
    /// every slot would.
    pub(crate) fn list_wall_slots(&mut self, parallel: bool) {
        let n = self.position.len();
        let stride = self.wall_stride;
        let lists = &mut self.wall_lists;
        lists.planes.clear();
        lists.rest.clear();
        lists.cuts.clear();
        lists.cuts.push((0, 0));
        lists.mode = Some((parallel, self.avx2, self.batched));
        // Some(None) until a group is taken, then Some(Some(k)) while all share entry k
        let mut plane_const: Option<Option<u32>> = Some(None);
        // the law of the groups: that of the first group taken
        let mut plane_kind: Option<LawKind> = None;
        let mut ends = vec![0];
        if parallel {
            ends.extend(&self.cut_lists.particle);
        }
        ends.push(n);
        let slots = &mut self.wall_slots;
        let (walls, table, alive) = (&self.walls, &self.contact_table, &self.alive);
        for s in slots.iter_mut() {
            s.planar_pass = false;
        }
        for block in ends.windows(2) {
            let (first, last) = (block[0], block[1]);
            if self.avx2 {
                let mut g = first;
                while g + 4 <= last {
                    for q in 0..stride {
                        let slot = |l: usize| &slots[(g + l) * stride + q];
                        if (0..4).all(|l| slot(l).wall == NO_WALL) {
                            // the four particles' lists end here
                            break;
                        }
                        let w = slot(0).wall;
                        let plane = matches!(
                            walls.get(w as usize).map(|w| &w.shape),
                            Some(WallShape::Plane { .. })
                        );
                        let kind = table[slot(0).k as usize].kind;
                        let take = plane
                            && matches!(kind, LawKind::Hertz | LawKind::HertzReissner)
                            && plane_kind.is_none_or(|k| k == kind)
                            && (0..4).all(|l| {
                                let s = slot(l);
                                s.wall == w && alive[g + l] && table[s.k as usize].kind == kind
                            });
                        if take {
                            plane_kind = Some(kind);
                            lists.planes.push(((g - first) as u32, q as u32));
                            for l in 0..4 {
                                let s = &mut slots[(g + l) * stride + q];
                                s.planar_pass = true;
                                plane_const = match plane_const {
                                    Some(None) => Some(Some(s.k)),
                                    Some(Some(k)) if k == s.k => Some(Some(k)),
                                    _ => None,
                                };
                            }
                        }
                    }
                    g += 4;
                }
            }
            let own = slots[first * stride..last * stride].chunks_exact(stride);
            for (k, (own, &alive)) in own.zip(&alive[first..last]).enumerate() {
                if !alive {
                    continue;
                }
                let listed = own
                    .iter()
                    .take_while(|s| s.wall != NO_WALL)
                    .enumerate()
                    .filter(|(_, s)| !s.planar_pass)
                    .map(|(q, _)| (k as u32, (k * stride + q) as u32));
                lists.rest.extend(listed);
            }
            lists.cuts.push((lists.planes.len(), lists.rest.len()));
        }
        lists.plane_const = plane_const.flatten();
        lists.plane_reissner = plane_kind == Some(LawKind::HertzReissner);
    }

    /// Rebuild the Verlet lists (pairs, wall slots, gather lists), carrying contact history over.
    pub(crate) fn rebuild(&mut self) {
        let n = self.position.len();
        self.rebuilds += 1;
        if let Some((point, normal)) = self.removal_plane {
            for i in 0..n {
                if self.alive[i] && normal.dot(self.position[i] - point) < 0.0 {
                    self.alive[i] = false;
                    self.removals.push((self.time, i as u32));
                }
            }
        }
        // ---- particle pairs
        self.grid.candidate_pairs(
            &self.position,
            &self.radius,
            &self.alive,
            self.skin,
            &mut self.candidate_scratch,
        );
        std::mem::swap(&mut self.pairs, &mut self.old_pairs);
        std::mem::swap(&mut self.pair_active, &mut self.old_pair_active);
        std::mem::swap(&mut self.pair_onset, &mut self.old_pair_onset);
        std::mem::swap(&mut self.pair_event, &mut self.old_pair_event);
        self.pairs.clear();
        self.pair_active.clear();
        self.pair_onset.clear();
        self.pair_event.clear();
        let events = self.record_events;
        // open contacts of pairs the new list drops (a removed particle)
        let mut dropped: Vec<usize> = Vec::new();
        let mut old = 0usize;
        for &(i, j) in &self.candidate_scratch {
            // both lists are sorted by (i, j): merge to carry the state of surviving pairs
            while old < self.old_pairs.len()
                && (self.old_pairs[old].i, self.old_pairs[old].j) < (i, j)
            {
                if events {
                    dropped.push(old);
                }
                old += 1;
            }
            if old < self.old_pairs.len()
                && (self.old_pairs[old].i, self.old_pairs[old].j) == (i, j)
            {
                self.pairs.push(self.old_pairs[old]);
                self.pair_active.push(self.old_pair_active[old]);
                self.pair_onset.push(self.old_pair_onset[old]);
                if events {
                    self.pair_event.push(self.old_pair_event[old]);
                }
                old += 1;
            } else {
                self.pairs.push(PairContact {
                    i,
                    j,
                    ..Default::default()
                });
                self.pair_active.push(false);
                self.pair_onset.push(false);
                if events {
                    self.pair_event.push(EventAcc::default());
                }
            }
        }
        if events {
            dropped.extend(old..self.old_pairs.len());
            for k in dropped {
                let (p, acc) = (self.old_pairs[k], self.old_pair_event[k]);
                if self.old_pair_active[k] {
                    self.close_dropped(&acc, p.i, Partner::Particle(p.j));
                }
            }
        }
        self.build_gather_lists();
        // ---- wall slots: walls within reach of each particle (the others are skipped); on
        // a mesh wall, each triangle within reach is a slot of its own
        std::mem::swap(&mut self.wall_slots, &mut self.old_slots);
        let old_stride = self.wall_stride;
        let mut found: Vec<(u32, u32)> = Vec::new();
        let mut start = vec![0usize; n + 1];
        let mut triangles: Vec<u32> = Vec::new();
        let mut stride = 1usize;
        for i in 0..n {
            if self.alive[i] {
                let reach = self.radius[i] + self.skin;
                for (w, wall) in self.walls.iter().enumerate() {
                    let ws = self.wall_state[w];
                    // the particle in the wall's reference frame
                    let p = wall.motion.rotate(-ws.angle, self.position[i] - ws.offset);
                    if let Some(mesh) = wall.mesh() {
                        triangles.clear();
                        mesh.triangles_within(p, reach, &mut triangles);
                        found.extend(triangles.iter().map(|&t| (w as u32, t)));
                    } else if let Some((_, _, d)) = wall.shape.closest(p) {
                        if d < reach {
                            found.push((w as u32, 0));
                        }
                    }
                }
            }
            start[i + 1] = found.len();
            stride = stride.max(start[i + 1] - start[i]);
        }
        self.wall_stride = stride;
        self.wall_slots.clear();
        self.wall_slots.resize(n * stride, WallContact::default());
        if events {
            std::mem::swap(&mut self.wall_event, &mut self.old_wall_event);
            self.wall_event.clear();
            self.wall_event.resize(n * stride, EventAcc::default());
        }
        for i in 0..n {
            for (k, &(wall, triangle)) in found[start[i]..start[i + 1]].iter().enumerate() {
                let carried = self
                    .old_slots
                    .get(i * old_stride..(i + 1) * old_stride)
                    .and_then(|s| {
                        s.iter()
                            .position(|s| s.wall == wall && s.triangle == triangle)
                    });
                self.wall_slots[i * stride + k] = match carried {
                    Some(q) => {
                        if events {
                            let from = i * old_stride + q;
                            self.wall_event[i * stride + k] = self.old_wall_event[from];
                            // carried: not logged as dropped below
                            self.old_wall_event[from].open = false;
                        }
                        self.old_slots[i * old_stride + q]
                    }
                    None => WallContact {
                        wall,
                        triangle,
                        ..Default::default()
                    },
                };
            }
        }
        if events {
            // open contacts of slots the new lists drop (a removed particle, a wall out of
            // reach)
            for k in 0..self.old_wall_event.len() {
                let (acc, wall) = (self.old_wall_event[k], self.old_slots[k].wall);
                if wall != NO_WALL && acc.open {
                    self.close_dropped(&acc, (k / old_stride) as u32, Partner::Wall(wall));
                }
            }
        }
        self.reference_position.clone_from(&self.position);
        for (k, ws) in self.wall_state.iter().enumerate() {
            self.reference_wall_offset[k] = ws.offset;
            self.reference_wall_angle[k] = ws.angle;
        }
        self.refresh_contact_constants();
        self.needs_rebuild = false;
    }
}
