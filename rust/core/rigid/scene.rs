//! A small stepping loop for rigid cartridges: gravity, a belt (plane z = 0 whose surface may
//! move), walls, and contacts between bodies, with a time step bounded by the contact
//! oscillation of the stiffest bead (or piece) contact.
//!
//! The time-step limit. A rigid clump has no elastic waves of its own, so the Rayleigh step
//! of a bead (≈ 0.66 µs for a 0.55 mm glass bead) would resolve nothing that exists here;
//! what the integrator must resolve is the Hertz contact between a body and its partner. The
//! limit is the Hertz contact duration t_c = 2.943 δ_max / v at the largest expected impact
//! speed, for the smallest contact radius of any shape, the stiffer of the plane and the
//! body–body moduli, and the smallest effective mass any surface point of a body can present
//! (m_eff = 1/λ_max(𝟙/m + S(r)ᵀ I⁻¹ S(r)) with S(r) the cross-product matrix of r, the mass felt by a push at lever arm r), divided by
//! [`STEPS_PER_CONTACT`]. A requested step above it is refused with
//! [`DemfemError::UnstableTimeStep`].
//!
//! Damping of multi-point contacts. When n beads (or parry points) of one body pair touch at
//! once, each carries the Tsuji damping of m*/n: n springs of similar stiffness k act as one
//! spring nk on the mass m*, and ζ √(m* nk) = n · ζ √((m*/n) k). With the whole m* per point
//! the pair would be √n times over-damped (a cartridge hitting a wall with its side touches
//! with ~60 beads at once and would keep a restitution of ~0.15 instead of 0.5). Between two
//! exact shapes a contact is a piece pair: its parry points share one Hertz law and one m*/n
//! (n = piece pairs touching), so the force does not jump with the number of points parry
//! reports from one step to the next.
//!
//! The contacts of a step (detection against planes, walls and other bodies, forces with
//! their friction history, onsets) are in the `contacts` submodule; putting removed bodies
//! back (re-feeding) in `reinsert`.

use std::collections::{HashMap, HashSet};

use nalgebra::{Matrix3, UnitQuaternion, Vector3};

use super::body::{RigidBodies, RigidBodyInit};
use super::collision::{
    BodyPose, ClumpPairScratch, ContactPoint, ExactContactCache, Plane, PolygonWall,
};
use super::forces::{ContactMaterial, RigidContactLaw};
use super::shape::{MassProperties, RigidShape};
use crate::contact::{effective_mass, effective_radius, hertz_contact_duration, hertz_stiffness};
use crate::error::{check_positive, DemfemError, Result};
use crate::geometry::{MeshWall, WallMotion, WallShape};

mod contacts;
mod reinsert;
mod revolution_geometry;
mod revolution_pass;

pub use reinsert::{Obstacle, UNIT_QUATERNION_TOLERANCE};

use contacts::FrictionHistory;

/// Steps per Hertz contact duration at the stable limit. With ~12 beads in contact at once
/// (a ring on the belt) the stiffness grows twelvefold and ω Δt ≈ 0.36, still far from the
/// Verlet bound of 2.
pub const STEPS_PER_CONTACT: f64 = 30.0;

/// Parameters of a rigid scene, SI.
#[derive(Debug, Clone)]
pub struct RigidSceneConfig {
    /// Gravity, m/s².
    pub gravity: Vector3<f64>,
    /// Belt and walls.
    pub planes: Vec<Plane>,
    /// Material of the bodies.
    pub body_material: ContactMaterial,
    /// Material of the belt and walls.
    pub plane_material: ContactMaterial,
    /// Restitution of a Hertz impact, in (0, 1].
    pub restitution: f64,
    /// Coulomb friction coefficient, ≥ 0.
    pub friction: f64,
    /// Largest impact speed the time step must resolve, m/s.
    pub max_expected_speed: f64,
    /// Time step, s; `None` takes the stable limit.
    pub time_step: Option<f64>,
    /// Walls beyond `planes`: planes or convex polygons with a prescribed motion (the gate).
    /// Their contacts are numbered after `planes` (wall `w` is boundary `planes.len() + w`).
    pub walls: Vec<RigidWall>,
    /// Outlet: a body whose centre of mass x has (x − point) · normal < 0 is removed (it
    /// stops moving and touching anything); `normal` (any length > 0) points to the kept
    /// side, as `DemSimulation`'s `removal_plane`. Points in m.
    pub removal_plane: Option<(Vector3<f64>, Vector3<f64>)>,
    /// Log the first step of every new contact ([`RigidOnset`]).
    pub record_onsets: bool,
    /// Threads of the contact geometry of bodies of revolution (≥ 1); the result is bitwise
    /// the same on any number.
    pub threads: usize,
}

