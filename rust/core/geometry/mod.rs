//! Walls, belt, gate and clump shapes for the DEM, built on parry3d-f64.
