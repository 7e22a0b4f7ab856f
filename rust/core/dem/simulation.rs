//! The DEM simulation: state as structure of arrays, the two-phase step and its contact
//! kernels.
//!
//! One step (leapfrog, velocities stored at half steps):
//! 1. rebuild the Verlet lists if a particle or a wall moved more than half the skin;
//! 2. **force phase** — for every candidate pair and every particle–wall slot, the contact
//!    force from x(t) and v(t − Δt/2) is written into the pair's or slot's own record (no
//!    shared accumulator);
//! 3. **particle phase** — for every particle: the pair forces are gathered in the fixed order
//!    of the particle's pair list, then its wall slots' forces in slot order, and the particle
//!    is advanced: v += F/m Δt, x += v Δt, ω += T/I Δt (with AVX2, four particles per
//!    instruction, the same operations per lane: `batch::advance4`).
//!
//! With several threads, the particles are cut into one contiguous block per thread (at
//! rebuild, `cut_lists`); in the force phase a thread takes the pairs whose first particle is
//! in its block and the block's wall slots, in the particle phase it advances the block. The
//! calling thread always runs block 0, so most of what a thread writes in one phase it reads
//! itself in the next, from its own core's cache, instead of rayon's work stealing moving
//! the blocks between cores every step (on two threads: 1.37× the speed of the work-stealing
//! split, median of seven alternating rounds). The blocks are handed out with nested
//! `rayon::join`s rather than a scope (1.03× on two threads, median of nine alternating
//! rounds). Where the blocks are cut follows the time each block measured since the last
//! cut (`Simulation::cut_blocks`); the results never depend on it.
//!
//! The kernels are monomorphised over the effect set (const generic `E`): the anchor table's
//! set (with and without `planar`) gets a specialised step without effect tests in the inner
//! loops, any other set runs the generic one. Law constants that depend only on the two bodies
//! (E*, G*, √R*, m*, damping prefactor, friction) are derived once per neighbour-list rebuild
//! (`ContactConst`, one table entry per distinct law, R* and m*, which pairs and wall slots
//! index), so a contact costs three square roots (distance, √δ, δ^{1/4}) and one division,
//! plus a square root and two divisions in gross sliding.
//!
//! Contacts are evaluated in batches (module `batch`): a chunk's contacts are found and
//! gathered first, then their geometry, laws and forces are computed in short loops (four
//! contacts per instruction with AVX2), then scattered. One contact at a time, its chain of
//! dependent operations (δ → √δ → δ^{1/4} → f_n → Coulomb cap → scaling) kept the processor
//! waiting; in a batch the chains of many contacts overlap. With AVX2, plane-wall slots (the
//! belt under every sphere) go into the batch four particles at a time, read as lanes rather
//! than copied contact by contact (`batch::plane_slots`). Which wall slots go where is
//! decided once per neighbour list (`Simulation::list_wall_slots`), not by scanning every
//! slot in every step. The one-at-a-time kernels
//! (`pair_kernel`, `wall_kernel`) remain the reference, used with rolling resistance, and
//! the batches reproduce them bit for bit ([`Simulation::set_batched`]).
//!
//! What a step writes is split by who reads it: the state the next step needs (`PairContact`,
//! `WallContact`, 48 and 40 bytes), what the particle phase gathers (`PairOut`, `WallOut`),
//! and what only the records read (`PairDetail`, `WallDetail`), written on the last step of
//! each [`Simulation::step`] call, so the step streams a third fewer cache lines.
//!
//! Every floating-point sum is taken in an order fixed by the lists, never by the thread
//! schedule, so results are bitwise identical for any thread count; the step synchronises
//! twice. Systems below [`PARALLEL_MIN_PARTICLES`] run serially.

use crate::contact::{self, ForceClamp};
use crate::dem::effects::{Effect, EffectSet};
use crate::dem::material::{ContactModel, PairLaw};
use crate::dem::neighbor::CellGrid;
use crate::dem::record::{ContactOnset, ContactRecord, Frame, Partner};
use crate::dem::scene::Scene;
use crate::error::{DemfemError, Result};
use crate::geometry::{Vec3, Wall, WallShape};
use std::sync::atomic::{AtomicU64, Ordering};

mod batch;
use batch::{pair_chunk_batched, wall_chunk_batched, Batch, BATCH, BATCH_SCRATCH};

/// Below this many particles the step runs on the calling thread whatever `threads` says:
/// a rayon fork-join costs microseconds, as much as the whole step of a small system.
pub const PARALLEL_MIN_PARTICLES: usize = 256;
/// Pairs per onset count: onsets and ends are counted per chunk of this many pairs, so the
/// onset log and the gather lists find them without a full scan. A thread's block of pairs
/// starts at a multiple of it, so it is also the granularity of the pair cuts (256 left
/// the default table's 2 000 pairs in eighths). The kernels take a whole block in one call.
const PAIR_CHUNK: usize = 64;
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
/// The batched pair kernel skips a pair out of contact only while it cannot touch for at
/// least this many steps at the last step's speed (see [`wake_travel`]).
const SKIP_STEPS: f64 = 8.0;
/// Granularity of the threads' particle blocks (64 was too coarse for the measured cuts:
/// 840 particles in steps of 64 swung the default table's cut between two chunks).
const PARTICLE_CHUNK: usize = 16;
const NO_WALL: u32 = u32::MAX;

/// A candidate particle pair of the Verlet list with the contact state the step carries: 32
/// bytes, two to a cache line, what the pair phase reads for every candidate (i, j) and for
/// every contact (the spring). Whether the pair is in contact, and whether its contact began
/// at the last force evaluation, are kept apart, in [`Simulation::pair_active`] and
/// [`Simulation::pair_onset`] (one byte per pair; the gather visits only the pairs in
/// contact, from lists of their own), and r_i + r_j is read from the radii: at 48 bytes, with
/// those two inside, the step's lines no longer fitted the 512 kB second-level cache of the
/// machine here (stop 22). What the step produces goes to [`PairOut`] (read by the gather) and, on
/// the last step of a [`Simulation::step`] call, to [`PairDetail`] (read only by the records),
/// so a step streams as few cache lines as it can.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(32))]
pub(crate) struct PairContact {
    pub(crate) i: u32,
    pub(crate) j: u32,
    /// Tangential spring displacement ξ, m (Mindlin history).
    pub(crate) history: Vec3,
}

/// What only the records read of an active pair: the normal and the normal force, written on
/// the last step of each [`Simulation::step`] call (so they describe the last force
/// evaluation whenever the caller can look), and the relative speeds at onset, written when
/// the contact begins.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct PairDetail {
    /// Unit normal from i to j.
    normal: Vec3,
    /// Normal force, N (> 0 compressive).
    normal_force: f64,
    /// Normal and tangential relative speed at onset, m/s.
    onset_normal_speed: f64,
    onset_tangential_speed: f64,
}

/// Constants of one contact (a pair or a particle–wall slot) derived from the pair law, the
/// reduced radius and the reduced mass once per neighbour-list rebuild, so the kernels do no
/// division and no law-table lookup per step. What `f_el`, `k_t` and `c_n` hold depends on
/// `kind`:
/// - [`LawKind::Hertz`] (Hertz–Mindlin, or Hertz–Reissner without shell), with s = √δ:
///   F_el = `f_el` s δ, k_t = `k_t` s, c_n = `c_n` √s, which equal 4/3 E* a δ, 8 G* a and
///   ζ √(2/3 m* 2E* a) for a = √(R* δ);
/// - [`LawKind::HertzReissner`], with u the root of u³ + u² = `s_scale` δ
///   ([`contact::hertz_reissner_root`]): F_el = `f_el` u³, k_t = `k_t` u,
///   c_n = `c_n` √(3u/(2 + 3u)), which equal F, 8 G* √(R* δ_H) with δ_H = (F/k_H)^{2/3}, and
///   ζ √(2/3 m* dF/dδ) (see [`contact::HertzReissnerScaled`]);
/// - [`LawKind::Linear`]: F_el = `f_el` δ, k_t = `k_t`, c_n = `c_n`.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C)]
pub(crate) struct ContactConst {
    r_star: f64,
    /// (k_H/k_R)², 1/m, for [`LawKind::HertzReissner`] (else 0): s = `s_scale` δ.
    s_scale: f64,
    /// Hertz: 4/3 E* √R*; Hertz–Reissner: k_R³/k_H², N; linear: k_n, N/m.
    f_el: f64,
    /// Hertz: 8 G* √R*; Hertz–Reissner: 8 G* √R* k_R/k_H, N/m; linear: k_t, N/m.
    k_t: f64,
    /// Hertz: ζ √(4/3 m* E* √R*); Hertz–Reissner: ζ √(2/3 m* k_R); linear: 2β √(m* k_n)
    /// (the pair law's `linear_damping` = 2β); N·s/m times the powers of s or u above.
    c_n: f64,
    /// c_t / c_n.
    ct_ratio: f64,
    /// Coulomb friction μ.
    mu: f64,
    /// Index of the pair law.
    law: u32,
    /// Which closed form applies.
    kind: LawKind,
}

/// The normal law of a contact, as far as its per-step evaluation goes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) enum LawKind {
    /// Hertz–Mindlin, or Hertz–Reissner–Mindlin without shell compliance.
    #[default]
    Hertz,
    /// Hertz in series with a Reissner shell, Mindlin on the Hertz indentation.
    HertzReissner,
    /// Linear spring–dashpot.
    Linear,
}

impl ContactConst {
    fn new(model: ContactModel, laws: &[PairLaw], law: usize, r_star: f64, m_star: f64) -> Self {
        let l = &laws[law];
        let sr = r_star.sqrt();
        let base = ContactConst {
            r_star,
            s_scale: 0.0,
            f_el: 4.0 / 3.0 * l.e_star * sr,
            k_t: 8.0 * l.g_star * sr,
            c_n: l.zeta * (2.0 / 3.0 * m_star * (2.0 * l.e_star * sr)).sqrt(),
            ct_ratio: l.tangential_damping_ratio,
            mu: l.friction,
            law: law as u32,
            kind: LawKind::Hertz,
        };
        match model {
            ContactModel::HertzMindlin => base,
            ContactModel::HertzReissnerMindlin if l.shell_stiffness.is_infinite() => base,
            ContactModel::HertzReissnerMindlin => {
                // the law's constants were validated (E*, R* > 0, k_R finite > 0)
                let k_h = base.f_el;
                let k_r = l.shell_stiffness;
                let hr = contact::HertzReissnerScaled::new_unchecked(k_h, k_r);
                ContactConst {
                    s_scale: hr.s_per_overlap,
                    f_el: hr.force_scale,
                    k_t: 8.0 * l.g_star * sr * (k_r / k_h),
                    c_n: l.zeta * (2.0 / 3.0 * m_star * k_r).sqrt(),
                    kind: LawKind::HertzReissner,
                    ..base
                }
            }
            ContactModel::LinearSpringDashpot {
                normal_stiffness,
                tangential_stiffness,
            } => ContactConst {
                f_el: normal_stiffness,
                k_t: tangential_stiffness,
                c_n: l.linear_damping * (m_star * normal_stiffness).sqrt(),
                kind: LawKind::Linear,
                ..base
            },
        }
    }
}

/// What the gather needs of a pair, written by the pair phase every step: one 64-byte line
/// per pair, so the gather (which visits pairs in particle order, not memory order) touches
/// one cache line per contact.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(64))]
pub(crate) struct PairOut {
    force: Vec3,
    torque_per_arm: Vec3,
    /// > 0 exactly when the pair is in contact.
    overlap: f64,
}

