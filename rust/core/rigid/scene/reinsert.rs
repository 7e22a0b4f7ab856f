//! Re-feeding: a body removed through the outlet (or by hand) is put back at a given pose,
//! so that a table can run "in operation" with a steady population.
//!
//! A body is put back only where it touches nothing: the pose is tested with the engine's
//! own contact geometry — the exact shapes (bodies of revolution, parry compounds, bead
//! clumps) against every boundary at the current time and every alive body — and refused
//! when any contact point is found. Since it touches nothing, its contact force is zero and
//! no other body's force changes: the forces of the last evaluation stay exact once the
//! body's own are set to its weight, so a run continues as if the body had been there all
//! along (no extra force evaluation, which would advance the friction springs of every
//! contact by one step).
//!
//! Everything kept between evaluations about the body — Mindlin springs, touching flags
//! (onsets), parry manifolds, its place in the Verlet list — is dropped, and the pair list is
//! rebuilt at the next evaluation. All of this runs on one thread, in a fixed order: the
//! result stays bitwise the same on any number of threads.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use super::revolution_geometry::{frames, Block};
use super::{PreparedShape, RigidScene};
use crate::error::{check_finite, DemfemError, Result};
use crate::rigid::collision::{
    clump_exact_contacts, exact_exact_contacts, exact_plane_contacts, exact_polygon_contacts,
    ContactPoint, ExactContactCache, Plane,
};
use crate::rigid::shape::RigidShape;

/// Largest departure of |q| from 1 that [`RigidScene::reinsert_body`] normalises away.
pub const UNIT_QUATERNION_TOLERANCE: f64 = 1e-6;

/// Distance below which two axis segments count as meeting, m.
const AXES_MEET: f64 = 1e-9;

/// What a body at a trial pose would touch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Obstacle {
    /// An alive body.
    Body(usize),
    /// A boundary: planes first, then walls.
    Wall(usize),
}

impl std::fmt::Display for Obstacle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Obstacle::Body(j) => write!(f, "body {j}"),
            Obstacle::Wall(p) => write!(f, "wall {p}"),
        }
    }
}

impl RigidScene {
    /// Put removed body `i` back at `position` (m, centre of mass) with `orientation` (body
    /// → world, a unit quaternion: |q| within [`UNIT_QUATERNION_TOLERANCE`] of 1 is
    /// normalised) and `velocity` (m/s), without spin. Refused, naming the field, when `i` is
    /// out of range or alive, a value is not finite, the quaternion is not unit, the position
    /// is on the removed side of the outlet, or the body would touch an alive body or a
    /// boundary there (the engine's exact contact test).
    pub fn reinsert_body(
        &mut self,
        i: usize,
        position: Vector3<f64>,
        orientation: Quaternion<f64>,
        velocity: Vector3<f64>,
    ) -> Result<()> {
        match self.reinsert_body_if_free(i, position, orientation, velocity)? {
            None => Ok(()),
            Some(obstacle) => Err(DemfemError::InvalidParameter {
                field: "position".into(),
                value: format!(
                    "({}, {}, {}): body {i} would overlap {obstacle} there",
                    position.x, position.y, position.z
                ),
                allowed: "a pose where the body touches no alive body and no wall".into(),
            }),
        }
    }

