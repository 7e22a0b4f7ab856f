//! Thin-shell model on a [`TriMesh`]: flat CST + DKT triangles ([`ShellTri`]) with 6 dof
//! per node, sparse assembly and a linear static solve (faer Cholesky). Dof index of
//! node n, component k (0–2 translations in m, 3–5 rotations in rad) is 6n + k.

use crate::error::{DemfemError, Result};
use crate::fem::element::ShellTri;
use crate::fem::material::LinearElastic;
use crate::fem::mesh::TriMesh;
use crate::fem::static_solve::solve_constrained;

mod explicit_contact;
mod explicit_state;

pub use explicit_contact::ShellEnergy;

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

/// Explicit central-difference dynamics of a [`ShellModel`]: precomputed global 18×18
/// element stiffnesses applied element by element in parallel into a per-element buffer,
/// gathered per node in element order (bitwise deterministic for any thread count);
/// lumped mass ρhA/3 per translation and ρh³/12·A/3 per rotation (physical rotary
/// inertia: its frequencies stay at the level of the CST membrane ones, so it does not
/// shrink the step). Fixed dofs are held at zero. Energies use the same exact discrete
/// balance as the tetrahedral solver ([`crate::fem::explicit`]).
#[derive(Debug, Clone)]
pub struct ShellExplicit {
    conn: Vec<[usize; 3]>,
    k_e: Vec<crate::fem::element::shell_dkt::ShellMatrix>,
    adjacency: crate::fem::assembly::NodeAdjacency,
    mass: Vec<f64>,
    free: Vec<bool>,
    loads: Vec<f64>,
    u: Vec<f64>,
    v: Vec<f64>,
    f: Vec<f64>,
    buffer: Vec<[f64; 18]>,
    f_prev: Vec<f64>,
    du_prev: Vec<f64>,
    dt: f64,
    dt_limit: f64,
    dt_requested: Option<f64>,
    lam_max: f64,
    dt_limit_without_contact: f64,
    contact: Option<crate::fem::contact::FemContact>,
    f_contact: Vec<[f64; 3]>,
    u3: Vec<[f64; 3]>,
    v3: Vec<[f64; 3]>,
    steps: u64,
    /// Kinetic (½ v^{n−½}·M v^{n+½}), internal, external work and initial energy, J.
    pub energy: [f64; 4],
}

impl ShellExplicit {
    /// Build from a model, the fixed dofs (node, dof 0–5) and the time step `dt` (s;
    /// `None` = 0.9 × the element eigenvalue bound 2/√(max_e λ_max(M_e⁻¹K_e)); a larger
    /// value is refused with [`DemfemError::UnstableTimeStep`]).
    pub fn new(model: &ShellModel, fixed: &[(usize, usize)], dt: Option<f64>) -> Result<Self> {
        use nalgebra::SymmetricEigen;
        let nn = model.mesh.nodes.len();
        let (e, nu, rho) = (
            model.material.young_modulus,
            model.material.poisson_ratio,
            model.material.density,
        );
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
        let mut mass = vec![0.0; 6 * nn];
        let mut lam_max: f64 = 0.0;
        for ((t, el), k) in model.mesh.triangles.iter().zip(&model.elements).zip(&k_e) {
            let mt = rho * el.thickness * el.area / 3.0;
            let mr = mt * el.thickness * el.thickness / 12.0;
            let me: [f64; 6] = [mt, mt, mt, mr, mr, mr];
            for &n in t {
                for c in 0..6 {
                    mass[6 * n + c] += me[c];
                }
            }
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
            lam_max = lam_max.max(l);
        }
        let dt_limit = crate::fem::stable_step::critical_step_from_eigenvalue(lam_max, 0.0, 0.0)?;
        let dt_req = dt;
        let dt = match dt {
            Some(d) => {
                crate::error::check_positive("dt", d)?;
                if d > dt_limit {
                    return Err(DemfemError::UnstableTimeStep {
                        dt: d,
                        limit: dt_limit,
                        reason: "shell element eigenvalue bound".into(),
                    });
                }
                d
            }
            None => 0.9 * dt_limit,
        };
        let mut free = vec![true; 6 * nn];
        for &(n, k) in fixed {
            if n >= nn || k > 5 {
                return Err(DemfemError::ShapeMismatch {
                    field: "fixed".into(),
                    detail: format!("node {n} dof {k} out of range"),
                });
            }
            free[6 * n + k] = false;
        }
        let conn4: Vec<[usize; 4]> = model
            .mesh
            .triangles
            .iter()
            .map(|t| [t[0], t[1], t[2], t[2]])
            .collect();
        // Reuse the tet adjacency with a repeated last node; the duplicate entry (local 3)
        // is skipped in the gather.
        let adjacency = crate::fem::assembly::NodeAdjacency::new(&conn4, nn)?;
        let nd = 6 * nn;
        Ok(Self {
            conn: model.mesh.triangles.clone(),
            buffer: vec![[0.0; 18]; k_e.len()],
            k_e,
            adjacency,
            mass,
            free,
            loads: vec![0.0; nd],
            u: vec![0.0; nd],
            v: vec![0.0; nd],
            f: vec![0.0; nd],
            f_prev: vec![0.0; nd],
            du_prev: vec![0.0; nd],
            dt,
            dt_limit,
            dt_requested: dt_req,
            lam_max,
            dt_limit_without_contact: dt_limit,
            contact: None,
            f_contact: Vec::new(),
            u3: Vec::new(),
            v3: Vec::new(),
            steps: 0,
            energy: [0.0; 4],
        })
    }

