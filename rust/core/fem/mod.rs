//! Explicit finite elements: cartridge meshes, linear tetrahedra and thin shells, explicit
//! central-difference dynamics, stress recovery and a sparse static solve.
