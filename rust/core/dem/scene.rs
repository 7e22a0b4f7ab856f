//! The scene: everything a simulation is built from (particles, materials, walls, effects and
//! numerical settings), with the checks that refuse inconsistent input.

use crate::dem::effects::{Effect, EffectSet};
use crate::dem::material::{DemContactLaw, Material};
use crate::error::{check_non_negative, check_positive, DemfemError, Result};
use crate::geometry::{Vec3, Wall};

/// Initial particle data (structure of arrays, one entry per sphere).
#[derive(Debug, Clone, Default)]
pub struct ParticleInit {
    /// Centres, m.
    pub position: Vec<Vec3>,
    /// Velocities, m/s.
    pub velocity: Vec<Vec3>,
    /// Angular velocities, rad/s.
    pub angular_velocity: Vec<Vec3>,
    /// Radii, m.
    pub radius: Vec<f64>,
    /// Material index of each sphere.
    pub material: Vec<usize>,
    /// User tag of each sphere (e.g. "first line"); carried, not interpreted.
    pub tag: Vec<u32>,
}

impl ParticleInit {
    /// Spheres at rest with material 0 and tag 0.
    pub fn at_rest(position: Vec<Vec3>, radius: Vec<f64>) -> Self {
        let n = position.len();
        ParticleInit {
            position,
            velocity: vec![Vec3::ZERO; n],
            angular_velocity: vec![Vec3::ZERO; n],
            radius,
            material: vec![0; n],
            tag: vec![0; n],
        }
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// Whether there are no particles.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }
}

/// A complete scene description.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The spheres.
    pub particles: ParticleInit,
    /// Material table; particles and walls index into it.
    pub materials: Vec<Material>,
    /// Walls.
    pub walls: Vec<Wall>,
    /// The effects the step runs (and the only ones the data may need).
    pub effects: EffectSet,
    /// Gravitational acceleration, m/s² (used only with the `gravity` effect).
    pub gravity: Vec3,
    /// Contact law of every pair.
    pub model: DemContactLaw,
    /// Clamp the damped normal force at ≥ 0 (no attraction); the Tsuji ζ is solved for the
    /// chosen clamping, so the realised restitution is e either way.
    pub clamp_normal_force: bool,
    /// User time step, s; `None` takes `time_step_safety` × the stable limit.
    pub time_step: Option<f64>,
    /// Fraction of the stable limit used when `time_step` is `None`.
    pub time_step_safety: f64,
    /// Largest relative speed expected in a contact, m/s; sets the Hertz stiffness used in the
    /// stable-step estimate.
    pub expected_max_speed: f64,
    /// Verlet skin, m; `None` takes 0.1 × the largest diameter.
    pub skin: Option<f64>,
    /// Worker threads (1 = serial). Results are bitwise identical for any value.
    pub threads: usize,
    /// Largest accepted initial overlap, as a fraction of the smaller radius.
    pub initial_overlap_tolerance: f64,
    /// Take a [`Frame`](crate::dem::Frame) every this many steps (0 = never).
    pub record_every: u64,
    /// Log every contact onset.
    pub record_onsets: bool,
    /// Log every whole contact, with its duration, peak forces and impulse measured step by
    /// step ([`ContactEvent`](crate::dem::ContactEvent)); costs nothing when off.
    pub record_events: bool,
    /// Outlet: a particle whose centre lies behind this plane (point, normal towards the
    /// kept side; m) is removed at the next neighbour-list rebuild (a particle leaving moves
    /// and soon triggers one). `None`: nothing is removed.
    pub removal_plane: Option<(Vec3, Vec3)>,
}