/// A candidate particle–wall contact slot: the state the step carries and the index of its
/// law constants (40 bytes). Its force and torque go to [`WallOut`], the record-only values
/// to [`WallDetail`], as for pairs.
#[derive(Debug, Clone, Copy)]
pub(crate) struct WallContact {
    pub(crate) wall: u32,
    pub(crate) active: bool,
    pub(crate) onset: bool,
    /// The AVX2 plane pass evaluates this slot (`batch::plane_slots`), so the batched wall
    /// kernel does not list it. Set with the wall lists (`Simulation::list_wall_slots`) when
    /// the neighbour lists or the step's mode change; derived, not saved.
    pub(crate) planar_pass: bool,
    pub(crate) history: Vec3,
    /// Law constants of this particle against this wall: index into the contact table
    /// (`Simulation::contact_table`; derived, not checkpointed).
    pub(crate) k: u32,
}

impl Default for WallContact {
    fn default() -> Self {
        WallContact {
            wall: NO_WALL,
            active: false,
            onset: false,
            planar_pass: false,
            history: Vec3::ZERO,
            k: 0,
        }
    }
}

/// Force (N) and torque (N·m) of an active wall slot on its particle, read by the gather.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C)]
pub(crate) struct WallOut {
    force: Vec3,
    torque: Vec3,
}

/// What only the records read of an active wall slot (see [`PairDetail`]); the contact point
/// is also written at onset.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct WallDetail {
    /// Unit normal from the particle towards the wall.
    normal: Vec3,
    /// Contact point on the wall, m.
    point: Vec3,
    /// Overlap, m.
    overlap: f64,
    /// Normal force, N.
    normal_force: f64,
    onset_normal_speed: f64,
    onset_tangential_speed: f64,
}

/// Current position offset and velocity of each wall.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct WallState {
    offset: Vec3,
    velocity: Vec3,
}

/// The stable time step of a scene and what sets it.
#[derive(Debug, Clone, PartialEq)]
pub struct StableStep {
    /// Largest accepted step, s.
    pub limit: f64,
    /// Which law or criterion sets it.
    pub reason: String,
}

/// A running DEM simulation.
pub struct Simulation {
    // ---- static data
    pub(crate) radius: Vec<f64>,
    pub(crate) mass: Vec<f64>,
    pub(crate) inv_mass: Vec<f64>,
    pub(crate) inertia: Vec<f64>,
    pub(crate) inv_inertia: Vec<f64>,
    pub(crate) material: Vec<u32>,
    pub(crate) tag: Vec<u32>,
    pub(crate) walls: Vec<Wall>,
    pub(crate) laws: Vec<PairLaw>,
    pub(crate) n_materials: usize,
    pub(crate) model: ContactModel,
    pub(crate) effects: EffectSet,
    pub(crate) gravity: Vec3,
    pub(crate) clamp: bool,
    pub(crate) dt: f64,
    pub(crate) stable: StableStep,
    pub(crate) skin: f64,
    pub(crate) threads: usize,
    /// Step with the AVX2 build of the kernels (bitwise the same results; see `simd`).
    avx2: bool,
    /// Evaluate contacts in batches ([`Batch`]; bitwise the same results as one at a time).
    batched: bool,
    /// See [`PairCtx::pairs_hertz`] (set with the contact constants).
    pairs_hertz: bool,
    /// See [`PairCtx::pairs_uniform`] (set with the contact constants).
    pairs_uniform: Option<(u32, f64)>,
    pub(crate) record_every: u64,
    pub(crate) record_onsets: bool,
    /// Outlet plane (point, unit normal towards the kept side).
    pub(crate) removal_plane: Option<(Vec3, Vec3)>,
    // ---- dynamic state (what a checkpoint holds)
    pub(crate) position: Vec<Vec3>,
    pub(crate) velocity: Vec<Vec3>,
    pub(crate) omega: Vec<Vec3>,
    pub(crate) alive: Vec<bool>,
    pub(crate) time: f64,
    pub(crate) steps: u64,
    pub(crate) pairs: Vec<PairContact>,
    /// Whether each pair was in contact at the last force evaluation.
    pub(crate) pair_active: Vec<bool>,
    /// Whether each pair's contact began at the last force evaluation.
    pub(crate) pair_onset: Vec<bool>,
    /// Until when each pair out of contact cannot touch, in units of [`Simulation::travel`]
    /// (m): a pair last found a gap g apart when the travel was D cannot touch while the
    /// travel is below D + g/2 (less a rounding margin), because neither of its particles
    /// has moved further than the travel since. The batched pair kernel skips it until then
    /// (exactly: a pair out of reach and not active does nothing); −∞ for a pair to test.
    /// Reset with the lists; not checkpointed.
    pair_wake: Vec<f64>,
    /// Upper bound, m, on the distance any particle has moved since the lists were built:
    /// the sum over steps of the largest |v| Δt, each rounded up. Derived, not checkpointed.
    travel: f64,
    /// What one step adds to the travel besides the largest |v| Δt, m: a bound on the
    /// rounding of x + v Δt at the coordinates of the scene.
    travel_slack: f64,
    /// What the last step added to the travel, m.
    travel_step: f64,
    pair_out: Vec<PairOut>,
    /// Record-only values of each pair (see [`PairDetail`]).
    pair_detail: Vec<PairDetail>,
    /// Rolling-resistance torque on i (−this on j) of each pair, N·m (`rolling_resistance`).
    pair_rolling: Vec<Vec3>,
    /// Law constants of each pair: index into `contact_table` (derived at rebuild and
    /// restore).
    pair_const: Vec<u32>,
    /// The distinct law constants of the pairs and wall slots (entry 0 unused): on a table of
    /// equal spheres a handful, so the constants stay in L1 instead of 64 bytes per contact
    /// streaming through the caches every step.
    contact_table: Vec<ContactConst>,
    pub(crate) wall_slots: Vec<WallContact>,
    wall_out: Vec<WallOut>,
    wall_detail: Vec<WallDetail>,
    /// This step writes the record-only values (the last step of a [`Simulation::step`] call).
    detail: bool,
    pub(crate) wall_stride: usize,
    pub(crate) reference_position: Vec<Vec3>,
    pub(crate) reference_wall_offset: Vec<Vec3>,
    pub(crate) needs_rebuild: bool,
    // ---- derived, rebuilt from the state
    /// Gather lists of the pairs in contact: `active_entry[active_base[i]..][..active_len[i]]`
    /// holds, in increasing order, 2e for each active pair e in which particle i is the
    /// first particle and 2e + 1 where it is the second (the low bit is the sign bit of the
    /// pair force on it). The room of particle i is the number of its candidate pairs, so
    /// the list never overflows; it is kept in step with `pair_active` by
    /// [`Simulation::sync_active_lists`] after each force phase, from the few contacts that
    /// began or ended.
    active_base: Vec<u32>,
    active_len: Vec<u32>,
    active_entry: Vec<u32>,
    /// `pair_active` as the gather lists hold it.
    pair_listed: Vec<bool>,
    /// The pairs in which particle i is the first particle are
    /// `pairs[pair_start[i]..pair_start[i + 1]]` (the list is sorted by (i, j)).
    pub(crate) pair_start: Vec<u32>,
    /// Where the parallel step splits its work into the threads' blocks (see [`CutLists`]).
    cut_lists: CutLists,
    /// The wall slots of the batched kernels, listed once per neighbour list (see
    /// [`Simulation::list_wall_slots`]).
    wall_lists: WallLists,
    grid: CellGrid,
    candidate_scratch: Vec<(u32, u32)>,
    old_pairs: Vec<PairContact>,
    old_pair_active: Vec<bool>,
    old_pair_onset: Vec<bool>,
    old_slots: Vec<WallContact>,
    wall_state: Vec<WallState>,
    /// Contacts begun and ended in each chunk of `PAIR_CHUNK` pairs at the last force
    /// evaluation.
    chunk_flips: Vec<Flips>,
    /// Per block of the particle phase: (largest squared displacement since the last rebuild,
    /// m², largest squared speed, m²/s², any non-finite value, wall onsets).
    chunk_results: Vec<(f64, f64, bool, u32)>,
    /// Per block: nanoseconds spent in the force phase and in the particle phase, summed
    /// over steps; empty unless [`Simulation::set_phase_timing`] turned the clock on.
    phase_clock: Vec<[AtomicU64; 2]>,
    /// The threads' cuts from measured times ([`Simulation::cut_blocks`]): per block,
    /// nanoseconds of both phases since the blocks were last cut, busy and waiting to start
    /// after the phase began (empty on one thread), the parallel steps they cover, and each
    /// block's estimated cost at that cut.
    balance_clock: Vec<[AtomicU64; 2]>,
    balance_steps: u64,
    balance_cost: Vec<f64>,
    pub(crate) contact_force_sum: Vec<Vec3>,
    pub(crate) coordination: Vec<u32>,
    pub(crate) wall_coordination: Vec<u32>,
    pool: Option<rayon::ThreadPool>,
    // ---- records
    pub(crate) frames: Vec<Frame>,
    pub(crate) onsets: Vec<ContactOnset>,
    pub(crate) rebuilds: u64,
    /// (time, particle) of every removal through the outlet plane.
    pub(crate) removals: Vec<(f64, u32)>,
}

impl std::fmt::Debug for Simulation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Simulation")
            .field("particles", &self.position.len())
            .field("walls", &self.walls.len())
            .field("time", &self.time)
            .field("steps", &self.steps)
            .field("dt", &self.dt)
            .field("effects", &self.effects.names())
            .finish()
    }
}

/// Read-only context of the pair kernel; the wall kernels share it (see [`WallCtx`]).
#[derive(Clone, Copy)]
struct PairCtx<'a> {
    /// The law constants the contacts index (`Simulation::contact_table`).
    table: &'a [ContactConst],
    position: &'a [Vec3],
    velocity: &'a [Vec3],
    omega: &'a [Vec3],
    radius: &'a [f64],
    inertia: &'a [f64],
    laws: &'a [PairLaw],
    model: ContactModel,
    effects: EffectSet,
    clamp: bool,
    dt: f64,
    /// Write the record-only values.
    detail: bool,
    /// The CPU has AVX2 and the step uses it (the batched force pass runs four contacts per
    /// instruction).
    avx2: bool,
    /// Evaluate contacts in batches.
    batched: bool,
    /// Every pair follows the Hertz law ([`LawKind::Hertz`]), so with AVX2 the batched pair
    /// kernel copies the constants without testing the law of each.
    pairs_hertz: bool,
    /// Every pair indexes the same Hertz or Hertz–Reissner entry of `table` and every
    /// particle has the same radius (m): (entry, radius). The batched pair kernel then writes
    /// the constants and radii into its batch once per call instead of once per contact,
    /// and with AVX2 evaluates the law in its lanes.
    pairs_uniform: Option<(u32, f64)>,
    /// The travel bound of this force evaluation, m (see [`Simulation::travel`]).
    travel: f64,
    /// A pair is skipped only if half its gap exceeds this, m: `SKIP_STEPS` times the
    /// travel of the last step.
    min_skip: f64,
}

/// Read-only context of the wall kernels (run in the force phase, next to the pairs).
struct WallCtx<'a> {
    /// State, laws and settings shared with the pair kernel.
    shared: PairCtx<'a>,
    alive: &'a [bool],
    walls: &'a [Wall],
    wall_state: &'a [WallState],
    wall_stride: usize,
}

