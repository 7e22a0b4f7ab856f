//! Save and restore an explicit run's dynamic state, contact included, in the one
//! checkpoint format of demfem ([`crate::state_io`], kind `fem`) and in one layout for every
//! element kind: build the solver from the same inputs, call [`Explicit::restore_state`],
//! and the run continues bitwise where it was saved.
//!
//! Sections, in order, per node of `D` degrees of freedom (tets 3: m; shells 6: m and rad):
//! `u` (displacement), `v` (its rate, per s), `f_int`, `f_damp`, `f_ext`, `f_total_prev`,
//! `f_damp_prev` (nodal forces, N and N m), `du_prev` (last increment), `extra_loads` (N);
//! `f_contact` (3-vectors, N); `clock` (time and step, s); `steps` (u64); `energy` (time s,
//! then kinetic, internal, external work, damping work, initial energy, J) and
//! `energy_history` (6 per report); `has_contact` (u64 0 or 1), then the contact model's
//! sections (`contact.*`, `fem/contact/state.rs`).

use crate::error::{DemfemError, Result};
use crate::fem::element_set::ElementSet;
use crate::state_io::{StateKind, StateReader, StateWriter};

use super::{EnergyReport, Explicit};

fn report_to(e: &EnergyReport) -> [f64; 6] {
    [
        e.time,
        e.kinetic,
        e.internal,
        e.external_work,
        e.damping_work,
        e.initial,
    ]
}

fn report_from(c: &[f64]) -> EnergyReport {
    EnergyReport {
        time: c[0],
        kinetic: c[1],
        internal: c[2],
        external_work: c[3],
        damping_work: c[4],
        initial: c[5],
    }
}

impl<E: ElementSet<D>, const D: usize> Explicit<E, D> {
    /// The dynamic state as bytes: displacements, velocities, the force and work memory of
    /// the integrator, time, steps, energies, and the contact model's state.
    pub fn save_state(&self) -> Vec<u8> {
        let mut w = StateWriter::new(StateKind::Fem);
        w.vecs("u", &self.u);
        w.vecs("v", &self.v);
        w.vecs("f_int", &self.f_int);
        w.vecs("f_damp", &self.f_damp);
        w.vecs("f_ext", &self.f_ext);
        w.vecs("f_total_prev", &self.f_total_prev);
        w.vecs("f_damp_prev", &self.f_damp_prev);
        w.vecs("du_prev", &self.du_prev);
        w.vecs("extra_loads", &self.extra_loads);
        w.vec3s("f_contact", &self.f_contact);
        w.f64s("clock", &[self.time, self.dt]);
        w.u64s("steps", &[self.steps]);
        w.f64s("energy", &report_to(&self.energy));
        let hist: Vec<f64> = self.history.iter().flat_map(report_to).collect();
        w.f64s("energy_history", &hist);
        w.u64s("has_contact", &[u64::from(self.contact.is_some())]);
        if let Some(c) = &self.contact {
            c.save_state(&mut w);
        }
        w.finish()
    }

    /// Restore a state saved by [`Self::save_state`] from a solver built from the same
    /// mesh, material, settings and contact. A state of another model (other sizes, another
    /// step, contact present or not) is refused and nothing changes.
    pub fn restore_state(&mut self, bytes: &[u8]) -> Result<()> {
        let mut r = StateReader::new(bytes, StateKind::Fem)?;
        let n = self.u.len();
        let u = r.vecs("u", Some(n))?;
        let v = r.vecs("v", Some(n))?;
        let f_int = r.vecs("f_int", Some(n))?;
        let f_damp = r.vecs("f_damp", Some(n))?;
        let f_ext = r.vecs("f_ext", Some(n))?;
        let f_total_prev = r.vecs("f_total_prev", Some(n))?;
        let f_damp_prev = r.vecs("f_damp_prev", Some(n))?;
        let du_prev = r.vecs("du_prev", Some(n))?;
        let extra_loads = r.vecs("extra_loads", Some(n))?;
        let f_contact = r.vec3s("f_contact", Some(self.f_contact.len()))?;
        let clock = r.f64s("clock", Some(2))?;
        let steps = r.u64s("steps", Some(1))?;
        let energy = r.f64s("energy", Some(6))?;
        let hist = r.f64s("energy_history", None)?;
        let has_contact = r.u64s("has_contact", Some(1))?[0] == 1;
        let mismatch = |detail: String| DemfemError::ShapeMismatch {
            field: "saved state".into(),
            detail,
        };
        if clock[1].to_bits() != self.dt.to_bits() {
            return Err(mismatch(format!(
                "saved with the step {:e} s, this solver steps {:e} s (other settings)",
                clock[1], self.dt
            )));
        }
        if has_contact != self.contact.is_some() || hist.len() % 6 != 0 {
            return Err(mismatch(
                "contact present in one of the saved state and this solver only".into(),
            ));
        }
        let contact = match &self.contact {
            Some(c) => {
                let mut c = c.clone();
                c.restore_state(&mut r)?;
                Some(c)
            }
            None => None,
        };
        r.finish()?;
        self.u = u;
        self.v = v;
        self.f_int = f_int;
        self.f_damp = f_damp;
        self.f_ext = f_ext;
        self.f_total_prev = f_total_prev;
        self.f_damp_prev = f_damp_prev;
        self.du_prev = du_prev;
        self.extra_loads = extra_loads;
        self.f_contact = f_contact;
        self.time = clock[0];
        self.steps = steps[0];
        self.energy = report_from(&energy);
        self.history = hist.chunks_exact(6).map(report_from).collect();
        if contact.is_some() {
            self.contact = contact;
        }
        Ok(())
    }
}
