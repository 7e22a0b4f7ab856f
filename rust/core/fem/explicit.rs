//! Explicit central-difference dynamics, one integrator for every element kind: an
//! [`Explicit`] steps any [`ElementSet`] with `D` dofs per node ([`ExplicitSolver`]: linear
//! tetrahedra, 3 translations per node; [`ShellExplicit`]: CST + DKT shells, 3 translations
//! and 3 rotations). The elements give the internal forces, the lumped masses and the step
//! bound; the integrator owns time stepping, boundary conditions, loads, damping, contact,
//! energies and checkpoints.
//!
//! Per step: the element forces f_int = K u^n are computed in parallel and gathered per
//! node in a fixed order, so the result is bitwise identical for any number of threads; no
//! global matrix is formed. Then, with lumped mass M (Belytschko, Liu & Moran, *Nonlinear
//! Finite Elements*, box 6.1):
//!
//! a^n = M⁻¹(f_ext^n − f_int^n − d^n),   v^{n+½} = v^{n−½} + Δt a^n (Δt/2 on the first step),
//! u^{n+1} = u^n + Δt v^{n+½},
//!
//! with the damping force d^n = αM v^{n−½} + βK v^{n−½} (Rayleigh, velocity lagged half a
//! step). Prescribed dofs get their velocity from the boundary condition, held dofs keep
//! their value; their reaction r = M a + f_int + d − f_ext is counted as external force in
//! the energy balance.
//!
//! Energies at t^n: kinetic ½ v^{n−½}·M v^{n+½}, internal ½ u^n·f_int^n, external work and
//! damping work by the trapezoidal rule in displacement, W^n = W^{n−1} + ½ Δu^{n−½}·(F^{n−1} + F^n).
//! With these definitions the central-difference recurrence satisfies
//! E_kin^n + E_int^n + W_damp^n − W_ext^n = E_kin^0 + E_int^0 exactly (multiply the update
//! by v^{n+½} + v^{n−½} and telescope), so the balance error measures round-off, lost
//! stability or forces that bypass the bookkeeping. The kinetic energy so defined is the
//! one the scheme conserves; it differs from ½ v·Mv at the same instant by O((ωΔt)²) per
//! mode. At n = 0, v^{−½} := v^0 − (Δt/2) a^0.
//!
//! Layout: `config` (settings and the energy report), `update` (the pass over the nodes),
//! `contact` (contact attached to a run), `state` (checkpoints), `tet` and `shell` (the
//! constructors of the two kinds).

mod config;
mod contact;
mod shell;
mod state;
mod tet;
mod update;

pub use config::{EnergyReport, ExplicitConfig, LoadHistory, Prescribed, PrescribedKind};
pub use contact::EnergyBalance;
pub use shell::ShellExplicit;
pub use tet::ExplicitSolver;

use rayon::prelude::*;

use crate::error::{check_positive, DemfemError, Result};
use crate::fem::contact::FemContact;
use crate::fem::element_set::{Clock, ElementSet, LumpedMass};
use crate::fem::reduce::det_sum;
use crate::fem::stable_step::{critical_step_from_eigenvalue, EigenvalueBound};

use update::{Chunk, NodePass};

/// Boundary condition of a dof: free.
const FREE: u8 = 0;
/// Boundary condition of a dof: displacement value·h(t) prescribed.
const DISPLACEMENT: u8 = 1;
/// Boundary condition of a dof: velocity prescribed.
const VELOCITY: u8 = 2;
/// Boundary condition of a dof: held at its value (a shell's fixed dof), velocity zero.
const HELD: u8 = 3;

/// Dof vectors of `D` values per node from a flat list (node-major), e.g. the 6 dofs of a
/// shell node; the list's length must be a multiple of `D`.
pub fn dof_rows<const D: usize>(flat: &[f64]) -> Result<Vec<[f64; D]>> {
    if flat.len() % D != 0 {
        return Err(DemfemError::ShapeMismatch {
            field: "dofs".into(),
            detail: format!("{} values are not {D} per node", flat.len()),
        });
    }
    Ok(flat
        .chunks_exact(D)
        .map(|c| {
            let mut r = [0.0; D];
            r.copy_from_slice(c);
            r
        })
        .collect())
}