/// Read-only context of the particle phase.
struct ParticleCtx<'a> {
    pair_rolling: &'a [Vec3],
    pair_out: &'a [PairOut],
    /// The gather lists (see [`Simulation::active_entry`]).
    active_base: &'a [u32],
    active_len: &'a [u32],
    active_entry: &'a [u32],
    radius: &'a [f64],
    inv_mass: &'a [f64],
    inv_inertia: &'a [f64],
    alive: &'a [bool],
    reference_position: &'a [Vec3],
    effects: EffectSet,
    gravity: Vec3,
    dt: f64,
    wall_stride: usize,
    /// Write the per-particle records (contact force sum, coordination numbers).
    detail: bool,
    /// Advance four particles per AVX2 instruction (`batch::advance4`).
    avx2: bool,
}

/// Tangential force with Mindlin history, rotated onto the current tangent plane, and the
/// Coulomb cap. Returns the force on the first body and updates `history`.
#[inline(always)]
fn tangential_force(
    history: &mut Vec3,
    normal: Vec3,
    v_t: Vec3,
    k_t: f64,
    c_t: f64,
    cap: f64,
    dt: f64,
) -> Vec3 {
    // follow the contact plane: drop the spring's normal part. The length lost per step is
    // (Ω Δt)²/2 of it for a contact turning at rate Ω, negligible over a contact's life, and
    // saves a square root and a division per contact and step.
    let mut xi = *history;
    xi -= xi.dot(normal) * normal;
    xi += v_t * dt;
    let mut f_t = -k_t * xi - c_t * v_t;
    let f2 = f_t.length_squared();
    if f2 > cap * cap {
        // gross sliding: the force sits on the cone; the spring carries it all
        f_t *= cap / f2.sqrt();
        xi = if k_t > 0.0 {
            f_t * (-1.0 / k_t)
        } else {
            Vec3::ZERO
        };
    }
    *history = xi;
    f_t
}

/// Contacts begun (onsets) and ended in one chunk of the pair list at one force evaluation.
#[derive(Debug, Clone, Copy, Default)]
struct Flips {
    onsets: u32,
    ends: u32,
}

/// The per-pair arrays of one block of the pair list that the pair kernels write, cut to
/// the block (index e = pair − block start).
struct PairLists<'a> {
    /// In contact at the last force evaluation.
    active: &'a mut [bool],
    /// The contact began at the last force evaluation.
    onset: &'a mut [bool],
    /// See [`Simulation::pair_wake`].
    wake: &'a mut [f64],
    out: &'a mut [PairOut],
    detail: &'a mut [PairDetail],
    rolling: &'a mut [Vec3],
}

/// The positions at which the parallel step cuts each kind of array into the threads'
/// blocks, one per boundary between consecutive blocks. `particle` and `pair` are set with
/// the gather lists; the others are derived from them and the wall stride when those change
/// (`Simulation::derive_cut_lists`), not collected in every step (seven allocations per step
/// on two threads).
#[derive(Debug, Default)]
struct CutLists {
    /// Particle arrays: at multiples of `PARTICLE_CHUNK`.
    particle: Vec<usize>,
    /// Pair arrays: the first pair whose i is in the next block, rounded to a multiple of
    /// `PAIR_CHUNK`.
    pair: Vec<usize>,
    /// The pair chunks' onset counts (a pair cut is a multiple of `PAIR_CHUNK` or the end of
    /// the list).
    chunk: Vec<usize>,
    /// Wall slot arrays.
    slot: Vec<usize>,
    /// One result per block: 1, 2, ….
    block: Vec<usize>,
}

/// One thread's block of the parallel force phase (see [`CutLists`]).
struct ForcePart<'a> {
    pairs: &'a mut [PairContact],
    /// The block's pair arrays (cut into chunks for the kernels).
    lists: PairLists<'a>,
    /// Onsets and ends of each of the block's pair chunks.
    flips: &'a mut [Flips],
    slots: &'a mut [WallContact],
    wall_out: &'a mut [WallOut],
    wall_detail: &'a mut [WallDetail],
}

/// The wall slots the batched wall kernel evaluates, listed when the neighbour lists (or the
/// step's mode) change rather than found by scanning every slot each step. Per block of the
/// force phase (`cuts`: the block boundaries in both lists).
#[derive(Debug, Default)]
struct WallLists {
    /// Groups of the AVX2 plane pass: (first particle relative to the block's first, slot
    /// column); the four particles from there hold the same plane in that column, with the
    /// constants of a Hertz law, or with those of a Hertz–Reissner law where
    /// `plane_reissner`, and are alive.
    planes: Vec<(u32, u32)>,
    /// Every group's law is Hertz–Reissner (else every group's is Hertz): the law of the
    /// first group taken, which the others must share.
    plane_reissner: bool,
    /// Every other slot holding a wall, of alive particles: (particle, slot), both relative
    /// to the block's first.
    rest: Vec<(u32, u32)>,
    /// Block b's groups are `planes[cuts[b].0..cuts[b + 1].0]`, its slots
    /// `rest[cuts[b].1..cuts[b + 1].1]`.
    cuts: Vec<(usize, usize)>,
    /// The entry of the contact table every slot of every group indexes, if they all index
    /// one: the plane pass then writes the constants into its batch once, not per group.
    plane_const: Option<u32>,
    /// The (parallel, AVX2, batched) mode the lists were made for; `None` once the neighbour
    /// lists change.
    mode: Option<(bool, bool, bool)>,
}

/// One block's part of the [`WallLists`].
#[derive(Clone, Copy)]
struct BlockWalls<'a> {
    planes: &'a [(u32, u32)],
    rest: &'a [(u32, u32)],
    /// [`WallLists::plane_const`].
    plane_const: Option<u32>,
    /// [`WallLists::plane_reissner`].
    plane_reissner: bool,
}

