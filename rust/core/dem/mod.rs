//! Discrete element method: particles (structure of arrays), contact laws, neighbour
//! search, integrator, effects, recorder and checkpoint.
//!
//! Build a [`Scene`] (particles, [`Material`]s, [`Wall`](crate::geometry::Wall)s, the
//! [`EffectSet`] it needs), then [`Simulation::new`] validates it, derives the time step and
//! runs it with [`Simulation::step`] / [`Simulation::run_until`]. SI units throughout.
//!
//! Where the time goes (perf, packed anchor table at 45 GPa, 1 thread): ~70 % in the particle
//! phase (gather, the particle's own wall contacts — every sphere has the belt contact, which
//! slides under a blocked sphere, so the Coulomb-cap branch with its square root and division
//! runs every step — and the leapfrog update), ~30 % in the pair phase. The code runs at about
//! 3 instructions per cycle, so it is instruction-bound, not memory-bound: further speed needs
//! fewer instructions per contact (SIMD over contacts), not better locality.

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
