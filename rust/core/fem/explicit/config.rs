//! The settings and reports of the explicit integrator: load histories, prescribed dofs,
//! the solver's settings (step, damping, mass scaling, step bound) and its energy report.
//! SI units: s, m, N, J.

use crate::error::{check_non_negative, check_open, check_positive, Result};
use crate::fem::material::LinearElastic;
use crate::fem::stable_step::StepBound;

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

    pub(super) fn validate(&self) -> Result<()> {
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
    /// bound is refused with [`crate::error::DemfemError::UnstableTimeStep`].
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

    /// Check the material, the safety factor (in (0, 1]) and the damping (≥ 0).
    pub(super) fn validate(&self) -> Result<()> {
        self.material.validate()?;
        check_open("safety_factor", self.safety_factor, 0.0, 1.0 + 1e-12)?;
        check_non_negative("rayleigh_alpha", self.rayleigh_alpha)?;
        check_non_negative("rayleigh_beta", self.rayleigh_beta)?;
        Ok(())
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
