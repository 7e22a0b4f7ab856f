//! Walls of the DEM scene (belt, side walls, funnel, gate) and the sphere–wall closest-point
//! queries the contact pass needs.
//!
//! A wall is a rigid shape in its reference position plus a prescribed rigid translation
//! (fixed, constant velocity or harmonic oscillation) and an optional *surface velocity*: the
//! velocity of its material points along its surface while the geometry stays put (a conveyor
//! belt). Shapes:
//!
//! * [`WallShape::Plane`]: an infinite half-space boundary, one-sided (particles live on the
//!   side the normal points to). Closest point by hand: it is one dot product.
//! * [`WallShape::Polygon`]: a finite, planar, convex polygon, two-sided (a thin wall: funnel
//!   faces, gate leaves, vertical wall strips via [`WallShape::vertical_strip`]). Closest point
//!   by hand (projection, then nearest edge point), which is exact at edges and corners and is
//!   cross-checked against parry3d's triangle projection in the tests.
//! * [`WallShape::Cuboid`]: a solid axis-aligned box, closest point through parry3d-f64's
//!   `Cuboid` point projection (faces, edges and corners handled by parry).
//! * [`WallShape::Mesh`]: a triangle mesh (walls from CAD), two-sided, its triangles found
//!   through the BVH of parry3d-f64's `TriMesh`; each (particle, triangle) within reach is a
//!   wall slot of its own, and the rule of module [`mesh`] counts each touching face, edge
//!   and vertex once.
//!
//! All lengths in metres, velocities in m/s, times in seconds.

use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Cuboid;

use crate::error::{check_non_negative, check_positive, DemfemError, Result};

pub mod mesh;
pub use mesh::{MeshFeature, MeshWall};

/// Three-component vector (x, y, z) used throughout the DEM (glam `DVec3` as re-exported by
/// parry3d-f64).
pub type Vec3 = parry3d_f64::math::Vector;

fn check_vec(field: &str, v: Vec3) -> Result<Vec3> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(DemfemError::InvalidParameter {
            field: field.to_string(),
            value: format!("{v:?}"),
            allowed: "finite components".into(),
        })
    }
}

/// Geometry of a wall in its reference position.
#[derive(Debug, Clone)]
pub enum WallShape {
    /// Infinite plane through `point` with unit `normal` pointing into the particle region.
    Plane {
        /// A point on the plane, m.
        point: Vec3,
        /// Unit normal towards the particles.
        normal: Vec3,
    },
    /// Convex planar polygon (vertices in order around the boundary), two-sided.
    Polygon {
        /// Vertices, m, at least three, coplanar, convex, in boundary order.
        vertices: Vec<Vec3>,
        /// Unit normal of the polygon plane (derived from the vertices).
        normal: Vec3,
        /// Inward-pointing unit normals of each edge, within the polygon plane.
        edge_normals: Vec<Vec3>,
    },
    /// Solid axis-aligned box (cuboid) with centre and half extents, m.
    Cuboid {
        /// Box centre, m.
        center: Vec3,
        /// Half extents along x, y, z, m.
        half_extents: Vec3,
        /// The parry shape used for the projection.
        shape: Cuboid,
    },
    /// Triangle mesh, two-sided (see [`MeshWall`]); shared, so cloning a scene is cheap.
    Mesh(std::sync::Arc<MeshWall>),
}

impl WallShape {
    /// An infinite plane through `point` whose normal `normal` (need not be unit) points to the
    /// particles.
    pub fn plane(point: Vec3, normal: Vec3) -> Result<Self> {
        check_vec("plane.point", point)?;
        check_vec("plane.normal", normal)?;
        let len = normal.length();
        if !(len > 0.0) {
            return Err(DemfemError::invalid("plane.normal length", len, "> 0"));
        }
        Ok(WallShape::Plane {
            point,
            normal: normal / len,
        })
    }

