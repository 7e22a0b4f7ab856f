//! Flat triangular thin-shell element: constant-strain membrane (CST) + discrete Kirchhoff
//! triangle bending (DKT; Batoz, Bathe & Ho, IJNME 15 (1980) 1771–1812) + a small
//! fictitious drilling stiffness, in a local frame per element, rotated to 6 global dof per
//! node (u_x, u_y, u_z, θ_x, θ_y, θ_z; rotations are right-hand rotation-vector
//! components, radians).
//!
//! Local conventions (Batoz): θ_x = ∂w/∂y, θ_y = −∂w/∂x; the rotations of the normal are
//! β_x = θ_y, β_y = −θ_x; curvatures κ = [β_x,x, β_y,y, β_x,y + β_y,x], so the in-plane
//! strain at distance z from the mid-surface is ε(z) = ε_m + z κ.

use nalgebra::SMatrix;

use crate::error::{check_positive, DemfemError, Result};
use crate::fem::mesh::{cross, dot, norm, sub};

/// 18×18 shell element matrix (node-major: 6 dof per node).
pub type ShellMatrix = SMatrix<f64, 18, 18>;
type Mat9 = SMatrix<f64, 9, 9>;
type Mat3x9 = SMatrix<f64, 3, 9>;

/// Fictitious drilling stiffness as a fraction of the largest bending rotation diagonal term.
const DRILLING_FRACTION: f64 = 1e-3;

/// Precomputed geometry of one flat shell triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShellTri {
    /// Local frame: rows are the unit vectors e1 (along edge 1→2), e2, e3 (normal).
    pub frame: [[f64; 3]; 3],
    /// Node coordinates in the local frame (origin at node 1), m.
    pub local: [[f64; 2]; 3],
    /// Area, m².
    pub area: f64,
    /// Thickness, m.
    pub thickness: f64,
}

impl ShellTri {
    /// Precompute from the three mid-surface vertices (m) and the thickness (m).
    pub fn new(x: [[f64; 3]; 3], thickness: f64) -> Result<Self> {
        check_positive("thickness", thickness)?;
        let a = sub(x[1], x[0]);
        let b = sub(x[2], x[0]);
        let n = cross(a, b);
        let nn = norm(n);
        let la = norm(a);
        if !(nn > 0.0) || !nn.is_finite() {
            return Err(DemfemError::Numerical("degenerate shell triangle".into()));
        }
        let e1 = [a[0] / la, a[1] / la, a[2] / la];
        let e3 = [n[0] / nn, n[1] / nn, n[2] / nn];
        let e2 = cross(e3, e1);
        let local = [[0.0, 0.0], [la, 0.0], [dot(b, e1), dot(b, e2)]];
        Ok(Self {
            frame: [e1, e2, e3],
            local,
            area: 0.5 * nn,
            thickness,
        })
    }

