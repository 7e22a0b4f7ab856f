//! Shapes of a rigid cartridge: the body of revolution it is derived from, a clump of beads,
//! an exact shape made of parry3d-f64 convex pieces, and the fast exact body of revolution
//! of [`super::revolution`].
//!
//! Every shape lives in the body frame: origin at the centre of mass, principal axes along
//! the frame axes, the cartridge axis along body z. The geometry itself comes from one place,
//! `demfem.cartridge.Cartridge` in Python (`stations()` and `bead_clump()`); here it arrives
//! as plain arrays in metres.

use nalgebra::{Matrix3, SymmetricEigen, UnitQuaternion, Vector3};
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::shape::{Compound, ConvexPolyhedron, Cylinder, SharedShape};

use super::revolution::RevolutionShape;
use crate::error::{check_non_negative, check_positive, DemfemError, Result};

/// Mass (kg), centre of mass (m) and principal inertia (kg·m²) of a body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    /// Mass, kg.
    pub mass: f64,
    /// Centre of mass in the input frame, m.
    pub center_of_mass: Vector3<f64>,
    /// Principal moments of inertia about the centre of mass, kg·m², in the order of the
    /// body-frame axes (x, y, z).
    pub principal_inertia: Vector3<f64>,
}

/// A glass body of revolution about z: at height z the glass is the annulus
/// r_in(z) ≤ r ≤ r_out(z), both radii linear between stations (as `Cartridge.stations()`).
#[derive(Debug, Clone, PartialEq)]
pub struct RevolutionProfile {
    z: Vec<f64>,
    r_in: Vec<f64>,
    r_out: Vec<f64>,
}

// 3-point Gauss–Legendre on [0, 1], exact to degree 5: the integrands below have degree ≤ 4.
const GAUSS_X: [f64; 3] = [0.112_701_665_379_258_3, 0.5, 0.887_298_334_620_741_7];
const GAUSS_W: [f64; 3] = [5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0];

impl RevolutionProfile {
    /// Validate stations: equal lengths ≥ 2, z non-decreasing from its first value,
    /// 0 ≤ r_in < r_out, all in metres.
    pub fn new(z: Vec<f64>, r_in: Vec<f64>, r_out: Vec<f64>) -> Result<Self> {
        if z.len() < 2 || r_in.len() != z.len() || r_out.len() != z.len() {
            return Err(DemfemError::ShapeMismatch {
                field: "stations".into(),
                detail: format!(
                    "z, r_in, r_out need equal lengths >= 2, got {}, {}, {}",
                    z.len(),
                    r_in.len(),
                    r_out.len()
                ),
            });
        }
        for k in 0..z.len() {
            if !z[k].is_finite() || (k > 0 && z[k] < z[k - 1]) {
                return Err(DemfemError::invalid("z", z[k], "finite and non-decreasing"));
            }
            check_non_negative("r_in", r_in[k])?;
            check_positive("r_out", r_out[k])?;
            if r_in[k] >= r_out[k] {
                return Err(DemfemError::invalid(
                    "r_in",
                    r_in[k],
                    &format!("< r_out = {}", r_out[k]),
                ));
            }
        }
        if z[z.len() - 1] <= z[0] {
            return Err(DemfemError::invalid(
                "z",
                z[z.len() - 1],
                "above the first station",
            ));
        }
        Ok(Self { z, r_in, r_out })
    }

    /// The default 3 mL cartridge of `demfem.cartridge.Cartridge()` (stations in m).
    pub fn default_cartridge() -> Self {
        Self {
            z: vec![0.0, 54.5e-3, 58.5e-3, 61.0e-3, 61.3e-3, 64.0e-3],
            r_in: vec![4.7e-3, 4.7e-3, 1.9e-3, 1.9e-3, 1.9e-3, 1.9e-3],
            r_out: vec![5.8e-3, 5.8e-3, 3.0e-3, 3.0e-3, 3.65e-3, 3.65e-3],
        }
    }

    /// Station heights, m.
    pub fn z(&self) -> &[f64] {
        &self.z
    }

    /// Outer radii at the stations, m.
    pub fn r_out(&self) -> &[f64] {
        &self.r_out
    }

    /// Inner radii at the stations, m.
    pub fn r_in(&self) -> &[f64] {
        &self.r_in
    }

