//! Thin-shell model on a [`TriMesh`]: flat CST + DKT triangles ([`ShellTri`]) with 6 dof
//! per node, sparse assembly and a linear static solve (faer Cholesky). Dof index of
//! node n, component k (0–2 translations in m, 3–5 rotations in rad) is 6n + k.
//! [`ShellElements`] are the triangles as the explicit integrator steps them
//! ([`crate::fem::explicit::ShellExplicit`]).

use crate::error::{DemfemError, Result};
use crate::fem::element::ShellTri;
use crate::fem::material::LinearElastic;
use crate::fem::mesh::TriMesh;
use crate::fem::static_solve::solve_constrained;

mod elements;

pub use elements::ShellElements;

/// A shell mesh with its material and precomputed elements.
#[derive(Debug, Clone)]
pub struct ShellModel {
    /// The mid-surface mesh.
    pub mesh: TriMesh,
    /// Material of every element.
    pub material: LinearElastic,
    /// Precomputed elements, one per triangle.
    pub elements: Vec<ShellTri>,
}

impl ShellModel {
    /// Check the mesh and precompute the elements.
    pub fn new(mesh: TriMesh, material: LinearElastic) -> Result<Self> {
        mesh.validate()?;
        material.validate()?;
        let elements = mesh
            .triangles
            .iter()
            .zip(&mesh.thickness)
            .map(|(t, &h)| ShellTri::new([mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]]], h))
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            mesh,
            material,
            elements,
        })
    }

    /// Number of dofs (6 per node).
    pub fn n_dofs(&self) -> usize {
        6 * self.mesh.nodes.len()
    }

    /// Global stiffness triplets (both triangles; duplicates to be summed).
    pub fn stiffness_triplets(&self) -> Vec<(usize, usize, f64)> {
        let (e, nu) = (self.material.young_modulus, self.material.poisson_ratio);
        let mut out = Vec::with_capacity(self.elements.len() * 324);
        for (t, el) in self.mesh.triangles.iter().zip(&self.elements) {
            let k = el.global_stiffness(e, nu);
            for a in 0..3 {
                for i in 0..6 {
                    for b in 0..3 {
                        for j in 0..6 {
                            out.push((6 * t[a] + i, 6 * t[b] + j, k[(6 * a + i, 6 * b + j)]));
                        }
                    }
                }
            }
        }
        out
    }

    /// Nodal forces (N) of a uniform load per unit mid-surface area `traction` (Pa,
    /// global components), lumped as area/3 per node. Length = `n_dofs`.
    pub fn area_load(&self, traction: [f64; 3]) -> Vec<f64> {
        let mut f = vec![0.0; self.n_dofs()];
        for (t, el) in self.mesh.triangles.iter().zip(&self.elements) {
            for &n in t {
                for c in 0..3 {
                    f[6 * n + c] += traction[c] * el.area / 3.0;
                }
            }
        }
        f
    }

    /// Linear static solve: loads `f` (N and N·m, length `n_dofs`) with prescribed dofs
    /// `fixed` (node, dof 0–5, value). Returns the dof vector (m, rad).
    pub fn solve_static(&self, f: &[f64], fixed: &[(usize, usize, f64)]) -> Result<Vec<f64>> {
        let nd = self.n_dofs();
        let mut pres = vec![None; nd];
        for &(n, k, v) in fixed {
            if n >= self.mesh.nodes.len() || k > 5 {
                return Err(DemfemError::ShapeMismatch {
                    field: "fixed".into(),
                    detail: format!("node {n} dof {k} out of range"),
                });
            }
            pres[6 * n + k] = Some(v);
        }
        let (x, _) = solve_constrained(nd, &self.stiffness_triplets(), f, &pres)?;
        Ok(x)
    }

    /// Maximum principal in-plane stress σ1 (Pa) of each element at the bottom, middle and
    /// top surfaces, for the dof vector `x` from [`Self::solve_static`].
    pub fn max_principal_stresses(&self, x: &[f64]) -> Result<Vec<[f64; 3]>> {
        if x.len() != self.n_dofs() {
            return Err(DemfemError::ShapeMismatch {
                field: "x".into(),
                detail: format!("expected {} dofs", self.n_dofs()),
            });
        }
        let (e, nu) = (self.material.young_modulus, self.material.poisson_ratio);
        Ok(self
            .mesh
            .triangles
            .iter()
            .zip(&self.elements)
            .map(|(t, el)| {
                let mut ug = [0.0; 18];
                for a in 0..3 {
                    ug[6 * a..6 * a + 6].copy_from_slice(&x[6 * t[a]..6 * t[a] + 6]);
                }
                el.surface_stresses(&ug, e, nu).map(|s| {
                    let c = 0.5 * (s[0] + s[1]);
                    let r = (0.25 * (s[0] - s[1]).powi(2) + s[2] * s[2]).sqrt();
                    c + r
                })
            })
            .collect())
    }
}
