//! A cartridge as a body of revolution made of a few coaxial pieces, with analytic contact
//! tests: the fast exact full shape.
//!
//! The outer glass surface of `demfem.cartridge.Cartridge` (its `stations()`, outer radius
//! linear between stations) is cut at every station into *frustums* (truncated cones about
//! the axis: the body cylinder, the shoulder cone, the neck cylinder, the flange chamfer and
//! the flange), the *edge circles* where the profile bends (the open bottom rim, the
//! body–shoulder edge, the flange edges) and the flat *faces* (the bottom and top caps, and
//! any flat step between two stations at one height). The bore is not modelled — only the
//! outer surface can touch anything, and the caps are solid discs as in the parry shape of
//! [`super::shape::ExactShape`], so both describe the same solid except for the cones, which
//! parry approximates by 32-gon hulls.
//!
//! Body frame: origin at the centre of mass, axis along body z (bottom at the lowest z). All
//! lengths in metres.
//!
//! Submodules: [`features`] finds the closest features of two pieces exactly (Lin–Canny
//! style: every pair of features whose closest points satisfy the normal-cone conditions),
//! [`contacts`] turns them into the contact points of the force law (bodies, planes, polygon
//! walls, beads), [`wall_edges`] handles the edges and corners of polygon walls and
//! [`mesh_walls`] the triangles, edges and corners of mesh walls.

pub mod contacts;
pub mod features;
pub mod mesh_walls;
pub mod wall_edges;

use nalgebra::Vector3;

use super::shape::{BoundingCapsule, RevolutionProfile};
use crate::error::{DemfemError, Result};

/// A frustum (truncated cone about the body axis) between two stations of positive height.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frustum {
    /// Lower and upper height along the axis (body frame), m.
    pub z: [f64; 2],
    /// Outer radius at the lower and upper height, m.
    pub r: [f64; 2],
    /// dr/dz of the side.
    pub slope: f64,
    /// 1/√(1 + slope²): the cosine of the half-angle of the cone.
    pub cos: f64,
    /// Mean radius of the side, m (the Hertz radius of the parry shape's piece; this shape
    /// uses the local radius, [`Frustum::radius_at`]).
    pub contact_radius: f64,
    /// Largest radius, m (the bounding capsule of the piece).
    pub reach: f64,
    /// Edge circles at the lower and upper end (indices into [`RevolutionShape::circles`]).
    pub circles: [usize; 2],
    /// Exterior faces at the lower and upper end (indices into [`RevolutionShape::faces`]).
    pub faces: [Option<usize>; 2],
}

impl Frustum {
    /// Outer radius at height `z` (body frame, extrapolated linearly), m.
    #[inline]
    pub fn radius_at(&self, z: f64) -> f64 {
        self.r[0] + self.slope * (z - self.z[0])
    }

    /// True when the side is a cylinder (constant radius).
    #[inline]
    pub fn is_cylinder(&self) -> bool {
        self.slope == 0.0
    }

    /// Axial length, m.
    #[inline]
    pub fn length(&self) -> f64 {
        self.z[1] - self.z[0]
    }
}

/// A circle of the profile: a station (z, r). Where the profile bends outwards (a convex
/// edge: the open bottom rim, the body–shoulder edge, the flange edges) it is a contact
/// feature with its normal cone; a concave crease (shoulder–neck, neck–flange) is not.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeCircle {
    /// Height along the axis (body frame), m.
    pub z: f64,
    /// Radius, m.
    pub r: f64,
    /// True for a convex edge (a contact feature).
    pub convex: bool,
    /// Normal cone of the edge in the meridian plane: the outward normal (n_z, n_ρ) of any
    /// touching partner has the angle φ = atan2(n_ρ, n_z) in `[cone[0], cone[1]]`, rad
    /// (0: along +z, π/2: radial, π: along −z).
    pub cone: [f64; 2],
}

impl EdgeCircle {
    /// Whether the meridian direction (n_z, n_ρ) lies in the normal cone, with a tolerance
    /// of `tolerance` rad.
    #[inline]
    pub fn cone_holds(&self, n_z: f64, n_rho: f64, tolerance: f64) -> bool {
        let phi = n_rho.atan2(n_z);
        phi >= self.cone[0] - tolerance && phi <= self.cone[1] + tolerance
    }