    /// Exact mass properties of the glass for density `density` (kg/m³): centre of mass on
    /// the axis (in the stations' frame), transverse inertia I_x = I_y and axial I_z.
    pub fn mass_properties(&self, density: f64) -> Result<MassProperties> {
        check_positive("density", density)?;
        let pi = std::f64::consts::PI;
        let (mut vol, mut vz, mut vz2, mut q4) = (0.0, 0.0, 0.0, 0.0);
        for k in 0..self.z.len() - 1 {
            let (za, zb) = (self.z[k], self.z[k + 1]);
            let h = zb - za;
            if h <= 0.0 {
                continue;
            }
            for (x, w) in GAUSS_X.iter().zip(GAUSS_W) {
                let zq = za + h * x;
                let ri = self.r_in[k] + (self.r_in[k + 1] - self.r_in[k]) * x;
                let ro = self.r_out[k] + (self.r_out[k + 1] - self.r_out[k]) * x;
                let area = pi * (ro * ro - ri * ri);
                vol += w * h * area;
                vz += w * h * area * zq;
                vz2 += w * h * area * zq * zq;
                q4 += w * h * (ro.powi(4) - ri.powi(4));
            }
        }
        let mass = density * vol;
        let zc = vz / vol;
        let axial = density * 0.5 * pi * q4;
        // thin disc about a diameter: π/4 (ro⁴ − ri⁴) per unit length, plus the parallel axis
        let transverse = density * (0.25 * pi * q4 + vz2) - mass * zc * zc;
        Ok(MassProperties {
            mass,
            center_of_mass: Vector3::new(0.0, 0.0, zc),
            principal_inertia: Vector3::new(transverse, transverse, axial),
        })
    }
}

/// A rigid clump of beads in its body frame (origin at the beads' centre of mass, principal
/// axes along x, y, z).
#[derive(Debug, Clone, PartialEq)]
pub struct BeadClump {
    /// Bead centres in the body frame, m.
    pub centers: Vec<Vector3<f64>>,
    /// Bead radii, m.
    pub radii: Vec<f64>,
    /// Largest |centre| + radius over the beads, m: the bounding sphere about the origin.
    pub bounding_radius: f64,
    /// Largest bead radius, m.
    pub max_bead_radius: f64,
    /// Smallest bead radius, m.
    pub min_bead_radius: f64,
    /// Lower corner of the body-frame box around all beads, m.
    pub aabb_min: Vector3<f64>,
    /// Upper corner of the body-frame box around all beads, m.
    pub aabb_max: Vector3<f64>,
    /// Rotation from the body (principal) frame to the frame the beads were given in.
    pub principal_frame: UnitQuaternion<f64>,
    /// Capsule along body z containing every bead.
    pub bounding_capsule: BoundingCapsule,
    /// Groups of nearby beads (≤ [`BEADS_PER_CHUNK`]) with bounding spheres, so a pair
    /// test transforms only the beads of groups that can reach the other body.
    pub chunks: Vec<BeadChunk>,
    /// Bead indices, grouped: chunk k owns `chunk_members[chunks[k].members.clone()]`.
    pub chunk_members: Vec<u32>,
}

/// Most beads in one [`BeadChunk`].
pub const BEADS_PER_CHUNK: usize = 16;

/// A group of nearby beads of a clump and the sphere around them (body frame).
#[derive(Debug, Clone, PartialEq)]
pub struct BeadChunk {
    /// Centre of the bounding sphere, m.
    pub center: Vector3<f64>,
    /// Radius of the bounding sphere (bead radii included), m.
    pub radius: f64,
    /// Range of this chunk's entries in `BeadClump::chunk_members`.
    pub members: std::ops::Range<usize>,
}

/// Split `members` at the median of the longest axis of their centres until each group has
/// at most [`BEADS_PER_CHUNK`] beads (a k-d tree's leaves).
fn split_into_chunks(
    centers: &[Vector3<f64>],
    radii: &[f64],
    members: &mut [u32],
    offset: usize,
    chunks: &mut Vec<BeadChunk>,
) {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for &m in members.iter() {
        lo = lo.inf(&centers[m as usize]);
        hi = hi.sup(&centers[m as usize]);
    }
    if members.len() <= BEADS_PER_CHUNK {
        let center = 0.5 * (lo + hi);
        let radius = members
            .iter()
            .map(|&m| (centers[m as usize] - center).norm() + radii[m as usize])
            .fold(0.0, f64::max);
        chunks.push(BeadChunk {
            center,
            radius,
            members: offset..offset + members.len(),
        });
        return;
    }
    let axis = (hi - lo).imax();
    let half = members.len() / 2;
    members.select_nth_unstable_by(half, |&a, &b| {
        centers[a as usize][axis].total_cmp(&centers[b as usize][axis])
    });
    let (left, right) = members.split_at_mut(half);
    split_into_chunks(centers, radii, left, offset, chunks);
    split_into_chunks(centers, radii, right, offset + half, chunks);
}