/// Explicit central-difference integrator of the element set `E` with `D` dofs per node.
#[derive(Debug, Clone)]
pub struct Explicit<E: ElementSet<D>, const D: usize> {
    config: ExplicitConfig,
    elements: E,
    /// Translational mass per node, kg.
    mass: Vec<f64>,
    /// Rotary inertia per node (dofs 3–5), kg·m²; empty when D = 3.
    rotary: Vec<f64>,
    dt: f64,
    dt_limit: f64,
    eigen: EigenvalueBound,
    // Per-dof boundary conditions (FREE, DISPLACEMENT, VELOCITY, HELD) and values.
    bc_kind: Vec<[u8; D]>,
    bc_value: Vec<[f64; D]>,
    bc_history: LoadHistory,
    loads: Vec<[f64; D]>,
    load_history: LoadHistory,
    extra_loads: Vec<[f64; D]>,
    u: Vec<[f64; D]>,
    v: Vec<[f64; D]>,
    f_int: Vec<[f64; D]>,
    f_damp: Vec<[f64; D]>,
    f_ext: Vec<[f64; D]>,
    f_total_prev: Vec<[f64; D]>,
    f_damp_prev: Vec<[f64; D]>,
    du_prev: Vec<[f64; D]>,
    time: f64,
    steps: u64,
    energy: EnergyReport,
    history: Vec<EnergyReport>,
    contact: Option<FemContact>,
    f_contact: Vec<[f64; 3]>,
    dt_limit_without_contact: f64,
    // Translations and their velocities for contact when D ≠ 3.
    u3: Vec<[f64; 3]>,
    v3: Vec<[f64; 3]>,
}

