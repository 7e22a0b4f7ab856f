//! The contact geometry of one evaluation of the revolution pass (`revolution_pass`):
//! every body against every boundary and every listed pair, found body by body and pair by
//! pair with nothing shared but the scene, so that blocks of bodies and of pairs run on the
//! scene's threads at once. Each block appends its contacts and weights with one record per
//! touching slot; the blocks are then read in order by the serial force pass, which is what
//! keeps the result bitwise the same on any number of threads.

use nalgebra::{UnitQuaternion, Vector3};

use super::{PreparedShape, PreparedWall, RigidScene};
use crate::error::{DemfemError, Result};
use crate::rigid::collision::{
    clump_clump_contacts, clump_mesh_contacts, clump_plane_contacts, clump_polygon_contacts,
    BodyPose, ClumpPairScratch, ContactPoint, Plane,
};
use crate::rigid::revolution::contacts::{
    bead_contact, pair_contacts, plane_contacts, PairScratch,
};
use crate::rigid::revolution::features::Placed;
use crate::rigid::revolution::wall_edges::polygon_edge_contacts;
use crate::rigid::shape::{MassProperties, RigidShape};

type V3 = Vector3<f64>;

/// One touching slot of a block: the slot (body × boundary, or pair), its contacts
/// `range` in the block's arrays, and whether a pair's contacts run from `b` to `a`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Touch {
    /// Wall slot (body · boundaries + boundary) or pair index.
    pub slot: usize,
    /// Range of the contacts and weights.
    pub range: (usize, usize),
    /// Surface velocity of the boundary (walls), m/s.
    pub surface_velocity: V3,
    /// A pair computed second body first (a clump against a body of revolution).
    pub flipped: bool,
}

/// The contacts of one block of bodies or pairs.
#[derive(Debug, Default)]
pub(super) struct Block {
    pub contacts: Vec<ContactPoint>,
    pub weights: Vec<f64>,
    pub touches: Vec<Touch>,
    pair_scratch: PairScratch,
    clump_scratch: ClumpPairScratch,
}

impl Block {
    /// Forget the contacts (keeping the buffers).
    pub fn clear(&mut self) {
        self.contacts.clear();
        self.weights.clear();
        self.touches.clear();
    }

    fn close(&mut self, slot: usize, start: usize, surface_velocity: V3, flipped: bool) {
        if self.contacts.len() > start {
            self.weights.resize(self.contacts.len(), 1.0);
            self.touches.push(Touch {
                slot,
                range: (start, self.contacts.len()),
                surface_velocity,
                flipped,
            });
        }
    }
}

/// A body of revolution placed with its frame of this evaluation ([axis, x, y], world).
#[inline]
pub(super) fn placed_with<'a>(
    shape: &'a crate::rigid::RevolutionShape,
    position: V3,
    frame: &[V3; 3],
) -> Placed<'a> {
    Placed {
        shape,
        origin: position,
        axis: frame[0],
        x: frame[1],
        y: frame[2],
    }
}

/// Each orientation's body z, x and y in the world.
pub(super) fn frames(orientations: &[UnitQuaternion<f64>], out: &mut Vec<[V3; 3]>) {
    out.clear();
    out.extend(orientations.iter().map(|q| {
        let r = q.to_rotation_matrix();
        let m = r.matrix();
        [
            m.column(2).into_owned(),
            m.column(0).into_owned(),
            m.column(1).into_owned(),
        ]
    }));
}

pub(super) fn mixed_exact() -> DemfemError {
    DemfemError::ShapeMismatch {
        field: "shape".into(),
        detail: "bodies of revolution share a scene with bead clumps and spheres, not with \
                 parry exact shapes"
            .into(),
    }
}

/// What the geometry reads of a scene (shared by the threads).
pub(super) struct View<'a> {
    shapes: &'a [(RigidShape, MassProperties)],
    body_shape: &'a [usize],
    alive: &'a [bool],
    position: &'a [V3],
    orientation: &'a [UnitQuaternion<f64>],
    planes: &'a [Plane],
    walls: &'a [PreparedWall],
}

