//! The elements of a mesh as the explicit integrator ([`crate::fem::explicit`]) sees them:
//! an [`ElementSet`] with `D` degrees of freedom per node (3 translations in m for tets; 3
//! translations and 3 rotations in rad for shells) gives the internal forces K·u (N, N·m),
//! the lumped masses (kg, kg·m²) and a proven bound on the largest eigenvalue of M⁻¹K
//! (1/s²) from which the stable step follows. Everything else (time stepping, boundary
//! conditions, loads, damping, contact, energies, checkpoints) is the integrator's, once for
//! every element kind.

use std::fmt::Debug;

use crate::error::Result;
use crate::fem::stable_step::{EigenvalueBound, StepBound};

/// Lumped masses of a mesh.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LumpedMass {
    /// Translational mass of each node, kg (the same for its three translations).
    pub translation: Vec<f64>,
    /// Rotary inertia of each node, kg·m², for elements with rotational dofs (the same for
    /// its three rotations); empty for elements without them.
    pub rotation: Vec<f64>,
}

/// How the integrator keeps its time. Both clocks are kept so that each element kind's
/// runs stay bitwise those of its earlier, separate solver (the time enters loads, boundary
/// conditions and moving rigid surfaces).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Clock {
    /// t^{n+1} = t^n + Δt, summed step by step (tets).
    Summed,
    /// t^n = n Δt, counted (shells).
    Counted,
}

/// A set of elements the explicit integrator can step, with `D` dofs per node (the first
/// three are the node's translations, m).
pub trait ElementSet<const D: usize>: Clone + Debug + Send + Sync {
    /// What the elements are called in messages ("tet", "shell").
    const NAME: &'static str;
    /// The integrator's clock for these elements.
    const CLOCK: Clock;
    /// Nodes per work item of the integrator's pass over the nodes; its energy sums are
    /// added per item in item order, so the sums (and the bits) depend on it, never on the
    /// number of threads. `usize::MAX`: one item, summed in node order.
    const NODE_CHUNK: usize;
    /// Whether contact meets these elements as shells (two-sided faces offset by half the
    /// thickness, [`crate::fem::contact::FemContact::new_shell`]) rather than as solids.
    const SHELL: bool;

    /// Number of nodes.
    fn n_nodes(&self) -> usize;

    /// Lumped masses, kg and kg·m².
    fn lumped_mass(&self) -> Result<LumpedMass>;

    /// A proven upper bound on λ_max(M⁻¹K), 1/s², for the lumped masses `mass` (from
    /// [`Self::lumped_mass`]), computed as `how` asks (where the elements support it).
    fn eigenvalue_bound(&mut self, mass: &LumpedMass, how: StepBound) -> Result<EigenvalueBound>;

    /// Internal forces K·u (N, N·m) of the dof vectors `u` (m, rad), into `f` (overwritten),
    /// bitwise the same for any number of threads.
    fn internal_forces(&mut self, u: &[[f64; D]], f: &mut [[f64; D]]);

    /// The translations (the first three dofs) of the dof vectors `u`, m: `u` itself when
    /// D = 3, otherwise copied into `scratch`.
    fn translations<'a>(u: &'a [[f64; D]], scratch: &'a mut Vec<[f64; 3]>) -> &'a [[f64; 3]];
}
