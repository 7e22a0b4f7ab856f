//! Assembly: element precomputation, lumped nodal masses, node→element adjacency for the
//! deterministic gather of element forces, sparse stiffness triplets, and consistent
//! nodal forces of a surface pressure.

use crate::error::{check_positive, DemfemError, Result};
use crate::fem::element::Tet4;
use crate::fem::mesh::{cross, TetMesh};

/// Precompute the [`Tet4`] geometry of every element (fails on an inverted element).
pub fn precompute_tets(mesh: &TetMesh) -> Result<Vec<Tet4>> {
    mesh.tets
        .iter()
        .enumerate()
        .map(|(e, t)| {
            Tet4::new([
                mesh.nodes[t[0]],
                mesh.nodes[t[1]],
                mesh.nodes[t[2]],
                mesh.nodes[t[3]],
            ])
            .map_err(|err| DemfemError::Numerical(format!("element {e}: {err}")))
        })
        .collect()
}

/// Lumped (row-sum) nodal masses, kg: each node receives ρ V s_e / 4 from every element e,
/// `mass_factor[e]` = s_e ≥ 1 being the optional mass-scaling factor (`None` = 1).
pub fn lumped_mass(
    mesh: &TetMesh,
    tets: &[Tet4],
    density: f64,
    mass_factor: Option<&[f64]>,
) -> Result<Vec<f64>> {
    check_positive("density", density)?;
    let mut m = vec![0.0; mesh.nodes.len()];
    for (e, (t, g)) in mesh.tets.iter().zip(tets).enumerate() {
        let s = mass_factor.map_or(1.0, |f| f[e]);
        let me = 0.25 * density * g.volume * s;
        for &n in t {
            m[n] += me;
        }
    }
    if let Some(i) = m.iter().position(|&x| !(x > 0.0)) {
        return Err(DemfemError::ShapeMismatch {
            field: "mesh.nodes".into(),
            detail: format!("node {i} belongs to no element (zero mass)"),
        });
    }
    Ok(m)
}

/// Compressed node→(element, local node) adjacency. Entries of node `n` are
/// `entries[offsets[n]..offsets[n+1]]`, each `4·element + local`, in increasing element
/// order. Summing element contributions in this fixed order makes the assembled force
/// independent of the number of threads (bitwise).
#[derive(Debug, Clone, PartialEq)]
pub struct NodeAdjacency {
    /// Offsets into `entries`, length `n_nodes + 1`.
    pub offsets: Vec<u32>,
    /// `4·element + local node` entries.
    pub entries: Vec<u32>,
}

impl NodeAdjacency {
    /// Build from the connectivity of a mesh with `n_nodes` nodes.
    pub fn new(tets: &[[usize; 4]], n_nodes: usize) -> Result<Self> {
        if tets.len().saturating_mul(4) >= u32::MAX as usize {
            return Err(DemfemError::ShapeMismatch {
                field: "mesh.tets".into(),
                detail: "too many elements for 32-bit adjacency".into(),
            });
        }
        let mut count = vec![0u32; n_nodes + 1];
        for t in tets {
            for &n in t {
                count[n + 1] += 1;
            }
        }
        for i in 0..n_nodes {
            count[i + 1] += count[i];
        }
        let offsets = count.clone();
        let mut fill = count;
        let mut entries = vec![0u32; tets.len() * 4];
        for (e, t) in tets.iter().enumerate() {
            for (a, &n) in t.iter().enumerate() {
                entries[fill[n] as usize] = (4 * e + a) as u32;
                fill[n] += 1;
            }
        }
        Ok(Self { offsets, entries })
    }
}

/// Stiffness triplets (row dof, column dof, value in N/m) of the whole mesh, dof = 3·node +
/// component; duplicates are to be summed. Only entries with row ≥ column (lower triangle)
/// are returned when `lower_only`.
pub fn stiffness_triplets(
    mesh: &TetMesh,
    tets: &[Tet4],
    lambda: f64,
    mu: f64,
    lower_only: bool,
) -> Vec<(usize, usize, f64)> {
    let mut out = Vec::with_capacity(mesh.tets.len() * if lower_only { 78 } else { 144 });
    for (t, g) in mesh.tets.iter().zip(tets) {
        let k = g.stiffness(lambda, mu);
        for a in 0..4 {
            for i in 0..3 {
                let r = 3 * t[a] + i;
                for b in 0..4 {
                    for j in 0..3 {
                        let c = 3 * t[b] + j;
                        if !lower_only || r >= c {
                            out.push((r, c, k[(3 * a + i, 3 * b + j)]));
                        }
                    }
                }
            }
        }
    }
    out
}

/// Consistent nodal forces (N) of a uniform pressure `pressure` (Pa, positive pushing
/// into the body) on the boundary faces whose three nodes all satisfy `on_surface`
/// (called with node coordinates in m). For a linear triangle the consistent load is
/// p·A/3 per node along the inward normal. Returns one force per node.
pub fn surface_pressure_loads(
    mesh: &TetMesh,
    pressure: f64,
    on_surface: impl Fn([f64; 3]) -> bool,
) -> Result<Vec<[f64; 3]>> {
    if !pressure.is_finite() {
        return Err(DemfemError::invalid("pressure", pressure, "finite"));
    }
    let mut f = vec![[0.0; 3]; mesh.nodes.len()];
    for face in mesh.boundary_faces() {
        let p = [
            mesh.nodes[face[0]],
            mesh.nodes[face[1]],
            mesh.nodes[face[2]],
        ];
        if !p.iter().all(|&x| on_surface(x)) {
            continue;
        }
        // cross of the edges = 2·A·n_out; the load is −p·A·n_out split equally.
        let n2 = cross(
            crate::fem::mesh::sub(p[1], p[0]),
            crate::fem::mesh::sub(p[2], p[0]),
        );
        for &node in &face {
            for c in 0..3 {
                f[node][c] -= pressure * n2[c] / 6.0;
            }
        }
    }
    Ok(f)
}
