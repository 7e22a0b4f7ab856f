//! Explicit central-difference dynamics of linear tetrahedra.
//!
//! Per step: element forces f_e = V σ(u) ∇N are computed in parallel into a per-element
//! buffer, then gathered per node in a fixed (element) order, so the result is bitwise
//! identical for any number of threads; no global matrix is formed. Then, with lumped
//! mass M (Belytschko, Liu & Moran, *Nonlinear Finite Elements*, box 6.1):
//!
//! a^n = M⁻¹(f_ext^n − f_int^n − d^n),   v^{n+½} = v^{n−½} + Δt a^n (Δt/2 on the first step),
//! u^{n+1} = u^n + Δt v^{n+½},
//!
//! with the damping force d^n = αM v^{n−½} + βK v^{n−½} (Rayleigh, velocity lagged half a
//! step). Prescribed dofs get their velocity from the boundary condition; their reaction
//! r = M a + f_int + d − f_ext is counted as external force in the energy balance.
//!
//! Energies at t^n: kinetic ½ v^{n−½}·M v^{n+½}, internal ½ u^n·f_int^n, external work and
//! damping work by the trapezoidal rule in displacement, W^n = W^{n−1} + ½ Δu^{n−½}·(F^{n−1} + F^n).
//! With these definitions the central-difference recurrence satisfies
//! E_kin^n + E_int^n + W_damp^n − W_ext^n = E_kin^0 + E_int^0 exactly (multiply the update
//! by v^{n+½} + v^{n−½} and telescope), so the balance error measures round-off, lost
//! stability or forces that bypass the bookkeeping. The kinetic energy so defined is the
//! one the scheme conserves; it differs from ½ v·Mv at the same instant by O((ωΔt)²) per
//! mode. At n = 0, v^{−½} := v^0 − (Δt/2) a^0.

mod state;

use rayon::prelude::*;

use crate::error::{check_non_negative, check_open, check_positive, DemfemError, Result};
use crate::fem::assembly::lumped_mass;
use crate::fem::contact::{ContactEnergy, FemContact};
use crate::fem::material::LinearElastic;
use crate::fem::mesh::{tet_quality, TetMesh};
use crate::fem::reduce::{det_sum, NODE_CHUNK};
use crate::fem::stable_step::{
    certified_eigenvalue_bound, critical_step_from_eigenvalue, mass_scaling_factors,
    EigenvalueBound, StepBound,
};
use crate::fem::tet_forces::TetForceKernel;

/// Time history multiplying nodal loads or prescribed displacements.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LoadHistory {
    /// Factor 1 at all times (a suddenly applied load).
    Constant,
    /// Linear rise from 0 at t = 0 to 1 at `rise_time` (s), then 1.
    Ramp {
        /// Rise time, s.
        rise_time: f64,
    },
    /// Smooth (half-cosine) rise from 0 to 1 over `rise_time` (s), then 1.
    SmoothRamp {
        /// Rise time, s.
        rise_time: f64,
    },
}

impl LoadHistory {
    /// Factor at time `t` (s).
    pub fn factor(&self, t: f64) -> f64 {
        match *self {
            LoadHistory::Constant => 1.0,
            LoadHistory::Ramp { rise_time } => (t / rise_time).clamp(0.0, 1.0),
            LoadHistory::SmoothRamp { rise_time } => {
                let s = (t / rise_time).clamp(0.0, 1.0);
                0.5 * (1.0 - (std::f64::consts::PI * s).cos())
            }
        }
    }

    fn validate(&self) -> Result<()> {
        match *self {
            LoadHistory::Constant => Ok(()),
            LoadHistory::Ramp { rise_time } | LoadHistory::SmoothRamp { rise_time } => {
                check_positive("rise_time", rise_time).map(|_| ())
            }
        }
    }
}

/// Kind of a prescribed degree of freedom.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PrescribedKind {
    /// Displacement u(t) = value·h(t) (m), h = the solver's boundary-condition history.
    Displacement(f64),
    /// Constant velocity (m/s).
    Velocity(f64),
}

