//! Explicit finite elements: cartridge meshes, linear tetrahedra and thin shells, explicit
//! central-difference dynamics, stress recovery and a sparse static solve.
//!
//! Layout (fenris style): [`mesh`] builds and checks meshes, [`element`] holds the element
//! kernels, [`assembly`] turns element quantities into global ones (lumped mass, sparse
//! stiffness, surface loads), [`contact`] gives bodies penalty contact with each other and
//! with rigid surfaces, [`shell`] assembles and solves thin-shell models, [`tet_forces`]
//! computes the nodal forces of a tet mesh, [`explicit`] integrates in time any
//! [`element_set::ElementSet`] ([`tet_elements`], [`shell::ShellElements`]),
//! [`stable_step`] bounds the critical time step, [`static_solve`] factorises the sparse
//! stiffness, [`stress`] recovers stresses and [`io`] writes VTK files. All quantities are
//! SI.

// `!(x > 0.0)` is deliberate throughout: it rejects NaN, which `x <= 0.0` would let through.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Index loops mirror the tensor formulas (f_a,i = V σ_ij g_a,j) and read better than zips.
#![allow(clippy::needless_range_loop)]

pub mod assembly;
pub mod contact;
pub mod element;
pub mod element_set;
pub mod explicit;
pub mod io;
pub mod material;
pub mod mesh;
mod reduce;
pub mod shell;
pub mod stable_step;
pub mod static_solve;
pub mod stress;
pub mod tet_elements;
pub mod tet_forces;

pub use explicit::{
    EnergyBalance, EnergyReport, Explicit, ExplicitConfig, ExplicitSolver, LoadHistory, Prescribed,
    PrescribedKind, ShellExplicit,
};
pub use material::LinearElastic;
pub use mesh::{AxisymmetricProfile, MeshQuality, TetMesh, TriMesh};