    /// A convex planar polygon from its vertices in boundary order (either orientation).
    pub fn polygon(vertices: Vec<Vec3>) -> Result<Self> {
        if vertices.len() < 3 {
            return Err(DemfemError::ShapeMismatch {
                field: "polygon.vertices".into(),
                detail: format!("need at least 3 vertices, got {}", vertices.len()),
            });
        }
        for v in &vertices {
            check_vec("polygon.vertex", *v)?;
        }
        // Newell's normal: robust for any simple polygon, its length is twice the area.
        let mut nn = Vec3::ZERO;
        let k = vertices.len();
        for a in 0..k {
            let p = vertices[a];
            let q = vertices[(a + 1) % k];
            nn += p.cross(q);
        }
        let area2 = nn.length();
        let size = vertices
            .iter()
            .map(|v| (*v - vertices[0]).length())
            .fold(0.0_f64, f64::max);
        if !(area2 > 1e-12 * size * size) {
            return Err(DemfemError::invalid(
                "polygon area",
                0.5 * area2,
                "> 0 (non-degenerate)",
            ));
        }
        let normal = nn / area2;
        let mut edge_normals = Vec::with_capacity(k);
        for a in 0..k {
            let p = vertices[a];
            let q = vertices[(a + 1) % k];
            if normal.dot(p - vertices[0]).abs() > 1e-9 * size {
                return Err(DemfemError::invalid(
                    "polygon vertex distance from plane",
                    normal.dot(p - vertices[0]),
                    "0 (planar polygon)",
                ));
            }
            let edge = q - p;
            let elen = edge.length();
            if !(elen > 0.0) {
                return Err(DemfemError::invalid("polygon edge length", elen, "> 0"));
            }
            edge_normals.push(normal.cross(edge / elen));
        }
        // convexity: every vertex must be on the inner side of every edge
        for a in 0..k {
            for (b, v) in vertices.iter().enumerate() {
                let d = edge_normals[a].dot(*v - vertices[a]);
                if d < -1e-9 * size {
                    return Err(DemfemError::invalid(
                        &format!("polygon vertex {b} against edge {a}"),
                        d,
                        ">= 0 (convex polygon in boundary order)",
                    ));
                }
            }
        }
        Ok(WallShape::Polygon {
            vertices,
            normal,
            edge_normals,
        })
    }

    /// A vertical wall strip (rectangle) above the segment (x0, y0)–(x1, y1), from height
    /// `z_bottom` to `z_top`, m.
    pub fn vertical_strip(
        x0: f64,
        y0: f64,
        x1: f64,
        y1: f64,
        z_bottom: f64,
        z_top: f64,
    ) -> Result<Self> {
        if !(z_top > z_bottom) {
            return Err(DemfemError::invalid(
                "strip z_top - z_bottom",
                z_top - z_bottom,
                "> 0",
            ));
        }
        WallShape::polygon(vec![
            Vec3::new(x0, y0, z_bottom),
            Vec3::new(x1, y1, z_bottom),
            Vec3::new(x1, y1, z_top),
            Vec3::new(x0, y0, z_top),
        ])
    }

    /// A solid axis-aligned box with the given centre and half extents, m.
    pub fn cuboid(center: Vec3, half_extents: Vec3) -> Result<Self> {
        check_vec("cuboid.center", center)?;
        check_positive("cuboid.half_extents.x", half_extents.x)?;
        check_positive("cuboid.half_extents.y", half_extents.y)?;
        check_positive("cuboid.half_extents.z", half_extents.z)?;
        Ok(WallShape::Cuboid {
            center,
            half_extents,
            shape: Cuboid::new(half_extents),
        })
    }

    /// Closest point of the wall (in its reference position) to `p`, and the unit normal of the
    /// contact pointing from the wall towards `p`, and the signed distance (negative when `p`
    /// is behind a plane or inside a cuboid). Returns `None` when `p` lies exactly on a
    /// two-sided polygon, where no normal is defined.
    #[inline(always)]
    pub fn closest(&self, p: Vec3) -> Option<(Vec3, Vec3, f64)> {
        match self {
            WallShape::Plane { point, normal } => {
                let d = normal.dot(p - *point);
                Some((p - d * *normal, *normal, d))
            }
            WallShape::Polygon {
                vertices,
                normal,
                edge_normals,
            } => {
                let q = closest_on_convex_polygon(p, vertices, *normal, edge_normals);
                let diff = p - q;
                let dist = diff.length();
                if dist > 0.0 {
                    Some((q, diff * (1.0 / dist), dist))
                } else {
                    None
                }
            }
            WallShape::Cuboid { center, shape, .. } => {
                let local = p - *center;
                let proj = shape.project_local_point(local, false);
                let q = proj.point + *center;
                let diff = p - q;
                let dist = diff.length();
                if dist > 0.0 {
                    if proj.is_inside {
                        // inside the solid: push out through the nearest face
                        Some((q, -diff / dist, -dist))
                    } else {
                        Some((q, diff / dist, dist))
                    }
                } else {
                    None
                }
            }
            WallShape::Mesh(mesh) => mesh.closest(p),
        }
    }
}

