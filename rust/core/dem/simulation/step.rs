//! One step's pipeline: the neighbour lists if due, the force phase (every pair and wall
//! slot writes its own record, in the threads' blocks), the update of the gather lists, the
//! particle phase (gather and advance), and the end of the step (reductions, onset log,
//! travel bound, time, whether to rebuild).

use super::batch::BATCH_SCRATCH;
use super::blocks::{join_parts, split_at_cuts, Clocks, CutLists, ForcePart};
use super::gather::ParticleCtx;
use super::pair::{PairCtx, PairLists};
use super::simd;
use super::state::Flips;
use super::wall::{BlockWalls, WallCtx};
use super::{Simulation, DYNAMIC, PAIR_CHUNK, SKIP_STEPS, TABLE, TABLE_PLANAR};
use crate::dem::effects::Effect;
use crate::error::{DemfemError, Result};
use crate::geometry::Vec3;

impl Simulation {
    /// Whether the next step ends with a recorded [`Frame`] (which needs the step's records).
    ///
    /// [`Frame`]: crate::dem::Frame
    pub(super) fn frame_due_next(&self) -> bool {
        self.record_every > 0 && (self.steps + 1) % self.record_every == 0
    }

    pub(super) fn one_step(&mut self, parallel: bool) -> Result<()> {
        if self.needs_rebuild {
            self.rebuild();
        }
        if self.wall_lists.mode != Some((parallel, self.avx2, self.batched)) {
            self.list_wall_slots(parallel);
        }
        if parallel {
            self.balance_steps += 1;
        }
        match self.effects.bits() {
            TABLE => self.force_and_advance::<TABLE>(parallel),
            TABLE_PLANAR => self.force_and_advance::<TABLE_PLANAR>(parallel),
            _ => self.force_and_advance::<DYNAMIC>(parallel),
        }
        self.finish_step()
    }