/// A wall of a rigid scene: a plane or a convex polygon of [`crate::geometry`], translated
/// rigidly by `motion` (fixed, constant velocity, harmonic: the gate), whose surface moves
/// with `surface_velocity` (m/s) on top of that (a belt).
#[derive(Debug, Clone)]
pub struct RigidWall {
    /// Geometry at its reference position, m.
    pub shape: WallShape,
    /// Prescribed translation.
    pub motion: WallMotion,
    /// Velocity of the surface material while the geometry stays put, m/s.
    pub surface_velocity: Vector3<f64>,
}

/// The first force evaluation of a new contact between a body and another body or a
/// boundary (a pair counts as one contact however many beads or points touch), with where
/// it touches: the deepest point and the poses of both bodies then, from which the contact's
/// place on each body (its height along the axis) and the angle between the axes follow.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidOnset {
    /// Simulated time, s.
    pub time: f64,
    /// The body (the lower index for body pairs).
    pub body: u32,
    /// The other body, or the boundary index (planes first, then walls).
    pub partner: u32,
    /// True when `partner` is a plane or wall.
    pub partner_is_wall: bool,
    /// Normal approach speed at the deepest contact point, m/s (> 0 approaching).
    pub normal_speed: f64,
    /// Tangential relative speed at that point, m/s.
    pub tangential_speed: f64,
    /// The deepest contact point, world, m.
    pub point: Vector3<f64>,
    /// Unit contact normal there, world: from the wall to the body, or from `body` to
    /// `partner`.
    pub normal: Vector3<f64>,
    /// Pose of `body` at the onset.
    pub body_pose: BodyPose,
    /// Pose of `partner` at the onset (`None` for a wall).
    pub partner_pose: Option<BodyPose>,
}

/// A wall prepared for the contact pass.
#[derive(Debug, Clone)]
enum PreparedShape {
    Plane {
        point: Vector3<f64>,
        normal: Vector3<f64>,
    },
    Polygon(PolygonWall),
    /// A triangle mesh (beads of clumps only): each bead against each triangle under the
    /// rule of [`crate::geometry::mesh`].
    Mesh(std::sync::Arc<MeshWall>),
}

#[derive(Debug, Clone)]
struct PreparedWall {
    shape: PreparedShape,
    motion: WallMotion,
    surface_velocity: Vector3<f64>,
}

fn prepare_wall(k: usize, wall: &RigidWall) -> Result<PreparedWall> {
    if !wall.surface_velocity.iter().all(|v| v.is_finite()) {
        return Err(DemfemError::invalid(
            &format!("walls[{k}].surface_velocity"),
            f64::NAN,
            "finite components",
        ));
    }
    if let WallMotion::Rotation { .. } = wall.motion {
        return Err(DemfemError::ShapeMismatch {
            field: format!("walls[{k}].motion"),
            detail: "rigid scenes take fixed, constant-velocity and harmonic walls, not \
                     rotating ones (yet)"
                .into(),
        });
    }
    if let WallMotion::ConstantVelocity { velocity } = wall.motion {
        if !velocity.is_finite() {
            return Err(DemfemError::invalid(
                &format!("walls[{k}].motion.velocity"),
                f64::NAN,
                "finite components",
            ));
        }
    }
    let shape = match &wall.shape {
        WallShape::Plane { point, normal } => PreparedShape::Plane {
            point: Vector3::new(point.x, point.y, point.z),
            normal: Vector3::new(normal.x, normal.y, normal.z),
        },
        polygon @ WallShape::Polygon { .. } => PreparedShape::Polygon(PolygonWall::new(polygon)?),
        WallShape::Cuboid { .. } => {
            return Err(DemfemError::ShapeMismatch {
                field: format!("walls[{k}]"),
                detail: "rigid scenes take plane and polygon walls, not cuboids".into(),
            })
        }
        WallShape::Mesh(mesh) => PreparedShape::Mesh(mesh.clone()),
    };
    Ok(PreparedWall {
        shape,
        motion: wall.motion,
        surface_velocity: wall.surface_velocity,
    })
}