/// One prescribed degree of freedom.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prescribed {
    /// Node index.
    pub node: usize,
    /// Component 0 = x, 1 = y, 2 = z.
    pub component: usize,
    /// What is prescribed.
    pub kind: PrescribedKind,
}

impl Prescribed {
    /// Fix all three components of `node` (zero displacement).
    pub fn fix_node(node: usize) -> [Prescribed; 3] {
        [0, 1, 2].map(|component| Prescribed {
            node,
            component,
            kind: PrescribedKind::Displacement(0.0),
        })
    }
}

/// Settings of the explicit solver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExplicitConfig {
    /// Material of every element.
    pub material: LinearElastic,
    /// Time step, s. `None`: `safety_factor` × the critical-step bound. A value above the
    /// bound is refused with [`DemfemError::UnstableTimeStep`].
    pub dt: Option<f64>,
    /// Fraction of the critical-step bound used when `dt` is `None`, in (0, 1].
    pub safety_factor: f64,
    /// Mass-proportional Rayleigh damping α, 1/s.
    pub rayleigh_alpha: f64,
    /// Stiffness-proportional Rayleigh damping β, s.
    pub rayleigh_beta: f64,
    /// Mass scaling: raise element masses so that the stable step is at least this, s.
    pub mass_scaling_dt: Option<f64>,
    /// Record an [`EnergyReport`] every this many steps (0 = do not record a history).
    pub energy_interval: usize,
    /// How the critical step is bounded (both ways are proven safe).
    pub step_bound: StepBound,
}

impl ExplicitConfig {
    /// Undamped, automatic time step at 0.9 × the bound, no mass scaling, energies every 100 steps.
    pub fn new(material: LinearElastic) -> Self {
        Self {
            material,
            dt: None,
            safety_factor: 0.9,
            rayleigh_alpha: 0.0,
            rayleigh_beta: 0.0,
            mass_scaling_dt: None,
            energy_interval: 100,
            step_bound: StepBound::CertifiedGlobal {
                margin: 0.01,
                iterations: 400,
            },
        }
    }
}

/// Energies at one instant, J.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnergyReport {
    /// Time, s.
    pub time: f64,
    /// Kinetic energy, J.
    pub kinetic: f64,
    /// Elastic strain energy, J.
    pub internal: f64,
    /// Work done by external loads and reactions of prescribed dofs, J.
    pub external_work: f64,
    /// Energy dissipated by Rayleigh damping, J.
    pub damping_work: f64,
    /// Kinetic plus internal energy at t = 0, J.
    pub initial: f64,
}

impl EnergyReport {
    /// |E_kin + E_int + W_damp − W_ext − E_0|, J.
    pub fn balance_error(&self) -> f64 {
        (self.kinetic + self.internal + self.damping_work - self.external_work - self.initial).abs()
    }
    /// Balance error relative to max(|E_kin|, E_int, |W_ext|, W_damp, |E_0|) (0 when all vanish).
    pub fn relative_balance_error(&self) -> f64 {
        let scale = self
            .kinetic
            .abs()
            .max(self.internal)
            .max(self.external_work.abs())
            .max(self.damping_work)
            .max(self.initial.abs());
        if scale > 0.0 {
            self.balance_error() / scale
        } else {
            0.0
        }
    }
}

/// Explicit central-difference solver for a tetrahedral mesh.
#[derive(Debug, Clone)]
pub struct ExplicitSolver {
    config: ExplicitConfig,
    kernel: TetForceKernel,
    mass: Vec<f64>,
    added_mass: f64,
    dt: f64,
    dt_limit: f64,
    critical_element: usize,
    eigen: EigenvalueBound,
    // Per-dof boundary conditions: 0 free, 1 displacement, 2 velocity.
    bc_kind: Vec<[u8; 3]>,
    bc_value: Vec<[f64; 3]>,
    bc_history: LoadHistory,
    loads: Vec<[f64; 3]>,
    load_history: LoadHistory,
    extra_loads: Vec<[f64; 3]>,
    u: Vec<[f64; 3]>,
    v: Vec<[f64; 3]>,
    f_int: Vec<[f64; 3]>,
    f_damp: Vec<[f64; 3]>,
    f_ext: Vec<[f64; 3]>,
    f_total_prev: Vec<[f64; 3]>,
    f_damp_prev: Vec<[f64; 3]>,
    du_prev: Vec<[f64; 3]>,
    time: f64,
    steps: u64,
    energy: EnergyReport,
    history: Vec<EnergyReport>,
    contact: Option<FemContact>,
    f_contact: Vec<[f64; 3]>,
    dt_limit_without_contact: f64,
}