    /// The meridian direction halfway through the normal cone, (n_z, n_ρ).
    #[inline]
    pub fn cone_middle(&self) -> (f64, f64) {
        let phi = 0.5 * (self.cone[0] + self.cone[1]);
        (phi.cos(), phi.sin())
    }
}

/// A flat face perpendicular to the axis: the bottom or top cap (a disc), or a flat step
/// between two stations at one height (an annulus).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlatFace {
    /// Height along the axis (body frame), m.
    pub z: f64,
    /// Inner and outer radius of the annulus, m (inner 0 for a cap).
    pub r: [f64; 2],
    /// +1 when the face looks along +z (outward normal +z), −1 along −z.
    pub facing: f64,
    /// The edge circle at its outer radius.
    pub outer_circle: usize,
    /// Hertz contact radius of the face, m: its outer radius (that of the edge around it,
    /// so that a contact sliding from the face over the edge keeps its stiffness).
    pub contact_radius: f64,
}

/// The fast exact cartridge: frustums, edge circles and flat faces in the body frame.
#[derive(Debug, Clone, PartialEq)]
pub struct RevolutionShape {
    /// The pieces, bottom to top.
    pub frustums: Vec<Frustum>,
    /// Every station as a circle, bottom to top.
    pub circles: Vec<EdgeCircle>,
    /// The flat faces.
    pub faces: Vec<FlatFace>,
    /// The outer profile in the meridian half-plane, (z, ρ) points from (z_bottom, 0) up
    /// the outside to (z_top, 0): the polyline that bounds the solid, m.
    pub outline: Vec<(f64, f64)>,
    /// Radius of the bounding sphere about the origin, m.
    pub bounding_radius: f64,
    /// Capsule along body z containing the shape.
    pub bounding_capsule: BoundingCapsule,
    /// Points on the outer surface (16 on every station circle), body frame, m: used to bound
    /// the effective mass of a contact for the time step (as the parry shape).
    pub rim_points: Vec<Vector3<f64>>,
    /// Smallest Hertz contact radius of any feature, m.
    pub min_contact_radius: f64,
}

/// Angle of the outward meridian normal of a side of slope `slope` (φ = atan2(n_ρ, n_z)).
fn side_angle(slope: f64) -> f64 {
    1.0_f64.atan2(-slope)
}

/// Most stations of a profile (feature keys of the friction history hold 8 bits).
pub const MAX_STATIONS: usize = 200;

/// Turning angles below this (rad) count as no edge (two sides in line).
const EDGE_ANGLE_TOLERANCE: f64 = 1e-9;