impl Default for RigidSceneConfig {
    fn default() -> Self {
        Self {
            gravity: Vector3::new(0.0, 0.0, -9.81),
            planes: Vec::new(),
            body_material: ContactMaterial::PAPER_GLASS,
            plane_material: ContactMaterial::PAPER_GLASS,
            restitution: 0.5,
            friction: 0.2,
            max_expected_speed: 5.0,
            time_step: None,
            walls: Vec::new(),
            removal_plane: None,
            record_onsets: false,
            threads: 1,
        }
    }
}

impl RigidSceneConfig {
    /// The belt: plane z = 0 (normal +z) whose surface moves with `belt_velocity` (m/s).
    pub fn belt(belt_velocity: Vector3<f64>) -> Result<Plane> {
        Plane::new(Vector3::zeros(), Vector3::z(), belt_velocity)
    }
}

/// Rigid bodies with shapes, planes and the step loop.
#[derive(Debug)]
pub struct RigidScene {
    /// Body state. After editing positions or velocities between runs, call
    /// [`RigidScene::invalidate_forces`] so the next run starts from fresh forces.
    pub bodies: RigidBodies,
    shapes: Vec<(RigidShape, MassProperties)>,
    body_shape: Vec<usize>,
    planes: Vec<Plane>,
    gravity: Vector3<f64>,
    model: RigidContactLaw,
    max_expected_speed: f64,
    requested_time_step: Option<f64>,
    time_step: f64,
    time: f64,
    steps: u64,
    forces_current: bool,
    contacts: Vec<ContactPoint>,
    clump_scratch: ClumpPairScratch,
    exact_caches: HashMap<(usize, usize), ExactContactCache>,
    sweep_order: Vec<(f64, f64, usize)>,
    evaluations: u64,
    friction_history: FrictionHistory,
    friction_history_next: FrictionHistory,
    contacts_last_step: usize,
    max_overlap_last_step: f64,
    elastic_energy_last_step: f64,
    walls: Vec<PreparedWall>,
    removal_plane: Option<(Vector3<f64>, Vector3<f64>)>,
    alive: Vec<bool>,
    removals: Vec<(f64, u32)>,
    reinsertions: Vec<(f64, u32)>,
    record_onsets: bool,
    onsets: Vec<RigidOnset>,
    touching: HashSet<u64>,
    touching_next: HashSet<u64>,
    coordination: Vec<u32>,
    wall_contacts: Vec<u32>,
    /// The contact pass of scenes with bodies of revolution (`None` without them).
    revolution: Option<revolution_pass::RevolutionPass>,
    /// The threads of that pass (`None`: one).
    pool: Option<rayon::ThreadPool>,
}

