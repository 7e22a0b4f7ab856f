//! What a step carries and writes per candidate pair and per particle–wall slot: the
//! contact state the next step needs ([`PairContact`], [`WallContact`]), what the particle
//! phase gathers ([`PairOut`], [`WallOut`]), what only the records read ([`PairDetail`],
//! [`WallDetail`]), the walls' motion ([`WallState`]) and the onset counts ([`Flips`]).

use super::NO_WALL;
use crate::geometry::Vec3;

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
    pub(super) normal: Vec3,
    /// Normal force, N (> 0 compressive).
    pub(super) normal_force: f64,
    /// Normal and tangential relative speed at onset, m/s.
    pub(super) onset_normal_speed: f64,
    pub(super) onset_tangential_speed: f64,
}

/// What the gather needs of a pair, written by the pair phase every step: one 64-byte line
/// per pair, so the gather (which visits pairs in particle order, not memory order) touches
/// one cache line per contact.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(64))]
pub(crate) struct PairOut {
    pub(super) force: Vec3,
    pub(super) torque_per_arm: Vec3,
    /// > 0 exactly when the pair is in contact.
    pub(super) overlap: f64,
}

/// A candidate particle–wall contact slot: the state the step carries and the index of its
/// law constants (40 bytes), and the triangle of a mesh wall. Its force and torque go to [`WallOut`], the record-only values
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
    /// The triangle of a mesh wall this slot holds (each triangle within reach of a particle
    /// is a slot of its own); 0 for the other walls. Fits in the slot's padding: still 40
    /// bytes.
    pub(crate) triangle: u32,
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
            triangle: 0,
        }
    }
}

/// Force (N) and torque (N·m) of an active wall slot on its particle, read by the gather.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C)]
pub(crate) struct WallOut {
    pub(super) force: Vec3,
    pub(super) torque: Vec3,
}

/// What only the records read of an active wall slot (see [`PairDetail`]); the contact point
/// is also written at onset.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct WallDetail {
    /// Unit normal from the particle towards the wall.
    pub(super) normal: Vec3,
    /// Contact point on the wall, m.
    pub(super) point: Vec3,
    /// Overlap, m.
    pub(super) overlap: f64,
    /// Normal force, N.
    pub(super) normal_force: f64,
    pub(super) onset_normal_speed: f64,
    pub(super) onset_tangential_speed: f64,
}

/// Current position offset and velocity of each wall, and its rotation angle (rad; 0 but
/// for a rotating wall, whose offset and velocity are zero).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct WallState {
    pub(super) offset: Vec3,
    pub(super) velocity: Vec3,
    pub(super) angle: f64,
}

/// Contacts begun (onsets) and ended in one chunk of the pair list at one force evaluation.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Flips {
    pub(super) onsets: u32,
    pub(super) ends: u32,
}