    /// As [`RigidScene::reinsert_body`], but an occupied pose is not an error: the body
    /// stays removed and what it would touch is returned (`None`: put back).
    pub fn reinsert_body_if_free(
        &mut self,
        i: usize,
        position: Vector3<f64>,
        orientation: Quaternion<f64>,
        velocity: Vector3<f64>,
    ) -> Result<Option<Obstacle>> {
        let n = self.bodies.len();
        if i >= n {
            return Err(DemfemError::InvalidParameter {
                field: "i".into(),
                value: i.to_string(),
                allowed: format!("the index of one of the {n} bodies"),
            });
        }
        if self.alive[i] {
            return Err(DemfemError::InvalidParameter {
                field: "i".into(),
                value: format!("{i} (alive)"),
                allowed: "a removed body".into(),
            });
        }
        check_finite("position", position.as_slice())?;
        check_finite("velocity", velocity.as_slice())?;
        check_finite("orientation", orientation.coords.as_slice())?;
        let norm = orientation.norm();
        if (norm - 1.0).abs() > UNIT_QUATERNION_TOLERANCE {
            return Err(DemfemError::InvalidParameter {
                field: "orientation".into(),
                value: format!("{:?} (norm {norm})", orientation.coords.as_slice()),
                allowed: format!(
                    "a unit quaternion (|q| within {UNIT_QUATERNION_TOLERANCE:e} of 1)"
                ),
            });
        }
        let orientation = UnitQuaternion::from_quaternion(orientation);
        if let Some((point, normal)) = self.removal_plane {
            if (position - point).dot(&normal) < 0.0 {
                return Err(DemfemError::InvalidParameter {
                    field: "position".into(),
                    value: format!("({}, {}, {})", position.x, position.y, position.z),
                    allowed: "on the kept side of the removal plane".into(),
                });
            }
        }
        // try the pose
        let saved = (self.bodies.position[i], self.bodies.orientation[i]);
        self.bodies.position[i] = position;
        self.bodies.orientation[i] = orientation;
        self.alive[i] = true;
        let obstacle = self.first_obstacle(i);
        if !matches!(obstacle, Ok(None)) {
            self.alive[i] = false;
            (self.bodies.position[i], self.bodies.orientation[i]) = saved;
            return obstacle;
        }
        self.bodies.velocity[i] = velocity;
        self.bodies.angular_velocity_body[i] = Vector3::zeros();
        // touching nothing: its force is its weight, every other force is unchanged
        self.bodies.force[i] = self.gravity * self.bodies.mass[i];
        self.bodies.torque[i] = Vector3::zeros();
        self.coordination[i] = 0;
        self.wall_contacts[i] = 0;
        self.forget_contacts_of(i);
        self.reinsertions.push((self.time, i as u32));
        Ok(None)
    }

    /// Bodies put back so far: (time (s), body index), in order.
    pub fn reinsertions(&self) -> &[(f64, u32)] {
        &self.reinsertions
    }

    /// Drop the contact memory of body `i`: friction springs, touching flags and parry
    /// manifolds of its pairs and boundary slots, and (bodies of revolution) its Verlet-list
    /// entries, with a rebuild forced.
    fn forget_contacts_of(&mut self, i: usize) {
        let body = i as u64;
        let involves = |object: u64| (object >> 32) == body || (object & 0xFFFF_FFFF) == body;
        self.friction_history.retain(|key, _| !involves(key.0));
        self.friction_history_next.clear();
        self.touching.retain(|&key| !involves(key));
        self.touching_next.clear();
        self.exact_caches.retain(|&(a, b), _| a != i && b != i);
        let n_boundaries = self.planes.len() + self.walls.len();
        if let Some(pass) = self.revolution.as_mut() {
            pass.forget_body(i, n_boundaries);
        }
    }