/// Runs `run` on every part, the first on the calling thread, the others offered to the
/// pool's threads through nested `rayon::join`s (cheaper than a scope: no heap-allocated
/// job, and a part no thread has taken yet is run by the caller rather than waited for).
/// The parts come straight from their iterator, not collected first.
fn join_parts<T, I, F>(parts: &mut std::iter::Peekable<I>, run: &F)
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
struct Clocks<'a> {
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
    fn begin(phase: &'a [[AtomicU64; 2]], balance: &'a [[AtomicU64; 2]]) -> Self {
        let on = !phase.is_empty() || !balance.is_empty();
        Clocks {
            phase,
            balance,
            began: on.then(std::time::Instant::now),
        }
    }

    /// The start of a block's work, if any clock runs.
    fn start(&self) -> Option<std::time::Instant> {
        self.began.map(|_| std::time::Instant::now())
    }

    /// Adds the time since `start` to block `block`'s phase `phase`, and to the balance
    /// clock also the wait from the phase's beginning to `start`.
    fn add(&self, block: usize, phase: usize, start: Option<std::time::Instant>) {
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
fn split_at_cuts<'a, T>(
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

/// Whether the step may use its AVX2 build: the CPU has AVX2 and `DEMFEM_NO_AVX2` is unset
/// (the variable forces the baseline build, e.g. to compare the two).
fn cpu_has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::env::var_os("DEMFEM_NO_AVX2").is_none() && std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// `E` value of the kernels' const generic that reads the effect set at run time; any other
/// value is the effect bit set itself, so `on::<E>` folds to a constant and the specialised
/// kernels carry no effect tests (see [`Simulation::step`] for the specialised sets).
const DYNAMIC: u16 = u16::MAX;

/// The anchor table's effects (gravity, belt, friction, rotation, damping): a specialised step.
const TABLE: u16 = Effect::Gravity as u16
    | Effect::Belt as u16
    | Effect::Friction as u16
    | Effect::Rotation as u16
    | Effect::Damping as u16;
/// The upright-cartridge table: [`TABLE`] plus planar motion.
const TABLE_PLANAR: u16 = TABLE | Effect::Planar as u16;

/// Whether effect `e` is on: a compile-time constant unless `E` is [`DYNAMIC`].
#[inline(always)]
fn on<const E: u16>(runtime: EffectSet, e: Effect) -> bool {
    if E == DYNAMIC {
        runtime.has(e)
    } else {
        E & e as u16 != 0
    }
}

/// Elastic normal force, damping coefficient and tangential stiffness of a contact at
/// overlap δ from its precomputed constants (see [`ContactConst`] for the closed forms).
#[inline(always)]
fn law_at<const E: u16>(
    k: &ContactConst,
    _model: ContactModel,
    _laws: &[PairLaw],
    effects: EffectSet,
    overlap: f64,
) -> (f64, f64, f64) {
    let damping = on::<E>(effects, Effect::Damping);
    match k.kind {
        LawKind::Hertz => {
            let s = overlap.sqrt();
            let c_n = if damping { k.c_n * s.sqrt() } else { 0.0 };
            (k.f_el * s * overlap, c_n, k.k_t * s)
        }
        LawKind::HertzReissner => {
            let u = contact::hertz_reissner_root(k.s_scale * overlap);
            // dF/dδ = k_R 3u/(2 + 3u), so c_n = ζ √(2/3 m* dF/dδ) = c_n √(3u/(2 + 3u))
            let c_n = if damping {
                let w = 3.0 * u;
                k.c_n * (w / (2.0 + w)).sqrt()
            } else {
                0.0
            };
            (k.f_el * (u * u * u), c_n, k.k_t * u)
        }
        LawKind::Linear => {
            let c_n = if damping { k.c_n } else { 0.0 };
            (k.f_el * overlap, c_n, k.k_t)
        }
    }
}

/// The centre distance x_j − x_i and its square when pair `p` touches; otherwise ends a
/// contact that was active (flags, history, the gather's overlap) and returns the squared
/// distance and whether a contact ended as the error. Shared by [`pair_kernel`] and the
/// batched kernel.
#[inline(always)]
fn pair_in_reach(
    p: &mut PairContact,
    active: &mut bool,
    onset: &mut bool,
    out: &mut PairOut,
    position: &[Vec3],
    reach2: f64,
) -> std::result::Result<(Vec3, f64), (f64, bool)> {
    let d = position[p.j as usize] - position[p.i as usize];
    let dist2 = d.length_squared();
    if dist2 >= reach2 || dist2 == 0.0 {
        // an inactive pair has nothing to reset: its output slot already reads "no contact"
        // (onset is only ever set together with active)
        let ended = *active;
        if ended {
            *active = false;
            *onset = false;
            p.history = Vec3::ZERO;
            out.overlap = 0.0;
        }
        return Err((dist2, ended));
    }
    Ok((d, dist2))
}

/// The travel (see [`Simulation::pair_wake`]) below which a pair whose centres are
/// √`dist2` apart, `r_sum` (m) needed to touch, found so when the travel was `travel`,
/// cannot touch: each particle moves at most the travel's growth, so the gap closes at most
/// twice as fast. The margin (a relative 1e-9 of the gap and 64 ε r_sum) covers the rounding
/// of the distances, far below any physical length of a scene. A pair that could touch
/// within a few steps (half its gap below `min_skip`, m) is tested every step instead
/// (−∞): the kernel's skip test then follows a steady pattern the branch predictor learns,
/// rather than turning every few steps.
#[inline(always)]
fn wake_travel(travel: f64, dist2: f64, r_sum: f64, min_skip: f64) -> f64 {
    // within r_sum + 2 min_skip the pair is tested every step: decided without the square
    // root (a pair at the border may go either way; both are exact)
    let near = r_sum + 2.0 * min_skip;
    if dist2 <= near * near {
        return f64::NEG_INFINITY;
    }
    let gap = dist2.sqrt() - r_sum;
    let half = 0.5 * (gap * (1.0 - 1e-9) - 64.0 * f64::EPSILON * r_sum);
    if half > min_skip {
        travel + half
    } else {
        f64::NEG_INFINITY
    }
}

/// Where and how a particle of radius `r` at `x` touches the wall of slot `s`.
struct WallTouch {
    /// Contact point on the wall, m.
    point: Vec3,
    /// Unit normal from the particle towards the wall.
    n: Vec3,
    /// Overlap, m.
    overlap: f64,
    /// Lever arm of the particle, m.
    arm: f64,
    /// Velocity of the wall's material at the contact (motion plus belt), m/s.
    wall_v: Vec3,
}

/// The contact of slot `s` when the particle touches its wall; otherwise ends a contact that
/// was active and returns `None`. Shared by [`wall_kernel`] and the batched kernel.
#[inline(always)]
fn wall_touch<const E: u16>(
    s: &mut WallContact,
    x: Vec3,
    r: f64,
    c: &WallCtx<'_>,
) -> Option<WallTouch> {
    let wall = &c.walls[s.wall as usize];
    // fixed walls (no moving_walls effect) sit at offset 0 with velocity 0: skip both
    let moving = on::<E>(c.shared.effects, Effect::MovingWalls);
    let ws = if moving {
        c.wall_state[s.wall as usize]
    } else {
        WallState::default()
    };
    let Some((point, out_normal, dist)) = wall_hit(wall, x, moving.then_some(ws.offset), r) else {
        end_wall_contact(s);
        return None;
    };
    let n = -out_normal; // from the particle towards the wall
    Some(WallTouch {
        point,
        n,
        overlap: r - dist,
        arm: dist.max(0.0),
        wall_v: wall_velocity::<E>(wall, ws, n, c.shared.effects),
    })
}

/// Slot `s` out of reach of its wall: ends a contact that was active.
#[inline(always)]
fn end_wall_contact(s: &mut WallContact) {
    if s.active {
        s.active = false;
        s.history = Vec3::ZERO;
    }
    s.onset = false;
}

/// Velocity of the wall's material at a contact with normal `n` (particle towards wall),
/// m/s: the wall's motion (`ws`, zero without `moving_walls`) plus the belt's surface velocity
/// tangent to the contact.
#[inline(always)]
fn wall_velocity<const E: u16>(wall: &Wall, ws: WallState, n: Vec3, effects: EffectSet) -> Vec3 {
    let moving = on::<E>(effects, Effect::MovingWalls);
    let mut wall_v = ws.velocity;
    if on::<E>(effects, Effect::Belt) {
        let s_v = wall.surface_velocity;
        let belt = s_v - s_v.dot(n) * n;
        wall_v = if moving { wall_v + belt } else { belt };
    }
    wall_v
}

/// Force of one candidate pair; returns whether a contact began.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn pair_kernel<const E: u16>(
    p: &mut PairContact,
    active: &mut bool,
    onset_flag: &mut bool,
    k: &ContactConst,
    out: &mut PairOut,
    detail: &mut PairDetail,
    rolling_torque: &mut Vec3,
    c: &PairCtx<'_>,
) -> Flips {
    let r_sum = c.radius[p.i as usize] + c.radius[p.j as usize];
    let (d, dist2) = match pair_in_reach(p, active, onset_flag, out, c.position, r_sum * r_sum) {
        Ok(hit) => hit,
        Err((_, ended)) => {
            return Flips {
                onsets: 0,
                ends: ended as u32,
            }
        }
    };
    let (i, j) = (p.i as usize, p.j as usize);
    let dist = dist2.sqrt();
    // rounding can give dist = r_sum for dist² just below r_sum²; keep the overlap positive,
    // the gather's activity test
    let overlap = (r_sum - dist).max(f64::MIN_POSITIVE);
    let n = d * (1.0 / dist); // one division instead of three
    let rotation = on::<E>(c.effects, Effect::Rotation);
    let mut v_rel = c.velocity[i] - c.velocity[j];
    if rotation {
        let arm_i = c.radius[i] - 0.5 * overlap;
        let arm_j = c.radius[j] - 0.5 * overlap;
        v_rel += (arm_i * c.omega[i] + arm_j * c.omega[j]).cross(n);
    }
    let v_n = v_rel.dot(n); // > 0 approaching
    let onset = !*active;
    *active = true;
    *onset_flag = onset;
    let v_t = v_rel - v_n * n;
    if onset {
        detail.onset_normal_speed = v_n;
        detail.onset_tangential_speed = v_t.length();
    }
    let (f_el, c_n, k_t) = law_at::<E>(k, c.model, c.laws, c.effects, overlap);
    let mut f_n = f_el + c_n * v_n;
    if c.clamp && f_n < 0.0 {
        f_n = 0.0;
    }
    let mut force = -f_n * n;
    let mut torque_per_arm = Vec3::ZERO;
    if on::<E>(c.effects, Effect::Friction) {
        let f_t = tangential_force(
            &mut p.history,
            n,
            v_t,
            k_t,
            c_n * k.ct_ratio,
            k.mu * f_n.max(0.0),
            c.dt,
        );
        force += f_t;
        if rotation {
            torque_per_arm = n.cross(f_t);
        }
    }
    if on::<E>(c.effects, Effect::RollingResistance) {
        let law = &c.laws[k.law as usize];
        let w_rel = c.omega[i] - c.omega[j];
        let w_roll = w_rel - w_rel.dot(n) * n;
        let w_mag = w_roll.length();
        if w_mag > 0.0 {
            let i_star = c.inertia[i] * c.inertia[j] / (c.inertia[i] + c.inertia[j]);
            // constant torque, but never more than what stops the relative rolling in one step
            let m = (law.rolling_friction * k.r_star * f_n.max(0.0)).min(i_star * w_mag / c.dt);
            *rolling_torque = -m / w_mag * w_roll;
        } else {
            *rolling_torque = Vec3::ZERO;
        }
    }
    if c.detail {
        detail.normal = n;
        detail.normal_force = f_n;
    }
    *out = PairOut {
        force,
        torque_per_arm,
        overlap,
    };
    Flips {
        onsets: onset as u32,
        ends: 0,
    }
}

/// Pair kernels of one block of the pair list (starting at a multiple of `PAIR_CHUNK`); the
/// contacts begun and ended are added to `flips`, one entry per `PAIR_CHUNK` pairs.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn pair_chunk<const E: u16>(
    chunk: &mut [PairContact],
    lists: PairLists<'_>,
    konst: &[u32],
    flips: &mut [Flips],
    c: &PairCtx<'_>,
    batch: &mut Batch,
) {
    if c.batched && !on::<E>(c.effects, Effect::RollingResistance) {
        return match c.pairs_uniform {
            Some(_) if c.avx2 => {
                pair_chunk_batched::<E, true>(chunk, lists, konst, flips, c, batch)
            }
            _ => pair_chunk_batched::<E, false>(chunk, lists, konst, flips, c, batch),
        };
    }
    // one at a time: every pair is tested (its wake stays a valid bound, see
    // `Simulation::pair_wake`, as the travel keeps growing)
    let PairLists {
        active,
        onset,
        out,
        detail,
        rolling,
        ..
    } = lists;
    for (e, ((((((p, a), s), o), d), r), k)) in chunk
        .iter_mut()
        .zip(active.iter_mut())
        .zip(onset.iter_mut())
        .zip(out.iter_mut())
        .zip(detail.iter_mut())
        .zip(rolling.iter_mut())
        .zip(konst)
        .enumerate()
    {
        let f = pair_kernel::<E>(p, a, s, &c.table[*k as usize], o, d, r, c);
        if let Some(chunk_flips) = flips.get_mut(e / PAIR_CHUNK) {
            chunk_flips.onsets += f.onsets;
            chunk_flips.ends += f.ends;
        }
    }
}

/// The kernel entry points ([`pair_chunk`], [`wall_chunk`], [`particle_chunk`]) compiled a
/// second time for AVX2, and chosen per chunk by `avx2` (set when the CPU has it; see
/// [`cpu_has_avx2`]). The AVX2 build runs the same IEEE operations in the same order (Rust
/// never fuses a multiply and an add on its own), so results are bitwise those of the
/// baseline build; the VEX three-operand encoding drops most of the register moves SSE2
/// needs around glam's three-component vectors.
mod simd {
    use super::*;

    /// `$name(avx2, args…)` calls `$inner::<E>(args…)`, through `$avx` (the same body
    /// compiled with AVX2 enabled) when `avx2` is set.
    macro_rules! avx2_dispatch {
        ($name:ident, $avx:ident, $inner:ident, ($($arg:ident: $ty:ty),*) -> $ret:ty) => {
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2")]
            #[allow(clippy::too_many_arguments)]
            fn $avx<const E: u16>($($arg: $ty),*) -> $ret {
                $inner::<E>($($arg),*)
            }

            #[inline(always)]
            #[allow(clippy::too_many_arguments)]
            pub(super) fn $name<const E: u16>(avx2: bool, $($arg: $ty),*) -> $ret {
                #[cfg(target_arch = "x86_64")]
                if avx2 {
                    // SAFETY: `avx2` is true only when the CPU reported AVX2.
                    return unsafe { $avx::<E>($($arg),*) };
                }
                let _ = avx2;
                $inner::<E>($($arg),*)
            }
        };
    }

    avx2_dispatch!(pair, pair_chunk_avx2, pair_chunk, (
        chunk: &mut [PairContact],
        lists: PairLists<'_>,
        konst: &[u32],
        flips: &mut [Flips],
        c: &PairCtx<'_>,
        batch: &mut Batch
    ) -> ());

    avx2_dispatch!(wall, wall_chunk_avx2, wall_chunk, (
        c: &WallCtx<'_>,
        first: usize,
        lists: BlockWalls<'_>,
        slots: &mut [WallContact],
        out: &mut [WallOut],
        detail: &mut [WallDetail],
        batch: &mut Batch
    ) -> ());

    avx2_dispatch!(particle, particle_chunk_avx2, particle_chunk, (
        c: &ParticleCtx<'_>,
        first: usize,
        position: &mut [Vec3],
        velocity: &mut [Vec3],
        omega: &mut [Vec3],
        force_sum: &mut [Vec3],
        coordination: &mut [u32],
        wall_coordination: &mut [u32],
        slots: &[WallContact],
        wall_out: &[WallOut]
    ) -> (f64, f64, bool, u32));
}

/// Closest point, unit normal (wall → x) and distance of a wall slot when the sphere of
/// radius r touches it. Half-spaces (the belt) by hand: one dot product, nothing else when
/// out of reach.
/// `offset` is `None` for walls that do not move (no `moving_walls` effect).
#[inline(always)]
fn wall_hit(wall: &Wall, x: Vec3, offset: Option<Vec3>, r: f64) -> Option<(Vec3, Vec3, f64)> {
    match &wall.shape {
        WallShape::Plane { point, normal } => {
            let p = offset.map_or(x, |o| x - o);
            let d = normal.dot(p - *point);
            if d < r {
                let q = p - d * *normal;
                Some((offset.map_or(q, |o| q + o), *normal, d))
            } else {
                None
            }
        }
        _ => match wall.closest_at(x, offset.unwrap_or(Vec3::ZERO)) {
            Some(h) if h.2 < r => Some(h),
            _ => None,
        },
    }
}