impl Scene {
    /// A scene with the default numerical settings: Hertz–Mindlin, clamped normal force, step
    /// 0.2 × the stable limit at an expected 1 m/s, skin 0.1 d, 1 thread, 1 % overlap
    /// tolerance, no records.
    pub fn new(
        particles: ParticleInit,
        materials: Vec<Material>,
        walls: Vec<Wall>,
        effects: EffectSet,
    ) -> Self {
        Scene {
            particles,
            materials,
            walls,
            effects,
            gravity: Vec3::new(0.0, 0.0, -9.81),
            model: DemContactLaw::HertzMindlin,
            clamp_normal_force: true,
            time_step: None,
            time_step_safety: 0.2,
            expected_max_speed: 1.0,
            skin: None,
            threads: 1,
            initial_overlap_tolerance: 0.01,
            record_every: 0,
            record_onsets: false,
            record_events: false,
            removal_plane: None,
        }
    }

    /// Check shapes, values and effects. Overlaps are checked when the simulation is built.
    pub fn validate(&self) -> Result<()> {
        let p = &self.particles;
        let n = p.position.len();
        for (field, len) in [
            ("velocity", p.velocity.len()),
            ("angular_velocity", p.angular_velocity.len()),
            ("radius", p.radius.len()),
            ("material", p.material.len()),
            ("tag", p.tag.len()),
        ] {
            if len != n {
                return Err(DemfemError::ShapeMismatch {
                    field: format!("particles.{field}"),
                    detail: format!("{len} entries for {n} particles"),
                });
            }
        }
        if n > (u32::MAX / 2) as usize {
            return Err(DemfemError::invalid("particle count", n as f64, "< 2^31"));
        }
        if self.materials.is_empty() {
            return Err(DemfemError::ShapeMismatch {
                field: "materials".into(),
                detail: "empty".into(),
            });
        }
        for (k, m) in self.materials.iter().enumerate() {
            m.validate(k)?;
        }
        self.model.validate()?;
        for i in 0..n {
            for (name, v) in [
                ("position", p.position[i]),
                ("velocity", p.velocity[i]),
                ("angular_velocity", p.angular_velocity[i]),
            ] {
                if !v.is_finite() {
                    return Err(DemfemError::InvalidParameter {
                        field: format!("particles.{name}[{i}]"),
                        value: format!("{v:?}"),
                        allowed: "finite".into(),
                    });
                }
            }
            check_positive(&format!("particles.radius[{i}]"), p.radius[i])?;
            if p.material[i] >= self.materials.len() {
                return Err(DemfemError::invalid(
                    &format!("particles.material[{i}]"),
                    p.material[i] as f64,
                    &format!("< {} (number of materials)", self.materials.len()),
                ));
            }
        }
        for (w, wall) in self.walls.iter().enumerate() {
            wall.validate()?;
            if wall.material >= self.materials.len() {
                return Err(DemfemError::invalid(
                    &format!("walls[{w}].material"),
                    wall.material as f64,
                    &format!("< {} (number of materials)", self.materials.len()),
                ));
            }
        }
        if !self.gravity.is_finite() {
            return Err(DemfemError::InvalidParameter {
                field: "gravity".into(),
                value: format!("{:?}", self.gravity),
                allowed: "finite".into(),
            });
        }
        if let Some(dt) = self.time_step {
            check_positive("time_step", dt)?;
        }
        crate::error::check_open("time_step_safety", self.time_step_safety, 0.0, 1.0 + 1e-12)?;
        check_positive("expected_max_speed", self.expected_max_speed)?;
        if let Some(s) = self.skin {
            check_positive("skin", s)?;
        }
        if self.threads == 0 {
            return Err(DemfemError::invalid("threads", 0.0, ">= 1"));
        }
        check_non_negative("initial_overlap_tolerance", self.initial_overlap_tolerance)?;
        if let Some((point, normal)) = self.removal_plane {
            if !(point.is_finite() && normal.is_finite() && normal.length() > 0.0) {
                return Err(DemfemError::InvalidParameter {
                    field: "removal_plane".into(),
                    value: format!("{point:?}, {normal:?}"),
                    allowed: "a finite point and a finite non-zero normal".into(),
                });
            }
        }
        self.check_effects()
    }