/// Smallest dihedral angle, degrees, of an element the explicit solver accepts: a sliver
/// below it has a critical step orders of magnitude below its neighbours' (1e-16 s for a
/// flattened tet) and would make the whole run take forever.
pub const MIN_ELEMENT_DIHEDRAL_DEG: f64 = 0.5;

/// Smallest element volume the explicit solver accepts, as a fraction of the mean.
pub const MIN_ELEMENT_VOLUME_FRACTION: f64 = 1e-12;

/// Refuse sliver elements (a dihedral angle below [`MIN_ELEMENT_DIHEDRAL_DEG`]) and
/// near-degenerate ones (volume below [`MIN_ELEMENT_VOLUME_FRACTION`] × the mean), naming
/// the element. Inverted elements and bad indices are left to [`TetMesh::validate`].
fn check_element_shapes(mesh: &TetMesh) -> Result<()> {
    mesh.validate()?;
    let mean = mesh.volume() / mesh.tets.len() as f64;
    for (e, t) in mesh.tets.iter().enumerate() {
        let q = tet_quality(t.map(|i| mesh.nodes[i]));
        if !(q.min_dihedral_deg >= MIN_ELEMENT_DIHEDRAL_DEG) {
            return Err(DemfemError::InvalidParameter {
                field: "mesh".into(),
                value: format!(
                    "element {e} is a sliver: min dihedral angle {:.3e}°",
                    q.min_dihedral_deg
                ),
                allowed: format!(
                    "elements with every dihedral angle >= {MIN_ELEMENT_DIHEDRAL_DEG}° \
                     (a sliver's stable step is far below its neighbours')"
                ),
            });
        }
        if !(q.volume >= MIN_ELEMENT_VOLUME_FRACTION * mean) {
            return Err(DemfemError::InvalidParameter {
                field: "mesh".into(),
                value: format!(
                    "element {e} has volume {:e} m³ (mean {mean:e} m³)",
                    q.volume
                ),
                allowed: format!(
                    "elements of volume >= {MIN_ELEMENT_VOLUME_FRACTION:e} × the mean"
                ),
            });
        }
    }
    Ok(())
}

