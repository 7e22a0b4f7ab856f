//! Contacts with the walls of a table read from CAD: flat polygon plates ([`PolygonWall`])
//! and triangle meshes, against bead clumps (by hand) and exact shapes (parry manifolds).
//! Lengths in m.

use nalgebra::Vector3;
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::shape::ConvexPolyhedron;

use super::exact::{manifold_contacts, piece_radius, ExactContactCache};
use super::primitives::{to_nalgebra, BodyPose, ContactPoint};
use crate::error::{DemfemError, Result};
use crate::geometry::{MeshWall, WallShape};
use crate::rigid::shape::{BeadClump, ExactShape};

/// Half thickness of the parry plate that stands for a polygon wall against exact shapes, m.
/// Overlaps are measured from the polygon's own plane (the plate's mid-plane): a contact
/// counts only where a body reaches past the plate's face by more than this, so the wall
/// acts at zero thickness; the plate only gives parry a solid with one face per side (a fan
/// of triangles would split a flat cap contact at the diagonals).
pub const POLYGON_PLATE_HALF_THICKNESS: f64 = 1e-4;

/// A convex polygon wall (two-sided, zero thickness, like the sphere DEM's) prepared for
/// rigid shapes: the closest-point geometry of [`WallShape::Polygon`] for beads, and the same
/// polygon as a thin parry plate (convex hull of the polygon shifted ± half a thickness along
/// its normal) for exact shapes, with overlaps measured from the mid-plane.
#[derive(Clone)]
pub struct PolygonWall {
    shape: WallShape,
    plate: ConvexPolyhedron,
    /// Largest distance of a vertex from the first vertex, m (a cheap cull radius).
    extent: f64,
    first_vertex: Vector3<f64>,
}

impl std::fmt::Debug for PolygonWall {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PolygonWall")
            .field("shape", &self.shape)
            .finish()
    }
}

impl PolygonWall {
    /// Prepare a [`WallShape::Polygon`] (vertices in m); other shapes are refused.
    pub fn new(shape: &WallShape) -> Result<Self> {
        let WallShape::Polygon {
            vertices, normal, ..
        } = shape
        else {
            return Err(DemfemError::ShapeMismatch {
                field: "wall".into(),
                detail: "PolygonWall needs a polygon".into(),
            });
        };
        let v0 = vertices[0];
        let h = *normal * POLYGON_PLATE_HALF_THICKNESS;
        let points: Vec<Vector> = vertices.iter().flat_map(|v| [*v + h, *v - h]).collect();
        let plate = ConvexPolyhedron::from_convex_hull(&points).ok_or_else(|| {
            DemfemError::Numerical("convex hull of a polygon wall's plate failed".into())
        })?;
        let extent = vertices
            .iter()
            .map(|v| (*v - v0).length())
            .fold(0.0, f64::max);
        Ok(Self {
            shape: shape.clone(),
            plate,
            extent,
            first_vertex: Vector3::new(v0.x, v0.y, v0.z),
        })
    }

    /// The polygon at its reference position: vertices (m, boundary order), unit normal and
    /// inward in-plane edge normals.
    pub fn parts(
        &self,
    ) -> (
        &[crate::geometry::Vec3],
        crate::geometry::Vec3,
        &[crate::geometry::Vec3],
    ) {
        match &self.shape {
            WallShape::Polygon {
                vertices,
                normal,
                edge_normals,
            } => (vertices, *normal, edge_normals),
            _ => (&[], crate::geometry::Vec3::ZERO, &[]),
        }
    }

    /// Closest point (m), unit normal from the wall towards `p` and distance (m) of the
    /// world point `p` from the wall displaced by `offset` (m).
    fn closest(
        &self,
        p: &Vector3<f64>,
        offset: &Vector3<f64>,
    ) -> Option<(Vector3<f64>, Vector3<f64>, f64)> {
        let local = p - offset;
        self.shape
            .closest(Vector::new(local.x, local.y, local.z))
            .map(|(q, n, d)| (to_nalgebra(q) + offset, to_nalgebra(n), d))
    }

    /// True when nothing within `reach` (m) of `p` can touch the wall displaced by `offset`.
    fn out_of_reach(&self, p: &Vector3<f64>, offset: &Vector3<f64>, reach: f64) -> bool {
        if (p - offset - self.first_vertex).norm() >= self.extent + reach {
            return true;
        }
        matches!(self.closest(p, offset), Some((_, _, d)) if d >= reach)
    }
}