/// Force and torque of one particle–wall slot on particle i, stored in the slot with the
/// contact state; flags onset.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn wall_kernel<const E: u16>(
    s: &mut WallContact,
    o: &mut WallOut,
    detail: &mut WallDetail,
    i: usize,
    x: Vec3,
    v: Vec3,
    w: Vec3,
    c: &WallCtx<'_>,
) {
    let r = c.shared.radius[i];
    let Some(WallTouch {
        point,
        n,
        overlap,
        arm,
        wall_v,
    }) = wall_touch::<E>(s, x, r, c)
    else {
        return;
    };
    let rotation = on::<E>(c.shared.effects, Effect::Rotation);
    let mut v_rel = v - wall_v;
    if rotation {
        v_rel += (arm * w).cross(n);
    }
    let v_n = v_rel.dot(n);
    let onset = !s.active;
    s.active = true;
    s.onset = onset;
    let v_t = v_rel - v_n * n;
    if onset {
        detail.onset_normal_speed = v_n;
        detail.onset_tangential_speed = v_t.length();
        detail.point = point;
    }
    let kk = &c.shared.table[s.k as usize];
    let (f_el, c_n, k_t) =
        law_at::<E>(kk, c.shared.model, c.shared.laws, c.shared.effects, overlap);
    let (ct_ratio, mu, law) = (kk.ct_ratio, kk.mu, kk.law as usize);
    let mut f_n = f_el + c_n * v_n;
    if c.shared.clamp && f_n < 0.0 {
        f_n = 0.0;
    }
    let mut force = -f_n * n;
    let mut torque = Vec3::ZERO;
    if on::<E>(c.shared.effects, Effect::Friction) {
        let f_t = tangential_force(
            &mut s.history,
            n,
            v_t,
            k_t,
            c_n * ct_ratio,
            mu * f_n.max(0.0),
            c.shared.dt,
        );
        force += f_t;
        if rotation {
            torque = arm * n.cross(f_t);
        }
    }
    if on::<E>(c.shared.effects, Effect::RollingResistance) {
        let law = &c.shared.laws[law];
        let w_roll = w - w.dot(n) * n;
        let w_mag = w_roll.length();
        if w_mag > 0.0 {
            let m = (law.rolling_friction * r * f_n.max(0.0))
                .min(c.shared.inertia[i] * w_mag / c.shared.dt);
            torque -= m / w_mag * w_roll;
        }
    }
    *o = WallOut { force, torque };
    if c.shared.detail {
        *detail = WallDetail {
            normal: n,
            point,
            overlap,
            normal_force: f_n,
            ..*detail
        };
    }
}

/// Wall kernels of the particles of one chunk starting at `first` (their slots).
#[inline(always)]
fn wall_chunk<const E: u16>(
    c: &WallCtx<'_>,
    first: usize,
    lists: BlockWalls<'_>,
    slots: &mut [WallContact],
    out: &mut [WallOut],
    detail: &mut [WallDetail],
    batch: &mut Batch,
) {
    let stride = c.wall_stride;
    if c.shared.batched && !on::<E>(c.shared.effects, Effect::RollingResistance) && stride <= BATCH
    {
        wall_chunk_batched::<E>(c, first, lists, slots, out, detail, batch);
        return;
    }
    for (k, ((slots, out), detail)) in slots
        .chunks_exact_mut(stride)
        .zip(out.chunks_exact_mut(stride))
        .zip(detail.chunks_exact_mut(stride))
        .enumerate()
    {
        let i = first + k;
        if !c.alive[i] {
            continue;
        }
        let (x, v, w) = (
            c.shared.position[i],
            c.shared.velocity[i],
            c.shared.omega[i],
        );
        for ((s, o), d) in slots.iter_mut().zip(out.iter_mut()).zip(detail.iter_mut()) {
            if s.wall == NO_WALL {
                break;
            }
            wall_kernel::<E>(s, o, d, i, x, v, w, c);
        }
    }
}

/// A running sum of vectors (glam's `+=`, component by component). On x86_64 it keeps x
/// and y in one SSE2 register and z apart: left to itself, LLVM packs the gather's force and
/// torque sums into 256-bit shapes that need a lane-crossing `vpermpd` per contact (3 µops
/// on first-generation Zen).
#[derive(Clone, Copy)]
struct Sum3 {
    #[cfg(target_arch = "x86_64")]
    xy: std::arch::x86_64::__m128d,
    #[cfg(not(target_arch = "x86_64"))]
    xy: (f64, f64),
    z: f64,
}

impl Sum3 {
    #[inline(always)]
    fn zero() -> Self {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: SSE2 is part of the x86_64 baseline.
        let xy = unsafe { std::arch::x86_64::_mm_setzero_pd() };
        #[cfg(not(target_arch = "x86_64"))]
        let xy = (0.0, 0.0);
        Sum3 { xy, z: 0.0 }
    }

    /// Adds s v, formed as glam's `v * s` (each component times s; the product commutes).
    #[inline(always)]
    fn add_scaled(&mut self, s: f64, v: Vec3) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: SSE2 is part of the x86_64 baseline.
        unsafe {
            use std::arch::x86_64::*;
            let p = _mm_mul_pd(_mm_setr_pd(v.x, v.y), _mm_set1_pd(s));
            self.xy = _mm_add_pd(self.xy, p);
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            self.xy = (self.xy.0 + v.x * s, self.xy.1 + v.y * s);
        }
        self.z += v.z * s;
    }

    /// Adds v with its sign bits flipped by `flip` (0 or the sign bit): bitwise v times +1.0
    /// or −1.0 (multiplying by ±1 is exact), without the multiply.
    #[inline(always)]
    fn add_flipped(&mut self, flip: u64, v: Vec3) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: SSE2 is part of the x86_64 baseline.
        unsafe {
            use std::arch::x86_64::*;
            let m = _mm_castsi128_pd(_mm_set1_epi64x(flip as i64));
            self.xy = _mm_add_pd(self.xy, _mm_xor_pd(_mm_setr_pd(v.x, v.y), m));
            self.z += _mm_cvtsd_f64(_mm_xor_pd(_mm_set_sd(v.z), m));
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let f = |x: f64| f64::from_bits(x.to_bits() ^ flip);
            self.xy = (self.xy.0 + f(v.x), self.xy.1 + f(v.y));
            self.z += f(v.z);
        }
    }

    /// Adds v.
    #[inline(always)]
    fn add(&mut self, v: Vec3) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: SSE2 is part of the x86_64 baseline.
        unsafe {
            use std::arch::x86_64::*;
            self.xy = _mm_add_pd(self.xy, _mm_setr_pd(v.x, v.y));
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            self.xy = (self.xy.0 + v.x, self.xy.1 + v.y);
        }
        self.z += v.z;
    }

    #[inline(always)]
    fn get(self) -> Vec3 {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: SSE2 is part of the x86_64 baseline.
        let (x, y) = unsafe {
            use std::arch::x86_64::*;
            (
                _mm_cvtsd_f64(self.xy),
                _mm_cvtsd_f64(_mm_unpackhi_pd(self.xy, self.xy)),
            )
        };
        #[cfg(not(target_arch = "x86_64"))]
        let (x, y) = self.xy;
        Vec3::new(x, y, self.z)
    }
}

/// What the particle phase reads to sum the forces on a particle (see [`Gather::particle`]).
struct Gather<'a> {
    c: &'a ParticleCtx<'a>,
    /// The chunk's slices (index k = particle − first).
    radius: &'a [f64],
    active_base: &'a [u32],
    active_len: &'a [u32],
    /// The pair arrays, cut to one length.
    pair_out: &'a [PairOut],
    pair_rolling: &'a [Vec3],
    slots: &'a [WallContact],
    wall_out: &'a [WallOut],
    stride: usize,
}

impl Gather<'_> {
    /// Force and torque on particle k of the chunk, its coordination numbers (pairs, walls)
    /// and its wall onsets: the pairs in list order, then the wall slots in slot order.
    #[inline(always)]
    fn particle<const E: u16>(&self, k: usize) -> (Vec3, Vec3, u32, u32, u32) {
        let Gather {
            c,
            radius,
            active_base,
            active_len,
            pair_out,
            pair_rolling,
            slots,
            wall_out,
            stride,
        } = *self;
        let rotation = on::<E>(c.effects, Effect::Rotation);
        let rolling = on::<E>(c.effects, Effect::RollingResistance);
        let planar = on::<E>(c.effects, Effect::Planar);
        let mut f = Sum3::zero();
        let mut t = Sum3::zero();
        // the pairs in contact in increasing index order (those where the particle is j
        // first, as their i is smaller); the force on i is +force, on j −force: added times
        // ±1, which is exactly the subtraction
        let start = active_base[k] as usize;
        let listed = c
            .active_entry
            .get(start..start + active_len[k] as usize)
            .unwrap_or(&[]);
        // every entry names a pair of `pair_out` (the lists are made from the pair list)
        let z = listed.len() as u32;
        let r = radius[k];
        for &a in listed {
            let e = (a >> 1) as usize;
            let Some(p) = pair_out.get(e) else {
                continue;
            };
            // + for the first particle (a even), − for the second (a odd): the sign bit
            // flipped
            let flip = u64::from(a) << 63;
            f.add_flipped(flip, p.force);
            if rotation {
                let arm = r - 0.5 * p.overlap;
                t.add_scaled(arm, p.torque_per_arm);
                if rolling {
                    t.add_flipped(flip, pair_rolling[e]);
                }
            }
        }
        if planar {
            // upright cartridges cannot climb on each other: particle forces act in the plane
            f.z = 0.0;
        }
        let mut zw = 0u32;
        let mut onsets = 0u32;
        let row = k * stride;
        let (own, out) = (&slots[row..row + stride], &wall_out[row..row + stride]);
        for q in 0..stride {
            let (s, o) = (&own[q], &out[q]);
            if s.wall == NO_WALL {
                break;
            }
            if s.active {
                zw += 1;
                if s.onset {
                    onsets += 1;
                }
                f.add(o.force);
                t.add(o.torque);
            }
        }
        (f.get(), t.get(), z, zw, onsets)
    }
}