    /// Pair phase and particle phase of one step, specialised on the effect set `E`.
    fn force_and_advance<const E: u16>(&mut self, parallel: bool) {
        let stride = self.wall_stride;
        let avx2 = self.avx2;
        // ---- force phase: every pair and every wall slot writes its own record only
        {
            let pair_ctx = PairCtx {
                table: &self.contact_table,
                position: &self.position,
                velocity: &self.velocity,
                omega: &self.omega,
                radius: &self.radius,
                inertia: &self.inertia,
                laws: &self.laws,
                model: self.model,
                effects: self.effects,
                clamp: self.clamp,
                dt: self.dt,
                detail: self.detail,
                avx2,
                batched: self.batched,
                pairs_hertz: self.pairs_hertz,
                pairs_uniform: self.pairs_uniform,
                travel: self.travel,
                min_skip: SKIP_STEPS * self.travel_step,
            };
            let wall_ctx = WallCtx {
                shared: pair_ctx,
                alive: &self.alive,
                walls: &self.walls,
                wall_state: &self.wall_state,
                wall_stride: stride,
            };
            let (pairs, pair_out, pair_const) =
                (&mut self.pairs, &mut self.pair_out, &self.pair_const);
            let (pair_detail, pair_rolling) = (&mut self.pair_detail, &mut self.pair_rolling);
            let (pair_active, pair_wake) = (&mut self.pair_active, &mut self.pair_wake);
            let pair_onset = &mut self.pair_onset;
            let (flips, slots) = (&mut self.chunk_flips, &mut self.wall_slots);
            let (wall_out, wall_detail) = (&mut self.wall_out, &mut self.wall_detail);
            let cut = &self.cut_lists;
            let wall_lists = &self.wall_lists;
            flips.clear();
            flips.resize(pairs.len().div_ceil(PAIR_CHUNK), Flips::default());
            let clock = Clocks::begin(
                &self.phase_clock,
                if parallel { &self.balance_clock } else { &[] },
            );
            let run = |(t, part): (usize, ForcePart<'_>)| {
                let start = clock.start();
                let (first_particle, first_pair) = match t.checked_sub(1) {
                    Some(b) => (cut.particle[b], cut.pair[b]),
                    None => (0, 0),
                };
                // the block's pairs in one call: the batches run on across the chunks of
                // `PAIR_CHUNK` pairs (whose onsets and ends are counted apart), so only the
                // block's last batch is partial
                let konst = &pair_const[first_pair..first_pair + part.pairs.len()];
                let (pairs, lists, flips) = (part.pairs, part.lists, part.flips);
                BATCH_SCRATCH.with_borrow_mut(|b| {
                    simd::pair::<E>(avx2, pairs, lists, konst, flips, &pair_ctx, b)
                });
                let block = match (wall_lists.cuts.get(t), wall_lists.cuts.get(t + 1)) {
                    (Some(a), Some(b)) => BlockWalls {
                        planes: &wall_lists.planes[a.0..b.0],
                        rest: &wall_lists.rest[a.1..b.1],
                        plane_const: wall_lists.plane_const,
                        plane_reissner: wall_lists.plane_reissner,
                    },
                    _ => BlockWalls {
                        planes: &[],
                        rest: &[],
                        plane_const: None,
                        plane_reissner: false,
                    },
                };
                BATCH_SCRATCH.with_borrow_mut(|b| {
                    let (s, o, d) = (part.slots, part.wall_out, part.wall_detail);
                    simd::wall::<E>(avx2, &wall_ctx, first_particle, block, s, o, d, b)
                });
                clock.add(t, 0, start);
            };
            if parallel {
                // one part per thread: the pairs whose first particle is in a block of
                // particles, and that block's wall slots; the particle phase then advances the
                // same block, mostly on the same core (the calling thread always runs part 0)
                let CutLists {
                    pair: pair_cuts,
                    chunk: chunk_cuts,
                    slot: slot_cuts,
                    ..
                } = &self.cut_lists;
                let mut parts = split_at_cuts(pairs, pair_cuts)
                    .zip(split_at_cuts(pair_active, pair_cuts))
                    .zip(split_at_cuts(pair_onset, pair_cuts))
                    .zip(split_at_cuts(pair_wake, pair_cuts))
                    .zip(split_at_cuts(pair_out, pair_cuts))
                    .zip(split_at_cuts(pair_detail, pair_cuts))
                    .zip(split_at_cuts(pair_rolling, pair_cuts))
                    .zip(split_at_cuts(flips, chunk_cuts))
                    .zip(split_at_cuts(slots, slot_cuts))
                    .zip(split_at_cuts(wall_out, slot_cuts))
                    .zip(split_at_cuts(wall_detail, slot_cuts))
                    .map(
                        |((((((((((p, a), st), k), o), d), r), on), s), wo), wd)| ForcePart {
                            pairs: p,
                            lists: PairLists {
                                active: a,
                                onset: st,
                                wake: k,
                                out: o,
                                detail: d,
                                rolling: r,
                            },
                            flips: on,
                            slots: s,
                            wall_out: wo,
                            wall_detail: wd,
                        },
                    )
                    .enumerate()
                    .peekable();
                join_parts(&mut parts, &run);
            } else {
                let whole = ForcePart {
                    pairs,
                    lists: PairLists {
                        active: pair_active,
                        onset: pair_onset,
                        wake: pair_wake,
                        out: pair_out,
                        detail: pair_detail,
                        rolling: pair_rolling,
                    },
                    flips,
                    slots,
                    wall_out,
                    wall_detail,
                };
                run((0, whole));
            }
        }
        if self.record_events {
            self.accumulate_events();
        }
        self.sync_active_lists();
        // ---- particle phase: gather in list order, advance
        {
            let ctx = ParticleCtx {
                pair_rolling: &self.pair_rolling,
                pair_out: &self.pair_out,
                active_base: &self.active_base,
                active_len: &self.active_len,
                active_entry: &self.active_entry,
                radius: &self.radius,
                inv_mass: &self.inv_mass,
                inv_inertia: &self.inv_inertia,
                alive: &self.alive,
                reference_position: &self.reference_position,
                effects: self.effects,
                gravity: self.gravity,
                dt: self.dt,
                wall_stride: stride,
                detail: self.detail,
                avx2,
            };
            if parallel {
                // the blocks of the force phase (see there); one result per block
                let CutLists {
                    particle: cuts,
                    block: result_cuts,
                    ..
                } = &self.cut_lists;
                self.chunk_results.clear();
                self.chunk_results
                    .resize(cuts.len() + 1, (0.0, 0.0, false, 0));
                let mut parts = split_at_cuts(&mut self.position, cuts)
                    .zip(split_at_cuts(&mut self.velocity, cuts))
                    .zip(split_at_cuts(&mut self.omega, cuts))
                    .zip(split_at_cuts(&mut self.contact_force_sum, cuts))
                    .zip(split_at_cuts(&mut self.coordination, cuts))
                    .zip(split_at_cuts(&mut self.wall_coordination, cuts))
                    .zip(split_at_cuts(&mut self.chunk_results, result_cuts))
                    .enumerate()
                    .peekable();
                let (slots, outs) = (&self.wall_slots, &self.wall_out);
                type Part<'c> = (
                    (
                        (
                            (
                                ((&'c mut [Vec3], &'c mut [Vec3]), &'c mut [Vec3]),
                                &'c mut [Vec3],
                            ),
                            &'c mut [u32],
                        ),
                        &'c mut [u32],
                    ),
                    &'c mut [(f64, f64, bool, u32)],
                );
                let clock = Clocks::begin(&self.phase_clock, &self.balance_clock);
                let run = |(t, ((((((x, v), w), f), z), zw), res)): (usize, Part<'_>)| {
                    let start = clock.start();
                    let first = if t == 0 { 0 } else { cuts[t - 1] };
                    let len = x.len();
                    let slots = &slots[first * stride..(first + len) * stride];
                    let outs = &outs[first * stride..(first + len) * stride];
                    res[0] = simd::particle::<E>(avx2, &ctx, first, x, v, w, f, z, zw, slots, outs);
                    clock.add(t, 1, start);
                };
                join_parts(&mut parts, &run);
            } else {
                let clock = Clocks::begin(&self.phase_clock, &[]);
                let start = clock.start();
                let result = simd::particle::<E>(
                    avx2,
                    &ctx,
                    0,
                    &mut self.position,
                    &mut self.velocity,
                    &mut self.omega,
                    &mut self.contact_force_sum,
                    &mut self.coordination,
                    &mut self.wall_coordination,
                    &self.wall_slots,
                    &self.wall_out,
                );
                clock.add(0, 1, start);
                self.chunk_results.clear();
                self.chunk_results.push(result);
            }
        }
    }

