//! The threads' blocks: where the parallel step cuts its arrays ([`CutLists`], one thread's
//! part of the force phase in [`ForcePart`]), how the parts are handed out
//! ([`join_parts`], [`split_at_cuts`]), the clocks of the phases ([`Clocks`]) and the cuts
//! themselves, from estimated costs and the blocks' measured times
//! (`Simulation::cut_blocks`).

use super::pair::PairLists;
use super::state::{Flips, PairContact, WallContact, WallDetail, WallOut};
use super::{Simulation, NO_WALL, PAIR_CHUNK};
use crate::dem::material::DemContactLaw;
use crate::geometry::WallShape;
use std::sync::atomic::{AtomicU64, Ordering};

/// Estimated cost of a step's work, in instructions of the anchor table's profile, for the
/// threads' cuts only (`Simulation::cut_blocks`): per particle (its update), per candidate
/// pair (its tests) and per pair in contact on top (the kernel and two gather entries).
const PARTICLE_COST: u64 = 130;
const PAIR_COST: u64 = 40;
const CONTACT_COST: u64 = 140;
/// [`CONTACT_COST`] of the Hertz–Reissner law, whose root the kernel solves too.
const CONTACT_COST_REISSNER: u64 = 200;
/// Per wall slot: a plane's (the belt, four at a time), any other wall's (closest points
/// on a polygon, one slot at a time).
const PLANE_SLOT_COST: u64 = 100;
const SLOT_COST: u64 = 250;
/// The first thread's extra share in the cuts, hundredths of a block: with it, the cut of
/// the anchor table (whose equal particle counts give the first thread 54 % of the cost
/// and ran faster than an equal-cost cut, stop 19) stays where it was.
const FIRST_BLOCK_EXTRA: u64 = 17;
/// Parallel steps the blocks' times are measured over before they move a cut (see
/// `Simulation::cut_blocks`): fewer would cut on noise.
const BALANCE_MIN_STEPS: u64 = 50;

/// Granularity of the threads' particle blocks (64 was too coarse for the measured cuts:
/// 840 particles in steps of 64 swung the default table's cut between two chunks).
const PARTICLE_CHUNK: usize = 16;

/// The positions at which the parallel step cuts each kind of array into the threads'
/// blocks, one per boundary between consecutive blocks. `particle` and `pair` are set with
/// the gather lists; the others are derived from them and the wall stride when those change
/// (`Simulation::derive_cut_lists`), not collected in every step (seven allocations per step
/// on two threads).
#[derive(Debug, Default)]
pub(super) struct CutLists {
    /// Particle arrays: at multiples of `PARTICLE_CHUNK`.
    pub(super) particle: Vec<usize>,
    /// Pair arrays: the first pair whose i is in the next block, rounded to a multiple of
    /// `PAIR_CHUNK`.
    pub(super) pair: Vec<usize>,
    /// The pair chunks' onset counts (a pair cut is a multiple of `PAIR_CHUNK` or the end of
    /// the list).
    pub(super) chunk: Vec<usize>,
    /// Wall slot arrays.
    pub(super) slot: Vec<usize>,
    /// One result per block: 1, 2, ….
    pub(super) block: Vec<usize>,
}

/// One thread's block of the parallel force phase (see [`CutLists`]).
pub(super) struct ForcePart<'a> {
    pub(super) pairs: &'a mut [PairContact],
    /// The block's pair arrays (cut into chunks for the kernels).
    pub(super) lists: PairLists<'a>,
    /// Onsets and ends of each of the block's pair chunks.
    pub(super) flips: &'a mut [Flips],
    pub(super) slots: &'a mut [WallContact],
    pub(super) wall_out: &'a mut [WallOut],
    pub(super) wall_detail: &'a mut [WallDetail],
}

/// Runs `run` on every part, the first on the calling thread, the others offered to the
/// pool's threads through nested `rayon::join`s (cheaper than a scope: no heap-allocated
/// job, and a part no thread has taken yet is run by the caller rather than waited for).
/// The parts come straight from their iterator, not collected first.
pub(super) fn join_parts<T, I, F>(parts: &mut std::iter::Peekable<I>, run: &F)
where
    T: Send,
    I: Iterator<Item = T> + Send,
    F: Fn(T) + Sync,
{
    if let Some(first) = parts.next() {
        if parts.peek().is_none() {
            run(first);
        } else {
            rayon::join(|| run(first), || join_parts(parts, run));
        }
    }
}

/// The clocks a step's phases add their time to: the phase clock of
/// [`Simulation::set_phase_timing`] and the balance clock of the threads' cuts (each empty
/// when off), with the instant the phase began (when a clock runs).
#[derive(Clone, Copy)]
pub(super) struct Clocks<'a> {
    phase: &'a [[AtomicU64; 2]],
    balance: &'a [[AtomicU64; 2]],
    began: Option<std::time::Instant>,
}

