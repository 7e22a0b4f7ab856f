//! Meshes: the axisymmetric cartridge description, structured revolved tetrahedral meshes,
//! mid-surface triangle shell meshes, structured box meshes (for verification) and element
//! quality measures.
//!
//! Hexahedral cells of the structured grids are split into six tetrahedra with the Kuhn
//! (Freudenthal) subdivision: each cell is cut along the diagonal from its lowest to its
//! highest corner in index space. The subdivision is translation invariant in index space,
//! so every shared face is cut by the same diagonal from both sides and the mesh is
//! conforming, including across the periodic seam in θ.

mod compose;
mod quality;
mod revolve;

pub use compose::{ball_tet_mesh, place, union};
pub use quality::{tet_quality, MeshQuality, TetQuality};
pub use revolve::{box_tet_mesh, AxisymmetricProfile, RevolvedTetMesh, MAX_TET_ELEMENTS};

use crate::error::{DemfemError, Result};

/// A mesh of linear tetrahedra.
#[derive(Debug, Clone, PartialEq)]
pub struct TetMesh {
    /// Node coordinates, m.
    pub nodes: Vec<[f64; 3]>,
    /// Element connectivity, four node indices per tetrahedron, positively oriented
    /// (node 3 on the side of the normal of face 0-1-2 given by the right-hand rule).
    pub tets: Vec<[usize; 4]>,
}

/// A mesh of flat triangles on a mid-surface, with a thickness per triangle.
#[derive(Debug, Clone, PartialEq)]
pub struct TriMesh {
    /// Node coordinates on the mid-surface, m.
    pub nodes: Vec<[f64; 3]>,
    /// Triangle connectivity, three node indices per element.
    pub triangles: Vec<[usize; 3]>,
    /// Shell thickness (normal to the mid-surface) of each triangle, m.
    pub thickness: Vec<f64>,
}

/// Signed volume of the tetrahedron (a, b, c, d), m³; positive for the orientation used
/// by [`TetMesh`].
pub fn signed_volume(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> f64 {
    let u = sub(b, a);
    let v = sub(c, a);
    let w = sub(d, a);
    dot(u, cross(v, w)) / 6.0
}

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
pub(crate) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

impl TetMesh {
    /// Check indices, finiteness and orientation: every node index in range, every
    /// coordinate finite, every element of positive volume.
    pub fn validate(&self) -> Result<()> {
        if self.nodes.is_empty() || self.tets.is_empty() {
            return Err(DemfemError::ShapeMismatch {
                field: "mesh".into(),
                detail: "a tetrahedral mesh needs at least one node and one element".into(),
            });
        }
        for (i, p) in self.nodes.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(DemfemError::ShapeMismatch {
                    field: "mesh.nodes".into(),
                    detail: format!("node {i} has a non-finite coordinate"),
                });
            }
        }
        let n = self.nodes.len();
        for (e, t) in self.tets.iter().enumerate() {
            if t.iter().any(|&i| i >= n) {
                return Err(DemfemError::ShapeMismatch {
                    field: "mesh.tets".into(),
                    detail: format!("element {e} refers to a node index >= {n}"),
                });
            }
            let v = signed_volume(
                self.nodes[t[0]],
                self.nodes[t[1]],
                self.nodes[t[2]],
                self.nodes[t[3]],
            );
            if !(v > 0.0) {
                return Err(DemfemError::ShapeMismatch {
                    field: "mesh.tets".into(),
                    detail: format!(
                        "element {e} has non-positive volume {v:e} m³ (inverted or degenerate)"
                    ),
                });
            }
        }
        Ok(())
    }

    /// Make every element positively oriented by swapping its last two nodes where the
    /// signed volume is negative (meshes from other tools use either orientation).
    /// Returns the number of elements flipped. Degenerate elements are left for
    /// [`TetMesh::validate`] to reject.
    pub fn orient(&mut self) -> usize {
        let mut flipped = 0;
        for t in self.tets.iter_mut() {
            if t.iter().all(|&i| i < self.nodes.len())
                && signed_volume(
                    self.nodes[t[0]],
                    self.nodes[t[1]],
                    self.nodes[t[2]],
                    self.nodes[t[3]],
                ) < 0.0
            {
                t.swap(2, 3);
                flipped += 1;
            }
        }
        flipped
    }

    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Number of elements.
    pub fn n_elements(&self) -> usize {
        self.tets.len()
    }

    /// Total volume, m³.
    pub fn volume(&self) -> f64 {
        self.tets
            .iter()
            .map(|t| {
                signed_volume(
                    self.nodes[t[0]],
                    self.nodes[t[1]],
                    self.nodes[t[2]],
                    self.nodes[t[3]],
                )
            })
            .sum()
    }

    /// Quality summary over all elements (min dihedral angle, max aspect ratio, ...).
    pub fn quality(&self) -> MeshQuality {
        MeshQuality::of_tets(&self.nodes, &self.tets)
    }

    /// Refuse sliver elements: error if any dihedral angle is below `min_dihedral_deg`
    /// degrees. Returns the quality summary otherwise.
    pub fn check_quality(&self, min_dihedral_deg: f64) -> Result<MeshQuality> {
        let q = self.quality();
        if !(q.min_dihedral_deg >= min_dihedral_deg) {
            return Err(DemfemError::InvalidParameter {
                field: "mesh".into(),
                value: format!(
                    "min dihedral angle {:.3}° at element {}",
                    q.min_dihedral_deg, q.worst_element
                ),
                allowed: format!("no sliver elements: every dihedral angle >= {min_dihedral_deg}°"),
            });
        }
        Ok(q)
    }

    /// Boundary faces: triangles that belong to exactly one tetrahedron, oriented with
    /// the right-hand normal pointing out of the body. Returned in a deterministic order
    /// (by element, then local face).
    pub fn boundary_faces(&self) -> Vec<[usize; 3]> {
        // Local faces with outward orientation for a positively oriented tet (0,1,2,3).
        const FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];
        let mut keyed: Vec<([usize; 3], usize, usize)> = Vec::with_capacity(self.tets.len() * 4);
        for (e, t) in self.tets.iter().enumerate() {
            for (f, lf) in FACES.iter().enumerate() {
                let mut key = [t[lf[0]], t[lf[1]], t[lf[2]]];
                key.sort_unstable();
                keyed.push((key, e, f));
            }
        }
        keyed.sort_unstable();
        let mut out = Vec::new();
        let mut i = 0;
        while i < keyed.len() {
            let mut j = i + 1;
            while j < keyed.len() && keyed[j].0 == keyed[i].0 {
                j += 1;
            }
            if j - i == 1 {
                let (_, e, f) = keyed[i];
                let t = self.tets[e];
                let lf = FACES[f];
                out.push((e, f, [t[lf[0]], t[lf[1]], t[lf[2]]]));
            }
            i = j;
        }
        out.sort_unstable_by_key(|x| (x.0, x.1));
        out.into_iter().map(|x| x.2).collect()
    }
}

