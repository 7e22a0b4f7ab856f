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

use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

use nalgebra::{Matrix3, UnitQuaternion, Vector3};

use super::body::{RigidBodies, RigidBodyInit};
use super::collision::{
    clump_clump_contacts, clump_exact_contacts, clump_plane_contacts, clump_polygon_contacts,
    exact_exact_contacts, exact_plane_contacts, exact_polygon_contacts, BodyPose, ClumpPairScratch,
    ContactPoint, ExactContactCache, Plane, PolygonWall,
};
use super::forces::{ContactMaterial, ContactModel};
use super::shape::{BoundingCapsule, MassProperties, RigidShape};
use crate::contact::{effective_mass, effective_radius, hertz_contact_duration, hertz_stiffness};
use crate::error::{check_positive, DemfemError, Result};
use crate::geometry::{WallMotion, WallShape};

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
/// boundary (a pair counts as one contact however many beads or points touch).
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
}

/// A wall prepared for the contact pass.
#[derive(Debug, Clone)]
enum PreparedShape {
    Plane {
        point: Vector3<f64>,
        normal: Vector3<f64>,
    },
    Polygon(PolygonWall),
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
        }
    }
}

impl RigidSceneConfig {
    /// The belt: plane z = 0 (normal +z) whose surface moves with `belt_velocity` (m/s).
    pub fn belt(belt_velocity: Vector3<f64>) -> Result<Plane> {
        Plane::new(Vector3::zeros(), Vector3::z(), belt_velocity)
    }
}

/// Key of a contact's friction history: (first object << 32 | second object, feature on the
/// first, feature on the second); planes are objects `u32::MAX − plane index`.
type ContactKey = (u64, u64, u64);

/// Force (N) and stored elastic energy (J) of one contact point, carrying its Mindlin spring
/// over from the previous step when `history` is given: the spring of `key` is read from the
/// first map (zero for a new contact) and the updated one stored in the second.
#[allow(clippy::too_many_arguments)]
fn force_with_history(
    model: &ContactModel,
    contact: &ContactPoint,
    relative_velocity: &Vector3<f64>,
    effective_mass: f64,
    e_star: f64,
    key: ContactKey,
    history: Option<(&FrictionHistory, &mut FrictionHistory)>,
    dt: f64,
) -> Result<(Vector3<f64>, f64)> {
    let mut xi = history
        .as_ref()
        .and_then(|(previous, _)| previous.get(&key).copied())
        .unwrap_or_else(Vector3::zeros);
    let (f, energy) = model.force_and_energy(
        contact,
        relative_velocity,
        effective_mass,
        e_star,
        &mut xi,
        dt,
    )?;
    if let Some((_, current)) = history {
        current.insert(key, xi);
    }
    Ok((f, energy))
}

/// Multiply–rotate hash for small integer keys (the FxHash scheme): the default SipHash
/// would cost more than the force it looks up.
#[derive(Default, Clone, Copy)]
struct ContactKeyHasher(u64);

