//! Stress recovery for linear tetrahedra: element stress tensors (constant per element),
//! nodal stresses by volume-weighted averaging, principal stresses, von Mises stress and
//! stresses sampled along a line (e.g. through the wall).
//!
//! Stress vectors are [xx, yy, zz, yz, xz, xy], Pa.

use crate::error::{DemfemError, Result};
use crate::fem::assembly::precompute_tets;
use crate::fem::element::tet4::stress_from_strain;
use crate::fem::material::LinearElastic;
use crate::fem::mesh::{signed_volume, TetMesh};

/// Element stresses (Pa) for nodal displacements `u` (m).
pub fn element_stresses(
    mesh: &TetMesh,
    material: &LinearElastic,
    u: &[[f64; 3]],
) -> Result<Vec<[f64; 6]>> {
    if u.len() != mesh.nodes.len() {
        return Err(DemfemError::ShapeMismatch {
            field: "u".into(),
            detail: format!("{} entries for {} nodes", u.len(), mesh.nodes.len()),
        });
    }
    let (lambda, mu) = material.lame();
    let tets = precompute_tets(mesh)?;
    Ok(mesh
        .tets
        .iter()
        .zip(&tets)
        .map(|(t, g)| {
            let ue = [u[t[0]], u[t[1]], u[t[2]], u[t[3]]];
            stress_from_strain(&g.strain(&ue), lambda, mu)
        })
        .collect())
}

/// Nodal stresses (Pa): average of the stresses of the elements around each node,
/// weighted by element volume.
pub fn nodal_stresses(mesh: &TetMesh, element_stress: &[[f64; 6]]) -> Result<Vec<[f64; 6]>> {
    if element_stress.len() != mesh.tets.len() {
        return Err(DemfemError::ShapeMismatch {
            field: "element_stress".into(),
            detail: "one stress per element expected".into(),
        });
    }
    let mut s = vec![[0.0; 6]; mesh.nodes.len()];
    let mut w = vec![0.0; mesh.nodes.len()];
    for (t, se) in mesh.tets.iter().zip(element_stress) {
        let v = signed_volume(
            mesh.nodes[t[0]],
            mesh.nodes[t[1]],
            mesh.nodes[t[2]],
            mesh.nodes[t[3]],
        );
        for &n in t {
            w[n] += v;
            for c in 0..6 {
                s[n][c] += v * se[c];
            }
        }
    }
    for (sn, wn) in s.iter_mut().zip(&w) {
        if *wn > 0.0 {
            for c in sn.iter_mut() {
                *c /= wn;
            }
        }
    }
    Ok(s)
}

/// Principal stresses σ1 ≥ σ2 ≥ σ3 (Pa) of a symmetric stress, by the closed-form
/// trigonometric solution of the characteristic cubic.
pub fn principal_stresses(s: &[f64; 6]) -> [f64; 3] {
    let (xx, yy, zz, yz, xz, xy) = (s[0], s[1], s[2], s[3], s[4], s[5]);
    let p1 = xy * xy + xz * xz + yz * yz;
    let q = (xx + yy + zz) / 3.0;
    if p1 <= 1e-30 * (xx * xx + yy * yy + zz * zz).max(f64::MIN_POSITIVE) {
        let mut e = [xx, yy, zz];
        e.sort_by(|a, b| b.total_cmp(a));
        return e;
    }
    let p2 = (xx - q).powi(2) + (yy - q).powi(2) + (zz - q).powi(2) + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    // B = (A − qI)/p, r = det(B)/2.
    let (bxx, byy, bzz, byz, bxz, bxy) = (
        (xx - q) / p,
        (yy - q) / p,
        (zz - q) / p,
        yz / p,
        xz / p,
        xy / p,
    );
    let det = bxx * (byy * bzz - byz * byz) - bxy * (bxy * bzz - byz * bxz)
        + bxz * (bxy * byz - byy * bxz);
    let r = (0.5 * det).clamp(-1.0, 1.0);
    let phi = r.acos() / 3.0;
    let e1 = q + 2.0 * p * phi.cos();
    let e3 = q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos();
    let e2 = 3.0 * q - e1 - e3;
    [e1, e2, e3]
}

/// Maximum principal stress σ1, Pa.
pub fn max_principal_stress(s: &[f64; 6]) -> f64 {
    principal_stresses(s)[0]
}

/// Von Mises equivalent stress, Pa.
pub fn von_mises(s: &[f64; 6]) -> f64 {
    let (xx, yy, zz, yz, xz, xy) = (s[0], s[1], s[2], s[3], s[4], s[5]);
    (0.5 * ((xx - yy).powi(2) + (yy - zz).powi(2) + (zz - xx).powi(2))
        + 3.0 * (xy * xy + yz * yz + xz * xz))
        .sqrt()
}

/// A stress sample on a line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineSample {
    /// Sample position, m.
    pub point: [f64; 3],
    /// Distance from the start of the line, m.
    pub distance: f64,
    /// Nodal stress interpolated linearly inside the containing element, Pa.
    pub stress: [f64; 6],
}

/// Sample the nodal stress field at `n_points` ≥ 2 equally spaced points from `a` to `b`
/// (m), interpolating linearly inside the containing tetrahedron. Points outside the mesh
/// (beyond a relative tolerance of 1e-9 in barycentric coordinates) are skipped.
pub fn stress_along_line(
    mesh: &TetMesh,
    nodal_stress: &[[f64; 6]],
    a: [f64; 3],
    b: [f64; 3],
    n_points: usize,
) -> Result<Vec<LineSample>> {
    if nodal_stress.len() != mesh.nodes.len() {
        return Err(DemfemError::ShapeMismatch {
            field: "nodal_stress".into(),
            detail: "one stress per node expected".into(),
        });
    }
    if n_points < 2 {
        return Err(DemfemError::invalid("n_points", n_points as f64, ">= 2"));
    }
    let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt();
    let mut out = Vec::with_capacity(n_points);
    for k in 0..n_points {
        let s = k as f64 / (n_points - 1) as f64;
        let p = [
            a[0] + s * (b[0] - a[0]),
            a[1] + s * (b[1] - a[1]),
            a[2] + s * (b[2] - a[2]),
        ];
        let mut best: Option<(f64, usize, [f64; 4])> = None;
        for (e, t) in mesh.tets.iter().enumerate() {
            let x = [
                mesh.nodes[t[0]],
                mesh.nodes[t[1]],
                mesh.nodes[t[2]],
                mesh.nodes[t[3]],
            ];
            let v = signed_volume(x[0], x[1], x[2], x[3]);
            let l = [
                signed_volume(p, x[1], x[2], x[3]) / v,
                signed_volume(x[0], p, x[2], x[3]) / v,
                signed_volume(x[0], x[1], p, x[3]) / v,
                signed_volume(x[0], x[1], x[2], p) / v,
            ];
            let worst = l.iter().cloned().fold(f64::INFINITY, f64::min);
            if best.is_none_or(|bb| worst > bb.0) {
                best = Some((worst, e, l));
            }
            if worst >= 0.0 {
                break;
            }
        }
        if let Some((worst, e, l)) = best {
            if worst >= -1e-9 {
                let t = mesh.tets[e];
                let mut st = [0.0; 6];
                for q in 0..4 {
                    for c in 0..6 {
                        st[c] += l[q] * nodal_stress[t[q]][c];
                    }
                }
                out.push(LineSample {
                    point: p,
                    distance: s * len,
                    stress: st,
                });
            }
        }
    }
    Ok(out)
}
