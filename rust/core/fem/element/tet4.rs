//! Linear (constant-strain) tetrahedron.
//!
//! Shape-function gradients are constant over the element, so the strain, the stress and
//! the nodal internal forces are closed-form sums: f_a = V σ ∇N_a. The same gradients give
//! the element stiffness used by the static solve and by the element eigenvalue bound of
//! the stable time step, so explicit and static paths share one element.
//!
//! Stress and strain vectors use the order [xx, yy, zz, yz, xz, xy] with *tensor* shear
//! components (ε_yz, not γ_yz = 2ε_yz).

use nalgebra::{SMatrix, SymmetricEigen};

use crate::error::{DemfemError, Result};
use crate::fem::mesh::signed_volume;

/// Precomputed geometry of a linear tetrahedron.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tet4 {
    /// Gradients ∇N_a of the four shape functions, 1/m.
    pub grads: [[f64; 3]; 4],
    /// Volume, m³.
    pub volume: f64,
}

/// 12×12 element matrix type (dof order: node 0 x,y,z, node 1 x,y,z, ...).
pub type ElementMatrix = SMatrix<f64, 12, 12>;

impl Tet4 {
    /// Precompute from the four vertex positions (m). Fails for a degenerate or inverted tet.
    pub fn new(x: [[f64; 3]; 4]) -> Result<Self> {
        let v = signed_volume(x[0], x[1], x[2], x[3]);
        if !(v > 0.0) || !v.is_finite() {
            return Err(DemfemError::Numerical(format!(
                "tetrahedron with non-positive volume {v:e} m³"
            )));
        }
        // Jacobian columns: edges from node 0. Rows of J⁻¹ are ∇N_1..∇N_3.
        let j = nalgebra::Matrix3::new(
            x[1][0] - x[0][0],
            x[2][0] - x[0][0],
            x[3][0] - x[0][0],
            x[1][1] - x[0][1],
            x[2][1] - x[0][1],
            x[3][1] - x[0][1],
            x[1][2] - x[0][2],
            x[2][2] - x[0][2],
            x[3][2] - x[0][2],
        );
        let jinv = j
            .try_inverse()
            .ok_or_else(|| DemfemError::Numerical("singular tetrahedron Jacobian".into()))?;
        let mut grads = [[0.0; 3]; 4];
        for a in 1..4 {
            for i in 0..3 {
                grads[a][i] = jinv[(a - 1, i)];
            }
        }
        for i in 0..3 {
            grads[0][i] = -(grads[1][i] + grads[2][i] + grads[3][i]);
        }
        Ok(Self { grads, volume: v })
    }

    /// Small strain [xx, yy, zz, yz, xz, xy] (tensor shear) from nodal displacements (m).
    pub fn strain(&self, u: &[[f64; 3]; 4]) -> [f64; 6] {
        let mut h = [[0.0; 3]; 3];
        for a in 0..4 {
            for i in 0..3 {
                for j in 0..3 {
                    h[i][j] += u[a][i] * self.grads[a][j];
                }
            }
        }
        [
            h[0][0],
            h[1][1],
            h[2][2],
            0.5 * (h[1][2] + h[2][1]),
            0.5 * (h[0][2] + h[2][0]),
            0.5 * (h[0][1] + h[1][0]),
        ]
    }

    /// Nodal internal forces f_a = V σ ∇N_a (N) for nodal displacements `u` (m) and Lamé
    /// constants `lambda`, `mu` (Pa).
    pub fn internal_force(&self, u: &[[f64; 3]; 4], lambda: f64, mu: f64) -> [[f64; 3]; 4] {
        let s = stress_from_strain(&self.strain(u), lambda, mu);
        let sig = [[s[0], s[5], s[4]], [s[5], s[1], s[3]], [s[4], s[3], s[2]]];
        let mut f = [[0.0; 3]; 4];
        for a in 0..4 {
            for i in 0..3 {
                f[a][i] = self.volume
                    * (sig[i][0] * self.grads[a][0]
                        + sig[i][1] * self.grads[a][1]
                        + sig[i][2] * self.grads[a][2]);
            }
        }
        f
    }

    /// Element stiffness matrix K_e (N/m):
    /// K_(a i)(b k) = V [λ g_a,i g_b,k + μ g_a,k g_b,i + μ δ_ik (g_a·g_b)].
    pub fn stiffness(&self, lambda: f64, mu: f64) -> ElementMatrix {
        let g = &self.grads;
        let mut k = ElementMatrix::zeros();
        for a in 0..4 {
            for b in 0..4 {
                let gab = g[a][0] * g[b][0] + g[a][1] * g[b][1] + g[a][2] * g[b][2];
                for i in 0..3 {
                    for kk in 0..3 {
                        let mut v = lambda * g[a][i] * g[b][kk] + mu * g[a][kk] * g[b][i];
                        if i == kk {
                            v += mu * gab;
                        }
                        k[(3 * a + i, 3 * b + kk)] = self.volume * v;
                    }
                }
            }
        }
        k
    }

    /// Largest eigenvalue of M_e⁻¹K_e (1/s²) with the lumped mass M_e = ρV/4 per node
    /// (`density` in kg/m³, scaled by `mass_factor` ≥ 1 for mass scaling).
    pub fn max_eigenvalue(&self, lambda: f64, mu: f64, density: f64, mass_factor: f64) -> f64 {
        let k = self.stiffness(lambda, mu);
        let eig = SymmetricEigen::new(k);
        let kmax = eig.eigenvalues.iter().cloned().fold(0.0f64, f64::max);
        kmax * 4.0 / (density * mass_factor * self.volume)
    }
}

/// Isotropic Hooke's law: σ = λ tr(ε) I + 2μ ε, both in [xx, yy, zz, yz, xz, xy] order
/// with tensor shear components; Pa.
pub fn stress_from_strain(e: &[f64; 6], lambda: f64, mu: f64) -> [f64; 6] {
    let tr = e[0] + e[1] + e[2];
    [
        lambda * tr + 2.0 * mu * e[0],
        lambda * tr + 2.0 * mu * e[1],
        lambda * tr + 2.0 * mu * e[2],
        2.0 * mu * e[3],
        2.0 * mu * e[4],
        2.0 * mu * e[5],
    ]
}
