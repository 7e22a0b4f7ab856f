//! Linear static solve K u = f with a sparse Cholesky factorisation (faer), assembled from
//! the same [`Tet4`](crate::fem::element::Tet4) stiffness as the explicit element forces.
//! Prescribed displacements are eliminated: only free dofs enter the factorisation and
//! the prescribed values move to the right-hand side.

use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};

use crate::error::{DemfemError, Result};
use crate::fem::assembly::{precompute_tets, stiffness_triplets};
use crate::fem::material::LinearElastic;
use crate::fem::mesh::TetMesh;

/// Displacements and reactions of a static solve.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticSolution {
    /// Nodal displacements, m.
    pub displacement: Vec<[f64; 3]>,
    /// Reaction forces K u − f at prescribed dofs (zero elsewhere), N.
    pub reaction: Vec<[f64; 3]>,
}

/// Solve K u = f for nodal loads `loads` (N, one per node) with the displacement of the
/// dofs in `prescribed` — (node, component, value in m) — fixed. The prescription must
/// remove all rigid-body modes, otherwise the factorisation fails with
/// [`DemfemError::Numerical`].
pub fn solve_static(mesh: &TetMesh, material: &LinearElastic, loads: &[[f64; 3]], prescribed: &[(usize, usize, f64)]) -> Result<StaticSolution> {
    mesh.validate()?;
    material.validate()?;
    let n = mesh.nodes.len();
    if loads.len() != n {
        return Err(DemfemError::ShapeMismatch { field: "loads".into(), detail: format!("{} entries for {n} nodes", loads.len()) });
    }
    let ndof = 3 * n;
    let mut fixed: Vec<Option<f64>> = vec![None; ndof];
    for &(node, c, v) in prescribed {
        if node >= n || c > 2 {
            return Err(DemfemError::ShapeMismatch { field: "prescribed".into(), detail: format!("node {node} component {c} out of range") });
        }
        if !v.is_finite() {
            return Err(DemfemError::invalid("prescribed value", v, "finite"));
        }
        fixed[3 * node + c] = Some(v);
    }
    let mut free_index = vec![usize::MAX; ndof];
    let mut nf = 0;
    for d in 0..ndof {
        if fixed[d].is_none() {
            free_index[d] = nf;
            nf += 1;
        }
    }
    let (lambda, mu) = material.lame();
    let tets = precompute_tets(mesh)?;
    let trips = stiffness_triplets(mesh, &tets, lambda, mu, false);
    let mut rhs = Mat::<f64>::zeros(nf, 1);
    for d in 0..ndof {
        if free_index[d] != usize::MAX {
            rhs[(free_index[d], 0)] = loads[d / 3][d % 3];
        }
    }
    let mut lower = Vec::with_capacity(trips.len() / 2 + ndof);
    for &(r, c, v) in &trips {
        match (free_index[r] != usize::MAX, free_index[c] != usize::MAX) {
            (true, true) => {
                if free_index[r] >= free_index[c] {
                    lower.push(Triplet::new(free_index[r], free_index[c], v));
                }
            }
            (true, false) => {
                if let Some(uc) = fixed[c] {
                    rhs[(free_index[r], 0)] -= v * uc;
                }
            }
            _ => {}
        }
    }
    let mut u = vec![[0.0; 3]; n];
    if nf > 0 {
        let k = SparseColMat::<usize, f64>::try_new_from_triplets(nf, nf, &lower)
            .map_err(|e| DemfemError::Numerical(format!("sparse stiffness assembly failed: {e:?}")))?;
        let llt = k
            .sp_cholesky(Side::Lower)
            .map_err(|e| DemfemError::Numerical(format!("stiffness not positive definite (insufficient supports?): {e:?}")))?;
        llt.solve_in_place(rhs.as_mut());
    }
    for d in 0..ndof {
        u[d / 3][d % 3] = match fixed[d] {
            Some(v) => v,
            None => rhs[(free_index[d], 0)],
        };
    }
    if u.iter().flatten().any(|x| !x.is_finite()) {
        return Err(DemfemError::Numerical("static solve produced non-finite displacements".into()));
    }
    // Reactions from K u − f at the prescribed dofs.
    let mut reaction = vec![[0.0; 3]; n];
    for &(r, c, v) in &trips {
        if fixed[r].is_some() {
            reaction[r / 3][r % 3] += v * u[c / 3][c % 3];
        }
    }
    for d in 0..ndof {
        if fixed[d].is_some() {
            reaction[d / 3][d % 3] -= loads[d / 3][d % 3];
        }
    }
    Ok(StaticSolution { displacement: u, reaction })
}