/// Beads of a clump against a polygon wall displaced by `offset` (m) (wall first, clump
/// second): a bead touches when its centre is closer than its radius to the polygon (face,
/// edge or corner). Beads farther than their radius from the polygon's plane are skipped with
/// one dot product each.
pub fn clump_polygon_contacts(
    wall: &PolygonWall,
    offset: &Vector3<f64>,
    clump: &BeadClump,
    pose: &BodyPose,
    out: &mut Vec<ContactPoint>,
) {
    if wall.out_of_reach(&pose.position, offset, clump.bounding_radius) {
        return;
    }
    let WallShape::Polygon { normal, .. } = &wall.shape else {
        return;
    };
    let n = Vector3::new(normal.x, normal.y, normal.z);
    let s0 = n.dot(&(pose.position - offset - wall.first_vertex));
    let n_body = pose.orientation.inverse_transform_vector(&n);
    for (i, (c, &r)) in clump.centers.iter().zip(&clump.radii).enumerate() {
        if (s0 + n_body.dot(c)).abs() >= r {
            continue;
        }
        let centre = pose.position + pose.orientation * c;
        if let Some((_, normal, distance)) = wall.closest(&centre, offset) {
            let overlap = r - distance;
            if overlap > 0.0 {
                out.push(ContactPoint {
                    point: centre - normal * (0.5 * (r + distance)),
                    normal,
                    overlap,
                    radius_first: f64::INFINITY,
                    radius_second: r,
                    feature_first: 0,
                    feature_second: i as u64,
                });
            }
        }
    }
}

/// Beads of a clump against a mesh wall displaced by `offset` (m) (wall first, clump
/// second): the triangles within the clump's bounding sphere through the mesh's BVH, then
/// each bead against each of them within its radius under the rule of
/// [`crate::geometry::mesh`] (each touching face, edge and vertex once). The contact's
/// `feature_first` is the triangle, so each (bead, triangle) keeps its own friction history.
pub fn clump_mesh_contacts(
    mesh: &MeshWall,
    offset: &Vector3<f64>,
    clump: &BeadClump,
    pose: &BodyPose,
    out: &mut Vec<ContactPoint>,
) {
    let local = pose.position - offset;
    let mut near = Vec::new();
    mesh.triangles_within(
        Vector::new(local.x, local.y, local.z),
        clump.bounding_radius,
        &mut near,
    );
    if near.is_empty() {
        return;
    }
    for (i, (c, &r)) in clump.centers.iter().zip(&clump.radii).enumerate() {
        let centre = pose.position + pose.orientation * c;
        let p = centre - offset;
        let p = Vector::new(p.x, p.y, p.z);
        for &t in &near {
            if let Some((_, normal, distance)) = mesh.contact(t, p, r) {
                let normal = to_nalgebra(normal);
                out.push(ContactPoint {
                    point: centre - normal * (0.5 * (r + distance)),
                    normal,
                    overlap: r - distance,
                    radius_first: f64::INFINITY,
                    radius_second: r,
                    feature_first: u64::from(t),
                    feature_second: i as u64,
                });
            }
        }
    }
}

/// An exact shape against a polygon wall displaced by `offset` (m) (wall first), through
/// parry's manifolds of the compound against the wall's thin plate; overlaps are measured
/// from the polygon's plane (see [`POLYGON_PLATE_HALF_THICKNESS`]).
pub fn exact_polygon_contacts(
    wall: &PolygonWall,
    offset: &Vector3<f64>,
    shape: &ExactShape,
    pose: &BodyPose,
    cache: &mut ExactContactCache,
    out: &mut Vec<ContactPoint>,
) -> Result<()> {
    if wall.out_of_reach(&pose.position, offset, shape.bounding_radius) {
        cache.reset();
        return Ok(());
    }
    let wall_pose = Pose::from_translation(Vector::new(offset.x, offset.y, offset.z));
    let flat = |_: u32| f64::INFINITY;
    let first_new = out.len();
    manifold_contacts(
        &wall_pose,
        &wall.plate,
        &flat,
        &pose.to_parry(),
        &shape.compound,
        &piece_radius(shape),
        None,
        cache,
        out,
    )?;
    // from the plate's face to the polygon's plane: half a thickness less overlap, and the
    // midpoint of the true overlap half of that further towards the wall
    let h = POLYGON_PLATE_HALF_THICKNESS;
    let mut k = first_new;
    while k < out.len() {
        if out[k].overlap > h {
            out[k].overlap -= h;
            let shift = out[k].normal * (0.5 * h);
            out[k].point -= shift;
            k += 1;
        } else {
            out.swap_remove(k);
        }
    }
    Ok(())
}