/// Closest point to `p` on a convex planar polygon (boundary order, inward edge normals).
fn closest_on_convex_polygon(
    p: Vec3,
    vertices: &[Vec3],
    normal: Vec3,
    edge_normals: &[Vec3],
) -> Vec3 {
    let proj = p - normal.dot(p - vertices[0]) * normal;
    let k = vertices.len();
    let mut inside = true;
    for a in 0..k {
        if edge_normals[a].dot(proj - vertices[a]) < 0.0 {
            inside = false;
            break;
        }
    }
    if inside {
        return proj;
    }
    // outside: the closest point lies on the boundary; for a convex polygon the nearest
    // boundary point to the projection is the nearest point to p as well (p - proj ⟂ plane)
    let mut best = vertices[0];
    let mut best_d2 = f64::INFINITY;
    for a in 0..k {
        let s = vertices[a];
        let e = vertices[(a + 1) % k] - s;
        let t = (e.dot(proj - s) / e.length_squared()).clamp(0.0, 1.0);
        let c = s + t * e;
        let d2 = (proj - c).length_squared();
        if d2 < best_d2 {
            best_d2 = d2;
            best = c;
        }
    }
    best
}

/// Prescribed rigid motion of a wall: a translation of its reference geometry, or a
/// rotation about a fixed axis (a star wheel, a rotating arm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WallMotion {
    /// The wall does not move.
    Fixed,
    /// x(t) = x0 + v t, v in m/s.
    ConstantVelocity {
        /// Velocity, m/s.
        velocity: Vec3,
    },
    /// x(t) = x0 + A sin(2π t / T + φ) d along the unit direction d (e.g. the gate).
    Harmonic {
        /// Unit direction of the oscillation.
        direction: Vec3,
        /// Amplitude A, m.
        amplitude: f64,
        /// Period T, s.
        period: f64,
        /// Phase φ, rad.
        phase: f64,
    },
    /// Rotation by θ(t) = ω t about the axis through `axis_point` along the unit `axis`
    /// (right-handed): a point y of the reference geometry is at
    /// c + R(θ)(y − c), moving at ω axis × (y(t) − c). Not for planes (infinite).
    Rotation {
        /// A point on the axis, m.
        axis_point: Vec3,
        /// Unit direction of the axis.
        axis: Vec3,
        /// Angular velocity ω, rad/s.
        angular_velocity: f64,
    },
}

impl WallMotion {
    /// A harmonic oscillation; the direction is normalised.
    pub fn harmonic(direction: Vec3, amplitude: f64, period: f64, phase: f64) -> Result<Self> {
        check_vec("harmonic.direction", direction)?;
        let len = direction.length();
        if !(len > 0.0) {
            return Err(DemfemError::invalid(
                "harmonic.direction length",
                len,
                "> 0",
            ));
        }
        check_non_negative("harmonic.amplitude", amplitude)?;
        check_positive("harmonic.period", period)?;
        if !phase.is_finite() {
            return Err(DemfemError::invalid("harmonic.phase", phase, "finite"));
        }
        Ok(WallMotion::Harmonic {
            direction: direction / len,
            amplitude,
            period,
            phase,
        })
    }

    /// A rotation about the axis through `axis_point` along `axis` (normalised) at
    /// `angular_velocity` rad/s.
    pub fn rotation(axis_point: Vec3, axis: Vec3, angular_velocity: f64) -> Result<Self> {
        check_vec("rotation.axis_point", axis_point)?;
        check_vec("rotation.axis", axis)?;
        let len = axis.length();
        if !(len > 0.0) {
            return Err(DemfemError::invalid("rotation.axis length", len, "> 0"));
        }
        if !angular_velocity.is_finite() {
            return Err(DemfemError::invalid(
                "rotation.angular_velocity",
                angular_velocity,
                "finite (rad/s)",
            ));
        }
        Ok(WallMotion::Rotation {
            axis_point,
            axis: axis / len,
            angular_velocity,
        })
    }

    /// Rotation angle at time t, rad (0 unless a [`WallMotion::Rotation`]).
    #[inline]
    pub fn angle_at(&self, t: f64) -> f64 {
        match *self {
            WallMotion::Rotation {
                angular_velocity, ..
            } => angular_velocity * t,
            _ => 0.0,
        }
    }

    /// `p` rotated by `angle` about the axis of a [`WallMotion::Rotation`] (Rodrigues);
    /// `p` itself for the other motions.
    #[inline]
    pub fn rotate(&self, angle: f64, p: Vec3) -> Vec3 {
        match *self {
            WallMotion::Rotation {
                axis_point, axis, ..
            } => axis_point + rotate_about(axis, angle, p - axis_point),
            _ => p,
        }
    }