    /// Refuse a scene whose data needs an effect it did not name, or that names an effect its
    /// data cannot use.
    pub fn check_effects(&self) -> Result<()> {
        let e = self.effects;
        let need = |effect: Effect, why: String| -> Result<()> {
            if e.has(effect) {
                Ok(())
            } else {
                Err(DemfemError::Effect(format!(
                    "{why} but the scene does not name '{}'",
                    effect.name()
                )))
            }
        };
        let unused = |effect: Effect, why: &str| -> Result<()> {
            if e.has(effect) {
                Err(DemfemError::Effect(format!(
                    "the scene names '{}' but {why}",
                    effect.name()
                )))
            } else {
                Ok(())
            }
        };
        // gravity
        if self.gravity != Vec3::ZERO {
            need(
                Effect::Gravity,
                format!("gravity = {:?} m/s² is non-zero", self.gravity),
            )?;
        } else {
            unused(Effect::Gravity, "gravity is zero")?;
        }
        // walls
        let mut any_surface = false;
        let mut any_moving = false;
        for (w, wall) in self.walls.iter().enumerate() {
            let belts = wall.mesh().is_some_and(|m| {
                (0..m.triangles().len() as u32)
                    .any(|t| m.triangle_velocity(t).is_some_and(|v| v != Vec3::ZERO))
            });
            if wall.surface_velocity != Vec3::ZERO || belts {
                any_surface = true;
                need(Effect::Belt, format!("walls[{w}] has a surface velocity"))?;
            }
            if wall.motion.is_moving() {
                any_moving = true;
                need(
                    Effect::MovingWalls,
                    format!("walls[{w}] has a prescribed motion"),
                )?;
            }
        }
        if !any_surface {
            unused(Effect::Belt, "no wall has a surface velocity")?;
        }
        if !any_moving {
            unused(Effect::MovingWalls, "no wall moves")?;
        }
        // materials in use
        let mut used = vec![false; self.materials.len()];
        for &m in &self.particles.material {
            if let Some(u) = used.get_mut(m) {
                *u = true;
            }
        }
        for wall in &self.walls {
            if let Some(u) = used.get_mut(wall.material) {
                *u = true;
            }
        }
        let mut any_friction = false;
        let mut any_rolling = false;
        let mut any_damping = false;
        for (k, m) in self.materials.iter().enumerate() {
            if !used[k] {
                continue;
            }
            if m.friction > 0.0 {
                any_friction = true;
                need(
                    Effect::Friction,
                    format!("materials[{k}].friction = {} > 0", m.friction),
                )?;
            }
            if m.rolling_friction > 0.0 {
                any_rolling = true;
                need(
                    Effect::RollingResistance,
                    format!(
                        "materials[{k}].rolling_friction = {} > 0",
                        m.rolling_friction
                    ),
                )?;
            }
            if m.restitution < 1.0 {
                any_damping = true;
                need(
                    Effect::Damping,
                    format!("materials[{k}].restitution = {} < 1", m.restitution),
                )?;
            }
        }
        if !any_friction {
            unused(Effect::Friction, "every material in use is frictionless")?;
        }
        if !any_rolling {
            unused(
                Effect::RollingResistance,
                "no material in use has rolling friction",
            )?;
        }
        if !any_damping {
            unused(Effect::Damping, "every material in use has restitution 1")?;
        }
        if e.has(Effect::RollingResistance) && !e.has(Effect::Rotation) {
            return Err(DemfemError::Effect(
                "'rolling_resistance' acts on rotation: name 'rotation' too".into(),
            ));
        }
        if !e.has(Effect::Rotation) {
            if let Some(i) = self
                .particles
                .angular_velocity
                .iter()
                .position(|w| *w != Vec3::ZERO)
            {
                return Err(DemfemError::Effect(format!(
                    "particles.angular_velocity[{i}] is non-zero but the scene does not name 'rotation'"
                )));
            }
        }
        if e.has(Effect::Planar) {
            if let Some(i) = self
                .particles
                .angular_velocity
                .iter()
                .position(|w| w.x != 0.0 || w.y != 0.0)
            {
                return Err(DemfemError::Effect(format!(
                    "'planar' allows rotation about z only, but particles.angular_velocity[{i}] has x or y components"
                )));
            }
        }
        Ok(())
    }
}
