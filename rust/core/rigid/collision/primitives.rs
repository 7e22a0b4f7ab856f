//! The vocabulary of rigid contact geometry: a contact point (world frame, normal from the
//! first object to the second, positive overlap), an infinite plane, a body's pose. SI units.

use nalgebra::{UnitQuaternion, Vector3};
use parry3d_f64::math::{Pose, Rotation, Vector};

use crate::error::{DemfemError, Result};

/// One contact point, world frame, SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPoint {
    /// Contact point, midway through the overlap, m.
    pub point: Vector3<f64>,
    /// Unit normal from the first object to the second.
    pub normal: Vector3<f64>,
    /// Overlap (interpenetration depth) > 0, m.
    pub overlap: f64,
    /// Curvature radius of the first surface at the contact, m (`inf` for a plane).
    pub radius_first: f64,
    /// Curvature radius of the second surface at the contact, m (`inf` for a plane).
    pub radius_second: f64,
    /// Feature of the first object that touches: the bead index for a clump, `piece << 32 |
    /// parry feature id` for an exact shape, 0 for a plane or sphere. Keys friction history.
    pub feature_first: u64,
    /// Feature of the second object, as `feature_first`.
    pub feature_second: u64,
}

/// An infinite plane bounding a solid half-space (the belt, a wall).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// A point of the plane, m.
    pub point: Vector3<f64>,
    /// Unit normal pointing out of the solid, into the free space.
    pub normal: Vector3<f64>,
    /// Velocity of the plane's surface (a belt moves tangentially), m/s.
    pub surface_velocity: Vector3<f64>,
}

impl Plane {
    /// A plane through `point` (m) with outward `normal` (any length > 0) whose surface
    /// moves with `surface_velocity` (m/s).
    pub fn new(
        point: Vector3<f64>,
        normal: Vector3<f64>,
        surface_velocity: Vector3<f64>,
    ) -> Result<Self> {
        let length = normal.norm();
        if length.is_nan()
            || length <= 0.0
            || length.is_infinite()
            || !point
                .iter()
                .chain(surface_velocity.iter())
                .all(|v| v.is_finite())
        {
            return Err(DemfemError::ShapeMismatch {
                field: "plane".into(),
                detail: "point and surface velocity finite, normal finite and non-zero".into(),
            });
        }
        Ok(Self {
            point,
            normal: normal / length,
            surface_velocity,
        })
    }

    /// Signed distance of `x` (m) from the plane, positive on the free side, m.
    pub fn signed_distance(&self, x: &Vector3<f64>) -> f64 {
        self.normal.dot(&(x - self.point))
    }
}

/// Position (m) and orientation (body → world) of a rigid body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyPose {
    /// Centre of mass, world, m.
    pub position: Vector3<f64>,
    /// Orientation, body → world.
    pub orientation: UnitQuaternion<f64>,
}

impl BodyPose {
    pub(super) fn to_parry(self) -> Pose {
        let (x, q) = (self.position, self.orientation.coords);
        Pose::from_parts(
            Vector::new(x.x, x.y, x.z),
            Rotation::from_xyzw(q[0], q[1], q[2], q[3]),
        )
    }
}

/// A parry vector as nalgebra's.
pub(super) fn to_nalgebra(v: Vector) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}
