//! Discrete element method: particles (structure of arrays), contact laws, neighbour
//! search, integrator, effects, recorder and checkpoint.
//!
//! Build a [`Scene`] (particles, [`Material`]s, [`Wall`](crate::geometry::Wall)s, the
//! [`EffectSet`] it needs), then [`Simulation::new`] validates it, derives the time step and
//! runs it with [`Simulation::step`] / [`Simulation::run_until`]. SI units throughout.

mod checkpoint;
mod effects;
mod material;
mod neighbor;
mod record;
mod scene;
mod simulation;
pub mod table;

pub use checkpoint::CHECKPOINT_VERSION;
pub use effects::{Effect, EffectSet};
pub use material::{ContactModel, Material, PairLaw};
pub use record::{ContactOnset, ContactRecord, Frame, Partner};
pub use scene::{ParticleInit, Scene};
pub use simulation::{stable_time_step, Simulation, StableStep, PARALLEL_MIN_PARTICLES};