impl TriMesh {
    /// Check indices, finiteness, positive area and positive thickness.
    pub fn validate(&self) -> Result<()> {
        if self.triangles.len() != self.thickness.len() {
            return Err(DemfemError::ShapeMismatch {
                field: "thickness".into(),
                detail: format!(
                    "{} values for {} triangles",
                    self.thickness.len(),
                    self.triangles.len()
                ),
            });
        }
        let n = self.nodes.len();
        for (e, t) in self.triangles.iter().enumerate() {
            if t.iter().any(|&i| i >= n) {
                return Err(DemfemError::ShapeMismatch {
                    field: "triangles".into(),
                    detail: format!("triangle {e} refers to a node index >= {n}"),
                });
            }
            let a = norm(cross(
                sub(self.nodes[t[1]], self.nodes[t[0]]),
                sub(self.nodes[t[2]], self.nodes[t[0]]),
            ));
            if !(a > 0.0) || !(self.thickness[e] > 0.0) || !self.thickness[e].is_finite() {
                return Err(DemfemError::ShapeMismatch {
                    field: "triangles".into(),
                    detail: format!("triangle {e} is degenerate or has non-positive thickness"),
                });
            }
        }
        Ok(())
    }

    /// Mid-surface area, m².
    pub fn area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                0.5 * norm(cross(
                    sub(self.nodes[t[1]], self.nodes[t[0]]),
                    sub(self.nodes[t[2]], self.nodes[t[0]]),
                ))
            })
            .sum()
    }

    /// Shell volume Σ area·thickness, m³.
    pub fn volume(&self) -> f64 {
        self.triangles
            .iter()
            .zip(&self.thickness)
            .map(|(t, h)| {
                0.5 * h
                    * norm(cross(
                        sub(self.nodes[t[1]], self.nodes[t[0]]),
                        sub(self.nodes[t[2]], self.nodes[t[0]]),
                    ))
            })
            .sum()
    }

    /// Smallest interior angle over all triangles, degrees (a sliver indicator).
    pub fn min_angle_deg(&self) -> f64 {
        let mut m = 180.0f64;
        for t in &self.triangles {
            for k in 0..3 {
                let a = self.nodes[t[k]];
                let b = self.nodes[t[(k + 1) % 3]];
                let c = self.nodes[t[(k + 2) % 3]];
                let u = sub(b, a);
                let v = sub(c, a);
                let cosang = (dot(u, v) / (norm(u) * norm(v))).clamp(-1.0, 1.0);
                m = m.min(cosang.acos().to_degrees());
            }
        }
        m
    }
}