/// Particle phase on one chunk of particles starting at `first`. Returns (largest squared
/// displacement since the last rebuild (m²), largest squared new speed (m²/s²), any
/// non-finite value, wall onsets).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn particle_chunk<const E: u16>(
    c: &ParticleCtx<'_>,
    first: usize,
    position: &mut [Vec3],
    velocity: &mut [Vec3],
    omega: &mut [Vec3],
    force_sum: &mut [Vec3],
    coordination: &mut [u32],
    wall_coordination: &mut [u32],
    slots: &[WallContact],
    wall_out: &[WallOut],
) -> (f64, f64, bool, u32) {
    let rotation = on::<E>(c.effects, Effect::Rotation);
    let rolling = on::<E>(c.effects, Effect::RollingResistance);
    let planar = on::<E>(c.effects, Effect::Planar);
    let gravity = if on::<E>(c.effects, Effect::Gravity) {
        c.gravity
    } else {
        Vec3::ZERO
    };
    let mut max_disp2: f64 = 0.0;
    let mut max_v2: f64 = 0.0;
    // 0 × finite = 0 while 0 × (inf or NaN) = NaN: one multiply-add per particle instead of
    // nine finiteness tests, checked once per chunk
    let mut probe = Vec3::ZERO;
    let mut wall_onsets = 0u32;
    // every per-particle array cut to this chunk once, so the loop indexes by k < len
    // without further bounds checks
    let len = position.len();
    let last = first + len;
    let alive = &c.alive[first..last];
    let radius = &c.radius[first..last];
    let inv_mass = &c.inv_mass[first..last];
    let inv_inertia = &c.inv_inertia[first..last];
    let reference = &c.reference_position[first..last];
    let active_base = &c.active_base[first..last];
    let active_len = &c.active_len[first..last];
    let (velocity, omega) = (&mut velocity[..len], &mut omega[..len]);
    let (force_sum, coordination) = (&mut force_sum[..len], &mut coordination[..len]);
    let wall_coordination = &mut wall_coordination[..len];
    let n_pairs = c.pair_out.len();
    let pair_out = &c.pair_out[..n_pairs];
    let pair_rolling = if rolling {
        &c.pair_rolling[..n_pairs]
    } else {
        &[]
    };
    let stride = c.wall_stride;
    let (slots, wall_out) = (&slots[..len * stride], &wall_out[..len * stride]);
    let g = Gather {
        c,
        radius,
        active_base,
        active_len,
        pair_out,
        pair_rolling,
        slots,
        wall_out,
        stride,
    };
    let gather = |k: usize| g.particle::<E>(k);
    let mut k = 0;
    while k < len {
        #[cfg(target_arch = "x86_64")]
        if c.avx2 && k + 4 <= len && alive[k..k + 4].iter().all(|&a| a) {
            // four particles: gathered one by one, advanced four per instruction
            macro_rules! one {
                ($l:expr) => {{
                    let (f, t, z, zw, onsets) = gather(k + $l);
                    wall_onsets += onsets;
                    if c.detail {
                        force_sum[k + $l] = f;
                        coordination[k + $l] = z;
                        wall_coordination[k + $l] = zw;
                    }
                    (f, t)
                }};
            }
            // written out four times, not a loop over an array: the sums stay in registers
            // (an array filled in a loop goes through the stack, and its reload as lanes
            // waits on the stores)
            let ((f0, t0), (f1, t1)) = (one!(0), one!(1));
            let ((f2, t2), (f3, t3)) = (one!(2), one!(3));
            let (fs, ts) = ([f0, f1, f2, f3], [t0, t1, t2, t3]);
            // SAFETY: `avx2` is set only when the CPU reported AVX2.
            let (disp2, v2, p) = unsafe {
                batch::advance4::<E>(
                    fs,
                    ts,
                    &mut position[k..k + 4],
                    &mut velocity[k..k + 4],
                    &mut omega[k..k + 4],
                    &reference[k..k + 4],
                    &inv_mass[k..k + 4],
                    &inv_inertia[k..k + 4],
                    gravity,
                    c.dt,
                    c.effects,
                )
            };
            probe.x += p;
            if disp2 > max_disp2 {
                max_disp2 = disp2;
            }
            if v2 > max_v2 {
                max_v2 = v2;
            }
            k += 4;
            continue;
        }
        if !alive[k] {
            k += 1;
            continue;
        }
        let (f, t, z, zw, onsets) = gather(k);
        wall_onsets += onsets;
        let (x, v, w) = (position[k], velocity[k], omega[k]);
        if c.detail {
            force_sum[k] = f;
            coordination[k] = z;
            wall_coordination[k] = zw;
        }
        let v_new = v + (f * inv_mass[k] + gravity) * c.dt;
        let x_new = x + v_new * c.dt;
        velocity[k] = v_new;
        position[k] = x_new;
        if rotation {
            let mut w_new = w + t * (inv_inertia[k] * c.dt);
            if planar {
                w_new.x = 0.0;
                w_new.y = 0.0;
            }
            omega[k] = w_new;
            probe += w_new * 0.0;
        }
        probe += (x_new + v_new) * 0.0;
        // a NaN displacement is caught by the probe; no NaN-aware max needed
        let disp2 = (x_new - reference[k]).length_squared();
        if disp2 > max_disp2 {
            max_disp2 = disp2;
        }
        let v2 = v_new.length_squared();
        if v2 > max_v2 {
            max_v2 = v2;
        }
        k += 1;
    }
    (max_disp2, max_v2, !probe.is_finite(), wall_onsets)
}

