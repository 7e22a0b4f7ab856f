//! Element kernels. [`shell_dkt`]: flat CST + DKT shell triangle (6 dof per node).
//! [`tet4`]: the constant-strain linear tetrahedron (3 translational dof
//! per node, small-strain isotropic elasticity, lumped mass).

pub mod shell_dkt;
pub mod tet4;

pub use shell_dkt::ShellTri;
pub use tet4::Tet4;
