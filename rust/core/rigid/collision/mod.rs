//! Contact geometry of rigid shapes: pure geometry, no forces.
//!
//! Every function appends [`ContactPoint`]s in the world frame to an output vector. The normal
//! points from the first object to the second, the overlap is positive, the point lies midway
//! through the overlap. Bead contacts are computed by hand (they are sphere–sphere and
//! sphere–plane tests); exact shapes go through parry3d-f64's contact manifolds, kept between
//! steps in an [`ExactContactCache`] so parry can match features (persistent manifolds).
//!
//! [`primitives`]: contact point, plane, pose; [`beads`]: bead clumps by hand; [`exact`]:
//! exact shapes through parry; [`walls`]: polygon and mesh walls from CAD.

pub mod beads;
pub mod exact;
pub mod primitives;
pub mod walls;

pub use beads::{
    clump_clump_contacts, clump_plane_contacts, clump_sphere_contacts, ClumpPairScratch,
};
pub use exact::{
    clump_exact_contacts, exact_exact_contacts, exact_plane_contacts, exact_sphere_contacts,
    ExactContactCache,
};
pub use primitives::{BodyPose, ContactPoint, Plane};
pub use walls::{
    clump_mesh_contacts, clump_polygon_contacts, exact_polygon_contacts, PolygonWall,
    POLYGON_PLATE_HALF_THICKNESS,
};