impl BeadClump {
    /// Build a clump from bead centres (m, any frame), radii (m) and masses (kg). Each bead
    /// counts as a solid sphere of its own mass; the clump is moved to its centre of mass and
    /// turned into its principal frame (kept as is when already principal, as for a ring
    /// clump along z). Returns the clump and its mass properties (centre of mass in the input
    /// frame).
    pub fn from_beads(
        centers: &[Vector3<f64>],
        radii: &[f64],
        masses: &[f64],
    ) -> Result<(Self, MassProperties)> {
        if centers.is_empty() || radii.len() != centers.len() || masses.len() != centers.len() {
            return Err(DemfemError::ShapeMismatch {
                field: "beads".into(),
                detail: format!(
                    "centers, radii, masses need equal non-zero lengths, got {}, {}, {}",
                    centers.len(),
                    radii.len(),
                    masses.len()
                ),
            });
        }
        let mut mass = 0.0;
        let mut first_moment = Vector3::zeros();
        for ((c, &r), &m) in centers.iter().zip(radii).zip(masses) {
            check_positive("bead radius", r)?;
            check_positive("bead mass", m)?;
            if !c.iter().all(|v| v.is_finite()) {
                return Err(DemfemError::ShapeMismatch {
                    field: "centers".into(),
                    detail: "bead centres must be finite".into(),
                });
            }
            mass += m;
            first_moment += c * m;
        }
        let com = first_moment / mass;
        let mut inertia = Matrix3::zeros();
        for ((c, &r), &m) in centers.iter().zip(radii).zip(masses) {
            let d = c - com;
            inertia += (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * m;
            inertia += Matrix3::identity() * (0.4 * m * r * r);
        }
        let diag = inertia.diagonal();
        let off = inertia[(0, 1)]
            .abs()
            .max(inertia[(0, 2)].abs())
            .max(inertia[(1, 2)].abs());
        let (principal_inertia, principal_frame) = if off <= 1e-9 * diag.max() {
            (diag, UnitQuaternion::identity())
        } else {
            let eig = SymmetricEigen::new(inertia);
            let mut axes = eig.eigenvectors;
            if axes.determinant() < 0.0 {
                axes.column_mut(2).neg_mut();
            }
            let rot = nalgebra::Rotation3::from_matrix_unchecked(axes);
            (eig.eigenvalues, UnitQuaternion::from_rotation_matrix(&rot))
        };
        let body_centers: Vec<Vector3<f64>> = centers
            .iter()
            .map(|c| principal_frame.inverse_transform_vector(&(c - com)))
            .collect();
        let clump = Self::from_body_frame(body_centers, radii.to_vec(), principal_frame);
        Ok((
            clump,
            MassProperties {
                mass,
                center_of_mass: com,
                principal_inertia,
            },
        ))
    }

    fn from_body_frame(
        centers: Vec<Vector3<f64>>,
        radii: Vec<f64>,
        principal_frame: UnitQuaternion<f64>,
    ) -> Self {
        let mut bounding_radius: f64 = 0.0;
        let mut aabb_min = Vector3::repeat(f64::INFINITY);
        let mut aabb_max = Vector3::repeat(f64::NEG_INFINITY);
        for (c, &r) in centers.iter().zip(&radii) {
            bounding_radius = bounding_radius.max(c.norm() + r);
            aabb_min = aabb_min.inf(&c.add_scalar(-r));
            aabb_max = aabb_max.sup(&c.add_scalar(r));
        }
        let max_bead_radius = radii.iter().cloned().fold(0.0, f64::max);
        let min_bead_radius = radii.iter().cloned().fold(f64::INFINITY, f64::min);
        // every bead centre lies within its radial distance of the axis segment at its own z
        let mut capsule = BoundingCapsule {
            z_min: f64::INFINITY,
            z_max: f64::NEG_INFINITY,
            radius: 0.0,
        };
        for (c, &r) in centers.iter().zip(&radii) {
            capsule.z_min = capsule.z_min.min(c.z);
            capsule.z_max = capsule.z_max.max(c.z);
            capsule.radius = capsule.radius.max(c.x.hypot(c.y) + r);
        }
        let mut chunk_members: Vec<u32> = (0..centers.len() as u32).collect();
        let mut chunks = Vec::new();
        split_into_chunks(&centers, &radii, &mut chunk_members, 0, &mut chunks);
        Self {
            centers,
            radii,
            bounding_radius,
            max_bead_radius,
            min_bead_radius,
            aabb_min,
            aabb_max,
            principal_frame,
            bounding_capsule: capsule,
            chunks,
            chunk_members,
        }
    }

    /// Number of beads.
    pub fn len(&self) -> usize {
        self.radii.len()
    }

    /// True for a clump without beads (never built by [`BeadClump::from_beads`]).
    pub fn is_empty(&self) -> bool {
        self.radii.is_empty()
    }
}

/// A body of revolution as a parry3d-f64 compound of convex pieces, in the body frame
/// (origin at the centre of mass, axis z).
///
/// One piece per segment between stations of the outer profile: a parry `Cylinder` where the
/// outer radius is constant (parry's cylinder axis is local y, so each one is turned by +90°
/// about x to put it along body z), and the convex hull of two 32-gons (vertices on the true
/// circles) where the radius changes (shoulder, flange chamfer). The bore is not modelled:
/// only the outer surface can touch anything. Each piece has a contact radius for Hertz: its
/// mean outer radius — the curvature of the side, which is where cartridges touch each other
/// and the walls; rim and cap contacts use the same radius (a choice, stated here: the true
/// rim is much sharper and would be softer).
#[derive(Clone)]
pub struct ExactShape {
    /// The parry compound, body frame.
    pub compound: Compound,
    /// Hertz contact radius per piece (index = parry sub-shape id), m.
    pub piece_contact_radius: Vec<f64>,
    /// Radius of the bounding sphere about the origin, m.
    pub bounding_radius: f64,
    /// Points on the outer surface (rims of every station), body frame, m: used to bound the
    /// effective mass of a contact for the time step.
    pub rim_points: Vec<Vector3<f64>>,
    /// Capsule along body z containing the shape.
    pub bounding_capsule: BoundingCapsule,
}

impl std::fmt::Debug for ExactShape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ExactShape")
            .field("pieces", &self.piece_contact_radius.len())
            .field("piece_contact_radius", &self.piece_contact_radius)
            .field("bounding_radius", &self.bounding_radius)
            .finish()
    }
}

