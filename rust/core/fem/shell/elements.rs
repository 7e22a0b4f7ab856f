//! Flat CST + DKT shell triangles as an [`ElementSet`] of the explicit integrator (6 dofs
//! per node: translations in m, rotations in rad). Internal forces: the precomputed global
//! 18×18 element stiffnesses applied element by element in parallel into a per-element
//! buffer, gathered per node in element order (bitwise the same for any number of threads).
//! Lumped mass ρhA/3 per translation and ρh³/12·A/3 per rotation (physical rotary inertia:
//! its frequencies stay at the level of the CST membrane ones, so it does not shrink the
//! step). Step bound: the element eigenvalue bound 2/√(max_e λ_max(M_e⁻¹K_e)).

use rayon::prelude::*;

use crate::error::{DemfemError, Result};
use crate::fem::assembly::NodeAdjacency;
use crate::fem::element::shell_dkt::ShellMatrix;
use crate::fem::element_set::{Clock, ElementSet, LumpedMass};
use crate::fem::stable_step::{EigenvalueBound, StepBound};

use super::ShellModel;

/// The triangles of a shell model with their stiffness matrices.
#[derive(Debug, Clone)]
pub struct ShellElements {
    conn: Vec<[usize; 3]>,
    k_e: Vec<ShellMatrix>,
    // Per element: thickness (m) and area (m²), for the masses.
    thickness_area: Vec<(f64, f64)>,
    density: f64,
    adjacency: NodeAdjacency,
    buffer: Vec<[f64; 18]>,
    n_nodes: usize,
}

impl ShellElements {
    /// The elements of `model` with their global stiffness matrices.
    pub fn new(model: &ShellModel) -> Result<Self> {
        let nn = model.mesh.nodes.len();
        let (e, nu) = (model.material.young_modulus, model.material.poisson_ratio);
        // Symmetrised exactly, so K_e u can be evaluated as columns · u (contiguous in
        // nalgebra's column-major storage).
        let k_e: Vec<_> = model
            .elements
            .iter()
            .map(|el| {
                let k = el.global_stiffness(e, nu);
                (k + k.transpose()) * 0.5
            })
            .collect();
        let conn4: Vec<[usize; 4]> = model
            .mesh
            .triangles
            .iter()
            .map(|t| [t[0], t[1], t[2], t[2]])
            .collect();
        // Reuse the tet adjacency with a repeated last node; the duplicate entry (local 3)
        // is skipped in the gather.
        let adjacency = NodeAdjacency::new(&conn4, nn)?;
        Ok(Self {
            conn: model.mesh.triangles.clone(),
            buffer: vec![[0.0; 18]; k_e.len()],
            k_e,
            thickness_area: model
                .elements
                .iter()
                .map(|el| (el.thickness, el.area))
                .collect(),
            density: model.material.density,
            adjacency,
            n_nodes: nn,
        })
    }

    /// Lumped masses of element `e`: per translation and per rotation, kg and kg·m².
    fn element_mass(&self, e: usize) -> (f64, f64) {
        let (h, area) = self.thickness_area[e];
        let mt = self.density * h * area / 3.0;
        let mr = mt * h * h / 12.0;
        (mt, mr)
    }
}

impl ElementSet<6> for ShellElements {
    const NAME: &'static str = "shell";
    const CLOCK: Clock = Clock::Counted;
    const NODE_CHUNK: usize = usize::MAX;
    const SHELL: bool = true;

    fn n_nodes(&self) -> usize {
        self.n_nodes
    }

    fn lumped_mass(&self) -> Result<LumpedMass> {
        let mut translation = vec![0.0; self.n_nodes];
        let mut rotation = vec![0.0; self.n_nodes];
        for (e, t) in self.conn.iter().enumerate() {
            let (mt, mr) = self.element_mass(e);
            for &n in t {
                translation[n] += mt;
                rotation[n] += mr;
            }
        }
        Ok(LumpedMass {
            translation,
            rotation,
        })
    }

    fn eigenvalue_bound(&mut self, _mass: &LumpedMass, how: StepBound) -> Result<EigenvalueBound> {
        use nalgebra::SymmetricEigen;
        if how != StepBound::ElementEigenvalue {
            return Err(DemfemError::InvalidParameter {
                field: "step_bound".into(),
                value: format!("{how:?}"),
                allowed: "StepBound::ElementEigenvalue for shells".into(),
            });
        }
        let mut lam_max: f64 = 0.0;
        let mut critical = 0;
        for (e, k) in self.k_e.iter().enumerate() {
            let (mt, mr) = self.element_mass(e);
            let me: [f64; 6] = [mt, mt, mt, mr, mr, mr];
            let mut s = *k;
            for i in 0..18 {
                for j in 0..18 {
                    s[(i, j)] /= (me[i % 6] * me[j % 6]).sqrt();
                }
            }
            let l = SymmetricEigen::new(s)
                .eigenvalues
                .iter()
                .cloned()
                .fold(0.0f64, f64::max);
            if l > lam_max {
                critical = e;
            }
            lam_max = lam_max.max(l);
        }
        Ok(EigenvalueBound {
            bound: lam_max,
            element_bound: lam_max,
            power_estimate: 0.0,
            factorizations: 0,
            critical_element: critical,
        })
    }

    fn internal_forces(&mut self, u: &[[f64; 6]], f: &mut [[f64; 6]]) {
        let (k_e, conn) = (&self.k_e, &self.conn);
        self.buffer.par_iter_mut().enumerate().for_each(|(e, out)| {
            let t = conn[e];
            let mut ue = [0.0; 18];
            for a in 0..3 {
                ue[6 * a..6 * a + 6].copy_from_slice(&u[t[a]]);
            }
            let k = k_e[e].as_slice();
            for (i, o) in out.iter_mut().enumerate() {
                let col = &k[18 * i..18 * i + 18];
                let mut s = 0.0;
                for j in 0..18 {
                    s += col[j] * ue[j];
                }
                *o = s;
            }
        });
        let (buffer, adj) = (&self.buffer, &self.adjacency);
        f.par_iter_mut().enumerate().for_each(|(n, fnode)| {
            let mut s = [0.0; 6];
            for &en in &adj.entries[adj.offsets[n] as usize..adj.offsets[n + 1] as usize] {
                let (e, a) = (en as usize / 4, en as usize % 4);
                if a == 3 {
                    continue;
                }
                for c in 0..6 {
                    s[c] += buffer[e][6 * a + c];
                }
            }
            *fnode = s;
        });
    }

    fn translations<'a>(u: &'a [[f64; 6]], scratch: &'a mut Vec<[f64; 3]>) -> &'a [[f64; 3]] {
        scratch.resize(u.len(), [0.0; 3]);
        for (x, u) in scratch.iter_mut().zip(u) {
            *x = [u[0], u[1], u[2]];
        }
        scratch
    }
}