    /// End of a step: reduce the chunk results, log onsets, advance time, decide the rebuild.
    fn finish_step(&mut self) -> Result<()> {
        let mut max_disp2: f64 = 0.0;
        let mut bad = false;
        let mut wall_onsets = 0u32;
        let mut max_v2: f64 = 0.0;
        for &(d, v2, b, o) in &self.chunk_results {
            max_disp2 = max_disp2.max(d);
            max_v2 = max_v2.max(v2);
            bad |= b;
            wall_onsets += o;
        }
        if self.record_onsets {
            self.log_onsets(wall_onsets > 0);
        }
        // the travel bound: no particle moved further than |v| Δt this step, up to the
        // rounding of |v|, of the product and of x + v Δt (the slack), and the sum's own
        // rounding (a relative 2ε of the travel)
        self.travel_step = max_v2.sqrt() * self.dt * (1.0 + 1e-12)
            + self.travel_slack
            + 2.0 * f64::EPSILON * self.travel;
        self.travel += self.travel_step;
        self.steps += 1;
        self.time = self.steps as f64 * self.dt;
        if bad {
            return Err(DemfemError::Numerical(format!(
                "non-finite position or velocity at t = {} s (step {}); dt = {:e} s, stable limit {:e} s",
                self.time, self.steps, self.dt, self.stable.limit
            )));
        }
        if self.effects.has(Effect::MovingWalls) {
            self.refresh_wall_state();
        }
        let half_skin = 0.5 * self.skin;
        let mut moved = max_disp2 > half_skin * half_skin;
        for (k, ws) in self.wall_state.iter().enumerate() {
            moved |= (ws.offset - self.reference_wall_offset[k]).length() > half_skin;
            // a rotation by Δθ moves no point of the wall further than reach × |Δθ|
            moved |=
                (ws.angle - self.reference_wall_angle[k]).abs() * self.wall_reach[k] > half_skin;
        }
        self.needs_rebuild = moved;
        if self.record_every > 0 && self.steps % self.record_every == 0 {
            self.frames.push(self.frame());
        }
        Ok(())
    }
}