/// Vertices per circle of the convex hulls that stand for cones.
const HULL_SEGMENTS: usize = 32;

impl ExactShape {
    /// Build from a profile; `center_of_mass_z` (m, in the stations' frame) becomes the origin.
    pub fn from_profile(profile: &RevolutionProfile, center_of_mass_z: f64) -> Result<Self> {
        if !center_of_mass_z.is_finite() {
            return Err(DemfemError::invalid(
                "center_of_mass_z",
                center_of_mass_z,
                "finite",
            ));
        }
        let y_to_z = Rotation::from_rotation_x(std::f64::consts::FRAC_PI_2);
        let mut pieces: Vec<(Pose, SharedShape)> = Vec::new();
        let mut piece_contact_radius = Vec::new();
        let mut bounding_radius: f64 = 0.0;
        let mut rim_points = Vec::new();
        let (z, r) = (profile.z(), profile.r_out());
        for k in 0..z.len() {
            let zk = z[k] - center_of_mass_z;
            bounding_radius = bounding_radius.max((zk * zk + r[k] * r[k]).sqrt());
            for j in 0..16 {
                let t = 2.0 * std::f64::consts::PI * j as f64 / 16.0;
                rim_points.push(Vector3::new(r[k] * t.cos(), r[k] * t.sin(), zk));
            }
        }
        for k in 0..z.len() - 1 {
            let (za, zb) = (z[k] - center_of_mass_z, z[k + 1] - center_of_mass_z);
            let (ra, rb) = (r[k], r[k + 1]);
            if zb - za <= 0.0 {
                continue; // a flat step: the larger neighbour's cap covers it
            }
            if ra == rb {
                let pose = Pose::from_parts(Vector::new(0.0, 0.0, 0.5 * (za + zb)), y_to_z);
                pieces.push((pose, SharedShape::new(Cylinder::new(0.5 * (zb - za), ra))));
            } else {
                let mut points = Vec::with_capacity(2 * HULL_SEGMENTS);
                for (zz, rr) in [(za, ra), (zb, rb)] {
                    for j in 0..HULL_SEGMENTS {
                        let t = 2.0 * std::f64::consts::PI * j as f64 / HULL_SEGMENTS as f64;
                        points.push(Vector::new(rr * t.cos(), rr * t.sin(), zz));
                    }
                }
                let hull = ConvexPolyhedron::from_convex_hull(&points).ok_or_else(|| {
                    DemfemError::Numerical(format!("convex hull of segment {k} failed"))
                })?;
                pieces.push((Pose::IDENTITY, SharedShape::new(hull)));
            }
            piece_contact_radius.push(0.5 * (ra + rb));
        }
        if pieces.is_empty() {
            return Err(DemfemError::ShapeMismatch {
                field: "stations".into(),
                detail: "no segment of positive length".into(),
            });
        }
        let bounding_capsule = BoundingCapsule {
            z_min: z[0] - center_of_mass_z,
            z_max: z[z.len() - 1] - center_of_mass_z,
            radius: r.iter().cloned().fold(0.0, f64::max),
        };
        Ok(Self {
            compound: Compound::new(pieces),
            piece_contact_radius,
            bounding_radius,
            rim_points,
            bounding_capsule,
        })
    }
}

