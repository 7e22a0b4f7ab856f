//! The contact surface of a tetrahedral mesh: its boundary faces (faces of exactly one
//! tetrahedron), oriented outward, with the penalty stiffness of each face taken from the
//! element under it, and the surface nodes with their tributary areas and stiffnesses.
//!
//! Penalty stiffness (OpenRadioss TYPE7, `Istf = 0`): a face of area A on an element of
//! volume V and bulk modulus K gets k_f = s·K·A²/V, s the penalty scale. A surface node gets
//! k_node = Σ k_f / 3 over its boundary faces (used against rigid surfaces, which have no
//! element of their own).

use std::collections::HashMap;

use crate::error::{DemfemError, Result};
use crate::fem::mesh::TetMesh;

use super::vec3::{cross, dot, norm, sub};

/// One boundary face, its three nodes ordered so that the right-hand normal points out of
/// the body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceFace {
    /// Global node indices.
    pub nodes: [usize; 3],
    /// The tetrahedron under the face.
    pub element: usize,
    /// Body of the face.
    pub body: u32,
    /// Penalty stiffness k_f = s·K·A²/V, N/m.
    pub stiffness: f64,
    /// Height of the element over the face, 3V/A, m: the deepest penetration the face
    /// takes as contact (beyond it a node is inside the element, not on the face).
    pub depth: f64,
    /// Area in the reference configuration, m².
    pub area: f64,
    /// Half the shell thickness for a shell face (two-sided, its contact surfaces offset
    /// by this from the mid-surface on both sides), 0 for the one-sided face of a solid, m.
    pub half_thickness: f64,
}

/// The boundary of a mesh made of several bodies.
#[derive(Debug, Clone)]
pub struct Surface {
    /// Boundary faces, in a fixed (element, local face) order.
    pub faces: Vec<SurfaceFace>,
    /// Surface nodes (global indices), ascending.
    pub nodes: Vec<usize>,
    /// Position of each global node in `nodes`, or `u32::MAX`.
    pub slot: Vec<u32>,
    /// Body of each surface node.
    pub node_body: Vec<u32>,
    /// Tributary area of each surface node (a third of its faces' areas), m².
    pub node_area: Vec<f64>,
    /// Penalty stiffness of each surface node, N/m.
    pub node_stiffness: Vec<f64>,
    /// Half the shell thickness at each surface node (0 for solids), m: a shell node's
    /// contact surfaces lie this far from it on both sides.
    pub node_half_thickness: Vec<f64>,
    /// Largest face diameter (longest edge) in the reference configuration, m.
    pub max_face_size: f64,
    /// Mean face edge length, m.
    pub mean_edge: f64,
}

/// Local faces of a tetrahedron (opposite node 3, 2, 1, 0).
const LOCAL_FACES: [([usize; 3], usize); 4] = [
    ([0, 1, 2], 3),
    ([0, 1, 3], 2),
    ([0, 2, 3], 1),
    ([1, 2, 3], 0),
];

