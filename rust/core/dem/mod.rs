//! Discrete element method: particles (structure of arrays), contact laws, neighbour
//! search, integrator, effects, recorder and checkpoint.
//!
//! Build a [`Scene`] (particles, [`Material`]s, [`Wall`](crate::geometry::Wall)s, the
//! [`EffectSet`] it needs), then [`Simulation::new`] validates it, derives the time step and
//! runs it with [`Simulation::step`] / [`Simulation::run_until`]. SI units throughout.
//!
//! Where the time goes (`valgrind --tool=callgrind`, exact instruction counts, packed anchor
//! table at 45 GPa, 1 thread, about 750 instructions per particle-step): the pair pass with its
//! share of the force pass ~300, the wall slots ~240 (every sphere has the belt contact, which
//! slides under a blocked sphere, so the Coulomb cap with its square root and division runs
//! every step; plane slots go four particles at a time through `plane_slots`), the particle
//! phase's gather and leapfrog update ~210 (the update four particles at a time, `advance4`).
//! The code runs at 2.4–3 instructions per cycle: the README's "DEM performance" section
//! lists what was tried and measured.

mod checkpoint;
mod effects;
mod material;
mod neighbor;
mod record;
mod scene;
mod simulation;
pub mod table;

pub use effects::{Effect, EffectSet};
pub use material::{DemContactLaw, Material, PairLaw};
pub use record::{ContactEvent, ContactOnset, ContactRecord, Frame, Partner};
pub use scene::{ParticleInit, Scene};
pub use simulation::{stable_time_step, Simulation, StableStep, PARALLEL_MIN_PARTICLES};