impl ExplicitSolver {
    /// Build the solver: precompute elements, lumped masses (with optional mass scaling)
    /// and the time step. Fails on bad input or a `config.dt` above the critical-step bound.
    pub fn new(mesh: &TetMesh, config: ExplicitConfig) -> Result<Self> {
        config.material.validate()?;
        check_open("safety_factor", config.safety_factor, 0.0, 1.0 + 1e-12)?;
        check_non_negative("rayleigh_alpha", config.rayleigh_alpha)?;
        check_non_negative("rayleigh_beta", config.rayleigh_beta)?;
        check_element_shapes(mesh)?;
        let (lambda, mu) = config.material.lame();
        let rho = config.material.density;
        let kernel = TetForceKernel::new(mesh, lambda, mu)?;
        let (factors, added_mass) = match config.mass_scaling_dt {
            Some(target) => {
                let (f, a) = mass_scaling_factors(kernel.tets(), lambda, mu, rho, target)?;
                (Some(f), a)
            }
            None => (None, 0.0),
        };
        let mass = lumped_mass(mesh, kernel.tets(), rho, factors.as_deref())?;
        let mut kernel = kernel;
        let eigen = certified_eigenvalue_bound(
            mesh,
            &mut kernel,
            &mass,
            &config.material,
            factors.as_deref(),
            config.step_bound,
        )?;
        let critical_element = eigen.critical_element;
        let dt_limit = critical_step_from_eigenvalue(
            eigen.bound,
            config.rayleigh_alpha,
            config.rayleigh_beta,
        )?;
        let dt = match config.dt {
            Some(dt) => {
                check_positive("dt", dt)?;
                if dt > dt_limit {
                    return Err(DemfemError::UnstableTimeStep {
                        dt,
                        limit: dt_limit,
                        reason: format!(
                            "bound {:e} 1/s² on λ_max(M⁻¹K) ({} factorisations; element bound {:e} at tet {critical_element}), with Rayleigh damping",
                            eigen.bound, eigen.factorizations, eigen.element_bound
                        ),
                    });
                }
                dt
            }
            None => config.safety_factor * dt_limit,
        };
        let n = mesh.nodes.len();
        let z = vec![[0.0; 3]; n];
        Ok(Self {
            config,
            kernel,
            mass,
            added_mass,
            dt,
            dt_limit,
            critical_element,
            eigen,
            bc_kind: vec![[0; 3]; n],
            bc_value: z.clone(),
            bc_history: LoadHistory::Constant,
            loads: z.clone(),
            load_history: LoadHistory::Constant,
            extra_loads: z.clone(),
            u: z.clone(),
            v: z.clone(),
            f_int: z.clone(),
            f_damp: z.clone(),
            f_ext: z.clone(),
            f_total_prev: z.clone(),
            f_damp_prev: z.clone(),
            du_prev: z,
            time: 0.0,
            steps: 0,
            energy: EnergyReport::default(),
            history: Vec::new(),
            contact: None,
            f_contact: Vec::new(),
            dt_limit_without_contact: dt_limit,
        })
    }

    fn check_len(&self, field: &str, len: usize) -> Result<()> {
        if len != self.mass.len() {
            return Err(DemfemError::ShapeMismatch {
                field: field.into(),
                detail: format!("{len} entries for {} nodes", self.mass.len()),
            });
        }
        Ok(())
    }

    /// Prescribe degrees of freedom (replaces any earlier prescription); `history` scales
    /// prescribed displacements in time.
    pub fn set_prescribed(
        &mut self,
        prescribed: &[Prescribed],
        history: LoadHistory,
    ) -> Result<()> {
        history.validate()?;
        let n = self.mass.len();
        let mut kind = vec![[0u8; 3]; n];
        let mut value = vec![[0.0; 3]; n];
        for p in prescribed {
            if p.node >= n || p.component > 2 {
                return Err(DemfemError::ShapeMismatch {
                    field: "prescribed".into(),
                    detail: format!(
                        "node {} component {} out of range ({n} nodes)",
                        p.node, p.component
                    ),
                });
            }
            let (k, v) = match p.kind {
                PrescribedKind::Displacement(v) => (1, v),
                PrescribedKind::Velocity(v) => (2, v),
            };
            if !v.is_finite() {
                return Err(DemfemError::invalid("prescribed value", v, "finite"));
            }
            let (k0, v0) = (kind[p.node][p.component], value[p.node][p.component]);
            if k0 != 0 && (k0 != k || v0 != v) {
                let name = |k: u8| if k == 1 { "displacement" } else { "velocity" };
                return Err(DemfemError::InvalidParameter {
                    field: "prescribed".into(),
                    value: format!(
                        "node {} component {} prescribed twice: {} {v0:e} and {} {v:e}",
                        p.node,
                        p.component,
                        name(k0),
                        name(k)
                    ),
                    allowed: "at most one value per node and component (repeating the same \
                              prescription is allowed)"
                        .into(),
                });
            }
            kind[p.node][p.component] = k;
            value[p.node][p.component] = v;
        }
        self.bc_kind = kind;
        self.bc_value = value;
        self.bc_history = history;
        Ok(())
    }