impl<E: ElementSet<D>, const D: usize> Explicit<E, D> {
    /// The integrator of `elements`: lumped masses, the step bound and the time step.
    /// Fails on a `config.dt` above the critical-step bound.
    pub fn from_elements(mut elements: E, config: ExplicitConfig) -> Result<Self> {
        config.validate()?;
        let lumped = elements.lumped_mass()?;
        let n = elements.n_nodes();
        if lumped.translation.len() != n || (D > 3 && lumped.rotation.len() != n) {
            return Err(DemfemError::Numerical(
                "lumped masses do not match the nodes".into(),
            ));
        }
        let eigen = elements.eigenvalue_bound(&lumped, config.step_bound)?;
        let LumpedMass {
            translation: mass,
            rotation: rotary,
        } = lumped;
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
                            "bound {:e} 1/s² on λ_max(M⁻¹K) ({} factorisations; element bound {:e} at {} {}), with Rayleigh damping",
                            eigen.bound, eigen.factorizations, eigen.element_bound, E::NAME, eigen.critical_element
                        ),
                    });
                }
                dt
            }
            None => config.safety_factor * dt_limit,
        };
        let z = vec![[0.0; D]; n];
        Ok(Self {
            config,
            elements,
            mass,
            rotary,
            dt,
            dt_limit,
            eigen,
            bc_kind: vec![[FREE; D]; n],
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
            u3: Vec::new(),
            v3: Vec::new(),
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

    /// Hold dofs (node, dof) at their value for the whole run (velocity zero); their
    /// reactions count as external work. Before the first step only.
    fn hold(&mut self, dofs: &[(usize, usize)]) -> Result<()> {
        self.require_start("held dofs")?;
        let n = self.mass.len();
        for &(node, k) in dofs {
            if node >= n || k >= D {
                return Err(DemfemError::ShapeMismatch {
                    field: "fixed".into(),
                    detail: format!("node {node} dof {k} out of range"),
                });
            }
            self.bc_kind[node][k] = HELD;
        }
        Ok(())
    }

    /// Prescribe degrees of freedom (replaces any earlier prescription; held dofs stay
    /// held and cannot be prescribed); `history` scales prescribed displacements in time.
    pub fn set_prescribed(
        &mut self,
        prescribed: &[Prescribed],
        history: LoadHistory,
    ) -> Result<()> {
        history.validate()?;
        let n = self.mass.len();
        let mut kind: Vec<[u8; D]> = self
            .bc_kind
            .iter()
            .map(|k| k.map(|k| if k == HELD { HELD } else { FREE }))
            .collect();
        let mut value = vec![[0.0; D]; n];
        for p in prescribed {
            if p.node >= n || p.component >= D {
                return Err(DemfemError::ShapeMismatch {
                    field: "prescribed".into(),
                    detail: format!(
                        "node {} component {} out of range ({n} nodes)",
                        p.node, p.component
                    ),
                });
            }
            let (k, v) = match p.kind {
                PrescribedKind::Displacement(v) => (DISPLACEMENT, v),
                PrescribedKind::Velocity(v) => (VELOCITY, v),
            };
            if !v.is_finite() {
                return Err(DemfemError::invalid("prescribed value", v, "finite"));
            }
            let (k0, v0) = (kind[p.node][p.component], value[p.node][p.component]);
            if k0 == HELD {
                return Err(DemfemError::InvalidParameter {
                    field: "prescribed".into(),
                    value: format!("node {} component {}", p.node, p.component),
                    allowed: "dofs not held fixed by the solver".into(),
                });
            }
            if k0 != FREE && (k0 != k || v0 != v) {
                let name = |k: u8| {
                    if k == DISPLACEMENT {
                        "displacement"
                    } else {
                        "velocity"
                    }
                };
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

    /// Nodal loads (N, and N·m on rotations), one per node, scaled in time by `history`.
    pub fn set_loads(&mut self, loads: Vec<[f64; D]>, history: LoadHistory) -> Result<()> {
        self.check_len("loads", loads.len())?;
        history.validate()?;
        if loads.iter().flatten().any(|x| !x.is_finite()) {
            return Err(DemfemError::Numerical("non-finite nodal load".into()));
        }
        self.loads = loads;
        self.load_history = history;
        Ok(())
    }

    /// Add the weight of the lumped masses in the acceleration field `g` (m/s²) to the
    /// loads (translations only).
    pub fn add_gravity(&mut self, g: [f64; 3]) -> Result<()> {
        if g.iter().any(|x| !x.is_finite()) {
            return Err(DemfemError::InvalidParameter {
                field: "gravity".into(),
                value: format!("{g:?}"),
                allowed: "finite".into(),
            });
        }
        for (l, m) in self.loads.iter_mut().zip(&self.mass) {
            for c in 0..3 {
                l[c] += m * g[c];
            }
        }
        Ok(())
    }

    /// Additional nodal forces (N) acting from now on until changed (e.g. contact forces
    /// from a coupled DEM step), not scaled by any history.
    pub fn set_extra_loads(&mut self, loads: &[[f64; D]]) -> Result<()> {
        self.check_len("extra_loads", loads.len())?;
        if loads.iter().flatten().any(|x| !x.is_finite()) {
            return Err(DemfemError::Numerical("non-finite extra load".into()));
        }
        self.extra_loads.copy_from_slice(loads);
        Ok(())
    }

    /// Initial displacement (m, rad); only before the first step.
    pub fn set_initial_displacement(&mut self, u: &[[f64; D]]) -> Result<()> {
        self.check_len("initial displacement", u.len())?;
        self.require_start("initial displacement")?;
        self.u.copy_from_slice(u);
        Ok(())
    }

    /// Initial velocity (m/s, rad/s); only before the first step. Held dofs must get 0.
    pub fn set_initial_velocity(&mut self, v: &[[f64; D]]) -> Result<()> {
        self.check_len("initial velocity", v.len())?;
        self.require_start("initial velocity")?;
        if let Some(x) = v.iter().flatten().find(|x| !x.is_finite()) {
            return Err(DemfemError::invalid("initial velocity", *x, "finite"));
        }
        for (i, (vi, k)) in v.iter().zip(&self.bc_kind).enumerate() {
            if let Some(d) = (0..D).find(|&d| k[d] == HELD && vi[d] != 0.0) {
                return Err(DemfemError::InvalidParameter {
                    field: "v0".into(),
                    value: format!("{:e} at fixed dof {d} of node {i}", vi[d]),
                    allowed: "0 at fixed dofs".into(),
                });
            }
        }
        self.v.copy_from_slice(v);
        Ok(())
    }

    /// Initial velocity `v` (m/s) of every node's translation (a rigid translation; held
    /// dofs keep 0, rotations 0).
    pub fn set_uniform_velocity(&mut self, v: [f64; 3]) -> Result<()> {
        let all: Vec<[f64; D]> = self
            .bc_kind
            .iter()
            .map(|k| {
                let mut r = [0.0; D];
                for c in 0..3 {
                    if k[c] != HELD {
                        r[c] = v[c];
                    }
                }
                r
            })
            .collect();
        self.set_initial_velocity(&all)
    }

    fn require_start(&self, what: &str) -> Result<()> {
        if self.steps > 0 {
            return Err(DemfemError::Effect(format!(
                "{what} can only be set before the first step"
            )));
        }
        Ok(())
    }

    /// Time step in use, s.
    pub fn dt(&self) -> f64 {
        self.dt
    }
    /// Provably stable step bound 2/√λ̄ (reduced for damping), s, contact included once
    /// attached.
    pub fn dt_limit(&self) -> f64 {
        self.dt_limit
    }
    /// The eigenvalue bound behind [`Self::dt_limit`] (without contact).
    pub fn eigenvalue_bound(&self) -> EigenvalueBound {
        self.eigen
    }
    /// Element that sets the element bound.
    pub fn critical_element(&self) -> usize {
        self.eigen.critical_element
    }
    /// Translational lumped mass of each node, kg.
    pub fn mass(&self) -> &[f64] {
        &self.mass
    }
    /// Rotary inertia of each node (its rotational dofs), kg·m²; empty without rotations.
    pub fn rotary_inertia(&self) -> &[f64] {
        &self.rotary
    }
    /// The elements.
    pub fn elements(&self) -> &E {
        &self.elements
    }
    /// Current time t^n, s.
    pub fn time(&self) -> f64 {
        match E::CLOCK {
            Clock::Summed => self.time,
            Clock::Counted => self.steps as f64 * self.dt,
        }
    }
    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }
    /// Dof vectors u^n (m, rad), one per node.
    pub fn displacement(&self) -> &[[f64; D]] {
        &self.u
    }
    /// Velocities at the last half step v^{n−½} (m/s, rad/s), one per node.
    pub fn velocity(&self) -> &[[f64; D]] {
        &self.v
    }
    /// Translation of each node u^n (the first three dofs), m.
    pub fn node_displacement(&self) -> Vec<[f64; 3]> {
        self.u.iter().map(|u| [u[0], u[1], u[2]]).collect()
    }
    /// Translational velocity of each node v^{n−½}, m/s.
    pub fn node_velocity(&self) -> Vec<[f64; 3]> {
        self.v.iter().map(|v| [v[0], v[1], v[2]]).collect()
    }
    /// Total linear momentum Σ m v of the translations, kg·m/s.
    pub fn momentum(&self) -> [f64; 3] {
        let mut p = [0.0; 3];
        for (m, v) in self.mass.iter().zip(&self.v) {
            for c in 0..3 {
                p[c] += m * v[c];
            }
        }
        p
    }
    /// Internal forces of the last force evaluation, N (N·m on rotations).
    pub fn internal_force(&self) -> &[[f64; D]] {
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

    /// Advance `n` steps; error on a contact failure (a runaway contact, an exceeded step
    /// allowance) and on non-finite values (checked every 64 steps and at the end).
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
            let s = self.u[i].iter().chain(&self.v[i]).sum::<f64>();
            if s.is_finite() {
                0.0
            } else {
                1.0
            }
        });
        if bad > 0.0 {
            return Err(DemfemError::Numerical(format!(
                "non-finite displacement or velocity at t = {:e} s",
                self.time()
            )));
        }
        Ok(())
    }

    /// One central-difference step from t^n to t^{n+1}.
    pub fn step(&mut self) {
        let dt = self.dt;
        let first = self.steps == 0;
        let dt_n = if first { 0.5 * dt } else { dt };
        let t = self.time();
        // Forces at t^n.
        self.elements.internal_forces(&self.u, &mut self.f_int);
        let (alpha, beta) = (self.config.rayleigh_alpha, self.config.rayleigh_beta);
        if beta > 0.0 {
            self.elements.internal_forces(&self.v, &mut self.f_damp);
            for f in self.f_damp.iter_mut() {
                for x in f.iter_mut() {
                    *x *= beta;
                }
            }
        }
        if let Some(c) = self.contact.as_mut() {
            let u = E::translations(&self.u, &mut self.u3);
            let v = E::translations(&self.v, &mut self.v3);
            c.compute(u, v, t, dt, &mut self.f_contact);
        }
        let chunk = E::NODE_CHUNK;
        let damped = alpha > 0.0 || beta > 0.0;
        // One fused, deterministic pass over nodes (see `update`); partial sums per fixed
        // chunk are added in chunk order.
        let pass = NodePass {
            mass: &self.mass,
            rotary: &self.rotary,
            f_int: &self.f_int,
            loads: &self.loads,
            extra: &self.extra_loads,
            f_contact: &self.f_contact,
            bc_kind: &self.bc_kind,
            bc_value: &self.bc_value,
            has_contact: self.contact.is_some(),
            alpha,
            beta,
            dt,
            dt_n,
            first,
            load_factor: self.load_history.factor(t),
            bc_factor_next: self.bc_history.factor(t + dt),
        };
        let partial: Vec<[f64; 4]> = self
            .v
            .par_chunks_mut(chunk)
            .zip(self.u.par_chunks_mut(chunk))
            .zip(self.du_prev.par_chunks_mut(chunk))
            .zip(self.f_total_prev.par_chunks_mut(chunk))
            .zip(self.f_damp.par_chunks(chunk))
            .zip(self.f_damp_prev.par_chunks_mut(chunk))
            .zip(self.f_ext.par_chunks_mut(chunk))
            .enumerate()
            .map(
                |(c, ((((((v, u), du_prev), f_total_prev), f_damp), f_damp_prev), f_ext))| {
                    let c = Chunk {
                        n0: c * chunk,
                        v,
                        u,
                        du_prev,
                        f_total_prev,
                        f_damp,
                        f_damp_prev,
                        f_ext,
                    };
                    if damped {
                        pass.chunk::<true>(c)
                    } else {
                        pass.chunk::<false>(c)
                    }
                },
            )
            .collect();
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
