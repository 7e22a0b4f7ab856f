//! # demfem core
//!
//! Pure-Rust core of demfem: contact laws, DEM time stepping and explicit FEM for the
//! breakage of glass cartridges packed by a conveyor belt (Boso et al.). No Python here:
//! `cargo test` and `cargo bench` run on this crate alone; the PyO3 layer lives in
//! `rust/bindings`.
//!
//! All quantities are SI: metres, kilograms, seconds, newtons, pascals.
#![warn(missing_docs)]

pub mod contact;
pub mod cpu;
pub mod dem;
pub mod error;
pub mod fem;
pub mod geometry;
pub mod rigid;
pub mod state_io;

pub use error::{DemfemError, Result};