    /// Displacement from the reference position at time t, m, and velocity, m/s (zero for
    /// a rotation, whose displacement and velocity depend on the point: [`Self::rotate`],
    /// [`Self::angle_at`]).
    #[inline]
    pub fn offset_and_velocity(&self, t: f64) -> (Vec3, Vec3) {
        match *self {
            WallMotion::Fixed | WallMotion::Rotation { .. } => (Vec3::ZERO, Vec3::ZERO),
            WallMotion::ConstantVelocity { velocity } => (velocity * t, velocity),
            WallMotion::Harmonic {
                direction,
                amplitude,
                period,
                phase,
            } => {
                let w = 2.0 * std::f64::consts::PI / period;
                let (s, c) = (w * t + phase).sin_cos();
                (direction * (amplitude * s), direction * (amplitude * w * c))
            }
        }
    }

    /// Whether the wall moves at all.
    pub fn is_moving(&self) -> bool {
        match *self {
            WallMotion::Fixed => false,
            WallMotion::ConstantVelocity { velocity } => velocity != Vec3::ZERO,
            WallMotion::Harmonic { amplitude, .. } => amplitude > 0.0,
            WallMotion::Rotation {
                angular_velocity, ..
            } => angular_velocity != 0.0,
        }
    }

    /// Largest speed the wall reaches, m/s (for a rotation: |ω|, the speed per metre from
    /// the axis).
    pub fn max_speed(&self) -> f64 {
        match *self {
            WallMotion::Fixed => 0.0,
            WallMotion::Rotation {
                angular_velocity, ..
            } => angular_velocity.abs(),
            WallMotion::ConstantVelocity { velocity } => velocity.length(),
            WallMotion::Harmonic {
                amplitude, period, ..
            } => amplitude * 2.0 * std::f64::consts::PI / period,
        }
    }
}

/// `v` rotated by `angle` (rad) about the unit `axis` (Rodrigues' formula).
#[inline]
pub fn rotate_about(axis: Vec3, angle: f64, v: Vec3) -> Vec3 {
    let (s, c) = angle.sin_cos();
    v * c + axis.cross(v) * s + axis * (axis.dot(v) * (1.0 - c))
}

/// A rigid wall: shape, prescribed motion, surface velocity and material index.
#[derive(Debug, Clone)]
pub struct Wall {
    /// Geometry in the reference position (t = 0 for harmonic walls with φ = 0).
    pub shape: WallShape,
    /// Prescribed translation.
    pub motion: WallMotion,
    /// Velocity of the wall surface material along the wall while the geometry stays put, m/s
    /// (a conveyor belt). Only its component tangent to the contact is used.
    pub surface_velocity: Vec3,
    /// Index into the scene's material table.
    pub material: usize,
}

impl Wall {
    /// A fixed wall without surface velocity.
    pub fn fixed(shape: WallShape, material: usize) -> Self {
        Wall {
            shape,
            motion: WallMotion::Fixed,
            surface_velocity: Vec3::ZERO,
            material,
        }
    }

    /// Validate the surface velocity (finite), and refuse a rotating plane.
    pub fn validate(&self) -> Result<()> {
        check_vec("wall.surface_velocity", self.surface_velocity)?;
        if let WallMotion::ConstantVelocity { velocity } = self.motion {
            check_vec("wall.velocity", velocity)?;
        }
        if matches!(self.motion, WallMotion::Rotation { .. })
            && matches!(self.shape, WallShape::Plane { .. })
        {
            return Err(DemfemError::ShapeMismatch {
                field: "wall.motion".into(),
                detail: "a plane cannot rotate (it is infinite); use a polygon or a mesh".into(),
            });
        }
        Ok(())
    }

    /// Largest distance of the wall's geometry from the axis of a rotating wall, m (0 for
    /// the other motions): a rotation by Δθ moves no point of the wall further than this
    /// × |Δθ|.
    pub fn rotation_reach(&self) -> f64 {
        let WallMotion::Rotation {
            axis_point, axis, ..
        } = self.motion
        else {
            return 0.0;
        };
        let radius = |v: &Vec3| {
            let d = *v - axis_point;
            (d - axis * axis.dot(d)).length()
        };
        match &self.shape {
            WallShape::Plane { .. } => f64::INFINITY,
            WallShape::Polygon { vertices, .. } => vertices.iter().map(radius).fold(0.0, f64::max),
            WallShape::Mesh(m) => m.vertices().iter().map(radius).fold(0.0, f64::max),
            WallShape::Cuboid {
                center,
                half_extents,
                ..
            } => (0..8)
                .map(|k| {
                    let s = Vec3::new(
                        if k & 1 == 0 { -1.0 } else { 1.0 },
                        if k & 2 == 0 { -1.0 } else { 1.0 },
                        if k & 4 == 0 { -1.0 } else { 1.0 },
                    );
                    radius(&(*center + s * *half_extents))
                })
                .fold(0.0, f64::max),
        }
    }