    /// DKT curvature–displacement matrix at area coordinates (ξ, η) = (L2, L3), local dofs
    /// (w, θx, θy) per node; 1/m.
    pub fn dkt_b(&self, xi: f64, eta: f64) -> Mat3x9 {
        let p = &self.local;
        let (x1, y1, x2, y2, x3, y3) = (p[0][0], p[0][1], p[1][0], p[1][1], p[2][0], p[2][1]);
        // Sides k = 4, 5, 6 are 23, 31, 12; x_ij = x_i − x_j.
        let sides = [(x2 - x3, y2 - y3), (x3 - x1, y3 - y1), (x1 - x2, y1 - y2)];
        let mut pp = [0.0; 3];
        let mut q = [0.0; 3];
        let mut r = [0.0; 3];
        let mut t = [0.0; 3];
        for (k, &(xij, yij)) in sides.iter().enumerate() {
            let l2 = xij * xij + yij * yij;
            pp[k] = -6.0 * xij / l2;
            q[k] = 3.0 * xij * yij / l2;
            r[k] = 3.0 * yij * yij / l2;
            t[k] = -6.0 * yij / l2;
        }
        let (p4, p5, p6) = (pp[0], pp[1], pp[2]);
        let (q4, q5, q6) = (q[0], q[1], q[2]);
        let (r4, r5, r6) = (r[0], r[1], r[2]);
        let (t4, t5, t6) = (t[0], t[1], t[2]);
        let a = 1.0 - 2.0 * xi;
        let c = 1.0 - 2.0 * eta;
        let hx_xi = [
            p6 * a + (p5 - p6) * eta,
            q6 * a - (q5 + q6) * eta,
            -4.0 + 6.0 * (xi + eta) + r6 * a - eta * (r5 + r6),
            -p6 * a + eta * (p4 + p6),
            q6 * a - eta * (q6 - q4),
            -2.0 + 6.0 * xi + r6 * a + eta * (r4 - r6),
            -eta * (p5 + p4),
            eta * (q4 - q5),
            -eta * (r5 - r4),
        ];
        let hy_xi = [
            t6 * a + eta * (t5 - t6),
            1.0 + r6 * a - eta * (r5 + r6),
            -q6 * a + eta * (q5 + q6),
            -t6 * a + eta * (t4 + t6),
            -1.0 + r6 * a + eta * (r4 - r6),
            -q6 * a - eta * (q4 - q6),
            -eta * (t4 + t5),
            eta * (r4 - r5),
            -eta * (q4 - q5),
        ];
        let hx_eta = [
            -p5 * c - xi * (p6 - p5),
            q5 * c - xi * (q5 + q6),
            -4.0 + 6.0 * (xi + eta) + r5 * c - xi * (r5 + r6),
            xi * (p4 + p6),
            xi * (q4 - q6),
            -xi * (r6 - r4),
            p5 * c - xi * (p4 + p5),
            q5 * c + xi * (q4 - q5),
            -2.0 + 6.0 * eta + r5 * c + xi * (r4 - r5),
        ];
        let hy_eta = [
            -t5 * c - xi * (t6 - t5),
            1.0 + r5 * c - xi * (r5 + r6),
            -q5 * c + xi * (q5 + q6),
            xi * (t4 + t6),
            xi * (r4 - r6),
            -xi * (q4 - q6),
            t5 * c - xi * (t4 + t5),
            -1.0 + r5 * c + xi * (r4 - r5),
            -q5 * c - xi * (q4 - q5),
        ];
        let (x31, y31, x12, y12) = (x3 - x1, y3 - y1, x1 - x2, y1 - y2);
        let two_a = x31 * y12 - x12 * y31;
        let mut b = Mat3x9::zeros();
        for j in 0..9 {
            b[(0, j)] = (y31 * hx_xi[j] + y12 * hx_eta[j]) / two_a;
            b[(1, j)] = (-x31 * hy_xi[j] - x12 * hy_eta[j]) / two_a;
            b[(2, j)] =
                (-x31 * hx_xi[j] - x12 * hx_eta[j] + y31 * hy_xi[j] + y12 * hy_eta[j]) / two_a;
        }
        b
    }

    /// CST membrane strain–displacement matrix, local dofs (u, v) per node; 1/m.
    pub fn membrane_b(&self) -> SMatrix<f64, 3, 6> {
        let p = &self.local;
        let two_a = 2.0 * self.area;
        let (x1, y1, x2, y2, x3, y3) = (p[0][0], p[0][1], p[1][0], p[1][1], p[2][0], p[2][1]);
        let (y23, y31, y12) = (y2 - y3, y3 - y1, y1 - y2);
        let (x32, x13, x21) = (x3 - x2, x1 - x3, x2 - x1);
        SMatrix::<f64, 3, 6>::from_row_slice(&[
            y23, 0.0, y31, 0.0, y12, 0.0, //
            0.0, x32, 0.0, x13, 0.0, x21, //
            x32, y23, x13, y31, x21, y12,
        ]) / two_a
    }

