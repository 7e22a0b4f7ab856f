//! Records of a run: periodic frames of the particle state, the contact list on demand, and
//! the log of every contact onset (the FEM load cases are built from the onsets).
//!
//! Velocities are the integrator's half-step (leapfrog) velocities v(t − Δt/2); with the small
//! steps of DEM the difference from v(t) is a fraction Δt/t_contact of a contact's velocity
//! change.

use crate::geometry::Vec3;

/// The partner of a contact: another particle or a wall.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Partner {
    /// Particle index.
    Particle(u32),
    /// Wall index.
    Wall(u32),
}

/// A snapshot of the particle state, taken every `record_every` steps.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Simulated time, s.
    pub time: f64,
    /// Step count.
    pub step: u64,
    /// Centres, m.
    pub position: Vec<Vec3>,
    /// Velocities, m/s.
    pub velocity: Vec<Vec3>,
    /// Angular velocities, rad/s.
    pub angular_velocity: Vec<Vec3>,
    /// Sum of contact forces (particles and walls, no gravity) on each particle, N.
    pub contact_force_sum: Vec<Vec3>,
    /// Number of particle–particle contacts of each particle (coordination number).
    pub coordination: Vec<u32>,
    /// Number of wall contacts of each particle.
    pub wall_contacts: Vec<u32>,
    /// Alive flag of each particle.
    pub alive: Vec<bool>,
}

/// One active contact, as returned by `Simulation::contacts`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactRecord {
    /// The first particle.
    pub particle: u32,
    /// The other body.
    pub partner: Partner,
    /// Unit normal from the particle towards the partner.
    pub normal: Vec3,
    /// Normal force magnitude (≥ 0 with clamping), N; it pushes the particle along −normal.
    pub normal_force: f64,
    /// Tangential force on the particle, N.
    pub tangential_force: Vec3,
    /// Overlap δ, m.
    pub overlap: f64,
    /// Contact point, m.
    pub point: Vec3,
}

/// The first step of a new contact (particle–particle or particle–wall).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactOnset {
    /// Simulated time at which the overlap first became positive, s.
    pub time: f64,
    /// Step count.
    pub step: u64,
    /// The first particle (the lower index for particle pairs).
    pub particle: u32,
    /// The other body.
    pub partner: Partner,
    /// Normal approach speed of the particle relative to the partner, m/s (> 0 approaching).
    pub normal_speed: f64,
    /// Tangential relative speed at the contact point, m/s.
    pub tangential_speed: f64,
    /// Centre of the particle, m.
    pub position: Vec3,
    /// Centre of the partner particle, or the contact point on the wall, m.
    pub partner_position: Vec3,
}

/// One whole contact, from its first step to its last (recorded with
/// [`Scene::record_events`](crate::dem::Scene::record_events)): the onset's speeds and
/// positions with what the contact did while it lasted, measured step by step.
///
/// The force sums are those of the steps in contact: the impulse is Σ F_n Δt over the force
/// evaluations with an overlap, the duration the time from the first such evaluation to the
/// first without one (exact to one step, Δt).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactEvent {
    /// Simulated time of the first force evaluation in contact, s.
    pub time: f64,
    /// Contact duration, s (to the end of the run for an open contact).
    pub duration: f64,
    /// The first particle (the lower index for particle pairs).
    pub particle: u32,
    /// The other body.
    pub partner: Partner,
    /// Normal approach speed at onset, m/s (> 0 approaching).
    pub normal_speed: f64,
    /// Tangential relative speed at the contact point at onset, m/s.
    pub tangential_speed: f64,
    /// Centre of the particle at onset, m.
    pub position: Vec3,
    /// Centre of the partner particle at onset, or the contact point on the wall, m.
    pub partner_position: Vec3,
    /// Largest normal force during the contact, N.
    pub peak_normal_force: f64,
    /// Normal impulse Σ F_n Δt, N·s.
    pub normal_impulse: f64,
    /// Largest tangential force magnitude during the contact, N.
    pub peak_tangential_force: f64,
    /// Largest overlap during the contact, m.
    pub max_overlap: f64,
    /// The contact ended within the run (false: still open when listed by
    /// `Simulation::open_events`, or cut short by a particle's removal).
    pub complete: bool,
}
