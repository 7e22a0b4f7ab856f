//! Rigid bodies for full-shape cartridges: a cartridge as a rigid clump of beads or as an
//! exact shape through parry3d-f64, their contact geometry and forces, and a small stepping
//! loop for scenes of rigid bodies on a belt between walls.
//!
//! - [`body`]: state (structure of arrays) and the symplectic rigid-body integrator;
//! - [`shape`]: the body of revolution, the bead clump and the exact parry compound;
//! - [`revolution`]: the fast exact cartridge, a body of revolution of coaxial frustums with
//!   analytic contact tests (bodies, planes, polygon walls, beads);
//! - [`collision`]: contact points between shapes, planes and spheres (pure geometry);
//! - [`forces`]: Hertz + Tsuji normal force and Mindlin–Coulomb friction per contact;
//! - [`scene`]: gravity, belt, walls, time-step limit and the step loop.
//!
//! Walls other than plain planes (convex polygons, moving walls such as the table's gate)
//! reuse the wall shapes and motions of [`crate::geometry`]; nothing here depends on the
//! sphere DEM in `dem/`.

pub mod body;
pub mod collision;
pub mod forces;
pub mod revolution;
pub mod scene;
pub mod shape;

pub use body::{RigidBodies, RigidBodyInit};
pub use collision::{BodyPose, ContactPoint, Plane, PolygonWall};
pub use forces::{ContactMaterial, RigidContactLaw};
pub use revolution::RevolutionShape;
pub use scene::{Obstacle, RigidOnset, RigidScene, RigidSceneConfig, RigidWall};
pub use shape::{
    BeadClump, BoundingCapsule, ExactShape, MassProperties, RevolutionProfile, RigidShape,
};