impl Simulation {
    /// Build a simulation from a scene: validate it, derive masses, pair laws and the time
    /// step, build the neighbour lists and refuse initial overlaps beyond the tolerance.
    pub fn new(scene: &Scene) -> Result<Self> {
        scene.validate()?;
        let p = &scene.particles;
        let n = p.len();
        let mut mass = Vec::with_capacity(n);
        let mut inertia = Vec::with_capacity(n);
        for i in 0..n {
            let r = p.radius[i];
            let m = scene.materials[p.material[i]].density * 4.0 / 3.0
                * std::f64::consts::PI
                * r
                * r
                * r;
            mass.push(m);
            inertia.push(0.4 * m * r * r);
        }
        let n_materials = scene.materials.len();
        let clamp = if scene.clamp_normal_force {
            ForceClamp::NonNegative
        } else {
            ForceClamp::None
        };
        let mut laws = Vec::with_capacity(n_materials * n_materials);
        // ζ from restitution costs a bisection over an ODE solve: once per distinct e
        let mut zeta_cache: Vec<(u64, f64)> = Vec::new();
        for a in 0..n_materials {
            for b in 0..n_materials {
                let (ma, mb) = (&scene.materials[a], &scene.materials[b]);
                let e = ma.restitution.min(mb.restitution);
                let zeta = if !scene.model.is_hertzian() {
                    0.0
                } else if let Some((_, z)) = zeta_cache.iter().find(|(k, _)| *k == e.to_bits()) {
                    *z
                } else {
                    let z = contact::tsuji_damping_for_restitution(e, clamp)?;
                    zeta_cache.push((e.to_bits(), z));
                    z
                };
                laws.push(PairLaw::with_zeta(ma, mb, scene.model, zeta)?);
            }
        }
        let stable = stable_time_step(scene, &mass)?;
        let dt = match scene.time_step {
            Some(dt) => {
                if dt > stable.limit {
                    return Err(DemfemError::UnstableTimeStep {
                        dt,
                        limit: stable.limit,
                        reason: stable.reason.clone(),
                    });
                }
                dt
            }
            None => scene.time_step_safety * stable.limit,
        };
        let d_max = p.radius.iter().fold(0.0_f64, |a, &r| a.max(2.0 * r));
        let skin = scene.skin.unwrap_or(0.1 * d_max.max(f64::MIN_POSITIVE));
        let pool = if scene.threads > 1 {
            Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(scene.threads)
                    .build()
                    .map_err(|e| {
                        DemfemError::Numerical(format!(
                            "cannot start {} threads: {e}",
                            scene.threads
                        ))
                    })?,
            )
        } else {
            None
        };
        let mut sim = Simulation {
            radius: p.radius.clone(),
            inv_mass: mass.iter().map(|m| 1.0 / m).collect(),
            inv_inertia: inertia.iter().map(|m| 1.0 / m).collect(),
            mass,
            inertia,
            material: p.material.iter().map(|&m| m as u32).collect(),
            tag: p.tag.clone(),
            walls: scene.walls.clone(),
            laws,
            n_materials,
            model: scene.model,
            effects: scene.effects,
            gravity: scene.gravity,
            clamp: scene.clamp_normal_force,
            dt,
            stable,
            skin,
            threads: scene.threads,
            avx2: cpu_has_avx2(),
            batched: true,
            pairs_hertz: false,
            pairs_uniform: None,
            record_every: scene.record_every,
            record_onsets: scene.record_onsets,
            removal_plane: scene.removal_plane.map(|(p, n)| (p, n / n.length())),
            position: p.position.clone(),
            velocity: p.velocity.clone(),
            omega: p.angular_velocity.clone(),
            alive: vec![true; n],
            time: 0.0,
            steps: 0,
            pairs: Vec::new(),
            pair_active: Vec::new(),
            pair_onset: Vec::new(),
            pair_wake: Vec::new(),
            travel: 0.0,
            travel_slack: 0.0,
            travel_step: 0.0,
            cut_lists: CutLists::default(),
            wall_lists: WallLists::default(),
            pair_out: Vec::new(),
            pair_detail: Vec::new(),
            pair_rolling: Vec::new(),
            pair_const: Vec::new(),
            contact_table: Vec::new(),
            wall_slots: Vec::new(),
            wall_out: Vec::new(),
            wall_detail: Vec::new(),
            detail: true,
            wall_stride: 1,
            reference_position: p.position.clone(),
            reference_wall_offset: vec![Vec3::ZERO; scene.walls.len()],
            needs_rebuild: true,
            active_base: vec![0; n + 1],
            active_len: vec![0; n],
            active_entry: Vec::new(),
            pair_listed: Vec::new(),
            pair_start: vec![0; n + 1],
            grid: CellGrid::default(),
            candidate_scratch: Vec::new(),
            old_pairs: Vec::new(),
            old_pair_active: Vec::new(),
            old_pair_onset: Vec::new(),
            old_slots: Vec::new(),
            wall_state: vec![WallState::default(); scene.walls.len()],
            chunk_flips: Vec::new(),
            chunk_results: Vec::new(),
            phase_clock: Vec::new(),
            balance_clock: Vec::new(),
            balance_steps: 0,
            balance_cost: Vec::new(),
            contact_force_sum: vec![Vec3::ZERO; n],
            coordination: vec![0; n],
            wall_coordination: vec![0; n],
            pool,
            frames: Vec::new(),
            onsets: Vec::new(),
            rebuilds: 0,
            removals: Vec::new(),
        };
        sim.refresh_wall_state();
        sim.rebuild();
        sim.check_initial_overlaps(scene.initial_overlap_tolerance)?;
        Ok(sim)
    }

    fn check_initial_overlaps(&self, tolerance: f64) -> Result<()> {
        for p in &self.pairs {
            let (i, j) = (p.i as usize, p.j as usize);
            let overlap =
                self.radius[i] + self.radius[j] - (self.position[j] - self.position[i]).length();
            if overlap > tolerance * self.radius[i].min(self.radius[j]) {
                return Err(DemfemError::InvalidParameter {
                    field: format!("particles {i} and {j}"),
                    value: format!("initial overlap {overlap:e} m"),
                    allowed: format!("overlap <= {tolerance} x the smaller radius"),
                });
            }
        }
        for i in 0..self.position.len() {
            for s in &self.wall_slots[i * self.wall_stride..(i + 1) * self.wall_stride] {
                if s.wall == NO_WALL {
                    break;
                }
                let ws = self.wall_state[s.wall as usize];
                if let Some((_, _, d)) =
                    self.walls[s.wall as usize].closest_at(self.position[i], ws.offset)
                {
                    let overlap = self.radius[i] - d;
                    if overlap > tolerance * self.radius[i] {
                        return Err(DemfemError::InvalidParameter {
                            field: format!("particle {i} and wall {}", s.wall),
                            value: format!("initial overlap {overlap:e} m"),
                            allowed: format!("overlap <= {tolerance} x the radius"),
                        });
                    }
                }
            }
        }
        Ok(())
    }

    pub(crate) fn refresh_wall_state(&mut self) {
        let moving = self.effects.has(Effect::MovingWalls);
        for (k, w) in self.walls.iter().enumerate() {
            let (offset, velocity) = if moving {
                w.motion.offset_and_velocity(self.time)
            } else {
                (Vec3::ZERO, Vec3::ZERO)
            };
            self.wall_state[k] = WallState { offset, velocity };
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
    fn sync_active_lists(&mut self) {
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
    fn cut_blocks(&mut self) {
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
            ContactModel::HertzReissnerMindlin => CONTACT_COST_REISSNER,
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
    fn derive_cut_lists(&mut self) {
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
        self.pairs.clear();
        self.pair_active.clear();
        self.pair_onset.clear();
        let mut old = 0usize;
        for &(i, j) in &self.candidate_scratch {
            // both lists are sorted by (i, j): merge to carry the state of surviving pairs
            while old < self.old_pairs.len()
                && (self.old_pairs[old].i, self.old_pairs[old].j) < (i, j)
            {
                old += 1;
            }
            if old < self.old_pairs.len()
                && (self.old_pairs[old].i, self.old_pairs[old].j) == (i, j)
            {
                self.pairs.push(self.old_pairs[old]);
                self.pair_active.push(self.old_pair_active[old]);
                self.pair_onset.push(self.old_pair_onset[old]);
            } else {
                self.pairs.push(PairContact {
                    i,
                    j,
                    ..Default::default()
                });
                self.pair_active.push(false);
                self.pair_onset.push(false);
            }
        }
        self.build_gather_lists();
        // ---- wall slots: walls within reach of each particle (the others are skipped)
        std::mem::swap(&mut self.wall_slots, &mut self.old_slots);
        let old_stride = self.wall_stride;
        let mut counts = vec![0usize; n];
        let mut stride = 1usize;
        for i in 0..n {
            if !self.alive[i] {
                continue;
            }
            let reach = self.radius[i] + self.skin;
            for (w, wall) in self.walls.iter().enumerate() {
                if let Some((_, _, d)) =
                    wall.closest_at(self.position[i], self.wall_state[w].offset)
                {
                    if d < reach {
                        counts[i] += 1;
                    }
                }
            }
            stride = stride.max(counts[i]);
        }
        self.wall_stride = stride;
        self.wall_slots.clear();
        self.wall_slots.resize(n * stride, WallContact::default());
        for i in 0..n {
            if counts[i] == 0 {
                continue;
            }
            let reach = self.radius[i] + self.skin;
            let mut k = 0;
            for (w, wall) in self.walls.iter().enumerate() {
                if let Some((_, _, d)) =
                    wall.closest_at(self.position[i], self.wall_state[w].offset)
                {
                    if d < reach {
                        let carried = self
                            .old_slots
                            .get(i * old_stride..(i + 1) * old_stride)
                            .and_then(|s| s.iter().find(|s| s.wall == w as u32).copied());
                        self.wall_slots[i * stride + k] = carried.unwrap_or(WallContact {
                            wall: w as u32,
                            ..Default::default()
                        });
                        k += 1;
                    }
                }
            }
        }
        self.reference_position.clone_from(&self.position);
        for (k, ws) in self.wall_state.iter().enumerate() {
            self.reference_wall_offset[k] = ws.offset;
        }
        self.refresh_contact_constants();
        self.needs_rebuild = false;
    }

    /// Whether the next step ends with a recorded [`Frame`] (which needs the step's records).
    fn frame_due_next(&self) -> bool {
        self.record_every > 0 && (self.steps + 1) % self.record_every == 0
    }

    /// Advance `n` steps.
    pub fn step(&mut self, n: u64) -> Result<()> {
        match self.pool.take() {
            Some(pool) if self.position.len() >= PARALLEL_MIN_PARTICLES => {
                let r = pool.install(|| {
                    for k in 0..n {
                        self.detail = k + 1 == n || self.frame_due_next();
                        self.one_step(true)?;
                    }
                    Ok(())
                });
                self.pool = Some(pool);
                r
            }
            other => {
                self.pool = other;
                for k in 0..n {
                    self.detail = k + 1 == n || self.frame_due_next();
                    self.one_step(false)?;
                }
                Ok(())
            }
        }
    }

    /// Advance until the simulated time reaches `t_end` (s); returns the steps taken.
    pub fn run_until(&mut self, t_end: f64) -> Result<u64> {
        if !t_end.is_finite() {
            return Err(DemfemError::invalid("t_end", t_end, "finite"));
        }
        let remaining = ((t_end - self.time) / self.dt).ceil();
        if remaining <= 0.0 {
            return Ok(0);
        }
        let n = remaining as u64;
        self.step(n)?;
        Ok(n)
    }

    fn one_step(&mut self, parallel: bool) -> Result<()> {
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
        }
        self.needs_rebuild = moved;
        if self.record_every > 0 && self.steps % self.record_every == 0 {
            self.frames.push(self.frame());
        }
        Ok(())
    }

    fn log_onsets(&mut self, walls: bool) {
        let time = self.time;
        let step = self.steps;
        for (c, flips) in self.chunk_flips.iter().enumerate() {
            if flips.onsets == 0 {
                continue;
            }
            let end = ((c + 1) * PAIR_CHUNK).min(self.pairs.len());
            for ((p, d), &onset) in self.pairs[c * PAIR_CHUNK..end]
                .iter()
                .zip(&self.pair_detail[c * PAIR_CHUNK..end])
                .zip(&self.pair_onset[c * PAIR_CHUNK..end])
            {
                if onset {
                    self.onsets.push(ContactOnset {
                        time,
                        step,
                        particle: p.i,
                        partner: Partner::Particle(p.j),
                        normal_speed: d.onset_normal_speed,
                        tangential_speed: d.onset_tangential_speed,
                        position: self.position_at_force_pass(p.i as usize),
                        partner_position: self.position_at_force_pass(p.j as usize),
                    });
                }
            }
        }
        if walls {
            let stride = self.wall_stride;
            for (k, (s, d)) in self.wall_slots.iter().zip(&self.wall_detail).enumerate() {
                if s.wall != NO_WALL && s.onset {
                    let i = k / stride;
                    self.onsets.push(ContactOnset {
                        time,
                        step,
                        particle: i as u32,
                        partner: Partner::Wall(s.wall),
                        normal_speed: d.onset_normal_speed,
                        tangential_speed: d.onset_tangential_speed,
                        position: self.position_at_force_pass(i),
                        partner_position: d.point,
                    });
                }
            }
        }
    }

    /// Position at which the onset was detected: the force pass saw x(t), the particle phase
    /// has since moved it by v Δt, so step back.
    fn position_at_force_pass(&self, i: usize) -> Vec3 {
        self.position[i] - self.velocity[i] * self.dt
    }

    /// The current state as a [`Frame`].
    pub fn frame(&self) -> Frame {
        Frame {
            time: self.time,
            step: self.steps,
            position: self.position.clone(),
            velocity: self.velocity.clone(),
            angular_velocity: self.omega.clone(),
            contact_force_sum: self.contact_force_sum.clone(),
            coordination: self.coordination.clone(),
            wall_contacts: self.wall_coordination.clone(),
            alive: self.alive.clone(),
        }
    }

    /// Active contacts at the last force evaluation (empty right after a checkpoint restore,
    /// whose contacts have not been evaluated yet, apart from their flags).
    pub fn contacts(&self) -> Vec<ContactRecord> {
        let mut out = Vec::new();
        let pairs = self.pairs.iter().zip(&self.pair_active);
        for (((p, &active), o), d) in pairs.zip(&self.pair_out).zip(&self.pair_detail) {
            if active && o.overlap > 0.0 {
                let i = p.i as usize;
                let x_i = self.position[i] - self.velocity[i] * self.dt;
                out.push(ContactRecord {
                    particle: p.i,
                    partner: Partner::Particle(p.j),
                    normal: d.normal,
                    normal_force: d.normal_force,
                    tangential_force: o.force + d.normal_force * d.normal,
                    overlap: o.overlap,
                    point: x_i + (self.radius[i] - 0.5 * o.overlap) * d.normal,
                });
            }
        }
        for (k, ((s, o), d)) in self
            .wall_slots
            .iter()
            .zip(&self.wall_out)
            .zip(&self.wall_detail)
            .enumerate()
        {
            if s.wall != NO_WALL && s.active && d.overlap > 0.0 {
                out.push(ContactRecord {
                    particle: (k / self.wall_stride) as u32,
                    partner: Partner::Wall(s.wall),
                    normal: d.normal,
                    normal_force: d.normal_force,
                    tangential_force: o.force + d.normal_force * d.normal,
                    overlap: d.overlap,
                    point: d.point,
                });
            }
        }
        out
    }

    // ---- accessors
    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.time
    }
    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }
    /// Time step, s.
    pub fn dt(&self) -> f64 {
        self.dt
    }
    /// The stable limit and what sets it.
    pub fn stable_step(&self) -> &StableStep {
        &self.stable
    }
    /// Whether the step runs its AVX2 build of the kernels (x86-64 CPUs with AVX2, unless the
    /// environment variable `DEMFEM_NO_AVX2` was set when the simulation was built).
    pub fn uses_avx2(&self) -> bool {
        self.avx2
    }

    /// Choose the AVX2 build (`true`, taken only if the CPU has AVX2) or the baseline build
    /// (`false`) of the step kernels; returns the build now in use. Both give bitwise the same
    /// results (a test checks it); this exists to compare their speed and to test that.
    pub fn set_avx2(&mut self, on: bool) -> bool {
        self.avx2 = on && cpu_has_avx2();
        self.avx2
    }

    /// Evaluate contacts in batches (`true`, the default; see the module documentation) or
    /// one at a time (`false`, the reference kernels). Both give bitwise the same results (a
    /// test checks it); this exists to compare their speed and to test that. Scenes with
    /// rolling resistance always run one at a time.
    pub fn set_batched(&mut self, on: bool) {
        self.batched = on;
    }

    /// Start (`true`, from zero) or stop the clock of [`Simulation::phase_times`]. Off by
    /// default: it reads the clock twice per block and phase in every step.
    pub fn set_phase_timing(&mut self, on: bool) {
        self.phase_clock.clear();
        if on {
            let blocks = self.threads.max(1);
            self.phase_clock
                .extend((0..blocks).map(|_| [AtomicU64::new(0), AtomicU64::new(0)]));
        }
    }

    /// Per block of the step (one per thread): seconds spent in the force phase and in the
    /// particle phase since [`Simulation::set_phase_timing`] turned the clock on (empty if
    /// it is off). A development aid for the balance between threads.
    pub fn phase_times(&self) -> Vec<[f64; 2]> {
        self.phase_clock
            .iter()
            .map(|c| {
                c.each_ref()
                    .map(|a| a.load(Ordering::Relaxed) as f64 * 1e-9)
            })
            .collect()
    }

    /// Where the threads' blocks of particles begin: one particle index per block after
    /// the first (empty on one thread). The cuts start from estimated costs and follow the
    /// blocks' measured times ([`Simulation::cut_blocks`]); results do not depend on them.
    pub fn block_cuts(&self) -> Vec<usize> {
        if self.threads > 1 {
            self.cut_lists.particle.clone()
        } else {
            Vec::new()
        }
    }

    /// How many particle–wall slots the AVX2 plane pass took in the last step (four particles
    /// at a time; see the module doc): a diagnostic of the kernels, 0 when the step does not
    /// use it (no AVX2, no batches, rolling resistance).
    pub fn plane_pass_slots(&self) -> usize {
        let used = self.avx2
            && self.batched
            && !self.effects.has(Effect::RollingResistance)
            && self.wall_stride <= BATCH
            && self.steps > 0;
        if !used {
            return 0;
        }
        self.wall_slots
            .iter()
            .filter(|s| s.wall != NO_WALL && s.planar_pass)
            .count()
    }

    /// How many candidate pairs out of contact the batched pair kernel will skip at the next
    /// step because they cannot have closed their gap yet (see [`Simulation::pair_wake`]); a
    /// diagnostic for tests and benchmarks.
    pub fn sleeping_pairs(&self) -> usize {
        self.pair_wake.iter().filter(|&&w| self.travel < w).count()
    }

    /// Whether the batched AVX2 pair kernel takes the uniform path: every pair indexes one
    /// Hertz or Hertz–Reissner law entry and every sphere has one radius, so the constants
    /// and radii are written into the batch once per chunk and the law is evaluated in the
    /// lanes (a diagnostic; results are bitwise those of the general path).
    pub fn uniform_pairs(&self) -> bool {
        self.avx2 && self.batched && self.pairs_uniform.is_some()
    }

    /// Whether contacts are evaluated in batches (see [`Simulation::set_batched`]).
    pub fn uses_batches(&self) -> bool {
        self.batched
    }

    /// Worker threads the simulation was built with.
    pub fn threads(&self) -> usize {
        self.threads
    }
    /// Verlet skin, m.
    pub fn skin(&self) -> f64 {
        self.skin
    }
    /// Number of neighbour-list rebuilds so far.
    pub fn rebuilds(&self) -> u64 {
        self.rebuilds
    }
    /// Candidate pairs in the Verlet list and particle–wall slots in use (a measure of the
    /// neighbour-list work per step).
    pub fn candidate_counts(&self) -> (usize, usize) {
        let slots = self.wall_slots.iter().filter(|s| s.wall != NO_WALL).count();
        (self.pairs.len(), slots)
    }
    /// Number of particles (alive or not).
    pub fn len(&self) -> usize {
        self.position.len()
    }
    /// Whether the simulation has no particle.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }
    /// Centres, m.
    pub fn positions(&self) -> &[Vec3] {
        &self.position
    }
    /// Velocities (half step), m/s.
    pub fn velocities(&self) -> &[Vec3] {
        &self.velocity
    }
    /// Angular velocities (half step), rad/s.
    pub fn angular_velocities(&self) -> &[Vec3] {
        &self.omega
    }
    /// Radii, m.
    pub fn radii(&self) -> &[f64] {
        &self.radius
    }
    /// Masses, kg.
    pub fn masses(&self) -> &[f64] {
        &self.mass
    }
    /// Moments of inertia, kg m².
    pub fn inertias(&self) -> &[f64] {
        &self.inertia
    }
    /// Tags.
    pub fn tags(&self) -> &[u32] {
        &self.tag
    }
    /// Alive flags.
    pub fn alive(&self) -> &[bool] {
        &self.alive
    }
    /// Sum of contact forces on each particle at the last step, N.
    pub fn contact_force_sums(&self) -> &[Vec3] {
        &self.contact_force_sum
    }
    /// Particle–particle coordination number of each particle at the last step.
    pub fn coordination(&self) -> &[u32] {
        &self.coordination
    }
    /// Wall contacts of each particle at the last step.
    pub fn wall_contact_counts(&self) -> &[u32] {
        &self.wall_coordination
    }
    /// Recorded frames.
    pub fn frames(&self) -> &[Frame] {
        &self.frames
    }
    /// Logged contact onsets.
    pub fn onsets(&self) -> &[ContactOnset] {
        &self.onsets
    }
    /// Drop the recorded frames and onsets (e.g. after copying them out).
    pub fn clear_records(&mut self) {
        self.frames.clear();
        self.onsets.clear();
    }
    /// Effects the step runs.
    pub fn effects(&self) -> EffectSet {
        self.effects
    }
    /// Pair law of materials a and b.
    pub fn pair_law(&self, a: usize, b: usize) -> Option<&PairLaw> {
        if a < self.n_materials && b < self.n_materials {
            self.laws.get(a * self.n_materials + b)
        } else {
            None
        }
    }

    /// (time in s, particle index) of every particle removed through the outlet plane.
    pub fn removals(&self) -> &[(f64, u32)] {
        &self.removals
    }

    /// Remove particle `i` from the simulation (it stops interacting and moving).
    pub fn remove_particle(&mut self, i: usize) -> Result<()> {
        if i >= self.position.len() {
            return Err(DemfemError::invalid(
                "particle index",
                i as f64,
                &format!("< {}", self.position.len()),
            ));
        }
        self.alive[i] = false;
        self.needs_rebuild = true;
        Ok(())
    }

    /// Put removed particle `i` back at `position` (m) with `velocity` (m/s) and no spin, e.g.
    /// to re-feed the table upstream. Refused if `i` is alive, if a value is not finite, or
    /// if the particle would overlap an alive particle. Its contacts start afresh at the next neighbour-list rebuild,
    /// which is forced.
    pub fn reinsert_particle(&mut self, i: usize, position: Vec3, velocity: Vec3) -> Result<()> {
        let n = self.position.len();
        if i >= n {
            return Err(DemfemError::invalid(
                "particle index",
                i as f64,
                &format!("< {n}"),
            ));
        }
        if self.alive[i] {
            return Err(DemfemError::invalid(
                "particle index",
                i as f64,
                "a removed particle (this one is alive)",
            ));
        }
        if !(position.is_finite() && velocity.is_finite()) {
            return Err(DemfemError::InvalidParameter {
                field: "position/velocity".into(),
                value: format!("{position:?} / {velocity:?}"),
                allowed: "finite".into(),
            });
        }
        let r = self.radius[i];
        for j in 0..n {
            if j == i || !self.alive[j] {
                continue;
            }
            let gap = (self.position[j] - position).length() - (r + self.radius[j]);
            if gap < -1e-9 * r.min(self.radius[j]) {
                return Err(DemfemError::InvalidParameter {
                    field: "position".into(),
                    value: format!("{position:?}"),
                    allowed: format!("a free site (particle {i} would overlap particle {j})"),
                });
            }
        }
        self.position[i] = position;
        self.velocity[i] = velocity;
        self.omega[i] = Vec3::ZERO;
        self.alive[i] = true;
        self.needs_rebuild = true;
        Ok(())
    }

    /// Kinetic energy (translation + rotation) of the alive particles, J.
    pub fn kinetic_energy(&self) -> f64 {
        let mut e = 0.0;
        for i in 0..self.position.len() {
            if self.alive[i] {
                e += 0.5 * self.mass[i] * self.velocity[i].length_squared()
                    + 0.5 * self.inertia[i] * self.omega[i].length_squared();
            }
        }
        e
    }

    /// Largest particle–particle or particle–wall overlap at the last step, m.
    pub fn max_overlap(&self) -> f64 {
        let a = self
            .pair_active
            .iter()
            .zip(&self.pair_out)
            .filter(|(&active, _)| active)
            .map(|(_, o)| o.overlap)
            .fold(0.0, f64::max);
        let b = self
            .wall_slots
            .iter()
            .zip(&self.wall_detail)
            .filter(|(s, _)| s.wall != NO_WALL && s.active)
            .map(|(_, d)| d.overlap)
            .fold(0.0, f64::max);
        a.max(b)
    }

    /// Number of alive spheres whose centre is higher than `floor_z` + radius + `tolerance`
    /// (m): spheres that ride on top of others, which an upright cartridge cannot do.
    pub fn riding_up_count(&self, floor_z: f64, tolerance: f64) -> usize {
        (0..self.position.len())
            .filter(|&i| self.alive[i] && self.position[i].z > floor_z + self.radius[i] + tolerance)
            .count()
    }
}