impl RevolutionShape {
    /// Build from a validated profile; `center_of_mass_z` (m, in the stations' frame)
    /// becomes the origin. Errors name the field: stations must give at least one piece of
    /// positive height, outer radii must be > 0.
    pub fn from_profile(profile: &RevolutionProfile, center_of_mass_z: f64) -> Result<Self> {
        if !center_of_mass_z.is_finite() {
            return Err(DemfemError::invalid(
                "center_of_mass_z",
                center_of_mass_z,
                "finite",
            ));
        }
        // stations, shifted, without repeats
        let mut stations: Vec<(f64, f64)> = Vec::new();
        for (&z, &r) in profile.z().iter().zip(profile.r_out()) {
            if !(r > 0.0 && r.is_finite()) {
                return Err(DemfemError::invalid("r_out", r, "finite and > 0"));
            }
            let zz = z - center_of_mass_z;
            if stations.last() != Some(&(zz, r)) {
                stations.push((zz, r));
            }
        }
        if stations.len() > MAX_STATIONS {
            return Err(DemfemError::ShapeMismatch {
                field: "stations".into(),
                detail: format!("at most {MAX_STATIONS} stations, got {}", stations.len()),
            });
        }
        if stations.len() < 2 || stations[stations.len() - 1].0 <= stations[0].0 {
            return Err(DemfemError::ShapeMismatch {
                field: "stations".into(),
                detail: "a body of revolution needs stations spanning a positive height".into(),
            });
        }
        let n = stations.len();
        // elements between stations: a side (positive height) or a flat step
        #[derive(Clone, Copy)]
        enum Element {
            Side(usize),
            Face(usize),
        }
        let mut frustums = Vec::new();
        let mut faces = Vec::new();
        let mut between = Vec::with_capacity(n + 1);
        // the bottom cap
        faces.push(FlatFace {
            z: stations[0].0,
            r: [0.0, stations[0].1],
            facing: -1.0,
            outer_circle: 0,
            contact_radius: 0.0,
        });
        between.push(Element::Face(0));
        for k in 0..n - 1 {
            let ((za, ra), (zb, rb)) = (stations[k], stations[k + 1]);
            if zb > za {
                let slope = (rb - ra) / (zb - za);
                frustums.push(Frustum {
                    z: [za, zb],
                    r: [ra, rb],
                    slope,
                    cos: 1.0 / (1.0 + slope * slope).sqrt(),
                    contact_radius: 0.5 * (ra + rb),
                    reach: ra.max(rb),
                    circles: [k, k + 1],
                    faces: [None, None],
                });
                between.push(Element::Side(frustums.len() - 1));
            } else {
                let facing = if rb < ra { 1.0 } else { -1.0 };
                faces.push(FlatFace {
                    z: za,
                    r: [ra.min(rb), ra.max(rb)],
                    facing,
                    outer_circle: if ra > rb { k } else { k + 1 },
                    contact_radius: 0.0,
                });
                between.push(Element::Face(faces.len() - 1));
            }
        }
        faces.push(FlatFace {
            z: stations[n - 1].0,
            r: [0.0, stations[n - 1].1],
            facing: 1.0,
            outer_circle: n - 1,
            contact_radius: 0.0,
        });
        between.push(Element::Face(faces.len() - 1));
        // faces attached to the pieces next to them; each face's contact radius is its outer
        // radius
        for (k, e) in between.iter().enumerate() {
            let Element::Face(f) = *e else { continue };
            let neighbours = [
                k.checked_sub(1).map(|j| between[j]),
                between.get(k + 1).copied(),
            ];
            for (side, nb) in neighbours.into_iter().enumerate() {
                if let Some(Element::Side(i)) = nb {
                    // the face is above piece i (side 0) or below it (side 1)
                    frustums[i].faces[1 - side] = Some(f);
                }
            }
            faces[f].contact_radius = faces[f].r[1];
        }
        let angle = |e: Element| match e {
            Element::Side(i) => side_angle(frustums[i].slope),
            Element::Face(f) => {
                if faces[f].facing > 0.0 {
                    0.0
                } else {
                    std::f64::consts::PI
                }
            }
        };
        let mut circles = Vec::with_capacity(n);
        for (k, &(z, r)) in stations.iter().enumerate() {
            let (below, above) = (angle(between[k]), angle(between[k + 1]));
            circles.push(EdgeCircle {
                z,
                r,
                convex: above < below - EDGE_ANGLE_TOLERANCE,
                cone: [above, below],
            });
        }
        let mut outline = vec![(stations[0].0, 0.0)];
        outline.extend(stations.iter().copied());
        outline.push((stations[n - 1].0, 0.0));
        let mut bounding_radius: f64 = 0.0;
        let mut rim_points = Vec::with_capacity(16 * n);
        for &(z, r) in &stations {
            bounding_radius = bounding_radius.max(z.hypot(r));
            for j in 0..16 {
                let t = 2.0 * std::f64::consts::PI * j as f64 / 16.0;
                rim_points.push(Vector3::new(r * t.cos(), r * t.sin(), z));
            }
        }
        let min_contact_radius = stations.iter().map(|s| s.1).fold(f64::INFINITY, f64::min);
        let bounding_capsule = BoundingCapsule {
            z_min: stations[0].0,
            z_max: stations[n - 1].0,
            radius: stations.iter().map(|s| s.1).fold(0.0, f64::max),
        };
        Ok(Self {
            frustums,
            circles,
            faces,
            outline,
            bounding_radius,
            bounding_capsule,
            rim_points,
            min_contact_radius,
        })
    }