/// Nanoseconds from `a` to `b` (0 if `b` is earlier).
fn nanos(a: std::time::Instant, b: std::time::Instant) -> u64 {
    u64::try_from(b.saturating_duration_since(a).as_nanos()).unwrap_or(u64::MAX)
}

impl<'a> Clocks<'a> {
    /// The clocks of a phase that begins now.
    pub(super) fn begin(phase: &'a [[AtomicU64; 2]], balance: &'a [[AtomicU64; 2]]) -> Self {
        let on = !phase.is_empty() || !balance.is_empty();
        Clocks {
            phase,
            balance,
            began: on.then(std::time::Instant::now),
        }
    }

    /// The start of a block's work, if any clock runs.
    pub(super) fn start(&self) -> Option<std::time::Instant> {
        self.began.map(|_| std::time::Instant::now())
    }

    /// Adds the time since `start` to block `block`'s phase `phase`, and to the balance
    /// clock also the wait from the phase's beginning to `start`.
    pub(super) fn add(&self, block: usize, phase: usize, start: Option<std::time::Instant>) {
        let (Some(start), Some(began)) = (start, self.began) else {
            return;
        };
        let now = std::time::Instant::now();
        let busy = nanos(start, now);
        if let Some(c) = self.phase.get(block) {
            c[phase].fetch_add(busy, Ordering::Relaxed);
        }
        if let Some(c) = self.balance.get(block) {
            c[0].fetch_add(busy, Ordering::Relaxed);
            c[1].fetch_add(nanos(began, start), Ordering::Relaxed);
        }
    }
}

/// `s` cut at the ascending positions `cuts` into `cuts.len() + 1` consecutive pieces.
/// An iterator, not a collection: the parallel step cuts a dozen arrays every step, and
/// allocating for each showed in its profile.
pub(super) fn split_at_cuts<'a, T>(
    s: &'a mut [T],
    cuts: &'a [usize],
) -> impl Iterator<Item = &'a mut [T]> + 'a {
    let mut rest = Some(s);
    let mut at = 0;
    let mut cuts = cuts.iter();
    std::iter::from_fn(move || {
        let s = rest.take()?;
        match cuts.next() {
            Some(&c) => {
                let (head, tail) = s.split_at_mut(c - at);
                at = c;
                rest = Some(tail);
                Some(head)
            }
            None => Some(s),
        }
    })
}

impl Simulation {
    /// The threads' blocks of particles and pairs ([`CutLists::particle`], [`CutLists::pair`]),
    /// at equal cost rather than equal particle counts: where the pack has formed among some
    /// particles while the others still ride the belt apart, as in the first second of the
    /// default table, equal counts left one thread 2.3× the other's force phase. The first
    /// cut is at equal estimated cost ([`Simulation::particle_costs`]). Once the blocks have
    /// been timed over `BALANCE_MIN_STEPS` parallel steps, each particle's estimate is
    /// scaled by its block's measured time per unit of estimate, and the cuts go where
    /// every block would end at the same time ([`Simulation::measured_balance`]); until
    /// then the cut stays. The estimates alone still left one thread 1.3–1.9× the other's
    /// force phase in the default table (stop 22). The pairs go with their first particle,
    /// so each thread's gather reads mostly rows its own core wrote. Results do not depend
    /// on the cuts. Needs the gather lists' `pair_start` and the wall slots.
    pub(super) fn cut_blocks(&mut self) {
        let n = self.position.len();
        let parts = self.threads.max(1);
        let cost = self.particle_costs();
        // while too few parallel steps are measured the cut stays (a window longer than the
        // time between rebuilds: early in a run these come every few dozen steps)
        let old = &self.cut_lists.particle;
        let measuring = parts > 1
            && old.len() == parts - 1
            && self.balance_clock.len() == parts
            && self.balance_steps < BALANCE_MIN_STEPS;
        let at = if measuring {
            old.clone()
        } else {
            self.cut_positions(&cost, parts)
        };
        let cuts = &mut self.cut_lists;
        cuts.particle.clear();
        cuts.pair.clear();
        let mut last = (0usize, 0usize);
        for &i in &at {
            let round = |x: usize, unit: usize| (x + unit / 2) / unit * unit;
            let p = round(i, PARTICLE_CHUNK).clamp(last.0, n);
            let start = self
                .pair_start
                .get(p)
                .map_or(self.pairs.len(), |&e| e as usize);
            let e = round(start, PAIR_CHUNK).clamp(last.1, self.pairs.len());
            last = (p, e);
            cuts.particle.push(p);
            cuts.pair.push(e);
        }
        if measuring {
            return;
        }
        // a new window of measurement for the new blocks
        self.balance_clock.clear();
        self.balance_cost.clear();
        self.balance_steps = 0;
        if parts > 1 {
            self.balance_clock
                .extend((0..parts).map(|_| [AtomicU64::new(0), AtomicU64::new(0)]));
            let mut from = 0;
            for b in 0..parts {
                let to = self.cut_lists.particle.get(b).copied().unwrap_or(n).min(n);
                let block = cost.get(from..to).unwrap_or(&[]);
                self.balance_cost.push(block.iter().sum::<u64>() as f64);
                from = to.max(from);
            }
        }
    }

