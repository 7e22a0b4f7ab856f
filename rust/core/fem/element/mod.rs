//! Element kernels. [`tet4`]: the constant-strain linear tetrahedron (3 translational dof
//! per node, small-strain isotropic elasticity, lumped mass).

pub mod tet4;

pub use tet4::Tet4;