impl RigidScene {
    /// The scene as the geometry reads it.
    pub(super) fn view(&self) -> View<'_> {
        View {
            shapes: &self.shapes,
            body_shape: &self.body_shape,
            alive: &self.alive,
            position: &self.bodies.position,
            orientation: &self.bodies.orientation,
            planes: &self.planes,
            walls: &self.walls,
        }
    }
}

impl View<'_> {
    fn pose(&self, i: usize) -> BodyPose {
        BodyPose {
            position: self.position[i],
            orientation: self.orientation[i],
        }
    }

    /// The contacts of bodies `bodies` with every boundary, appended to `block`; `offsets`
    /// are the walls' displacements and velocities now.
    pub(super) fn wall_geometry(
        &self,
        bodies: std::ops::Range<usize>,
        frames: &[[V3; 3]],
        offsets: &[(V3, V3)],
        block: &mut Block,
    ) -> Result<()> {
        let n_planes = self.planes.len();
        let n_boundaries = n_planes + self.walls.len();
        for i in bodies {
            if !self.alive[i] {
                continue;
            }
            let pose = self.pose(i);
            let shape = &self.shapes[self.body_shape[i]].0;
            for p in 0..n_boundaries {
                let start = block.contacts.len();
                let (plane_point, plane_normal, surface_velocity, prepared) = if p < n_planes {
                    let plane = self.planes[p];
                    (plane.point, plane.normal, plane.surface_velocity, None)
                } else {
                    let wall = &self.walls[p - n_planes];
                    let (offset, velocity) = offsets[p - n_planes];
                    let (point, normal) = match &wall.shape {
                        PreparedShape::Plane { point, normal } => (point + offset, *normal),
                        _ => (offset, Vector3::z()),
                    };
                    (
                        point,
                        normal,
                        wall.surface_velocity + velocity,
                        Some((wall, offset)),
                    )
                };
                let contacts = &mut block.contacts;
                let weights = &mut block.weights;
                weights.resize(contacts.len(), 1.0);
                match (prepared.map(|(w, o)| (&w.shape, o)), shape) {
                    (None | Some((PreparedShape::Plane { .. }, _)), RigidShape::Clump(clump)) => {
                        let plane = Plane {
                            point: plane_point,
                            normal: plane_normal,
                            surface_velocity: Vector3::zeros(),
                        };
                        clump_plane_contacts(&plane, clump, &pose, contacts);
                    }
                    (None | Some((PreparedShape::Plane { .. }, _)), RigidShape::Revolution(r)) => {
                        if plane_normal.dot(&(pose.position - plane_point)) < r.bounding_radius {
                            let body = placed_with(r, pose.position, &frames[i]);
                            plane_contacts(
                                &plane_point,
                                &plane_normal,
                                &body,
                                None,
                                contacts,
                                weights,
                            );
                        }
                    }
                    (Some((PreparedShape::Polygon(polygon), offset)), RigidShape::Clump(clump)) => {
                        clump_polygon_contacts(polygon, &offset, clump, &pose, contacts)
                    }
                    (
                        Some((PreparedShape::Polygon(polygon), offset)),
                        RigidShape::Revolution(r),
                    ) => {
                        polygon_contacts(polygon, &offset, r, &pose, &frames[i], contacts, weights);
                    }
                    (Some((PreparedShape::Mesh(mesh), offset)), RigidShape::Clump(clump)) => {
                        clump_mesh_contacts(mesh, &offset, clump, &pose, contacts)
                    }
                    (Some((PreparedShape::Mesh(mesh), offset)), RigidShape::Revolution(r)) => {
                        crate::rigid::revolution::mesh_walls::mesh_contacts(
                            mesh,
                            &offset,
                            &placed_with(r, pose.position, &frames[i]),
                            contacts,
                            weights,
                        )
                    }
                    (_, RigidShape::Exact(_)) => return Err(mixed_exact()),
                }
                block.close(i * n_boundaries + p, start, surface_velocity, false);
            }
        }
        Ok(())
    }

    /// The contacts of the listed pairs `range` (indices into `pairs`), appended to `block`.
    pub(super) fn pair_geometry(
        &self,
        pairs: &[(u32, u32)],
        range: std::ops::Range<usize>,
        frames: &[[V3; 3]],
        block: &mut Block,
    ) -> Result<()> {
        for k in range {
            let (a, b) = (pairs[k].0 as usize, pairs[k].1 as usize);
            if !(self.alive[a] && self.alive[b]) {
                continue;
            }
            let (pa, pb) = (self.pose(a), self.pose(b));
            let (shape_a, shape_b) = (
                &self.shapes[self.body_shape[a]].0,
                &self.shapes[self.body_shape[b]].0,
            );
            let reach = shape_a.bounding_radius() + shape_b.bounding_radius();
            if (pb.position - pa.position).norm() >= reach
                || !super::contacts::capsules_overlap(
                    &shape_a.bounding_capsule(),
                    &pa,
                    &shape_b.bounding_capsule(),
                    &pb,
                )
            {
                continue;
            }
            let start = block.contacts.len();
            block.weights.resize(start, 1.0);
            let mut flipped = false;
            match (shape_a, shape_b) {
                (RigidShape::Revolution(ra), RigidShape::Revolution(rb)) => pair_contacts(
                    &placed_with(ra, pa.position, &frames[a]),
                    &placed_with(rb, pb.position, &frames[b]),
                    &mut block.pair_scratch,
                    &mut block.contacts,
                    &mut block.weights,
                ),
                (RigidShape::Clump(ca), RigidShape::Revolution(rb)) => beads_against(
                    ca,
                    &pa,
                    &placed_with(rb, pb.position, &frames[b]),
                    &mut block.contacts,
                ),
                (RigidShape::Revolution(ra), RigidShape::Clump(cb)) => {
                    flipped = true;
                    beads_against(
                        cb,
                        &pb,
                        &placed_with(ra, pa.position, &frames[a]),
                        &mut block.contacts,
                    )
                }
                (RigidShape::Clump(ca), RigidShape::Clump(cb)) => clump_clump_contacts(
                    ca,
                    &pa,
                    cb,
                    &pb,
                    &mut block.clump_scratch,
                    &mut block.contacts,
                ),
                _ => return Err(mixed_exact()),
            }
            block.close(k, start, Vector3::zeros(), flipped);
        }
        Ok(())
    }
}