    /// Signed distance of the point (z, ρ) of the meridian half-plane (body frame) from the
    /// solid (negative inside), the closest point of the outline (z, ρ), its outward unit
    /// normal (n_z, n_ρ) and the Hertz contact radius there, m (the local radius r(z) on a
    /// side or an edge, the outer radius on a face: continuous over the surface).
    pub fn meridian_distance(&self, z: f64, rho: f64) -> (f64, (f64, f64), (f64, f64), f64) {
        // (squared distance, closest point, outward normal of the segment, segment)
        let mut best = (f64::INFINITY, (0.0, 0.0), (1.0, 0.0), 0);
        for k in 0..self.outline.len() - 1 {
            let (a, b) = (self.outline[k], self.outline[k + 1]);
            let (ez, er) = (b.0 - a.0, b.1 - a.1);
            let len2 = ez * ez + er * er;
            if len2 <= 0.0 {
                continue;
            }
            let t = (((z - a.0) * ez + (rho - a.1) * er) / len2).clamp(0.0, 1.0);
            let q = (a.0 + t * ez, a.1 + t * er);
            let (dz, dr) = (z - q.0, rho - q.1);
            let d2 = dz * dz + dr * dr;
            if d2 < best.0 {
                // outward normal of the segment: the outline runs clockwise in (z, ρ)
                // seen with ρ up, so the outside is to the left of its direction
                let len = len2.sqrt();
                best = (d2, q, (-er / len, ez / len), k);
            }
        }
        let (d2, q, side_normal, k) = best;
        let distance = d2.sqrt();
        let inside = self.contains(z, rho);
        let normal = if distance > 1e-300 {
            let (dz, dr) = ((z - q.0) / distance, (rho - q.1) / distance);
            if inside {
                (-dz, -dr)
            } else {
                (dz, dr)
            }
        } else {
            side_normal
        };
        // the Hertz radius: the local radius on a side or edge, the outer radius on a face
        let (a, b) = (self.outline[k], self.outline[k + 1]);
        let radius = if a.0 == b.0 { a.1.max(b.1) } else { q.1 };
        (if inside { -distance } else { distance }, q, normal, radius)
    }

    /// Whether the point (z, ρ) of the meridian half-plane lies inside the solid.
    pub fn contains(&self, z: f64, rho: f64) -> bool {
        self.frustums
            .iter()
            .any(|f| z >= f.z[0] && z <= f.z[1] && rho <= f.radius_at(z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn default_shape() -> RevolutionShape {
        let p = RevolutionProfile::default_cartridge();
        RevolutionShape::from_profile(&p, 0.0).unwrap()
    }

    #[test]
    fn default_cartridge_has_five_pieces_and_four_edges() {
        let s = default_shape();
        assert_eq!(s.frustums.len(), 5);
        assert_eq!(s.faces.len(), 2);
        let convex: Vec<bool> = s.circles.iter().map(|c| c.convex).collect();
        // rim, body–shoulder, shoulder–neck (crease), neck–chamfer (crease), chamfer–flange, top
        assert_eq!(convex, vec![true, true, false, false, true, true]);
        assert_eq!(s.min_contact_radius, 3.0e-3);
    }

    #[test]
    fn meridian_distance_inside_outside_and_at_the_rim() {
        let s = default_shape();
        let (d, _, n, _) = s.meridian_distance(0.02, 6.8e-3);
        assert!((d - 1.0e-3).abs() < 1e-15 && n == (0.0, 1.0));
        let (d, _, n, _) = s.meridian_distance(0.02, 5.3e-3);
        assert!((d + 0.5e-3).abs() < 1e-15 && n == (0.0, 1.0), "{d} {n:?}");
        let (d, q, _, r) = s.meridian_distance(-1e-3, 6.8e-3);
        assert!((d - 2f64.sqrt() * 1e-3).abs() < 1e-15 && q == (0.0, 5.8e-3) && r == 5.8e-3);
        // on the shoulder the radius is the local one
        let (_, q, _, r) = s.meridian_distance(0.0565, 5e-3);
        assert!(r == q.1 && r > 3e-3 && r < 5.8e-3);
        let (d, _, n, _) = s.meridian_distance(-1e-3, 1e-3);
        assert!((d - 1e-3).abs() < 1e-15 && n == (-1.0, 0.0));
    }

    #[test]
    fn flat_steps_are_faces() {
        let p = RevolutionProfile::new(
            vec![0.0, 0.01, 0.01, 0.02],
            vec![0.001; 4],
            vec![0.005, 0.005, 0.003, 0.003],
        )
        .unwrap();
        let s = RevolutionShape::from_profile(&p, 0.0).unwrap();
        assert_eq!(s.frustums.len(), 2);
        assert_eq!(s.faces.len(), 3);
        assert_eq!(s.faces[1].facing, 1.0);
        assert_eq!(s.faces[1].r, [0.003, 0.005]);
        assert_eq!(s.frustums[0].faces, [Some(0), Some(1)]);
        assert_eq!(s.frustums[1].faces, [Some(1), Some(2)]);
        assert!(s.circles[1].convex && !s.circles[2].convex);
    }
}