    /// Where the blocks of `parts` threads begin (particle indices, before rounding), given
    /// each particle's estimated cost: at equal measured time once the blocks have been
    /// timed ([`Simulation::measured_balance`]), the estimates of each block's particles
    /// scaled by its measured time per unit of estimate; at equal estimated cost otherwise.
    fn cut_positions(&self, cost: &[u64], parts: usize) -> Vec<usize> {
        let n = cost.len();
        let measured = self.measured_balance(parts);
        let old = &self.cut_lists.particle;
        let weight: Vec<f64> = match &measured {
            Some((rate, _)) => {
                let mut b = 0;
                let mut weight = Vec::with_capacity(n);
                for (i, &c) in cost.iter().enumerate() {
                    while b < old.len() && i >= old[b] {
                        b += 1;
                    }
                    weight.push(c as f64 * rate[b]);
                }
                weight
            }
            None => cost.iter().map(|&c| c as f64).collect(),
        };
        let total: f64 = weight.iter().sum();
        // where each cut sits, as a fraction of the total: measured, the shares that end
        // every block at the same time; on estimates alone, the calling thread (which starts
        // its block first, the others taking theirs from the join) gets FIRST_BLOCK_EXTRA
        // hundredths of a block more, cut t at (t + x)/(parts + x)
        let bounds: Vec<f64> = match measured {
            Some((_, bounds)) => bounds,
            None => {
                let x = FIRST_BLOCK_EXTRA as f64;
                let whole = 100.0 * parts as f64 + x;
                (1..parts).map(|t| (100.0 * t as f64 + x) / whole).collect()
            }
        };
        let mut at = Vec::with_capacity(parts.saturating_sub(1));
        let (mut t, mut sum) = (0usize, 0.0);
        for (i, &w) in weight.iter().enumerate() {
            while t < bounds.len() && sum >= total * bounds[t] {
                at.push(i);
                t += 1;
            }
            sum += w;
        }
        at.resize(parts.saturating_sub(1), n);
        at
    }

    /// Each particle's estimated cost of a step: its update, its candidate pairs and pairs
    /// in contact (those it is the first particle of), its wall slots.
    fn particle_costs(&self) -> Vec<u64> {
        let stride = self.wall_stride.max(1);
        let contact_cost = match self.model {
            DemContactLaw::HertzReissnerMindlin => CONTACT_COST_REISSNER,
            _ => CONTACT_COST,
        };
        let mut cost = vec![PARTICLE_COST; self.position.len()];
        for (p, &on) in self.pairs.iter().zip(&self.pair_active) {
            if let Some(c) = cost.get_mut(p.i as usize) {
                *c += PAIR_COST + contact_cost * u64::from(on);
            }
        }
        for (c, row) in cost.iter_mut().zip(self.wall_slots.chunks_exact(stride)) {
            for s in row.iter().take_while(|s| s.wall != NO_WALL) {
                let plane = matches!(
                    self.walls.get(s.wall as usize).map(|w| &w.shape),
                    Some(WallShape::Plane { .. })
                );
                *c += if plane { PLANE_SLOT_COST } else { SLOT_COST };
            }
        }
        cost
    }

    /// What the blocks measured since they were last cut: each block's busy time per unit
    /// of estimated cost (ns), and where the cuts go (as fractions of the total busy time)
    /// for every block to end at the same time, the later starts of the blocks that wait
    /// for a thread included: block b's busy time becomes (Σ busy + Σ wait)/parts − wait_b.
    /// `None` on one thread, after fewer than `BALANCE_MIN_STEPS` parallel steps, or where a
    /// block has no time or no cost.
    fn measured_balance(&self, parts: usize) -> Option<(Vec<f64>, Vec<f64>)> {
        if parts < 2
            || self.balance_steps < BALANCE_MIN_STEPS
            || self.balance_clock.len() != parts
            || self.balance_cost.len() != parts
            || self.cut_lists.particle.len() != parts - 1
        {
            return None;
        }
        let (mut rate, mut wait) = (Vec::with_capacity(parts), Vec::with_capacity(parts));
        let mut busy_total = 0.0;
        for (clock, &cost) in self.balance_clock.iter().zip(&self.balance_cost) {
            let busy = clock[0].load(Ordering::Relaxed) as f64;
            if busy <= 0.0 || cost <= 0.0 {
                return None;
            }
            rate.push(busy / cost);
            wait.push(clock[1].load(Ordering::Relaxed) as f64);
            busy_total += busy;
        }
        let end = (busy_total + wait.iter().sum::<f64>()) / parts as f64;
        let mut bounds = Vec::with_capacity(parts - 1);
        let mut sum = 0.0;
        for w in &wait[..parts - 1] {
            sum += (end - w).max(0.0);
            bounds.push((sum / busy_total).min(1.0));
        }
        Some((rate, bounds))
    }