impl Surface {
    /// Extract the boundary of `mesh`. `body_of_node[i]` names the body of node i; every
    /// element must have its four nodes in one body. `bulk_modulus` K (Pa) and
    /// `penalty_scale` s give the face stiffnesses.
    pub fn new(
        mesh: &TetMesh,
        body_of_node: &[u32],
        bulk_modulus: f64,
        penalty_scale: f64,
    ) -> Result<Self> {
        let n = mesh.nodes.len();
        if body_of_node.len() != n {
            return Err(DemfemError::ShapeMismatch {
                field: "body_of_node".into(),
                detail: format!("{} entries for {n} nodes", body_of_node.len()),
            });
        }
        let mut count: HashMap<[usize; 3], (usize, usize, usize)> =
            HashMap::with_capacity(2 * mesh.tets.len());
        for (e, t) in mesh.tets.iter().enumerate() {
            let b = body_of_node[t[0]];
            if t.iter().any(|&i| body_of_node[i] != b) {
                return Err(DemfemError::ShapeMismatch {
                    field: "body_of_node".into(),
                    detail: format!("element {e} has nodes in more than one body"),
                });
            }
            for (lf, (f, _)) in LOCAL_FACES.iter().enumerate() {
                let mut key = [t[f[0]], t[f[1]], t[f[2]]];
                key.sort_unstable();
                count
                    .entry(key)
                    .and_modify(|c| c.2 += 1)
                    .or_insert((e, lf, 1));
            }
        }
        let mut boundary: Vec<(usize, usize)> = count
            .values()
            .filter(|c| c.2 == 1)
            .map(|c| (c.0, c.1))
            .collect();
        boundary.sort_unstable();
        let mut faces = Vec::with_capacity(boundary.len());
        for (e, lf) in boundary {
            let t = mesh.tets[e];
            let (f, opp) = LOCAL_FACES[lf];
            let mut nodes = [t[f[0]], t[f[1]], t[f[2]]];
            let x = |i: usize| mesh.nodes[i];
            let nrm = cross(sub(x(nodes[1]), x(nodes[0])), sub(x(nodes[2]), x(nodes[0])));
            if dot(nrm, sub(x(t[opp]), x(nodes[0]))) > 0.0 {
                nodes.swap(1, 2);
            }
            let area = 0.5 * norm(nrm);
            let vol = (dot(
                sub(x(t[1]), x(t[0])),
                cross(sub(x(t[2]), x(t[0])), sub(x(t[3]), x(t[0]))),
            ) / 6.0)
                .abs();
            if !(area > 0.0) || !(vol > 0.0) {
                return Err(DemfemError::Numerical(format!(
                    "element {e}: degenerate boundary face (area {area:e} m², volume {vol:e} m³)"
                )));
            }
            faces.push(SurfaceFace {
                nodes,
                element: e,
                body: body_of_node[nodes[0]],
                stiffness: penalty_scale * bulk_modulus * area * area / vol,
                depth: 3.0 * vol / area,
                area,
                half_thickness: 0.0,
            });
        }
        Ok(Self::from_faces(faces, &mesh.nodes, body_of_node))
    }

    /// The surface of `faces` over the nodes `x` (m): the surface nodes (those of the faces,
    /// in increasing order) with their tributary areas A/3, stiffnesses k_f/3 and
    /// area-weighted half thicknesses, the largest and the mean face edge. Shared by the
    /// tetrahedral and the shell surfaces.
    pub(super) fn from_faces(
        faces: Vec<SurfaceFace>,
        x: &[[f64; 3]],
        body_of_node: &[u32],
    ) -> Self {
        let mut max_face_size: f64 = 0.0;
        let mut edge_sum = 0.0;
        for f in &faces {
            let [a, b, c] = f.nodes.map(|i| x[i]);
            let edges = [norm(sub(b, a)), norm(sub(c, b)), norm(sub(a, c))];
            max_face_size = max_face_size.max(edges[0].max(edges[1]).max(edges[2]));
            edge_sum += edges[0] + edges[1] + edges[2];
        }
        let mut slot = vec![u32::MAX; x.len()];
        let mut nodes: Vec<usize> = faces.iter().flat_map(|f| f.nodes).collect();
        nodes.sort_unstable();
        nodes.dedup();
        for (k, &i) in nodes.iter().enumerate() {
            slot[i] = k as u32;
        }
        let mut node_area = vec![0.0; nodes.len()];
        let mut node_stiffness = vec![0.0; nodes.len()];
        let mut node_half_thickness = vec![0.0; nodes.len()];
        for f in &faces {
            for &i in &f.nodes {
                let s = slot[i] as usize;
                node_area[s] += f.area / 3.0;
                node_stiffness[s] += f.stiffness / 3.0;
                node_half_thickness[s] += f.half_thickness * f.area / 3.0;
            }
        }
        // a node's half thickness: the area-weighted mean of its faces' (0 for solids)
        for (h, a) in node_half_thickness.iter_mut().zip(&node_area) {
            *h /= a;
        }
        let mean_edge = if faces.is_empty() {
            0.0
        } else {
            edge_sum / (3.0 * faces.len() as f64)
        };
        let node_body = nodes.iter().map(|&i| body_of_node[i]).collect();
        Self {
            faces,
            nodes,
            slot,
            node_body,
            node_area,
            node_stiffness,
            node_half_thickness,
            max_face_size,
            mean_edge,
        }
    }
}
