//! The contact's share of the stable step. With mass-normalised coordinates, a spring k
//! between a node and a face adds at most k (1/√m_s + 1/√m_f,min)² to a Gershgorin row;
//! [`FemContact::eigenvalue_allowance`] is that bound for the stiffest face times
//! [`super::ContactSettings::contacts_per_node`], plus the rigid and spring terms, certified
//! into the solver's step. Every step the Gershgorin bound of the springs actually active is
//! checked against it, so a run never goes past its certified step silently. Eigenvalues
//! in 1/s², masses in kg.

use rayon::prelude::*;

use crate::error::{DemfemError, Result};

use super::hits::Hit;
use super::{FemContact, NODE_CHUNK};

impl FemContact {
    /// Largest Gershgorin bound of the active contact springs seen so far, 1/s².
    pub fn max_contact_eigenvalue(&self) -> f64 {
        self.max_gershgorin
    }
    /// The eigenvalue allowance certified into the step, 1/s².
    pub fn allowance(&self) -> f64 {
        self.allowance
    }

    /// Bound on the contact's contribution to λ_max(M⁻¹K) for nodal masses `mass` (kg),
    /// 1/s²; also fixes the masses for the per-step check.
    pub fn eigenvalue_allowance(&mut self, mass: &[f64]) -> Result<f64> {
        if mass.len() != self.reference.len() {
            return Err(DemfemError::ShapeMismatch {
                field: "mass".into(),
                detail: format!("{} entries for {} nodes", mass.len(), self.reference.len()),
            });
        }
        let sf = &self.surface;
        // Lightest surface node of each body (the slaves a face can meet).
        let mut min_mass = vec![f64::INFINITY; self.n_bodies];
        for (k, &i) in sf.nodes.iter().enumerate() {
            let b = sf.node_body[k] as usize;
            min_mass[b] = min_mass[b].min(mass[i]);
        }
        let mut face_term: f64 = 0.0;
        for f in &sf.faces {
            let mf = f
                .nodes
                .iter()
                .map(|&i| mass[i])
                .fold(f64::INFINITY, f64::min);
            let ms = (0..self.n_bodies)
                .filter(|&b| b != f.body as usize)
                .map(|b| min_mass[b])
                .fold(f64::INFINITY, f64::min);
            if ms.is_finite() {
                let q = 1.0 / ms.sqrt() + 1.0 / mf.sqrt();
                face_term = face_term.max(f.stiffness * q * q);
            }
        }
        let mut rigid_term: f64 = 0.0;
        if !self.rigid.is_empty() {
            for (k, &i) in sf.nodes.iter().enumerate() {
                rigid_term = rigid_term.max(sf.node_stiffness[k] / mass[i]);
            }
            rigid_term *= self.rigid.len().min(2) as f64;
        }
        let mut spring_row = vec![0.0; mass.len()];
        for s in &self.springs {
            spring_row[s.node] += s.stiffness / mass[s.node];
        }
        let spring_term = spring_row.iter().fold(0.0f64, |a, &b| a.max(b));
        // A shell node is a slave and, at a ridge met head-on, the corner its own faces give
        // weight 1 to another body's slave: two full-stiffness springs per node.
        let face_term = if self.is_shell() {
            2.0 * face_term
        } else {
            face_term
        };
        let allowance = self.settings.contacts_per_node * face_term + rigid_term + spring_term;
        if !allowance.is_finite() {
            return Err(DemfemError::Numerical(
                "contact step allowance is not finite (a node of zero mass on the surface?)".into(),
            ));
        }
        self.allowance = allowance;
        self.mass = mass.to_vec();
        Ok(allowance)
    }

    /// The Gershgorin row bounds of this step's contact springs (`hits`, in order), into the
    /// per-node bounds (cleared first), 1/s².
    pub(super) fn gershgorin_of_hits(&mut self, hits: &[Hit]) {
        self.gershgorin
            .par_chunks_mut(NODE_CHUNK)
            .for_each(|c| c.fill(0.0));
        for h in hits {
            let i = self.surface.nodes[h.slave as usize];
            let mi = 1.0 / self.mass[i].sqrt();
            if h.rigid {
                self.gershgorin[i] += h.stiffness * mi * mi;
            } else {
                let face = self.surface.faces[h.partner as usize];
                let s: f64 = mi
                    + (0..3)
                        .map(|j| h.weights[j].abs() / self.mass[face.nodes[j]].sqrt())
                        .sum::<f64>();
                self.gershgorin[i] += h.stiffness * mi * s;
                for j in 0..3 {
                    let node = face.nodes[j];
                    self.gershgorin[node] +=
                        h.stiffness * h.weights[j].abs() / self.mass[node].sqrt() * s;
                }
            }
        }
    }

    /// Keep a failure when the active springs' Gershgorin bound exceeds the certified
    /// allowance at time `t` (s).
    pub(super) fn check_allowance(&mut self, t: f64) {
        let g = self.gershgorin.par_iter().cloned().reduce(|| 0.0, f64::max);
        self.max_gershgorin = self.max_gershgorin.max(g);
        if g > self.allowance * (1.0 + 1e-12) && self.failure.is_none() {
            self.failure = Some(DemfemError::Numerical(format!(
                "at t = {t:e} s the active contact springs need an eigenvalue allowance of {g:e} 1/s², above the {:e} 1/s² certified in the step; raise contacts_per_node or lower penalty_scale",
                self.allowance
            )));
        }
    }
}
