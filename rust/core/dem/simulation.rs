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
//!
//! The code is split by what it does:
//! - `api`: [`Simulation::new`], [`Simulation::step`] and the rest of the public API;
//! - `step`: one step's pipeline (force phase, gather lists, particle phase, end of step);
//! - `pair` and `wall`: the one-at-a-time pair and wall kernels (the reference);
//! - `law`: the contact laws' constants (`ContactConst`) and their evaluation;
//! - `state`: what a step carries and writes per pair and per wall slot;
//! - `batch`: the batched kernels, with their AVX2 lanes in `batch::avx2`;
//! - `simd`: the kernels' entry points compiled a second time for AVX2;
//! - `gather`: the particle phase (the gather and the leapfrog update);
//! - `blocks`: the threads' blocks, their cuts and their clocks;
//! - `lists`: the neighbour lists (pairs, wall slots, gather lists, wall lists);
//! - `records`: frames, contact records and the onset log;
//! - `stable`: the stable time step.

use crate::dem::effects::{Effect, EffectSet};
use crate::dem::material::{DemContactLaw, PairLaw};
use crate::dem::neighbor::CellGrid;
use crate::dem::record::{ContactEvent, ContactOnset, Frame};
use crate::geometry::{Vec3, Wall};
use std::sync::atomic::AtomicU64;

mod api;
mod batch;
mod blocks;
mod chunk;
mod events;
mod gather;
mod law;
mod lists;
mod pair;
mod records;
mod simd;
mod stable;
mod state;
mod step;
mod wall;

use blocks::CutLists;
pub(crate) use events::EventAcc;
use law::ContactConst;
use lists::WallLists;
pub use stable::{stable_time_step, StableStep};
use state::{Flips, PairDetail, PairOut, WallDetail, WallOut, WallState};
pub(crate) use state::{PairContact, WallContact};

/// Below this many particles the step runs on the calling thread whatever `threads` says:
/// a rayon fork-join costs microseconds, as much as the whole step of a small system.
pub const PARALLEL_MIN_PARTICLES: usize = 256;
/// Pairs per onset count: onsets and ends are counted per chunk of this many pairs, so the
/// onset log and the gather lists find them without a full scan. A thread's block of pairs
/// starts at a multiple of it, so it is also the granularity of the pair cuts (256 left
/// the default table's 2 000 pairs in eighths). The kernels take a whole block in one call.
const PAIR_CHUNK: usize = 64;

/// The batched pair kernel skips a pair out of contact only while it cannot touch for at
/// least this many steps at the last step's speed (see [`pair::wake_travel`]).
const SKIP_STEPS: f64 = 8.0;

const NO_WALL: u32 = u32::MAX;

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
    pub(crate) model: DemContactLaw,
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
    ///
    /// [`Batch`]: batch::Batch
    batched: bool,
    /// See [`PairCtx::pairs_hertz`] (set with the contact constants).
    ///
    /// [`PairCtx::pairs_hertz`]: pair::PairCtx::pairs_hertz
    pairs_hertz: bool,
    /// See [`PairCtx::pairs_uniform`] (set with the contact constants).
    ///
    /// [`PairCtx::pairs_uniform`]: pair::PairCtx::pairs_uniform
    pairs_uniform: Option<(u32, f64)>,
    pub(crate) record_every: u64,
    pub(crate) record_onsets: bool,
    /// Log whole contacts ([`ContactEvent`]; see `events`).
    pub(crate) record_events: bool,
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
    /// Event accumulator of each pair (empty unless `record_events`).
    pub(crate) pair_event: Vec<EventAcc>,
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
    /// Event accumulator of each wall slot (empty unless `record_events`).
    pub(crate) wall_event: Vec<EventAcc>,
    wall_out: Vec<WallOut>,
    wall_detail: Vec<WallDetail>,
    /// This step writes the record-only values (the last step of a [`Simulation::step`] call).
    detail: bool,
    pub(crate) wall_stride: usize,
    pub(crate) reference_position: Vec<Vec3>,
    pub(crate) reference_wall_offset: Vec<Vec3>,
    /// Rotation angle of each wall at the last rebuild, rad (0 unless it rotates).
    pub(crate) reference_wall_angle: Vec<f64>,
    /// [`Wall::rotation_reach`] of each wall, m: how far a rotation by 1 rad moves it at
    /// most (the rebuild test).
    wall_reach: Vec<f64>,
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
    old_pair_event: Vec<EventAcc>,
    old_slots: Vec<WallContact>,
    old_wall_event: Vec<EventAcc>,
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
    pub(crate) events: Vec<ContactEvent>,
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