impl Hasher for ContactKeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_u64(&mut self, value: u64) {
        self.0 = (self.0.rotate_left(5) ^ value).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

type FrictionHistory = HashMap<ContactKey, Vector3<f64>, BuildHasherDefault<ContactKeyHasher>>;

fn plane_object(plane: usize) -> u64 {
    (u32::MAX as u64) - plane as u64
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
    model: ContactModel,
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
    record_onsets: bool,
    onsets: Vec<RigidOnset>,
    touching: HashSet<u64>,
    touching_next: HashSet<u64>,
    coordination: Vec<u32>,
    wall_contacts: Vec<u32>,
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
        let model = ContactModel::new(
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
            record_onsets: config.record_onsets,
            onsets: Vec::new(),
            touching: HashSet::new(),
            touching_next: HashSet::new(),
            coordination: Vec::new(),
            wall_contacts: Vec::new(),
        })
    }

    /// Register a shape with its mass properties (principal inertia in the shape's body
    /// frame); returns its id.
    pub fn add_shape(&mut self, shape: RigidShape, mass: MassProperties) -> Result<usize> {
        check_positive("mass", mass.mass)?;
        for k in 0..3 {
            check_positive("principal_inertia", mass.principal_inertia[k])?;
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
        for &shape_id in &self.body_shape {
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

    /// Take body `i` out of the scene: it stops, feels no force and touches nothing.
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

    /// Note that bodies (or a body and a boundary) touch under `key`; log an onset when they
    /// did not touch at the previous evaluation. `relative` is the velocity of the second
    /// surface minus the first at the deepest point, whose normal is `normal`.
    fn note_touch(
        &mut self,
        key: u64,
        body: usize,
        partner: usize,
        partner_is_wall: bool,
        time: f64,
        relative: &Vector3<f64>,
        normal: &Vector3<f64>,
    ) {
        self.touching_next.insert(key);
        if partner_is_wall {
            self.wall_contacts[body] += 1;
        } else {
            self.coordination[body] += 1;
            self.coordination[partner] += 1;
        }
        if self.record_onsets && !self.touching.contains(&key) {
            let v_n = relative.dot(normal);
            let (first, second) = if partner_is_wall {
                (body, partner)
            } else {
                (body.min(partner), body.max(partner))
            };
            self.onsets.push(RigidOnset {
                time,
                body: first as u32,
                partner: second as u32,
                partner_is_wall,
                normal_speed: -v_n,
                tangential_speed: (relative - normal * v_n).norm(),
            });
        }
    }

    /// Gravity and every contact force and torque of the configuration at time `time` (s).
    fn compute_forces(&mut self, time: f64) -> Result<()> {
        self.bodies.clear_forces();
        self.evaluations += 1;
        let evaluation = self.evaluations;
        let dt = self.time_step;
        // friction history: springs of contacts that persist carry over, the rest are dropped
        let with_history = self.model.friction > 0.0;
        let previous = std::mem::take(&mut self.friction_history);
        let mut current = std::mem::take(&mut self.friction_history_next);
        current.clear();
        for i in 0..self.bodies.len() {
            self.bodies.force[i] = if self.alive[i] {
                self.gravity * self.bodies.mass[i]
            } else {
                Vector3::zeros()
            };
        }
        std::mem::swap(&mut self.touching, &mut self.touching_next);
        self.touching_next.clear();
        self.coordination.iter_mut().for_each(|c| *c = 0);
        self.wall_contacts.iter_mut().for_each(|c| *c = 0);
        let mut contacts = std::mem::take(&mut self.contacts);
        let mut count = 0;
        let mut max_overlap: f64 = 0.0;
        let mut elastic_energy = 0.0;
        let n_planes = self.planes.len();
        let n_boundaries = n_planes + self.walls.len();
        // boundaries at this time: planes as given, walls displaced by their motion
        let offsets: Vec<(Vector3<f64>, Vector3<f64>)> = self
            .walls
            .iter()
            .map(|w| {
                let (x, v) = w.motion.offset_and_velocity(time);
                (Vector3::new(x.x, x.y, x.z), Vector3::new(v.x, v.y, v.z))
            })
            .collect();
        for i in 0..self.bodies.len() {
            if !self.alive[i] {
                continue;
            }
            let pose = self.pose(i);
            for p in 0..n_boundaries {
                contacts.clear();
                let shape_i = &self.shapes[self.body_shape[i]].0;
                let surface_velocity = if p < n_planes {
                    let plane = self.planes[p];
                    match shape_i {
                        RigidShape::Clump(clump) => {
                            clump_plane_contacts(&plane, clump, &pose, &mut contacts)
                        }
                        RigidShape::Exact(shape) => {
                            let cache = self.exact_caches.entry((i, usize::MAX - p)).or_default();
                            cache.last_used = evaluation;
                            exact_plane_contacts(&plane, shape, &pose, cache, &mut contacts)?
                        }
                    }
                    plane.surface_velocity
                } else {
                    let wall = &self.walls[p - n_planes];
                    let (offset, velocity) = offsets[p - n_planes];
                    match (&wall.shape, shape_i) {
                        (PreparedShape::Plane { point, normal }, _) => {
                            let plane = Plane {
                                point: point + offset,
                                normal: *normal,
                                surface_velocity: Vector3::zeros(),
                            };
                            match shape_i {
                                RigidShape::Clump(clump) => {
                                    clump_plane_contacts(&plane, clump, &pose, &mut contacts)
                                }
                                RigidShape::Exact(shape) => {
                                    let cache =
                                        self.exact_caches.entry((i, usize::MAX - p)).or_default();
                                    cache.last_used = evaluation;
                                    exact_plane_contacts(
                                        &plane,
                                        shape,
                                        &pose,
                                        cache,
                                        &mut contacts,
                                    )?
                                }
                            }
                        }
                        (PreparedShape::Polygon(polygon), RigidShape::Clump(clump)) => {
                            clump_polygon_contacts(polygon, &offset, clump, &pose, &mut contacts)
                        }
                        (PreparedShape::Polygon(polygon), RigidShape::Exact(shape)) => {
                            let cache = self.exact_caches.entry((i, usize::MAX - p)).or_default();
                            cache.last_used = evaluation;
                            exact_polygon_contacts(
                                polygon,
                                &offset,
                                shape,
                                &pose,
                                cache,
                                &mut contacts,
                            )?
                        }
                    }
                    wall.surface_velocity + velocity
                };
                if contacts.is_empty() {
                    continue;
                }
                count += contacts.len();
                let m_star = self.bodies.mass[i] / contacts.len() as f64;
                let mut deepest = 0;
                for (k, c) in contacts.iter().enumerate() {
                    if c.overlap > contacts[deepest].overlap {
                        deepest = k;
                    }
                }
                let c0 = contacts[deepest];
                let relative0 = self.bodies.point_velocity(i, &c0.point) - surface_velocity;
                self.note_touch(
                    plane_object(p) << 32 | i as u64,
                    i,
                    p,
                    true,
                    time,
                    &relative0,
                    &c0.normal,
                );
                for c in &contacts {
                    max_overlap = max_overlap.max(c.overlap);
                    let relative = self.bodies.point_velocity(i, &c.point) - surface_velocity;
                    let key = (
                        plane_object(p) << 32 | i as u64,
                        c.feature_first,
                        c.feature_second,
                    );
                    let (f, energy) = force_with_history(
                        &self.model,
                        c,
                        &relative,
                        m_star,
                        self.model.e_star_body_plane,
                        key,
                        with_history.then_some((&previous, &mut current)),
                        dt,
                    )?;
                    elastic_energy += energy;
                    self.apply(i, &c.point, &f);
                }
            }
        }
        // broad phase: sort and sweep the bounding spheres along x (O(N log N) pairs)
        let mut order = std::mem::take(&mut self.sweep_order);
        order.clear();
        for i in 0..self.bodies.len() {
            if !self.alive[i] {
                continue;
            }
            let r = self.shapes[self.body_shape[i]].0.bounding_radius();
            order.push((
                self.bodies.position[i].x - r,
                self.bodies.position[i].x + r,
                i,
            ));
        }
        order.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
        for (k, &(_, upper, first_index)) in order.iter().enumerate() {
            for &(lower, _, second_index) in &order[k + 1..] {
                if lower >= upper {
                    break;
                }
                let (a, b) = (first_index.min(second_index), first_index.max(second_index));
                let (pa, pb) = (self.pose(a), self.pose(b));
                let (shape_a, shape_b) = (
                    &self.shapes[self.body_shape[a]].0,
                    &self.shapes[self.body_shape[b]].0,
                );
                let reach = shape_a.bounding_radius() + shape_b.bounding_radius();
                let apart = (pb.position - pa.position).norm() >= reach
                    || !capsules_overlap(
                        &shape_a.bounding_capsule(),
                        &pa,
                        &shape_b.bounding_capsule(),
                        &pb,
                    );
                if apart {
                    continue;
                }
                contacts.clear();
                // the clump–exact pair is always computed with the clump first
                let mut flipped = false;
                match (
                    &self.shapes[self.body_shape[a]].0,
                    &self.shapes[self.body_shape[b]].0,
                ) {
                    (RigidShape::Clump(ca), RigidShape::Clump(cb)) => clump_clump_contacts(
                        ca,
                        &pa,
                        cb,
                        &pb,
                        &mut self.clump_scratch,
                        &mut contacts,
                    ),
                    (RigidShape::Exact(ea), RigidShape::Exact(eb)) => {
                        let cache = self.exact_caches.entry((a, b)).or_default();
                        cache.last_used = evaluation;
                        exact_exact_contacts(ea, &pa, eb, &pb, cache, &mut contacts)?
                    }
                    (RigidShape::Clump(ca), RigidShape::Exact(eb)) => {
                        clump_exact_contacts(ca, &pa, eb, &pb, &mut contacts)?
                    }
                    (RigidShape::Exact(ea), RigidShape::Clump(cb)) => {
                        flipped = true;
                        clump_exact_contacts(cb, &pb, ea, &pa, &mut contacts)?
                    }
                }
                if contacts.is_empty() {
                    continue;
                }
                let (first, second) = if flipped { (b, a) } else { (a, b) };
                let both_exact = matches!(
                    (
                        &self.shapes[self.body_shape[a]].0,
                        &self.shapes[self.body_shape[b]].0
                    ),
                    (RigidShape::Exact(_), RigidShape::Exact(_))
                );
                // the pair's m* is shared by its contacts (module docs); between exact shapes
                // a contact is a piece pair, whose points share one force law
                let sharing = if both_exact {
                    distinct_piece_pairs(&contacts)
                } else {
                    contacts.len()
                };
                let m_star = effective_mass(self.bodies.mass[first], self.bodies.mass[second])?
                    / sharing as f64;
                let mut deepest = 0;
                for (k, c) in contacts.iter().enumerate() {
                    if c.overlap > contacts[deepest].overlap {
                        deepest = k;
                    }
                }
                let c0 = contacts[deepest];
                let relative0 = self.bodies.point_velocity(second, &c0.point)
                    - self.bodies.point_velocity(first, &c0.point);
                self.note_touch(
                    (a as u64) << 32 | b as u64,
                    a,
                    b,
                    false,
                    time,
                    &relative0,
                    &c0.normal,
                );
                count += contacts.len();
                for c in &contacts {
                    max_overlap = max_overlap.max(c.overlap);
                    let relative = self.bodies.point_velocity(second, &c.point)
                        - self.bodies.point_velocity(first, &c.point);
                    let key = (
                        (first as u64) << 32 | second as u64,
                        c.feature_first,
                        c.feature_second,
                    );
                    let (f, energy) = force_with_history(
                        &self.model,
                        c,
                        &relative,
                        m_star,
                        self.model.e_star_body_body,
                        key,
                        with_history.then_some((&previous, &mut current)),
                        dt,
                    )?;
                    // between two exact shapes each piece pair is one contact, however many
                    // points parry reports for it (see `piece_pair_share`)
                    let share = if both_exact {
                        piece_pair_share(&contacts, c)
                    } else {
                        1.0
                    };
                    let f = f * share;
                    elastic_energy += energy * share;
                    self.apply(second, &c.point, &f);
                    self.apply(first, &c.point, &(-f));
                }
            }
        }
        // manifolds of pairs that drifted apart are stale: forget them
        if !self.exact_caches.is_empty() {
            self.exact_caches
                .retain(|_, cache| cache.last_used == evaluation);
        }
        self.contacts = contacts;
        self.sweep_order = order;
        self.friction_history = current;
        self.friction_history_next = previous;
        self.contacts_last_step = count;
        self.max_overlap_last_step = max_overlap;
        self.elastic_energy_last_step = elastic_energy;
        self.forces_current = true;
        Ok(())
    }

    #[inline]
    fn apply(&mut self, body: usize, point: &Vector3<f64>, force: &Vector3<f64>) {
        self.bodies.force[body] += force;
        self.bodies.torque[body] += (point - self.bodies.position[body]).cross(force);
    }
}

/// Share of the force law a contact point of two exact shapes carries: 1 / (points reported
/// for its piece pair). Parry describes one piece–piece contact by a varying number of
/// points — the deepest point alone, or with the clipped corners of a flat cap (5 or 9 for
/// two caps pressed together, chosen by round-off from one step to the next) or the ends of
/// a line contact — each at (about) the full overlap. Counting every point as a Hertz
/// contact makes the stiffness jump with that number between steps, which does work (an
/// undamped head-on cap impact gained 0.3 % of its energy); sharing one Hertz law among
/// the points keeps the total force a function of the overlap and lets the points only
/// place it.
fn piece_pair_share(contacts: &[ContactPoint], c: &ContactPoint) -> f64 {
    let pieces = |x: &ContactPoint| (x.feature_first >> 32, x.feature_second >> 32);
    let key = pieces(c);
    let count = contacts.iter().filter(|x| pieces(x) == key).count();
    1.0 / count.max(1) as f64
}

/// Number of distinct piece pairs among the contacts of two exact shapes.
fn distinct_piece_pairs(contacts: &[ContactPoint]) -> usize {
    let pieces = |x: &ContactPoint| (x.feature_first >> 32, x.feature_second >> 32);
    let mut count = 0;
    for (k, c) in contacts.iter().enumerate() {
        if !contacts[..k].iter().any(|x| pieces(x) == pieces(c)) {
            count += 1;
        }
    }
    count.max(1)
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

/// True when the bounding capsules of two bodies overlap (a cheap, tight cull for long
/// bodies: two upright cartridges 2 cm apart have overlapping bounding spheres, not capsules).
fn capsules_overlap(
    a: &BoundingCapsule,
    pose_a: &BodyPose,
    b: &BoundingCapsule,
    pose_b: &BodyPose,
) -> bool {
    let axis_a = pose_a.orientation * Vector3::z();
    let axis_b = pose_b.orientation * Vector3::z();
    let (a0, a1) = (
        pose_a.position + axis_a * a.z_min,
        pose_a.position + axis_a * a.z_max,
    );
    let (b0, b1) = (
        pose_b.position + axis_b * b.z_min,
        pose_b.position + axis_b * b.z_max,
    );
    let reach = a.radius + b.radius;
    segment_distance_squared(&a0, &a1, &b0, &b1) < reach * reach
}

/// Squared distance between segments [p0, p1] and [q0, q1], m² (Ericson, *Real-Time
/// Collision Detection*, §5.1.9).
fn segment_distance_squared(
    p0: &Vector3<f64>,
    p1: &Vector3<f64>,
    q0: &Vector3<f64>,
    q1: &Vector3<f64>,
) -> f64 {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    let tiny = 1e-30;
    let (s, t) = if a <= tiny && e <= tiny {
        (0.0, 0.0)
    } else if a <= tiny {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= tiny {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s = if denom > tiny {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    (p0 + d1 * s - (q0 + d2 * t)).norm_squared()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_distance_matches_hand_cases() {
        let z = Vector3::zeros();
        let ex = Vector3::x();
        // parallel segments 2 apart
        let d = segment_distance_squared(
            &z,
            &ex,
            &Vector3::new(0.0, 2.0, 0.0),
            &Vector3::new(1.0, 2.0, 0.0),
        );
        assert!((d - 4.0).abs() < 1e-15);
        // crossing skew segments 3 apart in z
        let d = segment_distance_squared(
            &Vector3::new(-1.0, 0.0, 0.0),
            &ex,
            &Vector3::new(0.0, -1.0, 3.0),
            &Vector3::new(0.0, 1.0, 3.0),
        );
        assert!((d - 9.0).abs() < 1e-15);
        // end to end along a line
        let d = segment_distance_squared(
            &z,
            &ex,
            &Vector3::new(3.0, 0.0, 0.0),
            &Vector3::new(4.0, 0.0, 0.0),
        );
        assert!((d - 4.0).abs() < 1e-15);
    }
}