    /// The first boundary, then the first alive body (lowest index), that body `i` touches at
    /// its current pose, by the contact tests of the force evaluation.
    fn first_obstacle(&self, i: usize) -> Result<Option<Obstacle>> {
        let n = self.bodies.len();
        let n_planes = self.planes.len();
        let n_boundaries = n_planes + self.walls.len();
        let offsets = self.wall_offsets(self.time);
        let shape_i = &self.shapes[self.body_shape[i]].0;
        let pose_i = self.pose(i);
        let mut frames_now = Vec::new();
        frames(&self.bodies.orientation, &mut frames_now);
        let view = self.view();
        let mut block = Block::default();
        // boundaries
        if let RigidShape::Exact(shape) = shape_i {
            let mut contacts = Vec::new();
            for p in 0..n_boundaries {
                contacts.clear();
                let mut cache = ExactContactCache::default();
                if p < n_planes {
                    exact_plane_contacts(
                        &self.planes[p],
                        shape,
                        &pose_i,
                        &mut cache,
                        &mut contacts,
                    )?;
                } else {
                    let (offset, _) = offsets[p - n_planes];
                    match &self.walls[p - n_planes].shape {
                        PreparedShape::Plane { point, normal } => {
                            let plane = Plane {
                                point: point + offset,
                                normal: *normal,
                                surface_velocity: Vector3::zeros(),
                            };
                            exact_plane_contacts(&plane, shape, &pose_i, &mut cache, &mut contacts)?
                        }
                        PreparedShape::Polygon(polygon) => exact_polygon_contacts(
                            polygon,
                            &offset,
                            shape,
                            &pose_i,
                            &mut cache,
                            &mut contacts,
                        )?,
                        PreparedShape::Mesh(_) => {
                            return Err(DemfemError::ShapeMismatch {
                                field: format!("walls[{}]", p - n_planes),
                                detail: "a mesh wall takes bead clumps and spheres, not exact \
                                         shapes (yet)"
                                    .into(),
                            })
                        }
                    }
                }
                if !contacts.is_empty() {
                    return Ok(Some(Obstacle::Wall(p)));
                }
            }
        } else {
            view.wall_geometry(i..i + 1, &frames_now, &offsets, &mut block)?;
            if let Some(touch) = block.touches.first() {
                return Ok(Some(Obstacle::Wall(touch.slot % n_boundaries.max(1))));
            }
        }
        // bodies, culled by bounding spheres as the force pass does
        let r_i = shape_i.bounding_radius();
        let mut contacts: Vec<ContactPoint> = Vec::new();
        for j in 0..n {
            if j == i || !self.alive[j] {
                continue;
            }
            let shape_j = &self.shapes[self.body_shape[j]].0;
            if (self.bodies.position[j] - pose_i.position).norm() >= r_i + shape_j.bounding_radius()
            {
                continue;
            }
            if self.axes_cross(i, j) {
                return Ok(Some(Obstacle::Body(j)));
            }
            let (a, b) = (i.min(j), i.max(j));
            let touches = match (
                &self.shapes[self.body_shape[a]].0,
                &self.shapes[self.body_shape[b]].0,
            ) {
                (RigidShape::Exact(ea), RigidShape::Exact(eb)) => {
                    contacts.clear();
                    let mut cache = ExactContactCache::default();
                    exact_exact_contacts(
                        ea,
                        &self.pose(a),
                        eb,
                        &self.pose(b),
                        &mut cache,
                        &mut contacts,
                    )?;
                    !contacts.is_empty()
                }
                (RigidShape::Clump(c), RigidShape::Exact(e)) => {
                    contacts.clear();
                    clump_exact_contacts(c, &self.pose(a), e, &self.pose(b), &mut contacts)?;
                    !contacts.is_empty()
                }
                (RigidShape::Exact(e), RigidShape::Clump(c)) => {
                    contacts.clear();
                    clump_exact_contacts(c, &self.pose(b), e, &self.pose(a), &mut contacts)?;
                    !contacts.is_empty()
                }
                _ => {
                    block.clear();
                    let pair = [(a as u32, b as u32)];
                    view.pair_geometry(&pair, 0..1, &frames_now, &mut block)?;
                    !block.touches.is_empty()
                }
            };
            if touches {
                return Ok(Some(Obstacle::Body(j)));
            }
        }
        Ok(None)
    }

    /// True when the axis segments of bodies `i` and `j` (their bounding capsules' cores,
    /// inside the bodies) come closer than [`AXES_MEET`] plus the radii the bodies are solid
    /// to around them: the bodies then surely overlap. A body of revolution holds the
    /// capsule of its smallest outline radius ρ about its core shortened by ρ at each end
    /// (the cartridge's neck: 3 mm); other shapes count their core alone. The contact tests
    /// are built for the micrometre overlaps of a step and may find nothing between bodies
    /// that overlap through and through — two cartridges at one site, whose normal is
    /// undefined, or a body re-fed at its site millimetres from one that has not left it
    /// yet —; this catches those.
    fn axes_cross(&self, i: usize, j: usize) -> bool {
        let core = |k: usize| {
            let shape = &self.shapes[self.body_shape[k]].0;
            let capsule = shape.bounding_capsule();
            let solid = match shape {
                // the outline runs from (z_bottom, 0) up the outside to (z_top, 0)
                RigidShape::Revolution(r) => r.outline[1..r.outline.len().saturating_sub(1)]
                    .iter()
                    .map(|p| p.1)
                    .fold(f64::INFINITY, f64::min)
                    .min(0.5 * (capsule.z_max - capsule.z_min))
                    .max(0.0),
                _ => 0.0,
            };
            let axis = self.bodies.orientation[k] * Vector3::z();
            let x = self.bodies.position[k];
            (
                x + axis * (capsule.z_min + solid),
                x + axis * (capsule.z_max - solid),
                solid,
            )
        };
        let (a0, a1, ra) = core(i);
        let (b0, b1, rb) = core(j);
        let reach = AXES_MEET + ra + rb;
        super::contacts::segment_distance_squared(&a0, &a1, &b0, &b1) < reach * reach
    }
}