    /// Nodal loads (N), one per node, scaled in time by `history`.
    pub fn set_loads(&mut self, loads: Vec<[f64; 3]>, history: LoadHistory) -> Result<()> {
        self.check_len("loads", loads.len())?;
        history.validate()?;
        if loads.iter().flatten().any(|x| !x.is_finite()) {
            return Err(DemfemError::Numerical("non-finite nodal load".into()));
        }
        self.loads = loads;
        self.load_history = history;
        Ok(())
    }

    /// Additional nodal forces (N) acting from now on until changed (e.g. contact forces
    /// from a coupled DEM step), not scaled by any history.
    pub fn set_extra_loads(&mut self, loads: &[[f64; 3]]) -> Result<()> {
        self.check_len("extra_loads", loads.len())?;
        if loads.iter().flatten().any(|x| !x.is_finite()) {
            return Err(DemfemError::Numerical("non-finite extra load".into()));
        }
        self.extra_loads.copy_from_slice(loads);
        Ok(())
    }

    /// Initial displacement (m); only before the first step.
    pub fn set_initial_displacement(&mut self, u: &[[f64; 3]]) -> Result<()> {
        self.check_len("initial displacement", u.len())?;
        self.require_start("initial displacement")?;
        self.u.copy_from_slice(u);
        Ok(())
    }

    /// Initial velocity (m/s); only before the first step.
    pub fn set_initial_velocity(&mut self, v: &[[f64; 3]]) -> Result<()> {
        self.check_len("initial velocity", v.len())?;
        self.require_start("initial velocity")?;
        self.v.copy_from_slice(v);
        Ok(())
    }

    fn require_start(&self, what: &str) -> Result<()> {
        if self.steps > 0 {
            return Err(DemfemError::Effect(format!(
                "{what} can only be set before the first step"
            )));
        }
        Ok(())
    }

    /// Attach a contact model (before the first step). The stable step is re-certified
    /// with the contact's eigenvalue allowance added to the bound (Weyl: λ_max(A + B) ≤
    /// λ_max(A) + λ_max(B)); an automatic step is reduced to fit, a fixed `dt` above the new
    /// limit is refused. Bodies overlapping at the start are refused.
    pub fn set_contact(&mut self, mut contact: FemContact) -> Result<()> {
        self.require_start("contact")?;
        let allowance = contact.eigenvalue_allowance(&self.mass)?;
        contact.check_initial_overlap(&self.u)?;
        let limit = critical_step_from_eigenvalue(
            self.eigen.bound + allowance,
            self.config.rayleigh_alpha,
            self.config.rayleigh_beta,
        )?;
        let dt = match self.config.dt {
            Some(dt) if dt > limit => {
                return Err(DemfemError::UnstableTimeStep {
                    dt,
                    limit,
                    reason: format!(
                        "element bound {:e} 1/s² plus contact allowance {allowance:e} 1/s²",
                        self.eigen.bound
                    ),
                })
            }
            Some(dt) => dt,
            None => self.config.safety_factor * limit,
        };
        self.dt = dt;
        self.dt_limit = limit;
        self.f_contact = vec![[0.0; 3]; self.mass.len()];
        self.contact = Some(contact);
        Ok(())
    }

    /// The attached contact model.
    pub fn contact(&self) -> Option<&FemContact> {
        self.contact.as_ref()
    }
    /// Contact energies (zero without contact).
    pub fn contact_energy(&self) -> ContactEnergy {
        self.contact
            .as_ref()
            .map(|c| c.energy())
            .unwrap_or_default()
    }
    /// Stable step bound without the contact's allowance, s.
    pub fn dt_limit_without_contact(&self) -> f64 {
        self.dt_limit_without_contact
    }
    /// Contact forces of the last step, N per node (empty without contact).
    pub fn contact_force(&self) -> &[[f64; 3]] {
        &self.f_contact
    }