    /// Closest point, outward unit normal (wall → p) and signed distance of `p` to the wall at
    /// displacement `offset`, m.
    #[inline(always)]
    pub fn closest_at(&self, p: Vec3, offset: Vec3) -> Option<(Vec3, Vec3, f64)> {
        self.shape
            .closest(p - offset)
            .map(|(q, n, d)| (q + offset, n, d))
    }

    /// Surface velocity at a contact with `triangle` (of a mesh wall whose triangles carry
    /// their own, [`MeshWall::triangle_velocity`]; else the wall's), m/s.
    #[inline(always)]
    pub fn surface_velocity_at(&self, triangle: u32) -> Vec3 {
        match &self.shape {
            WallShape::Mesh(m) => m
                .triangle_velocity(triangle)
                .unwrap_or(self.surface_velocity),
            _ => self.surface_velocity,
        }
    }

    /// The triangle mesh of a [`WallShape::Mesh`] wall.
    #[inline(always)]
    pub fn mesh(&self) -> Option<&MeshWall> {
        match &self.shape {
            WallShape::Mesh(m) => Some(m),
            _ => None,
        }
    }

    /// What a contact slot of this wall sees of a sphere of radius `r` at `p`, the wall at
    /// displacement `offset`: closest point, unit normal (wall → p) and distance, or `None`
    /// out of contact. `triangle` is the slot's triangle on a mesh wall (ignored otherwise,
    /// where the whole wall is one slot). For the initial-overlap check and the records.
    pub fn slot_closest_at(
        &self,
        triangle: u32,
        p: Vec3,
        offset: Vec3,
        r: f64,
    ) -> Option<(Vec3, Vec3, f64)> {
        match &self.shape {
            WallShape::Mesh(m) => m
                .contact(triangle, p - offset, r)
                .map(|(q, n, d)| (q + offset, n, d)),
            _ => self.closest_at(p, offset),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d_f64::shape::Triangle;

    #[test]
    fn polygon_closest_point_matches_parry_triangle() {
        let a = Vec3::new(0.0, 0.0, 0.0);
        let b = Vec3::new(1.0, 0.2, 0.1);
        let c = Vec3::new(0.3, 1.0, -0.2);
        let poly = WallShape::polygon(vec![a, b, c]).unwrap();
        let tri = Triangle::new(a, b, c);
        let mut s = 12345u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) * 3.0 - 1.0
        };
        for _ in 0..2000 {
            let p = Vec3::new(rnd(), rnd(), rnd());
            let (q, _, d) = poly.closest(p).unwrap();
            let proj = tri.project_local_point(p, true);
            assert!(
                (q - proj.point).length() < 1e-12,
                "{p:?}: {q:?} vs {:?}",
                proj.point
            );
            assert!((d - (p - proj.point).length()).abs() < 1e-12);
        }
    }

    #[test]
    fn non_convex_polygon_is_refused() {
        let v = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(1.0, 0.3, 0.0),
            Vec3::new(2.0, 2.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        assert!(WallShape::polygon(v).is_err());
    }

    #[test]
    fn cuboid_edge_and_inside() {
        let c = WallShape::cuboid(Vec3::ZERO, Vec3::new(1.0, 1.0, 1.0)).unwrap();
        // beyond an edge: closest point on the edge, normal along the diagonal
        let (q, n, d) = c.closest(Vec3::new(2.0, 2.0, 0.5)).unwrap();
        assert!((q - Vec3::new(1.0, 1.0, 0.5)).length() < 1e-14);
        assert!((n - Vec3::new(1.0, 1.0, 0.0) / 2f64.sqrt()).length() < 1e-14);
        assert!((d - 2f64.sqrt()).abs() < 1e-14);
        // inside: pushed out through the nearest face, negative distance
        let (q, n, d) = c.closest(Vec3::new(0.9, 0.0, 0.0)).unwrap();
        assert!((q - Vec3::new(1.0, 0.0, 0.0)).length() < 1e-14);
        assert!((n - Vec3::X).length() < 1e-14);
        assert!((d + 0.1).abs() < 1e-14);
    }
}