    /// The cut positions of [`CutLists`] that follow from its particle and pair cuts and the
    /// wall stride.
    pub(super) fn derive_cut_lists(&mut self) {
        let stride = self.wall_stride;
        let cuts = &mut self.cut_lists;
        cuts.chunk.clear();
        cuts.chunk
            .extend(cuts.pair.iter().map(|e| e.div_ceil(PAIR_CHUNK)));
        cuts.slot.clear();
        cuts.slot.extend(cuts.particle.iter().map(|p| p * stride));
        cuts.block.clear();
        cuts.block.extend(1..=cuts.particle.len());
    }
}

#[cfg(test)]
mod balance_tests {
    use super::*;
    use crate::dem::table::{anchor_scene, TableStart};

    fn packed(threads: usize) -> Simulation {
        let mut scene = anchor_scene(1e8, TableStart::PackedIntoFunnel).unwrap();
        scene.threads = threads;
        Simulation::new(&scene).unwrap()
    }

    fn bits(sim: &Simulation) -> Vec<u64> {
        let mut out = Vec::new();
        for v in sim.positions().iter().chain(sim.velocities()) {
            out.extend([v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]);
        }
        out
    }

    /// Pretend the blocks measured `busy` and `wait` (ns) over `steps` steps, and cut again.
    fn recut(sim: &mut Simulation, busy: [u64; 2], wait: [u64; 2], steps: u64) {
        for (c, (b, w)) in sim.balance_clock.iter().zip(busy.iter().zip(wait)) {
            c[0].store(*b, Ordering::Relaxed);
            c[1].store(w, Ordering::Relaxed);
        }
        sim.balance_steps = steps;
        // what a rebuild runs after listing the pairs and slots
        sim.refresh_contact_constants();
    }

    #[test]
    fn cuts_follow_measured_times_and_change_no_result() {
        let mut a = packed(2);
        let mut reference = packed(1);
        a.step(60).unwrap();
        reference.step(60).unwrap();
        let start = a.block_cuts();
        assert_eq!(start.len(), 1);
        let (est0, est1) = (a.balance_cost[0], a.balance_cost[1]);
        assert!(est0 > 0.0 && est1 > 0.0);
        // too few steps measured: the cut stays
        recut(
            &mut a,
            [3_000_000, 1_000_000],
            [0, 0],
            BALANCE_MIN_STEPS - 1,
        );
        assert_eq!(a.block_cuts(), start);
        // the first block twice as slow per unit of cost as the second, no waits: its cut
        // moves down until the predicted busy times (cost × the rate of the block each
        // particle was in) are equal, to within one chunk of particles
        let costs: Vec<f64> = a.particle_costs().iter().map(|&c| c as f64).collect();
        recut(&mut a, [(2.0 * est0) as u64, est1 as u64], [0, 0], 100);
        let cut = a.block_cuts()[0];
        assert!(cut < start[0], "cut {cut} not below {}", start[0]);
        let rate = |i: usize| if i < start[0] { 2.0 } else { 1.0 };
        let t0: f64 = (0..cut).map(|i| costs[i] * rate(i)).sum();
        let t1: f64 = (cut..costs.len()).map(|i| costs[i] * rate(i)).sum();
        let chunk = (0..costs.len() / PARTICLE_CHUNK)
            .map(|c| {
                (c * PARTICLE_CHUNK..(c + 1) * PARTICLE_CHUNK)
                    .map(|i| costs[i] * rate(i))
                    .sum::<f64>()
            })
            .fold(0.0, f64::max);
        assert!(
            (t0 - t1).abs() <= chunk,
            "predicted busy {t0} / {t1}, chunk {chunk}"
        );
        // equal rates, but the second block starts 20 % of a block late: the first block
        // takes more than half
        let (e0, e1) = (a.balance_cost[0], a.balance_cost[1]);
        let wait = 0.2 * (e0 + e1) / 2.0;
        recut(&mut a, [e0 as u64, e1 as u64], [0, wait as u64], 100);
        let (f0, f1) = (a.balance_cost[0], a.balance_cost[1]);
        assert!(f0 > f1, "first block {f0}, second {f1}");
        // whatever the cuts, the results are those of one thread
        a.step(300).unwrap();
        reference.step(300).unwrap();
        assert_eq!(bits(&a), bits(&reference));
    }
}
