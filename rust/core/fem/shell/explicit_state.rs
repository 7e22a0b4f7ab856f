//! Save and restore the explicit shell solver's dynamic state, contact included (see
//! [`crate::fem::state_io`]): build the solver from the same inputs (mesh, fixed dofs,
//! step, loads, contact), call [`ShellExplicit::restore_state`], and the run continues
//! bitwise where it was saved.

use crate::error::{DemfemError, Result};
use crate::fem::state_io::{StateReader, StateWriter};

use super::ShellExplicit;

impl ShellExplicit {
    /// The dynamic state as bytes: dofs, velocities, the force and work memory of the
    /// integrator, steps, energies and the contact model's state.
    pub fn save_state(&self) -> Vec<u8> {
        let mut w = StateWriter::new();
        w.f64s("shell.u", &self.u);
        w.f64s("shell.v", &self.v);
        w.f64s("shell.f", &self.f);
        w.f64s("shell.f_prev", &self.f_prev);
        w.f64s("shell.du_prev", &self.du_prev);
        w.vec3s("shell.f_contact", &self.f_contact);
        w.f64s("shell.dt", &[self.dt]);
        w.u64s("shell.steps", &[self.steps]);
        w.f64s("shell.energy", &self.energy);
        w.u64s("shell.has_contact", &[u64::from(self.contact.is_some())]);
        if let Some(c) = &self.contact {
            c.save_state(&mut w);
        }
        w.finish()
    }

    /// Restore a state saved by [`Self::save_state`] on a solver built from the same inputs;
    /// a state of another model (other sizes, another step, contact present or not) is
    /// refused and nothing changes.
    pub fn restore_state(&mut self, bytes: &[u8]) -> Result<()> {
        let mut r = StateReader::new(bytes)?;
        let nd = self.u.len();
        let u = r.f64s("shell.u", Some(nd))?;
        let v = r.f64s("shell.v", Some(nd))?;
        let f = r.f64s("shell.f", Some(nd))?;
        let f_prev = r.f64s("shell.f_prev", Some(nd))?;
        let du_prev = r.f64s("shell.du_prev", Some(nd))?;
        let f_contact = r.vec3s("shell.f_contact", Some(self.f_contact.len()))?;
        let dt = r.f64s("shell.dt", Some(1))?;
        let steps = r.u64s("shell.steps", Some(1))?;
        let energy = r.f64s("shell.energy", Some(4))?;
        let has_contact = r.u64s("shell.has_contact", Some(1))?[0] == 1;
        let mismatch = |detail: String| DemfemError::ShapeMismatch {
            field: "saved state".into(),
            detail,
        };
        if dt[0].to_bits() != self.dt.to_bits() {
            return Err(mismatch(format!(
                "saved with the step {:e} s, this solver steps {:e} s (other settings)",
                dt[0], self.dt
            )));
        }
        if has_contact != self.contact.is_some() {
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
        self.f = f;
        self.f_prev = f_prev;
        self.du_prev = du_prev;
        self.f_contact = f_contact;
        self.steps = steps[0];
        self.energy = [energy[0], energy[1], energy[2], energy[3]];
        if contact.is_some() {
            self.contact = contact;
        }
        Ok(())
    }
}