    /// Time step, s.
    pub fn dt(&self) -> f64 {
        self.dt
    }
    /// Element eigenvalue bound on the critical step, s.
    pub fn dt_limit(&self) -> f64 {
        self.dt_limit
    }
    /// Dof vector u^n (m, rad).
    pub fn displacement(&self) -> &[f64] {
        &self.u
    }
    /// Time t^n, s.
    pub fn time(&self) -> f64 {
        self.steps as f64 * self.dt
    }
    /// Relative energy balance error |E_kin + E_int − W_ext − E_0| / scale.
    pub fn relative_balance_error(&self) -> f64 {
        let [k, i, w, e0] = self.energy;
        let scale = k.abs().max(i).max(w.abs()).max(e0.abs());
        if scale > 0.0 {
            (k + i - w - e0).abs() / scale
        } else {
            0.0
        }
    }

    /// Constant nodal loads (N, N·m), length 6 × nodes.
    pub fn set_loads(&mut self, f: &[f64]) -> Result<()> {
        if f.len() != self.loads.len() || f.iter().any(|x| !x.is_finite()) {
            return Err(DemfemError::ShapeMismatch {
                field: "loads".into(),
                detail: format!("{} finite values expected", self.loads.len()),
            });
        }
        self.loads.copy_from_slice(f);
        Ok(())
    }

    /// Initial dof vector (m, rad); before the first step only.
    pub fn set_initial_displacement(&mut self, u: &[f64]) -> Result<()> {
        if u.len() != self.u.len() || self.steps > 0 {
            return Err(DemfemError::ShapeMismatch {
                field: "u0".into(),
                detail: "wrong length or solver already started".into(),
            });
        }
        self.u.copy_from_slice(u);
        Ok(())
    }

    fn internal_forces(&mut self) {
        use rayon::prelude::*;
        let (k_e, conn, u) = (&self.k_e, &self.conn, &self.u);
        self.buffer.par_iter_mut().enumerate().for_each(|(e, out)| {
            let t = conn[e];
            let mut ue = [0.0; 18];
            for a in 0..3 {
                ue[6 * a..6 * a + 6].copy_from_slice(&u[6 * t[a]..6 * t[a] + 6]);
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
        self.f.par_chunks_mut(6).enumerate().for_each(|(n, fnode)| {
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
            fnode.copy_from_slice(&s);
        });
    }

    /// Advance `n` steps; error on a non-finite state or a contact failure (a runaway
    /// contact, an exceeded step allowance).
    pub fn run(&mut self, n: u64) -> Result<()> {
        for _ in 0..n {
            self.step();
            if let Some(err) = self.contact.as_mut().and_then(|c| c.take_failure()) {
                return Err(err);
            }
        }
        if self.u.iter().chain(&self.v).any(|x| !x.is_finite()) {
            return Err(DemfemError::Numerical("non-finite shell state".into()));
        }
        Ok(())
    }

    /// One central-difference step.
    pub fn step(&mut self) {
        self.internal_forces();
        let first = self.steps == 0;
        let dt = self.dt;
        let has_contact = self.contact_forces();
        let dt_n = if first { 0.5 * dt } else { dt };
        let (mut ek, mut ei, mut dw) = (0.0, 0.0, 0.0);
        for d in 0..self.u.len() {
            let m = self.mass[d];
            let v_old = self.v[d];
            let f_ext = if has_contact && d % 6 < 3 {
                self.loads[d] + self.f_contact[d / 6][d % 6]
            } else {
                self.loads[d]
            };
            let (v_new, f_tot) = if self.free[d] {
                (v_old + dt_n * (f_ext - self.f[d]) / m, f_ext)
            } else {
                let a = -v_old / dt_n;
                (0.0, m * a + self.f[d])
            };
            let v_prev = if first { 2.0 * v_old - v_new } else { v_old };
            ek += 0.5 * m * v_prev * v_new;
            ei += 0.5 * self.u[d] * self.f[d];
            dw += 0.5 * self.du_prev[d] * (self.f_prev[d] + f_tot);
            self.f_prev[d] = f_tot;
            self.v[d] = v_new;
            self.du_prev[d] = dt * v_new;
            self.u[d] += dt * v_new;
        }
        let w = self.energy[2] + dw;
        let e0 = if first { ek + ei } else { self.energy[3] };
        self.energy = [ek, ei, w, e0];
        self.steps += 1;
    }
}