/// A capsule around a shape in its body frame: the segment from (0, 0, z_min) to
/// (0, 0, z_max) swept by a sphere of radius `radius`, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundingCapsule {
    /// Lower end of the axis segment (body z), m.
    pub z_min: f64,
    /// Upper end of the axis segment (body z), m.
    pub z_max: f64,
    /// Radius, m.
    pub radius: f64,
}

/// The shape of one rigid body.
#[derive(Debug, Clone)]
pub enum RigidShape {
    /// A clump of beads.
    Clump(BeadClump),
    /// An exact shape through parry3d-f64.
    Exact(ExactShape),
    /// The fast exact body of revolution with analytic contact tests
    /// ([`super::revolution`]).
    Revolution(RevolutionShape),
}

impl RigidShape {
    /// Radius of the bounding sphere about the centre of mass, m.
    pub fn bounding_radius(&self) -> f64 {
        match self {
            RigidShape::Clump(c) => c.bounding_radius,
            RigidShape::Exact(e) => e.bounding_radius,
            RigidShape::Revolution(r) => r.bounding_radius,
        }
    }

    /// Capsule along body z that contains the shape.
    pub fn bounding_capsule(&self) -> BoundingCapsule {
        match self {
            RigidShape::Clump(c) => c.bounding_capsule,
            RigidShape::Exact(e) => e.bounding_capsule,
            RigidShape::Revolution(r) => r.bounding_capsule,
        }
    }

    /// Smallest Hertz contact radius of the shape, m (stiffness scale for the time step).
    pub fn min_contact_radius(&self) -> f64 {
        match self {
            RigidShape::Clump(c) => c.min_bead_radius,
            RigidShape::Exact(e) => e
                .piece_contact_radius
                .iter()
                .cloned()
                .fold(f64::INFINITY, f64::min),
            RigidShape::Revolution(r) => r.min_contact_radius,
        }
    }

    /// Body-frame points where contacts can happen (bead centres or rims), m.
    pub fn surface_sample(&self) -> &[Vector3<f64>] {
        match self {
            RigidShape::Clump(c) => &c.centers,
            RigidShape::Exact(e) => &e.rim_points,
            RigidShape::Revolution(r) => &r.rim_points,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tube_mass_properties_match_closed_form() {
        let (ri, ro, l, rho) = (4.7e-3, 5.8e-3, 0.064, 2230.0);
        let p = RevolutionProfile::new(vec![0.0, l], vec![ri, ri], vec![ro, ro]).unwrap();
        let mp = p.mass_properties(rho).unwrap();
        let m = rho * std::f64::consts::PI * (ro * ro - ri * ri) * l;
        assert!((mp.mass - m).abs() < 1e-14);
        assert!((mp.center_of_mass.z - 0.5 * l).abs() < 1e-15);
        let axial = 0.5 * m * (ro * ro + ri * ri);
        let trans = m * (3.0 * (ro * ro + ri * ri) + l * l) / 12.0;
        assert!((mp.principal_inertia.z / axial - 1.0).abs() < 1e-12);
        assert!((mp.principal_inertia.x / trans - 1.0).abs() < 1e-12);
    }

    #[test]
    fn default_cartridge_mass_is_python_value() {
        // demfem.cartridge.Cartridge().mass = 0.00494114260432321 kg
        let mp = RevolutionProfile::default_cartridge()
            .mass_properties(2230.0)
            .unwrap();
        assert!(
            (mp.mass / 0.004_941_142_604_323_21 - 1.0).abs() < 1e-12,
            "{}",
            mp.mass
        );
    }

    #[test]
    fn bad_stations_are_refused() {
        assert!(RevolutionProfile::new(vec![0.0, 1.0], vec![2.0, 0.1], vec![1.0, 1.0]).is_err());
        assert!(RevolutionProfile::new(vec![0.0], vec![0.1], vec![1.0]).is_err());
        assert!(RevolutionProfile::new(vec![1.0, 0.0], vec![0.1, 0.1], vec![1.0, 1.0]).is_err());
    }
}
