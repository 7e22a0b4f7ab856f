//! Walls from triangle meshes (CAD: STL and the like): the validated mesh with its
//! adjacency, parry3d-f64's [`TriMesh`] for its BVH, and the sphere–triangle contact with the
//! rule that counts each touching feature of the surface once.
//!
//! # The contact rule at edges and vertices
//!
//! The wall is the union of its triangles, two-sided (like [`WallShape::Polygon`]). A sphere
//! at `x` touches it where the distance from `x` to the surface has a local minimum below
//! the radius. Each candidate triangle `t` of a particle's wall slots gives its closest point
//! `q` to `x` and the feature `q` lies on: the face interior, an edge or a vertex. Then:
//!
//! * a **face** contact is always kept;
//! * an **edge** or **vertex** contact at feature F is kept only if every other triangle
//!   that holds F has its own closest point at F as well (none of them is closer elsewhere,
//!   none has a face contact): that is the condition for `q` to be a local minimum of the
//!   distance over the surface (for each triangle holding F, `q` is its closest point exactly
//!   when (x − q)·(y − q) ≤ 0 for every y of it). Of the triangles that agree, only the one
//!   with the lowest index keeps the contact, so the feature is counted once.
//!
//! On a flat surface of many triangles this gives exactly one contact wherever the sphere
//! is (face, shared edge or shared vertex), the same as on a plane; at a convex edge or
//! corner of the mesh one contact at the edge or vertex; in a concave fold one per face.
//! Edge and vertex points are computed from the feature alone (the segment from its
//! lower-numbered vertex, the vertex itself), so every triangle holding a feature finds the
//! same point and distance to the last bit. The test needs no other slot's state, so each
//! (particle, triangle) slot is evaluated on its own, as every other wall slot.
//!
//! The contact radius is the sphere's radius against a flat, for edges and vertices too (as
//! for polygon walls): R* = r.
//!
//! All lengths in metres.

use std::sync::Arc;

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::query::PointProjection;
use parry3d_f64::shape::TriMesh;

use super::Vec3;
use crate::error::{DemfemError, Result};

/// Which part of a triangle its closest point to a query point lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFeature {
    /// The interior of the triangle.
    Face,
    /// An edge, by its index in [`MeshWall::edges`].
    Edge(u32),
    /// A vertex, by its index in [`MeshWall::vertices`].
    Vertex(u32),
}

/// A validated triangle mesh wall with its adjacency (edges, triangles around each edge and
/// vertex) and parry's [`TriMesh`] for the BVH of its triangles.
#[derive(Clone)]
pub struct MeshWall {
    trimesh: TriMesh,
    vertices: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    /// Edge k of triangle t joins its corners k and (k + 1) % 3.
    triangle_edges: Vec<[u32; 3]>,
    /// Each edge's vertices, lower index first.
    edges: Vec<[u32; 2]>,
    edge_start: Vec<u32>,
    edge_triangles: Vec<u32>,
    vertex_start: Vec<u32>,
    vertex_triangles: Vec<u32>,
    /// Surface velocity of each triangle, m/s (belts: one mesh floor whose regions move at
    /// their own speeds), or empty: the wall's own surface velocity everywhere.
    triangle_velocities: Vec<Vec3>,
    fingerprint: u64,
}

impl std::fmt::Debug for MeshWall {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MeshWall")
            .field("vertices", &self.vertices.len())
            .field("triangles", &self.triangles.len())
            .field("triangle_velocities", &self.triangle_velocities.len())
            .field("fingerprint", &self.fingerprint)
            .finish()
    }
}

