//! Triangle-mesh walls (CAD tables, `geometry::MeshWall`) against a body of revolution.
//!
//! The same three kinds of contact as a convex polygon (`wall_edges`), per triangle: its
//! face (the anchored points of the body's edge circles that overlap the triangle's plane,
//! on the side of the body's centre, and project into the triangle), its edges and its
//! corners. An edge counts only where it is the closest feature of every triangle holding it
//! (the normal leaves each of them across the edge), and a corner only where it is the
//! closest feature of every edge leaving it: so the shared edges and vertices of a flat
//! stretch of mesh give no contact of their own, and a convex fold or corner gives one. Each
//! edge and vertex is visited once. Contacts are oriented wall first; friction springs are
//! keyed by triangle, edge or vertex. Lengths in m.

use nalgebra::Vector3;

use super::contacts::plane_contacts;
use super::features::Placed;
use super::wall_edges::{corner_contact, edge_contacts};
use crate::geometry::MeshWall;
use crate::rigid::collision::ContactPoint;

type V3 = Vector3<f64>;

/// Wall-side key offsets of a mesh's triangles, edges and vertices.
const TRIANGLE_KEY: u64 = 1 << 40;
const EDGE_KEY: u64 = 2 << 40;
const VERTEX_KEY: u64 = 3 << 40;

/// Contacts of a mesh wall displaced by `offset` (m) with a body, appended to `out` with
/// weights (see the module docs).
pub fn mesh_contacts(
    mesh: &MeshWall,
    offset: &V3,
    body: &Placed,
    out: &mut Vec<ContactPoint>,
    weights: &mut Vec<f64>,
) {
    let local = body.origin - offset;
    let mut near = Vec::new();
    mesh.triangles_within(
        crate::geometry::Vec3::new(local.x, local.y, local.z),
        body.shape.bounding_radius,
        &mut near,
    );
    if near.is_empty() {
        return;
    }
    let vertex = |v: u32| {
        let p = mesh.vertices()[v as usize];
        V3::new(p.x, p.y, p.z) + offset
    };
    let mut edges = Vec::new();
    let mut corners = Vec::new();
    for &t in &near {
        let [a, b, c] = mesh.triangles()[t as usize].map(vertex);
        let Some(mut normal) = (b - a).cross(&(c - a)).try_normalize(0.0) else {
            continue;
        };
        if normal.dot(&(body.origin - a)) < 0.0 {
            normal = -normal;
        }
        let inside = |x: &V3| {
            [(a, b), (b, c), (c, a)]
                .iter()
                .all(|(p, q)| normal.cross(&(q - p)).dot(&(x - p)) >= 0.0)
        };
        let start = out.len();
        plane_contacts(&a, &normal, body, Some(&inside), out, weights);
        for contact in &mut out[start..] {
            contact.feature_first = TRIANGLE_KEY + t as u64;
        }
        edges.extend(mesh.triangle_edges(t));
        corners.extend(mesh.triangles()[t as usize]);
    }
    edges.sort_unstable();
    edges.dedup();
    corners.sort_unstable();
    corners.dedup();
    let mut inward = Vec::with_capacity(2);
    for &e in &edges {
        let [i, j] = mesh.edges()[e as usize];
        let (va, vb) = (vertex(i), vertex(j));
        let direction = (vb - va).normalize();
        inward.clear();
        for &u in mesh.edge_triangles(e) {
            let third = mesh.triangles()[u as usize]
                .into_iter()
                .find(|&w| w != i && w != j)
                .map(vertex);
            if let Some(w) = third {
                let across = (w - va) - direction * (w - va).dot(&direction);
                if let Some(unit) = across.try_normalize(0.0) {
                    inward.push(unit);
                }
            }
        }
        edge_contacts(&va, &vb, &inward, EDGE_KEY + e as u64, body, out, weights);
    }
    let mut neighbours = Vec::new();
    for &v in &corners {
        neighbours.clear();
        for &u in mesh.vertex_triangles(v) {
            for w in mesh.triangles()[u as usize] {
                if w != v {
                    neighbours.push(vertex(w));
                }
            }
        }
        corner_contact(
            &vertex(v),
            &neighbours,
            VERTEX_KEY + v as u64,
            body,
            out,
            weights,
        );
    }
}