/// A polygon wall displaced by `offset` against a body of revolution: the face (anchored
/// points of the edge circles inside the polygon, on the side of the body's centre), then
/// the edges and corners.
fn polygon_contacts(
    polygon: &crate::rigid::PolygonWall,
    offset: &V3,
    shape: &crate::rigid::RevolutionShape,
    pose: &BodyPose,
    frame: &[V3; 3],
    contacts: &mut Vec<ContactPoint>,
    weights: &mut Vec<f64>,
) {
    let (vertices, normal, edge_normals) = polygon.parts();
    if vertices.is_empty() {
        return;
    }
    let to_na = |v: &crate::geometry::Vec3| Vector3::new(v.x, v.y, v.z);
    let first = to_na(&vertices[0]) + offset;
    let mut n = to_na(&normal);
    let side = n.dot(&(pose.position - first));
    if side.abs() >= shape.bounding_radius {
        return;
    }
    if side < 0.0 {
        n = -n;
    }
    let body = placed_with(shape, pose.position, frame);
    let inside = |x: &V3| {
        vertices
            .iter()
            .zip(edge_normals)
            .all(|(v, e)| to_na(e).dot(&(x - to_na(v) - offset)) >= 0.0)
    };
    plane_contacts(&first, &n, &body, Some(&inside), contacts, weights);
    let world: Vec<V3> = vertices.iter().map(|v| to_na(v) + offset).collect();
    let inward: Vec<V3> = edge_normals.iter().map(to_na).collect();
    polygon_edge_contacts(&world, &inward, &body, contacts, weights);
}

/// The beads of a clump against a body of revolution (clump first).
fn beads_against(
    clump: &crate::rigid::BeadClump,
    pose: &BodyPose,
    body: &Placed,
    contacts: &mut Vec<ContactPoint>,
) {
    let local = pose
        .orientation
        .inverse_transform_vector(&(body.origin - pose.position));
    for (k, (c, &r)) in clump.centers.iter().zip(&clump.radii).enumerate() {
        if (c - local).norm() >= body.shape.bounding_radius + r {
            continue;
        }
        let centre = pose.position + pose.orientation * c;
        if let Some(mut contact) = bead_contact(&centre, r, body) {
            contact.feature_first = k as u64;
            contacts.push(contact);
        }
    }
}