    /// Time step in use, s.
    pub fn dt(&self) -> f64 {
        self.dt
    }
    /// Provably stable step bound 2/√(max_e λ_e) (reduced for damping), s.
    pub fn dt_limit(&self) -> f64 {
        self.dt_limit
    }
    /// The eigenvalue bound behind [`Self::dt_limit`].
    pub fn eigenvalue_bound(&self) -> EigenvalueBound {
        self.eigen
    }
    /// Element that sets the element bound.
    pub fn critical_element(&self) -> usize {
        self.critical_element
    }
    /// Mass added by mass scaling, kg.
    pub fn added_mass(&self) -> f64 {
        self.added_mass
    }
    /// Lumped nodal masses, kg.
    pub fn mass(&self) -> &[f64] {
        &self.mass
    }
    /// Current time t^n, s.
    pub fn time(&self) -> f64 {
        self.time
    }
    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }
    /// Displacement u^n, m.
    pub fn displacement(&self) -> &[[f64; 3]] {
        &self.u
    }
    /// Velocity at the last half step v^{n−½}, m/s.
    pub fn velocity(&self) -> &[[f64; 3]] {
        &self.v
    }
    /// Internal forces of the last force evaluation, N.
    pub fn internal_force(&self) -> &[[f64; 3]] {
        &self.f_int
    }
    /// Energies at the start of the last step taken.
    pub fn energy(&self) -> EnergyReport {
        self.energy
    }
    /// Recorded energy history (every `energy_interval` steps).
    pub fn energy_history(&self) -> &[EnergyReport] {
        &self.history
    }
    /// The element-force kernel (for K·x products, e.g. eigenvalue estimates).
    pub fn kernel_mut(&mut self) -> &mut TetForceKernel {
        &mut self.kernel
    }

    /// Error if the energy balance error exceeds `relative_tolerance` × the energy scale.
    pub fn check_energy_balance(&self, relative_tolerance: f64) -> Result<()> {
        let r = self.energy.relative_balance_error();
        if r > relative_tolerance || !r.is_finite() {
            return Err(DemfemError::Numerical(format!(
                "energy balance error {:.3e} (relative {r:.3e}) at t = {:e} s exceeds {relative_tolerance:e}",
                self.energy.balance_error(),
                self.energy.time
            )));
        }
        Ok(())
    }

    /// Advance `n` steps; checks for non-finite values every 64 steps and at the end.
    pub fn run(&mut self, n: u64) -> Result<()> {
        for i in 0..n {
            self.step();
            if let Some(err) = self.contact.as_mut().and_then(|c| c.take_failure()) {
                return Err(err);
            }
            if (i + 1) % 64 == 0 || i + 1 == n {
                self.check_finite()?;
            }
        }
        Ok(())
    }

    fn check_finite(&self) -> Result<()> {
        let bad = det_sum(self.u.len(), |i| {
            let s = self.u[i][0]
                + self.u[i][1]
                + self.u[i][2]
                + self.v[i][0]
                + self.v[i][1]
                + self.v[i][2];
            if s.is_finite() {
                0.0
            } else {
                1.0
            }
        });
        if bad > 0.0 {
            return Err(DemfemError::Numerical(format!(
                "non-finite displacement or velocity at t = {:e} s",
                self.time
            )));
        }
        Ok(())
    }

    /// One central-difference step from t^n to t^{n+1}.
    pub fn step(&mut self) {
        let dt = self.dt;
        let first = self.steps == 0;
        let dt_n = if first { 0.5 * dt } else { dt };
        let t = self.time;
        // Forces at t^n.
        self.kernel.apply(&self.u, &mut self.f_int);
        let (alpha, beta) = (self.config.rayleigh_alpha, self.config.rayleigh_beta);
        if beta > 0.0 {
            self.kernel.apply(&self.v, &mut self.f_damp);
            for f in self.f_damp.iter_mut() {
                f[0] *= beta;
                f[1] *= beta;
                f[2] *= beta;
            }
        }
        if let Some(c) = self.contact.as_mut() {
            c.compute(&self.u, &self.v, t, dt, &mut self.f_contact);
        }
        let has_contact = self.contact.is_some();
        let lf = self.load_history.factor(t);
        let bf_next = self.bc_history.factor(t + dt);
        // One fused, deterministic pass over nodes: damping and external forces at t^n,
        // velocity update (free or prescribed), reactions, energy increments, and the
        // displacement update. Partial sums per fixed chunk are added in chunk order.
        let partial: Vec<[f64; 4]> = {
            let mass = &self.mass;
            let f_int = &self.f_int;
            let loads = &self.loads;
            let extra = &self.extra_loads;
            let fc = &self.f_contact;
            let bc_kind = &self.bc_kind;
            let bc_value = &self.bc_value;
            self.v
                .par_chunks_mut(NODE_CHUNK)
                .zip(self.u.par_chunks_mut(NODE_CHUNK))
                .zip(self.du_prev.par_chunks_mut(NODE_CHUNK))
                .zip(self.f_total_prev.par_chunks_mut(NODE_CHUNK))
                .zip(self.f_damp.par_chunks_mut(NODE_CHUNK))
                .zip(self.f_damp_prev.par_chunks_mut(NODE_CHUNK))
                .zip(self.f_ext.par_chunks_mut(NODE_CHUNK))
                .enumerate()
                .map(|(c, ((((((vc, uc), duc), ftp), fd), fdp), fe))| {
                    let n0 = c * NODE_CHUNK;
                    let mut acc = [0.0f64; 4];
                    for k in 0..vc.len() {
                        let i = n0 + k;
                        let m = mass[i];
                        for d in 0..3 {
                            let v_old = vc[k][d];
                            // βK v^{n−½} is in fd when β > 0; add αM v^{n−½}.
                            let stiff = if beta > 0.0 { fd[k][d] } else { 0.0 };
                            let damp = stiff + alpha * m * v_old;
                            let f_ext = if has_contact {
                                loads[i][d] * lf + extra[i][d] + fc[i][d]
                            } else {
                                loads[i][d] * lf + extra[i][d]
                            };
                            fe[k][d] = f_ext;
                            let resid = f_ext - f_int[i][d] - damp;
                            let u_old = uc[k][d];
                            let (v_new, reaction) = match bc_kind[i][d] {
                                0 => (v_old + dt_n * resid / m, 0.0),
                                kind => {
                                    let vn = if kind == 1 {
                                        (bc_value[i][d] * bf_next - u_old) / dt
                                    } else {
                                        bc_value[i][d]
                                    };
                                    let a = (vn - v_old) / dt_n;
                                    (vn, m * a - resid)
                                }
                            };
                            let f_total = f_ext + reaction;
                            let v_prev = if first { 2.0 * v_old - v_new } else { v_old };
                            acc[0] += 0.5 * m * v_prev * v_new;
                            acc[1] += 0.5 * duc[k][d] * (ftp[k][d] + f_total);
                            acc[2] += 0.5 * duc[k][d] * (fdp[k][d] + damp);
                            acc[3] += 0.5 * u_old * f_int[i][d];
                            vc[k][d] = v_new;
                            ftp[k][d] = f_total;
                            fdp[k][d] = damp;
                            let du = dt * v_new;
                            uc[k][d] = u_old + du;
                            duc[k][d] = du;
                        }
                    }
                    acc
                })
                .collect()
        };
        let (mut e_kin, mut w_ext, mut w_damp, mut e_int) = (0.0, 0.0, 0.0, 0.0);
        for p in &partial {
            e_kin += p[0];
            w_ext += p[1];
            w_damp += p[2];
            e_int += p[3];
        }
        self.energy = EnergyReport {
            time: t,
            kinetic: e_kin,
            internal: e_int,
            external_work: self.energy.external_work + w_ext,
            damping_work: self.energy.damping_work + w_damp,
            initial: if first {
                e_kin + e_int
            } else {
                self.energy.initial
            },
        };
        let ei = self.config.energy_interval;
        if ei > 0 && self.steps % ei as u64 == 0 {
            self.history.push(self.energy);
        }
        self.time = t + dt;
        self.steps += 1;
    }
}