    /// Element stiffness in the local frame (N/m, N, N·m), local dof order per node
    /// (u, v, w, θx, θy, θz), for Young's modulus `e` (Pa) and Poisson ratio `nu`.
    pub fn local_stiffness(&self, e: f64, nu: f64) -> ShellMatrix {
        let h = self.thickness;
        let plane =
            SMatrix::<f64, 3, 3>::new(1.0, nu, 0.0, nu, 1.0, 0.0, 0.0, 0.0, 0.5 * (1.0 - nu))
                * (e / (1.0 - nu * nu));
        let dm = plane * h;
        let db = plane * (h * h * h / 12.0);
        let bm = self.membrane_b();
        let km = bm.transpose() * dm * bm * self.area;
        // Bending: 3-point (edge mid-point) rule, exact for the quadratic integrand.
        let mut kb = Mat9::zeros();
        for (xi, eta) in [(0.5, 0.0), (0.5, 0.5), (0.0, 0.5)] {
            let b = self.dkt_b(xi, eta);
            kb += b.transpose() * db * b * (self.area / 3.0);
        }
        let mut k = ShellMatrix::zeros();
        for a in 0..3 {
            for b in 0..3 {
                for i in 0..2 {
                    for j in 0..2 {
                        k[(6 * a + i, 6 * b + j)] = km[(2 * a + i, 2 * b + j)];
                    }
                }
                for i in 0..3 {
                    for j in 0..3 {
                        k[(6 * a + 2 + i, 6 * b + 2 + j)] = kb[(3 * a + i, 3 * b + j)];
                    }
                }
            }
        }
        // Drilling: rows sum to zero, so a uniform θz costs nothing.
        // Scaled by the bending *rotation* diagonal terms (N·m), not the w terms (N/m).
        let kd = DRILLING_FRACTION
            * (0..3)
                .flat_map(|a| [kb[(3 * a + 1, 3 * a + 1)], kb[(3 * a + 2, 3 * a + 2)]])
                .fold(0.0, f64::max);
        for a in 0..3 {
            for b in 0..3 {
                k[(6 * a + 5, 6 * b + 5)] = if a == b { kd } else { -0.5 * kd };
            }
        }
        k
    }

    /// 18×18 rotation taking global dofs to local ones (u_local = T u_global).
    pub fn transformation(&self) -> ShellMatrix {
        let mut t = ShellMatrix::zeros();
        for blk in 0..6 {
            for i in 0..3 {
                for j in 0..3 {
                    t[(3 * blk + i, 3 * blk + j)] = self.frame[i][j];
                }
            }
        }
        t
    }

    /// Element stiffness in global dofs, Tᵀ K_local T.
    pub fn global_stiffness(&self, e: f64, nu: f64) -> ShellMatrix {
        let t = self.transformation();
        t.transpose() * self.local_stiffness(e, nu) * t
    }

    /// In-plane stresses [σ11, σ22, σ12] (Pa, local axes e1, e2) at the bottom (z = −h/2),
    /// middle and top (z = +h/2) surfaces at the centroid, for global element dofs `ug`.
    pub fn surface_stresses(&self, ug: &[f64; 18], e: f64, nu: f64) -> [[f64; 3]; 3] {
        let t = self.transformation();
        let ul = t * SMatrix::<f64, 18, 1>::from_column_slice(ug);
        let mut um = SMatrix::<f64, 6, 1>::zeros();
        let mut ub = SMatrix::<f64, 9, 1>::zeros();
        for a in 0..3 {
            um[2 * a] = ul[6 * a];
            um[2 * a + 1] = ul[6 * a + 1];
            for i in 0..3 {
                ub[3 * a + i] = ul[6 * a + 2 + i];
            }
        }
        let em = self.membrane_b() * um;
        let kappa = self.dkt_b(1.0 / 3.0, 1.0 / 3.0) * ub;
        let plane =
            SMatrix::<f64, 3, 3>::new(1.0, nu, 0.0, nu, 1.0, 0.0, 0.0, 0.0, 0.5 * (1.0 - nu))
                * (e / (1.0 - nu * nu));
        let h = self.thickness;
        [-0.5 * h, 0.0, 0.5 * h].map(|z| {
            let s = plane * (em + kappa * z);
            [s[0], s[1], s[2]]
        })
    }
}
