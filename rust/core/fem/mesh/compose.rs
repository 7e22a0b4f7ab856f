//! Meshes made of other meshes: a ball (a structured cube mapped radially onto a sphere),
//! rigid placement (rotation and translation) of a mesh, and the union of several meshes
//! into one with a body number per node, as the contact model takes them.

use crate::error::{check_positive, DemfemError, Result};

use super::{box_tet_mesh, TetMesh};

/// Tet mesh of a ball of `radius` (m) centred at the origin, from a cube of 2n × 2n × 2n
/// cells: the inner half (|p|_∞ ≤ ½) is a core cube of half-side 0.35 R, and the outer cells
/// are blended from the core's faces onto the sphere along d(p/|p|_∞), d the smooth
/// cube-to-sphere map x' = x √(1 − y²/2 − z²/2 + y²z²/3) (and cyclically).
pub fn ball_tet_mesh(radius: f64, n: usize) -> Result<TetMesh> {
    check_positive("radius", radius)?;
    if n == 0 || n > 200 {
        return Err(DemfemError::invalid(
            "n",
            n as f64,
            "an integer in [1, 200]",
        ));
    }
    // Half the cube's cells form a core cube of half-side 0.35 R; the outer shell of cells
    // is blended from the core's faces onto the sphere, so no cell has three faces on it.
    const CORE: f64 = 0.5;
    const CORE_SIZE: f64 = 0.35;
    let cells = 2 * n;
    let mut mesh = box_tet_mesh(2.0, 2.0, 2.0, cells, cells, cells)?;
    for x in mesh.nodes.iter_mut() {
        let p = [x[0] - 1.0, x[1] - 1.0, x[2] - 1.0];
        let s = p[0].abs().max(p[1].abs()).max(p[2].abs());
        if s <= CORE {
            *x = [
                p[0] * radius * CORE_SIZE / CORE,
                p[1] * radius * CORE_SIZE / CORE,
                p[2] * radius * CORE_SIZE / CORE,
            ];
            continue;
        }
        let q = [p[0] / s, p[1] / s, p[2] / s];
        let sq = [q[0] * q[0], q[1] * q[1], q[2] * q[2]];
        let d = [
            q[0] * (1.0 - 0.5 * sq[1] - 0.5 * sq[2] + sq[1] * sq[2] / 3.0).sqrt(),
            q[1] * (1.0 - 0.5 * sq[2] - 0.5 * sq[0] + sq[2] * sq[0] / 3.0).sqrt(),
            q[2] * (1.0 - 0.5 * sq[0] - 0.5 * sq[1] + sq[0] * sq[1] / 3.0).sqrt(),
        ];
        // Blend from the core cube's boundary (at s = CORE) to the sphere (at s = 1).
        let tau = (s - CORE) / (1.0 - CORE);
        for k in 0..3 {
            let b = radius * CORE_SIZE * q[k];
            x[k] = b + tau * (radius * d[k] - b);
        }
    }
    mesh.validate()?;
    Ok(mesh)
}

/// The mesh rotated by the 3×3 matrix `rotation` (rows; must be a proper rotation) about
/// the origin, then moved by `translation` (m).
pub fn place(mesh: &TetMesh, rotation: [[f64; 3]; 3], translation: [f64; 3]) -> Result<TetMesh> {
    let r = rotation;
    let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
        - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
        + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    let mut orth: f64 = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            let d: f64 = (0..3).map(|k| r[i][k] * r[j][k]).sum();
            orth = orth.max((d - if i == j { 1.0 } else { 0.0 }).abs());
        }
    }
    if !(orth < 1e-9) || !((det - 1.0).abs() < 1e-9) {
        return Err(DemfemError::InvalidParameter {
            field: "rotation".into(),
            value: format!("{r:?}"),
            allowed: "a proper rotation matrix (orthonormal rows, determinant 1)".into(),
        });
    }
    if !translation.iter().all(|x| x.is_finite()) {
        return Err(DemfemError::InvalidParameter {
            field: "translation".into(),
            value: format!("{translation:?}"),
            allowed: "finite".into(),
        });
    }
    let nodes = mesh
        .nodes
        .iter()
        .map(|x| {
            let mut y = translation;
            for i in 0..3 {
                y[i] += r[i][0] * x[0] + r[i][1] * x[1] + r[i][2] * x[2];
            }
            y
        })
        .collect();
    Ok(TetMesh {
        nodes,
        tets: mesh.tets.clone(),
    })
}

/// The union of `meshes` (nodes and elements renumbered in order) and the body number of
/// every node (the index of its mesh).
pub fn union(meshes: &[TetMesh]) -> (TetMesh, Vec<u32>) {
    let mut nodes = Vec::new();
    let mut tets = Vec::new();
    let mut body = Vec::new();
    for (b, m) in meshes.iter().enumerate() {
        let off = nodes.len();
        nodes.extend_from_slice(&m.nodes);
        tets.extend(m.tets.iter().map(|t| t.map(|i| i + off)));
        body.extend(std::iter::repeat_n(b as u32, m.nodes.len()));
    }
    (TetMesh { nodes, tets }, body)
}