impl RigidScene {
    /// An empty scene.
    pub fn new(config: RigidSceneConfig) -> Result<Self> {
        if !config.gravity.iter().all(|g| g.is_finite()) {
            return Err(DemfemError::ShapeMismatch {
                field: "gravity".into(),
                detail: "components must be finite".into(),
            });
        }
        check_positive("max_expected_speed", config.max_expected_speed)?;
        if config.threads == 0 {
            return Err(DemfemError::invalid("threads", 0.0, "a whole number >= 1"));
        }
        let pool = if config.threads > 1 {
            Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(config.threads)
                    .build()
                    .map_err(|e| {
                        DemfemError::Numerical(format!(
                            "cannot start {} threads: {e}",
                            config.threads
                        ))
                    })?,
            )
        } else {
            None
        };
        if let Some(dt) = config.time_step {
            check_positive("time_step", dt)?;
        }
        let walls = config
            .walls
            .iter()
            .enumerate()
            .map(|(k, w)| prepare_wall(k, w))
            .collect::<Result<Vec<_>>>()?;
        let removal_plane = match config.removal_plane {
            None => None,
            Some((point, normal)) => {
                let length = normal.norm();
                if !(length > 0.0 && length.is_finite() && point.iter().all(|v| v.is_finite())) {
                    return Err(DemfemError::ShapeMismatch {
                        field: "removal_plane".into(),
                        detail: "point finite, normal finite and non-zero".into(),
                    });
                }
                Some((point, normal / length))
            }
        };
        let model = RigidContactLaw::new(
            config.body_material,
            config.plane_material,
            config.restitution,
            config.friction,
        )?;
        Ok(Self {
            bodies: RigidBodies::new(),
            shapes: Vec::new(),
            body_shape: Vec::new(),
            planes: config.planes,
            gravity: config.gravity,
            model,
            max_expected_speed: config.max_expected_speed,
            requested_time_step: config.time_step,
            time_step: f64::INFINITY,
            time: 0.0,
            steps: 0,
            forces_current: false,
            contacts: Vec::new(),
            clump_scratch: ClumpPairScratch::default(),
            exact_caches: HashMap::new(),
            sweep_order: Vec::new(),
            evaluations: 0,
            friction_history: FrictionHistory::default(),
            friction_history_next: FrictionHistory::default(),
            contacts_last_step: 0,
            max_overlap_last_step: 0.0,
            elastic_energy_last_step: 0.0,
            walls,
            removal_plane,
            alive: Vec::new(),
            removals: Vec::new(),
            reinsertions: Vec::new(),
            record_onsets: config.record_onsets,
            onsets: Vec::new(),
            touching: HashSet::new(),
            touching_next: HashSet::new(),
            coordination: Vec::new(),
            wall_contacts: Vec::new(),
            revolution: None,
            pool,
        })
    }

    /// Register a shape with its mass properties (principal inertia in the shape's body
    /// frame); returns its id.
    pub fn add_shape(&mut self, shape: RigidShape, mass: MassProperties) -> Result<usize> {
        check_positive("mass", mass.mass)?;
        for k in 0..3 {
            check_positive("principal_inertia", mass.principal_inertia[k])?;
        }
        let revolution = matches!(shape, RigidShape::Revolution(_));
        let exact = |s: &RigidShape| matches!(s, RigidShape::Exact(_));
        let mixed = if revolution {
            self.shapes.iter().any(|(s, _)| exact(s))
        } else {
            exact(&shape) && self.revolution.is_some()
        };
        if mixed {
            return Err(DemfemError::ShapeMismatch {
                field: "shape".into(),
                detail: "bodies of revolution share a scene with bead clumps and spheres, not \
                         with parry exact shapes"
                    .into(),
            });
        }
        if revolution && self.revolution.is_none() {
            self.revolution = Some(revolution_pass::RevolutionPass::default());
        }
        self.shapes.push((shape, mass));
        Ok(self.shapes.len() - 1)
    }

    /// Add a body of shape `shape_id` at `position` (m, centre of mass) with `orientation`
    /// (body → world), `velocity` (m/s) and body-frame `angular_velocity_body` (rad/s).
    pub fn add_body(
        &mut self,
        shape_id: usize,
        position: Vector3<f64>,
        orientation: UnitQuaternion<f64>,
        velocity: Vector3<f64>,
        angular_velocity_body: Vector3<f64>,
    ) -> Result<usize> {
        let (_, mass) = self
            .shapes
            .get(shape_id)
            .ok_or_else(|| DemfemError::ShapeMismatch {
                field: "shape_id".into(),
                detail: format!("{shape_id} but only {} shapes exist", self.shapes.len()),
            })?;
        let index = self.bodies.push(RigidBodyInit {
            position,
            orientation,
            velocity,
            angular_velocity_body,
            mass: mass.mass,
            principal_inertia: mass.principal_inertia,
        })?;
        let (shape, mass) = &self.shapes[shape_id];
        if matches!(shape, RigidShape::Revolution(_))
            && mass.principal_inertia.x == mass.principal_inertia.y
        {
            // bodies of revolution turn as symmetric tops, in closed form
            self.bodies.set_symmetric_top(index, true)?;
        }
        self.body_shape.push(shape_id);
        self.alive.push(true);
        self.coordination.push(0);
        self.wall_contacts.push(0);
        self.forces_current = false;
        self.update_time_step()?;
        Ok(index)
    }

    /// The stable time-step limit of the current bodies (see the module docs), s.
    pub fn time_step_limit(&self) -> Result<f64> {
        let mut limit = f64::INFINITY;
        let e_star = self
            .model
            .e_star_body_body
            .max(self.model.e_star_body_plane);
        // each shape in use once: the limit is the same for every body of a shape
        let mut in_use = self.body_shape.clone();
        in_use.sort_unstable();
        in_use.dedup();
        for &shape_id in &in_use {
            let (shape, mass) = &self.shapes[shape_id];
            let m_eff = smallest_effective_mass(shape.surface_sample(), mass);
            let radius = shape.min_contact_radius();
            // against a plane: R* = r, m* = m_eff; against a twin body: R* = r/2, m* = m_eff/2
            for (r_star, m_star) in [
                (radius, m_eff),
                (
                    effective_radius(radius, radius)?,
                    effective_mass(m_eff, m_eff)?,
                ),
            ] {
                let k_h = hertz_stiffness(r_star, e_star)?;
                let duration = hertz_contact_duration(k_h, m_star, self.max_expected_speed)?;
                limit = limit.min(duration / STEPS_PER_CONTACT);
            }
        }
        Ok(limit)
    }

    fn update_time_step(&mut self) -> Result<()> {
        let limit = self.time_step_limit()?;
        self.time_step = match self.requested_time_step {
            Some(dt) if dt > limit => {
                return Err(DemfemError::UnstableTimeStep {
                    dt,
                    limit,
                    reason: format!(
                        "Hertz contact of the stiffest rigid-body contact at {} m/s, {} steps per contact",
                        self.max_expected_speed, STEPS_PER_CONTACT
                    ),
                })
            }
            Some(dt) => dt,
            None => limit,
        };
        Ok(())
    }

    /// Mark the stored forces as stale (after editing `bodies` by hand).
    pub fn invalidate_forces(&mut self) {
        self.forces_current = false;
    }

    /// Time step in use, s.
    pub fn time_step(&self) -> f64 {
        self.time_step
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Contact points found in the last force evaluation.
    pub fn contacts_last_step(&self) -> usize {
        self.contacts_last_step
    }

    /// Largest overlap in the last force evaluation, m.
    pub fn max_overlap_last_step(&self) -> f64 {
        self.max_overlap_last_step
    }

    /// Elastic energy stored in the contacts at the last force evaluation, J: the Hertz
    /// potential 2/5 k_H δ^{5/2} of every contact point plus the Mindlin springs ½ k_t |ξ|².
    /// With the bodies' kinetic and gravitational energy it makes the total energy, which
    /// damping and sliding friction can only lower.
    pub fn elastic_energy_last_step(&self) -> f64 {
        self.elastic_energy_last_step
    }

    /// Whether each body is still in the scene (not removed through the outlet).
    pub fn alive(&self) -> &[bool] {
        &self.alive
    }

    /// Bodies removed through the outlet: (time (s), body index).
    pub fn removals(&self) -> &[(f64, u32)] {
        &self.removals
    }

    /// Contact onsets logged so far (with `record_onsets`).
    pub fn onsets(&self) -> &[RigidOnset] {
        &self.onsets
    }

    /// Drop the logged onsets.
    pub fn clear_onsets(&mut self) {
        self.onsets.clear();
    }

    /// Bodies each body touched in the last force evaluation (coordination number).
    pub fn coordination(&self) -> &[u32] {
        &self.coordination
    }

    /// Planes and walls each body touched in the last force evaluation.
    pub fn wall_contacts(&self) -> &[u32] {
        &self.wall_contacts
    }

    /// Rebuilds of the candidate-pair list of the revolution pass (0 without bodies of
    /// revolution).
    pub fn pair_list_rebuilds(&self) -> u64 {
        self.revolution.as_ref().map_or(0, |p| p.rebuilds())
    }

    /// Shape of body `i`.
    pub fn shape_of(&self, i: usize) -> Option<&RigidShape> {
        self.body_shape.get(i).map(|&s| &self.shapes[s].0)
    }

    /// Advance `n_steps` steps of velocity Verlet (kick–drift–kick).
    pub fn run(&mut self, n_steps: u64) -> Result<()> {
        if self.bodies.is_empty() {
            return Ok(());
        }
        let h = self.time_step;
        if !self.forces_current {
            self.compute_forces(self.time)?;
        }
        for _ in 0..n_steps {
            self.bodies.kick(0.5 * h);
            self.bodies.drift(h);
            self.compute_forces(self.time + h)?;
            self.bodies.kick(0.5 * h);
            self.time += h;
            self.steps += 1;
            if self.removal_plane.is_some() {
                self.remove_past_outlet();
            }
        }
        for i in 0..self.bodies.len() {
            let finite = self.bodies.position[i].iter().all(|v| v.is_finite())
                && self.bodies.velocity[i].iter().all(|v| v.is_finite())
                && self.bodies.angular_velocity_body[i]
                    .iter()
                    .all(|v| v.is_finite());
            if !finite {
                return Err(DemfemError::Numerical(format!(
                    "body {i} has a non-finite state at t = {} s",
                    self.time
                )));
            }
        }
        Ok(())
    }

    /// Each wall's displacement and velocity at `time` (s): (offset m, velocity m/s), in the
    /// order of `walls` (the boundaries after the planes).
    fn wall_offsets(&self, time: f64) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        self.walls
            .iter()
            .map(|w| {
                let (x, v) = w.motion.offset_and_velocity(time);
                (Vector3::new(x.x, x.y, x.z), Vector3::new(v.x, v.y, v.z))
            })
            .collect()
    }

    fn pose(&self, i: usize) -> BodyPose {
        BodyPose {
            position: self.bodies.position[i],
            orientation: self.bodies.orientation[i],
        }
    }

    /// Remove the bodies whose centre of mass has crossed the removal plane.
    fn remove_past_outlet(&mut self) {
        let Some((point, normal)) = self.removal_plane else {
            return;
        };
        for i in 0..self.bodies.len() {
            if self.alive[i] && (self.bodies.position[i] - point).dot(&normal) < 0.0 {
                self.remove_body(i);
            }
        }
    }

    /// Take body `i` out of the scene: it stops, feels no force and touches nothing (until
    /// [`RigidScene::reinsert_body`] puts it back).
    pub fn remove_body(&mut self, i: usize) {
        if i < self.alive.len() && self.alive[i] {
            self.alive[i] = false;
            self.bodies.velocity[i] = Vector3::zeros();
            self.bodies.angular_velocity_body[i] = Vector3::zeros();
            self.bodies.force[i] = Vector3::zeros();
            self.bodies.torque[i] = Vector3::zeros();
            self.removals.push((self.time, i as u32));
        }
    }
}

/// Smallest effective mass a push at any of `points` (body frame, m) can feel, kg.
fn smallest_effective_mass(points: &[Vector3<f64>], mass: &MassProperties) -> f64 {
    let inverse_inertia = Matrix3::from_diagonal(&mass.principal_inertia.map(|i| 1.0 / i));
    let mut smallest = mass.mass;
    for r in points {
        let cross = r.cross_matrix();
        let inverse_mass =
            Matrix3::identity() / mass.mass + cross.transpose() * inverse_inertia * cross;
        let largest = inverse_mass.symmetric_eigenvalues().max();
        if largest > 0.0 {
            smallest = smallest.min(1.0 / largest);
        }
    }
    smallest
}