/// CSR lists: for each key in 0..n, the values of the (key, value) pairs, in value order.
fn csr(n: usize, pairs: &mut [(u32, u32)]) -> (Vec<u32>, Vec<u32>) {
    pairs.sort_unstable();
    let mut start = vec![0u32; n + 1];
    for &(k, _) in pairs.iter() {
        start[k as usize + 1] += 1;
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    (start, pairs.iter().map(|&(_, v)| v).collect())
}

impl MeshWall {
    /// A mesh from its vertices (m) and triangles (three vertex indices each). Refused:
    /// no triangles, non-finite coordinates, indices out of range, and degenerate triangles
    /// (area at most 1e-12 of the squared size of the mesh's bounding box), each error naming
    /// the vertex or triangle.
    pub fn new(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Arc<Self>> {
        if triangles.is_empty() {
            return Err(DemfemError::ShapeMismatch {
                field: "mesh.triangles".into(),
                detail: "need at least one triangle, got none".into(),
            });
        }
        if triangles.len() >= u32::MAX as usize || vertices.len() >= u32::MAX as usize {
            return Err(DemfemError::ShapeMismatch {
                field: "mesh.triangles".into(),
                detail: format!("at most {} triangles and vertices", u32::MAX - 1),
            });
        }
        let (mut lo, mut hi) = (Vec3::splat(f64::INFINITY), Vec3::splat(f64::NEG_INFINITY));
        for (k, v) in vertices.iter().enumerate() {
            if !v.is_finite() {
                return Err(DemfemError::InvalidParameter {
                    field: format!("mesh.vertices[{k}]"),
                    value: format!("{v:?}"),
                    allowed: "finite coordinates, m".into(),
                });
            }
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        let size2 = (hi - lo).length_squared();
        let min_area = 1e-12 * size2;
        let mut edge_pairs: Vec<(u64, u32)> = Vec::with_capacity(3 * triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            for &c in tri {
                if c as usize >= vertices.len() {
                    return Err(DemfemError::InvalidParameter {
                        field: format!("mesh.triangles[{t}]"),
                        value: format!("{tri:?}"),
                        allowed: format!("vertex indices in 0..{}", vertices.len()),
                    });
                }
            }
            let [a, b, c] = tri.map(|c| vertices[c as usize]);
            let area = 0.5 * (b - a).cross(c - a).length();
            if !(area > min_area) {
                return Err(DemfemError::InvalidParameter {
                    field: format!("mesh.triangles[{t}] area"),
                    value: format!("{area:e} m²"),
                    allowed: format!("> {min_area:e} m² (a non-degenerate triangle)"),
                });
            }
            for k in 0..3 {
                let (p, q) = (tri[k], tri[(k + 1) % 3]);
                let key = (u64::from(p.min(q)) << 32) | u64::from(p.max(q));
                edge_pairs.push((key, (3 * t + k) as u32));
            }
        }
        // number the edges in (lo, hi) order; each triangle side gets its edge's number
        edge_pairs.sort_unstable();
        let mut edges: Vec<[u32; 2]> = Vec::new();
        let mut triangle_edges = vec![[0u32; 3]; triangles.len()];
        let mut by_edge: Vec<(u32, u32)> = Vec::with_capacity(edge_pairs.len());
        for (n, &(key, side)) in edge_pairs.iter().enumerate() {
            if n == 0 || edge_pairs[n - 1].0 != key {
                edges.push([(key >> 32) as u32, key as u32]);
            }
            let e = (edges.len() - 1) as u32;
            triangle_edges[side as usize / 3][side as usize % 3] = e;
            by_edge.push((e, side / 3));
        }
        let (edge_start, edge_triangles) = csr(edges.len(), &mut by_edge);
        let mut by_vertex: Vec<(u32, u32)> = triangles
            .iter()
            .enumerate()
            .flat_map(|(t, tri)| tri.iter().map(move |&c| (c, t as u32)))
            .collect();
        let (vertex_start, vertex_triangles) = csr(vertices.len(), &mut by_vertex);
        let mut fingerprint = 0xcbf29ce484222325u64;
        let mut hash = |bits: u64| {
            for b in bits.to_le_bytes() {
                fingerprint ^= u64::from(b);
                fingerprint = fingerprint.wrapping_mul(0x100000001b3);
            }
        };
        for v in &vertices {
            hash(v.x.to_bits());
            hash(v.y.to_bits());
            hash(v.z.to_bits());
        }
        for tri in &triangles {
            hash((u64::from(tri[0]) << 32) | u64::from(tri[1]));
            hash(u64::from(tri[2]));
        }
        let trimesh = TriMesh::new(vertices.clone(), triangles.clone()).map_err(|e| {
            DemfemError::ShapeMismatch {
                field: "mesh".into(),
                detail: format!("parry refused the mesh: {e:?}"),
            }
        })?;
        Ok(Arc::new(MeshWall {
            trimesh,
            vertices,
            triangles,
            triangle_edges,
            edges,
            edge_start,
            edge_triangles,
            vertex_start,
            vertex_triangles,
            triangle_velocities: Vec::new(),
            fingerprint,
        }))
    }

    /// A mesh whose triangles each carry their own surface velocity (m/s, one per triangle):
    /// a floor of several belts meeting edge to edge, so that the contact rule counts a
    /// sphere on the seam between two belts once. At a seam the lower-numbered triangle's
    /// belt drives the sphere.
    pub fn with_triangle_velocities(
        vertices: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
        velocities: Vec<Vec3>,
    ) -> Result<Arc<Self>> {
        if velocities.len() != triangles.len() {
            return Err(DemfemError::ShapeMismatch {
                field: "mesh.triangle_velocities".into(),
                detail: format!(
                    "expected one per triangle ({}), got {}",
                    triangles.len(),
                    velocities.len()
                ),
            });
        }
        for (t, v) in velocities.iter().enumerate() {
            if !v.is_finite() {
                return Err(DemfemError::InvalidParameter {
                    field: format!("mesh.triangle_velocities[{t}]"),
                    value: format!("{v:?}"),
                    allowed: "finite components, m/s".into(),
                });
            }
        }
        let mut mesh = Arc::unwrap_or_clone(Self::new(vertices, triangles)?);
        for v in &velocities {
            for c in [v.x, v.y, v.z] {
                mesh.fingerprint ^= c.to_bits();
                mesh.fingerprint = mesh.fingerprint.wrapping_mul(0x100000001b3);
            }
        }
        mesh.triangle_velocities = velocities;
        Ok(Arc::new(mesh))
    }

    /// The surface velocity of triangle `t`, m/s, if the triangles carry their own.
    #[inline(always)]
    pub fn triangle_velocity(&self, t: u32) -> Option<Vec3> {
        self.triangle_velocities.get(t as usize).copied()
    }

    /// The vertices, m.
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// The triangles (vertex indices).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The edges (vertex indices, lower first).
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    /// The edges of triangle `t`: edge k joins its corners k and (k + 1) % 3.
    pub fn triangle_edges(&self, t: u32) -> [u32; 3] {
        self.triangle_edges[t as usize]
    }

    /// The triangles holding edge `e`.
    pub fn edge_triangles(&self, e: u32) -> &[u32] {
        let e = e as usize;
        &self.edge_triangles[self.edge_start[e] as usize..self.edge_start[e + 1] as usize]
    }

    /// The triangles holding vertex `v`.
    pub fn vertex_triangles(&self, v: u32) -> &[u32] {
        let v = v as usize;
        &self.vertex_triangles[self.vertex_start[v] as usize..self.vertex_start[v + 1] as usize]
    }

    /// The number of edges not shared by exactly two triangles (0 for a closed manifold
    /// mesh), and the first of them.
    pub fn open_edges(&self) -> (usize, Option<[u32; 2]>) {
        let mut count = 0;
        let mut first = None;
        for (e, edge) in self.edges.iter().enumerate() {
            if self.edge_triangles(e as u32).len() != 2 {
                count += 1;
                first = first.or(Some(*edge));
            }
        }
        (count, first)
    }

    /// Refuse a mesh that is not closed (an edge not shared by exactly two triangles),
    /// naming `field`.
    pub fn require_closed(&self, field: &str) -> Result<()> {
        match self.open_edges() {
            (0, _) => Ok(()),
            (n, first) => Err(DemfemError::InvalidParameter {
                field: field.to_string(),
                value: format!(
                    "{n} edges not shared by exactly two triangles (first: vertices {:?})",
                    first.unwrap_or_default()
                ),
                allowed: "a closed mesh (every edge shared by exactly two triangles)".into(),
            }),
        }
    }

    /// Closest point of triangle `t` to `p` and the feature it lies on. Edge and vertex
    /// points are computed from the feature alone (see the module docs), so every triangle
    /// holding the feature finds the same point.
    #[inline]
    pub fn closest_on_triangle(&self, t: u32, p: Vec3) -> (Vec3, MeshFeature) {
        let tri = self.triangles[t as usize];
        let [a, b, c] = tri.map(|k| self.vertices[k as usize]);
        // Ericson, Real-Time Collision Detection, 5.1.5: the Voronoi regions in turn
        let (ab, ac, ap) = (b - a, c - a, p - a);
        let (d1, d2) = (ab.dot(ap), ac.dot(ap));
        if d1 <= 0.0 && d2 <= 0.0 {
            return (a, MeshFeature::Vertex(tri[0]));
        }
        let bp = p - b;
        let (d3, d4) = (ab.dot(bp), ac.dot(bp));
        if d3 >= 0.0 && d4 <= d3 {
            return (b, MeshFeature::Vertex(tri[1]));
        }
        let vc = d1 * d4 - d3 * d2;
        if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            return self.on_edge(self.triangle_edges[t as usize][0], p);
        }
        let cp = p - c;
        let (d5, d6) = (ab.dot(cp), ac.dot(cp));
        if d6 >= 0.0 && d5 <= d6 {
            return (c, MeshFeature::Vertex(tri[2]));
        }
        let vb = d5 * d2 - d1 * d6;
        if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            return self.on_edge(self.triangle_edges[t as usize][2], p);
        }
        let va = d3 * d6 - d5 * d4;
        if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
            return self.on_edge(self.triangle_edges[t as usize][1], p);
        }
        let denom = 1.0 / (va + vb + vc);
        (a + ab * (vb * denom) + ac * (vc * denom), MeshFeature::Face)
    }

    /// Closest point of edge `e` to `p` from its lower-numbered vertex; a vertex feature
    /// where the projection falls on an end.
    #[inline]
    fn on_edge(&self, e: u32, p: Vec3) -> (Vec3, MeshFeature) {
        let [i, j] = self.edges[e as usize];
        let (s, f) = (self.vertices[i as usize], self.vertices[j as usize]);
        let d = f - s;
        let u = d.dot(p - s) / d.length_squared();
        if !(u > 0.0) {
            (s, MeshFeature::Vertex(i))
        } else if u >= 1.0 {
            (f, MeshFeature::Vertex(j))
        } else {
            (s + u * d, MeshFeature::Edge(e))
        }
    }

    /// The contact of a sphere of radius `r` at `p` with triangle `t` under the rule of the
    /// module docs: closest point, unit normal (wall → p) and distance, or `None` when the
    /// triangle does not touch, when its feature's contact belongs to another triangle, or
    /// when `p` lies on the surface (no normal defined).
    #[inline]
    pub fn contact(&self, t: u32, p: Vec3, r: f64) -> Option<(Vec3, Vec3, f64)> {
        let (q, feature) = self.closest_on_triangle(t, p);
        let diff = p - q;
        let d2 = diff.length_squared();
        if !(d2 < r * r) || d2 == 0.0 {
            return None;
        }
        let others = match feature {
            MeshFeature::Face => &[][..],
            MeshFeature::Edge(e) => self.edge_triangles(e),
            MeshFeature::Vertex(v) => self.vertex_triangles(v),
        };
        for &u in others {
            if u == t {
                continue;
            }
            let (q2, f2) = self.closest_on_triangle(u, p);
            if f2 == feature {
                if u < t {
                    // the same feature, counted by the lower-numbered triangle
                    return None;
                }
            } else if f2 == MeshFeature::Face || (p - q2).length_squared() < d2 {
                // another triangle holding the feature is closer elsewhere: not a minimum
                return None;
            }
        }
        let d = d2.sqrt();
        Some((q, diff * (1.0 / d), d))
    }

    /// Append to `out` (sorted) the triangles whose distance to `p` is below `reach`, m,
    /// found through the BVH.
    pub fn triangles_within(&self, p: Vec3, reach: f64, out: &mut Vec<u32>) {
        let start = out.len();
        let aabb = Aabb::from_half_extents(p, Vec3::splat(reach));
        let reach2 = reach * reach;
        for t in self.trimesh.bvh().intersect_aabb(&aabb) {
            if (t as usize) < self.triangles.len() {
                let (q, _) = self.closest_on_triangle(t, p);
                if (p - q).length_squared() < reach2 {
                    out.push(t);
                }
            }
        }
        out[start..].sort_unstable();
    }

    /// Closest point of the whole mesh to `p`, unit normal (mesh → p) and distance (through
    /// the BVH); `None` when `p` lies on the surface.
    pub fn closest(&self, p: Vec3) -> Option<(Vec3, Vec3, f64)> {
        let (_, (d, proj)) = self.trimesh.bvh().project_point(p, f64::INFINITY, |t, _| {
            Some(PointProjection::new(
                false,
                self.closest_on_triangle(t, p).0,
            ))
        })?;
        if d > 0.0 {
            Some((proj.point, (p - proj.point) / d, d))
        } else {
            None
        }
    }

    /// A stable hash of the vertices and triangles (for scene fingerprints).
    pub fn fingerprint(&self) -> u64 {
        self.fingerprint
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d_f64::query::PointQuery;
    use parry3d_f64::shape::Triangle;

    /// A flat square [0, 1]² at z = 0 cut into 2 n² triangles.
    fn grid(n: usize) -> Arc<MeshWall> {
        let mut v = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                v.push(Vec3::new(i as f64 / n as f64, j as f64 / n as f64, 0.0));
            }
        }
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut t = Vec::new();
        for j in 0..n {
            for i in 0..n {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        MeshWall::new(v, t).unwrap()
    }

    fn rnd(s: &mut u64) -> f64 {
        *s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*s >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn closest_on_triangle_matches_parry() {
        let m = MeshWall::new(
            vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.2, 0.1),
                Vec3::new(0.3, 1.0, -0.2),
            ],
            vec![[0, 1, 2]],
        )
        .unwrap();
        let tri = Triangle::new(m.vertices[0], m.vertices[1], m.vertices[2]);
        let mut s = 7u64;
        for _ in 0..5000 {
            let p = Vec3::new(rnd(&mut s), rnd(&mut s), rnd(&mut s)) * 3.0 - 1.0;
            let (q, _) = m.closest_on_triangle(0, p);
            let proj = tri.project_local_point(p, true);
            assert!((q - proj.point).length() < 1e-12, "{p:?}");
        }
    }

    #[test]
    fn flat_grid_counts_one_contact_everywhere() {
        let m = grid(8);
        let mut s = 99u64;
        let r = 0.05;
        let mut cand = Vec::new();
        for k in 0..20000 {
            // every tenth point exactly above a vertex or an edge of the grid
            let (mut x, mut y) = (0.1 + 0.8 * rnd(&mut s), 0.1 + 0.8 * rnd(&mut s));
            if k % 10 == 0 {
                x = (x * 8.0).round() / 8.0;
            }
            if k % 20 == 0 {
                y = (y * 8.0).round() / 8.0;
            }
            let h = r * (0.5 + 0.49 * rnd(&mut s));
            let p = Vec3::new(x, y, if k % 2 == 0 { h } else { -h });
            cand.clear();
            m.triangles_within(p, r, &mut cand);
            let hits: Vec<_> = cand.iter().filter_map(|&t| m.contact(t, p, r)).collect();
            assert_eq!(hits.len(), 1, "{p:?}: {hits:?}");
            let (q, n, d) = hits[0];
            assert!((d - h).abs() < 1e-14);
            assert!((q - Vec3::new(x, y, 0.0)).length() < 1e-14);
            assert!((n.z.abs() - 1.0).abs() < 1e-14);
        }
    }

    #[test]
    fn convex_edge_and_corner_of_a_box_count_once() {
        // the unit cube's surface, 12 triangles
        let v: Vec<Vec3> = (0..8)
            .map(|k| Vec3::new((k & 1) as f64, (k >> 1 & 1) as f64, (k >> 2 & 1) as f64))
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let t: Vec<[u32; 3]> = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        let m = MeshWall::new(v, t).unwrap();
        assert_eq!(m.open_edges().0, 0);
        m.require_closed("mesh").unwrap();
        let r = 0.3;
        for (p, q) in [
            // beyond an edge, beyond a corner, above a face's diagonal
            (Vec3::new(1.1, 1.1, 0.5), Vec3::new(1.0, 1.0, 0.5)),
            (Vec3::new(1.1, 1.1, 1.1), Vec3::new(1.0, 1.0, 1.0)),
            (Vec3::new(0.5, 0.5, 1.2), Vec3::new(0.5, 0.5, 1.0)),
            (Vec3::new(-0.1, 0.3, 0.3), Vec3::new(0.0, 0.3, 0.3)),
        ] {
            let hits: Vec<_> = (0..12).filter_map(|t| m.contact(t, p, r)).collect();
            assert_eq!(hits.len(), 1, "{p:?}: {hits:?}");
            assert!((hits[0].0 - q).length() < 1e-14, "{p:?}: {hits:?}");
            assert!(((hits[0].2) - (p - q).length()).abs() < 1e-14);
        }
    }

    #[test]
    fn concave_fold_counts_each_face() {
        // floor z = 0 and wall x = 0 meeting along the y axis (an inside corner)
        let v = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let t = vec![[0, 1, 2], [0, 2, 3], [0, 3, 5], [0, 5, 4]];
        let m = MeshWall::new(v, t).unwrap();
        let p = Vec3::new(0.1, 0.5, 0.1);
        let hits: Vec<_> = (0..4).filter_map(|t| m.contact(t, p, 0.2)).collect();
        assert_eq!(hits.len(), 2, "{hits:?}");
        assert_eq!(m.open_edges().0, 6);
        assert!(m.require_closed("walls[0]").is_err());
    }

    #[test]
    fn bad_meshes_are_refused() {
        let v = vec![Vec3::ZERO, Vec3::X, Vec3::Y, 2.0 * Vec3::X];
        assert!(MeshWall::new(v.clone(), vec![]).is_err());
        assert!(MeshWall::new(v.clone(), vec![[0, 1, 4]]).is_err());
        let e = MeshWall::new(v.clone(), vec![[0, 1, 2], [0, 1, 3]]).unwrap_err();
        assert!(format!("{e}").contains("mesh.triangles[1] area"), "{e}");
        let e = MeshWall::new(v.clone(), vec![[0, 1, 2], [2, 2, 1]]).unwrap_err();
        assert!(format!("{e}").contains("mesh.triangles[1]"), "{e}");
        let mut w = v;
        w[3].x = f64::NAN;
        assert!(MeshWall::new(w, vec![[0, 1, 2]]).is_err());
    }

    #[test]
    fn closest_over_the_mesh() {
        let m = grid(4);
        let (q, n, d) = m.closest(Vec3::new(0.3, 0.6, 0.2)).unwrap();
        assert!((q - Vec3::new(0.3, 0.6, 0.0)).length() < 1e-14);
        assert!((n - Vec3::Z).length() < 1e-14 && (d - 0.2).abs() < 1e-14);
        let (q, _, _) = m.closest(Vec3::new(1.5, 0.5, -0.1)).unwrap();
        assert!((q - Vec3::new(1.0, 0.5, 0.0)).length() < 1e-14);
    }
}
