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
pub fn solve_static(
    mesh: &TetMesh,
    material: &LinearElastic,
    loads: &[[f64; 3]],
    prescribed: &[(usize, usize, f64)],
) -> Result<StaticSolution> {
    mesh.validate()?;
    material.validate()?;
    let n = mesh.nodes.len();
    if loads.len() != n {
        return Err(DemfemError::ShapeMismatch {
            field: "loads".into(),
            detail: format!("{} entries for {n} nodes", loads.len()),
        });
    }
    let ndof = 3 * n;
    let mut fixed: Vec<Option<f64>> = vec![None; ndof];
    for &(node, c, v) in prescribed {
        if node >= n || c > 2 {
            return Err(DemfemError::ShapeMismatch {
                field: "prescribed".into(),
                detail: format!("node {node} component {c} out of range"),
            });
        }
        if !v.is_finite() {
            return Err(DemfemError::invalid("prescribed value", v, "finite"));
        }
        fixed[3 * node + c] = Some(v);
    }
    let (lambda, mu) = material.lame();
    let tets = precompute_tets(mesh)?;
    let trips = stiffness_triplets(mesh, &tets, lambda, mu, false);
    let f: Vec<f64> = loads.iter().flatten().cloned().collect();
    let (x, r) = solve_constrained(ndof, &trips, &f, &fixed)?;
    let to3 = |v: &[f64]| {
        v.chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect::<Vec<[f64; 3]>>()
    };
    let (u, reaction) = (to3(&x), to3(&r));
    Ok(StaticSolution {
        displacement: u,
        reaction,
    })
}

/// Solve K x = f for a symmetric positive definite K given as full (both triangles)
/// triplets (row, col, value; duplicates summed) of size `ndof`, with `fixed[d] = Some(v)`
/// prescribing dof d. Returns (x, reactions K x − f at fixed dofs, 0 elsewhere).
pub fn solve_constrained(
    ndof: usize,
    trips: &[(usize, usize, f64)],
    f: &[f64],
    fixed: &[Option<f64>],
) -> Result<(Vec<f64>, Vec<f64>)> {
    if f.len() != ndof || fixed.len() != ndof {
        return Err(DemfemError::ShapeMismatch {
            field: "rhs".into(),
            detail: format!("expected {ndof} dofs"),
        });
    }
    let mut free_index = vec![usize::MAX; ndof];
    let mut nf = 0;
    for d in 0..ndof {
        if fixed[d].is_none() {
            free_index[d] = nf;
            nf += 1;
        }
    }
    let mut rhs = Mat::<f64>::zeros(nf, 1);
    for d in 0..ndof {
        if free_index[d] != usize::MAX {
            rhs[(free_index[d], 0)] = f[d];
        }
    }
    let mut lower = Vec::with_capacity(trips.len() / 2 + ndof);
    for &(r, c, v) in trips {
        if r >= ndof || c >= ndof {
            return Err(DemfemError::ShapeMismatch {
                field: "triplets".into(),
                detail: format!("index ({r}, {c}) >= {ndof}"),
            });
        }
        match (free_index[r] != usize::MAX, free_index[c] != usize::MAX) {
            (true, true) if free_index[r] >= free_index[c] => {
                lower.push(Triplet::new(free_index[r], free_index[c], v));
            }
            (true, false) => {
                if let Some(uc) = fixed[c] {
                    rhs[(free_index[r], 0)] -= v * uc;
                }
            }
            _ => {}
        }
    }
    if nf > 0 {
        let k = SparseColMat::<usize, f64>::try_new_from_triplets(nf, nf, &lower).map_err(|e| {
            DemfemError::Numerical(format!("sparse stiffness assembly failed: {e:?}"))
        })?;
        let llt = k.sp_cholesky(Side::Lower).map_err(|e| {
            DemfemError::Numerical(format!(
                "stiffness not positive definite (insufficient supports?): {e:?}"
            ))
        })?;
        llt.solve_in_place(rhs.as_mut());
    }
    let x: Vec<f64> = (0..ndof)
        .map(|d| fixed[d].unwrap_or_else(|| rhs[(free_index[d], 0)]))
        .collect();
    if x.iter().any(|v| !v.is_finite()) {
        return Err(DemfemError::Numerical(
            "static solve produced non-finite displacements".into(),
        ));
    }
    let mut reaction = vec![0.0; ndof];
    for &(r, c, v) in trips {
        if fixed[r].is_some() {
            reaction[r] += v * x[c];
        }
    }
    for d in 0..ndof {
        if fixed[d].is_some() {
            reaction[d] -= f[d];
        }
    }
    Ok((x, reaction))
}