/// Stable time step of a scene: the smaller of the Rayleigh step of every particle (Hertz
/// laws only, where stiffness comes from E) and half the critical step 2/ω of the stiffest
/// single contact at `expected_max_speed`, normal (ω² = k'_n/m*) and tangential
/// (ω² = k_t/m_t, m_t = 2/7 m* with rotation: a rolling sphere's tangential inertia). The
/// factor 1/2 allows for several simultaneous contacts (a dense lattice raises the highest
/// eigenfrequency by up to about 2).
pub fn stable_time_step(scene: &Scene, mass: &[f64]) -> Result<StableStep> {
    let p = &scene.particles;
    let v = scene.expected_max_speed;
    let friction = scene.effects.has(Effect::Friction);
    let rotation = scene.effects.has(Effect::Rotation);
    let mut best = StableStep {
        limit: f64::INFINITY,
        reason: "no particle".into(),
    };
    let mut consider = |limit: f64, reason: &dyn Fn() -> String| {
        if limit < best.limit {
            best = StableStep {
                limit,
                reason: reason(),
            };
        }
    };
    // distinct (material, radius, mass) classes only: the table is usually monodisperse
    let mut seen: Vec<(usize, u64)> = Vec::new();
    let mut wall_materials: Vec<usize> = scene.walls.iter().map(|w| w.material).collect();
    wall_materials.sort_unstable();
    wall_materials.dedup();
    for i in 0..p.len() {
        let key = (p.material[i], p.radius[i].to_bits());
        if seen.contains(&key) {
            continue;
        }
        seen.push(key);
        let mat = &scene.materials[p.material[i]];
        let r = p.radius[i];
        let m = mass[i];
        if scene.model.is_hertzian() {
            let t =
                contact::rayleigh_time_step(r, mat.density, mat.young_modulus, mat.poisson_ratio)?;
            consider(t, &|| {
                format!(
                    "Rayleigh step of particle {i} (r = {r} m, material {})",
                    p.material[i]
                )
            });
        }
        let mut partners: Vec<(usize, f64, f64, String)> = vec![(
            p.material[i],
            0.5 * m,
            0.5 * r,
            format!("particle {i} against its twin"),
        )];
        for &wm in &wall_materials {
            partners.push((
                wm,
                m,
                r,
                format!("particle {i} against a wall of material {wm}"),
            ));
        }
        for (other, m_star, r_star, what) in partners {
            let law = PairLaw::with_zeta(mat, &scene.materials[other], scene.model, 0.0)?;
            let (k_n, k_t) = match scene.model {
                ContactModel::LinearSpringDashpot {
                    normal_stiffness,
                    tangential_stiffness,
                } => (normal_stiffness, tangential_stiffness),
                _ => {
                    // Hertz bounds Hertz–Reissner from above (the shell only softens)
                    let k_h = contact::hertz_stiffness(r_star, law.e_star)?;
                    let d = contact::hertz_max_overlap(k_h, m_star, v);
                    (1.5 * k_h * d.sqrt(), 8.0 * law.g_star * (r_star * d).sqrt())
                }
            };
            let dt_n = 0.5 * 2.0 * (m_star / k_n).sqrt();
            consider(dt_n, &|| {
                format!("normal contact stiffness, {what}, at {v} m/s")
            });
            if friction {
                let m_t = if rotation { 2.0 / 7.0 * m_star } else { m_star };
                let dt_t = 0.5 * 2.0 * (m_t / k_t).sqrt();
                consider(dt_t, &|| {
                    format!("tangential contact stiffness, {what}, at {v} m/s")
                });
            }
        }
    }
    if !best.limit.is_finite() {
        best.limit = f64::MAX;
    }
    Ok(best)
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
