//! Save and restore the contact model's dynamic state (see [`crate::state_io`]): stick
//! forces, the contact memory of every surface node, the work accumulators, the output
//! history and the broad phase's lists, so that a restored run continues bitwise.

use crate::error::{DemfemError, Result};
use crate::state_io::{StateReader, StateWriter};

use super::{ChannelSample, ContactEnergy, FemContact};

impl FemContact {
    /// Append the dynamic state to `w`.
    pub fn save_state(&self, w: &mut StateWriter) {
        w.vec3s("contact.stick", &self.stick);
        w.vec3s("contact.stick_rigid", &self.stick_rigid);
        w.u32s("contact.last_face", &self.last_face);
        w.u64s("contact.last_contact", &self.last_contact);
        w.u32s("contact.contact_face", &self.contact_face);
        w.f64s("contact.last_depth", &self.last_depth);
        w.f64s("contact.offset", &self.offset);
        if self.is_shell() {
            w.f64s("contact.side", &self.side);
        }
        w.vec3s("contact.x", &self.x);
        w.vec3s("contact.f_prev", &self.f_prev);
        w.vec3s("contact.u_prev", &self.u_prev);
        w.f64s("contact.normal_load", &self.normal_load);
        let e = self.energy;
        w.f64s(
            "contact.energy",
            &[
                e.elastic,
                e.springs,
                e.friction_work,
                e.rigid_work,
                e.contact_work,
            ],
        );
        w.f64s("contact.history", &self.history);
        let sample: Vec<f64> = self
            .sample
            .iter()
            .flat_map(|s| {
                [
                    s.normal_force,
                    s.tangential_force,
                    s.area,
                    s.max_penetration,
                ]
            })
            .collect();
        w.f64s("contact.sample", &sample);
        w.u64s("contact.counters", &[self.steps, self.active as u64]);
        w.f64s("contact.max_gershgorin", &[self.max_gershgorin]);
        let start: Vec<u64> = self.broad.start.iter().map(|&s| s as u64).collect();
        w.u64s("contact.broad.start", &start);
        w.u32s("contact.broad.candidates", &self.broad.candidates);
        w.vec3s("contact.broad.built_at", &self.broad.built_at);
        w.u64s("contact.broad.builds", &[self.broad.builds]);
    }

    /// Restore the state written by [`Self::save_state`] on a model built from the same
    /// inputs; sizes that differ are refused before anything changes.
    pub fn restore_state(&mut self, r: &mut StateReader<'_>) -> Result<()> {
        let ns = self.surface.nodes.len();
        let n = self.x.len();
        let stick = r.vec3s("contact.stick", Some(ns))?;
        let stick_rigid = r.vec3s("contact.stick_rigid", Some(self.stick_rigid.len()))?;
        let last_face = r.u32s("contact.last_face", Some(ns))?;
        let last_contact = r.u64s("contact.last_contact", Some(ns))?;
        let contact_face = r.u32s("contact.contact_face", Some(ns))?;
        let last_depth = r.f64s("contact.last_depth", Some(ns))?;
        let offset = r.f64s("contact.offset", Some(ns))?;
        let side = if self.is_shell() {
            Some(r.f64s("contact.side", Some(ns))?)
        } else {
            None
        };
        let x = r.vec3s("contact.x", Some(n))?;
        let f_prev = r.vec3s("contact.f_prev", Some(n))?;
        let u_prev = r.vec3s("contact.u_prev", Some(n))?;
        let normal_load = r.f64s("contact.normal_load", Some(ns))?;
        let e = r.f64s("contact.energy", Some(5))?;
        let history = r.f64s("contact.history", None)?;
        let sample = r.f64s("contact.sample", None)?;
        let counters = r.u64s("contact.counters", Some(2))?;
        let max_g = r.f64s("contact.max_gershgorin", Some(1))?;
        let start = r.u64s("contact.broad.start", None)?;
        let candidates = r.u32s("contact.broad.candidates", None)?;
        let built_at = r.vec3s("contact.broad.built_at", None)?;
        let builds = r.u64s("contact.broad.builds", Some(1))?;
        let stride = 1 + 4 * self.channels().len();
        if history.len() % stride != 0 || sample.len() % 4 != 0 {
            return Err(DemfemError::ShapeMismatch {
                field: "saved state".into(),
                detail: "contact history of another channel layout".into(),
            });
        }
        if start
            .last()
            .is_some_and(|&s| s as usize != candidates.len())
        {
            return Err(DemfemError::ShapeMismatch {
                field: "saved state".into(),
                detail: "broad-phase lists do not match their offsets".into(),
            });
        }
        self.stick = stick;
        self.stick_rigid = stick_rigid;
        self.last_face = last_face;
        self.last_contact = last_contact;
        self.contact_face = contact_face;
        self.last_depth = last_depth;
        self.offset = offset;
        if let Some(side) = side {
            self.side = side;
        }
        self.x = x;
        self.f_prev = f_prev;
        self.u_prev = u_prev;
        self.normal_load = normal_load;
        self.energy = ContactEnergy {
            elastic: e[0],
            springs: e[1],
            friction_work: e[2],
            rigid_work: e[3],
            contact_work: e[4],
        };
        self.history = history;
        self.sample = sample
            .chunks_exact(4)
            .map(|c| ChannelSample {
                normal_force: c[0],
                tangential_force: c[1],
                area: c[2],
                max_penetration: c[3],
            })
            .collect();
        self.steps = counters[0];
        self.active = counters[1] as usize;
        self.max_gershgorin = max_g[0];
        self.broad.start = start.into_iter().map(|s| s as usize).collect();
        self.broad.candidates = candidates;
        self.broad.built_at = built_at;
        self.broad.builds = builds[0];
        self.broad.refresh_live();
        self.failure = None;
        Ok(())
    }
}
