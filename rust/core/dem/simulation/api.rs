//! The public API of [`Simulation`]: building one from a scene ([`Simulation::new`]),
//! stepping it ([`Simulation::step`], [`Simulation::run_until`]), its settings (AVX2,
//! batches, phase timing), its state and diagnostics, and removing and reinserting
//! particles.

use super::batch::BATCH;
use super::blocks::CutLists;
use super::lists::WallLists;
use super::simd::cpu_has_avx2;
use super::stable::{stable_time_step, StableStep};
use super::state::WallState;
use super::{Simulation, NO_WALL, PARALLEL_MIN_PARTICLES};
use crate::contact::{self, ForceClamp};
use crate::dem::effects::{Effect, EffectSet};
use crate::dem::material::PairLaw;
use crate::dem::neighbor::CellGrid;
use crate::dem::record::{ContactOnset, Frame};
use crate::dem::scene::Scene;
use crate::error::{DemfemError, Result};
use crate::geometry::Vec3;
use std::sync::atomic::{AtomicU64, Ordering};

impl Simulation {
    /// Build a simulation from a scene: validate it, derive masses, pair laws and the time
    /// step, build the neighbour lists and refuse initial overlaps beyond the tolerance.
    pub fn new(scene: &Scene) -> Result<Self> {
        scene.validate()?;
        let p = &scene.particles;
        let n = p.len();
        let mut mass = Vec::with_capacity(n);
        let mut inertia = Vec::with_capacity(n);
        for i in 0..n {
            let r = p.radius[i];
            let m = scene.materials[p.material[i]].density * 4.0 / 3.0
                * std::f64::consts::PI
                * r
                * r
                * r;
            mass.push(m);
            inertia.push(0.4 * m * r * r);
        }
        let n_materials = scene.materials.len();
        let clamp = if scene.clamp_normal_force {
            ForceClamp::NonNegative
        } else {
            ForceClamp::None
        };
        let mut laws = Vec::with_capacity(n_materials * n_materials);
        // ζ from restitution costs a bisection over an ODE solve: once per distinct e
        let mut zeta_cache: Vec<(u64, f64)> = Vec::new();
        for a in 0..n_materials {
            for b in 0..n_materials {
                let (ma, mb) = (&scene.materials[a], &scene.materials[b]);
                let e = ma.restitution.min(mb.restitution);
                let zeta = if !scene.model.is_hertzian() {
                    0.0
                } else if let Some((_, z)) = zeta_cache.iter().find(|(k, _)| *k == e.to_bits()) {
                    *z
                } else {
                    let z = contact::tsuji_damping_for_restitution(e, clamp)?;
                    zeta_cache.push((e.to_bits(), z));
                    z
                };
                laws.push(PairLaw::with_zeta(ma, mb, scene.model, zeta)?);
            }
        }
        let stable = stable_time_step(scene, &mass)?;
        let dt = match scene.time_step {
            Some(dt) => {
                if dt > stable.limit {
                    return Err(DemfemError::UnstableTimeStep {
                        dt,
                        limit: stable.limit,
                        reason: stable.reason.clone(),
                    });
                }
                dt
            }
            None => scene.time_step_safety * stable.limit,
        };
        let d_max = p.radius.iter().fold(0.0_f64, |a, &r| a.max(2.0 * r));
        let skin = scene.skin.unwrap_or(0.1 * d_max.max(f64::MIN_POSITIVE));
        let pool = if scene.threads > 1 {
            Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(scene.threads)
                    .build()
                    .map_err(|e| {
                        DemfemError::Numerical(format!(
                            "cannot start {} threads: {e}",
                            scene.threads
                        ))
                    })?,
            )
        } else {
            None
        };
        let mut sim = Simulation {
            radius: p.radius.clone(),
            inv_mass: mass.iter().map(|m| 1.0 / m).collect(),
            inv_inertia: inertia.iter().map(|m| 1.0 / m).collect(),
            mass,
            inertia,
            material: p.material.iter().map(|&m| m as u32).collect(),
            tag: p.tag.clone(),
            walls: scene.walls.clone(),
            laws,
            n_materials,
            model: scene.model,
            effects: scene.effects,
            gravity: scene.gravity,
            clamp: scene.clamp_normal_force,
            dt,
            stable,
            skin,
            threads: scene.threads,
            avx2: cpu_has_avx2(),
            batched: true,
            pairs_hertz: false,
            pairs_uniform: None,
            record_every: scene.record_every,
            record_onsets: scene.record_onsets,
            record_events: scene.record_events,
            removal_plane: scene.removal_plane.map(|(p, n)| (p, n / n.length())),
            position: p.position.clone(),
            velocity: p.velocity.clone(),
            omega: p.angular_velocity.clone(),
            alive: vec![true; n],
            time: 0.0,
            steps: 0,
            pairs: Vec::new(),
            pair_active: Vec::new(),
            pair_onset: Vec::new(),
            pair_event: Vec::new(),
            pair_wake: Vec::new(),
            travel: 0.0,
            travel_slack: 0.0,
            travel_step: 0.0,
            cut_lists: CutLists::default(),
            wall_lists: WallLists::default(),
            pair_out: Vec::new(),
            pair_detail: Vec::new(),
            pair_rolling: Vec::new(),
            pair_const: Vec::new(),
            contact_table: Vec::new(),
            wall_slots: Vec::new(),
            wall_event: Vec::new(),
            wall_out: Vec::new(),
            wall_detail: Vec::new(),
            detail: true,
            wall_stride: 1,
            reference_position: p.position.clone(),
            reference_wall_offset: vec![Vec3::ZERO; scene.walls.len()],
            reference_wall_angle: vec![0.0; scene.walls.len()],
            wall_reach: scene.walls.iter().map(|w| w.rotation_reach()).collect(),
            needs_rebuild: true,
            active_base: vec![0; n + 1],
            active_len: vec![0; n],
            active_entry: Vec::new(),
            pair_listed: Vec::new(),
            pair_start: vec![0; n + 1],
            grid: CellGrid::default(),
            candidate_scratch: Vec::new(),
            old_pairs: Vec::new(),
            old_pair_active: Vec::new(),
            old_pair_onset: Vec::new(),
            old_pair_event: Vec::new(),
            old_slots: Vec::new(),
            old_wall_event: Vec::new(),
            wall_state: vec![WallState::default(); scene.walls.len()],
            chunk_flips: Vec::new(),
            chunk_results: Vec::new(),
            phase_clock: Vec::new(),
            balance_clock: Vec::new(),
            balance_steps: 0,
            balance_cost: Vec::new(),
            contact_force_sum: vec![Vec3::ZERO; n],
            coordination: vec![0; n],
            wall_coordination: vec![0; n],
            pool,
            frames: Vec::new(),
            onsets: Vec::new(),
            events: Vec::new(),
            rebuilds: 0,
            removals: Vec::new(),
        };
        sim.refresh_wall_state();
        sim.rebuild();
        sim.check_initial_overlaps(scene.initial_overlap_tolerance)?;
        Ok(sim)
    }

    fn check_initial_overlaps(&self, tolerance: f64) -> Result<()> {
        for p in &self.pairs {
            let (i, j) = (p.i as usize, p.j as usize);
            let overlap =
                self.radius[i] + self.radius[j] - (self.position[j] - self.position[i]).length();
            if overlap > tolerance * self.radius[i].min(self.radius[j]) {
                return Err(DemfemError::InvalidParameter {
                    field: format!("particles {i} and {j}"),
                    value: format!("initial overlap {overlap:e} m"),
                    allowed: format!("overlap <= {tolerance} x the smaller radius"),
                });
            }
        }
        for i in 0..self.position.len() {
            for s in &self.wall_slots[i * self.wall_stride..(i + 1) * self.wall_stride] {
                if s.wall == NO_WALL {
                    break;
                }
                let ws = self.wall_state[s.wall as usize];
                if let Some((_, _, d)) = self.walls[s.wall as usize].slot_closest_at(
                    s.triangle,
                    self.position[i],
                    ws.offset,
                    self.radius[i],
                ) {
                    let overlap = self.radius[i] - d;
                    if overlap > tolerance * self.radius[i] {
                        return Err(DemfemError::InvalidParameter {
                            field: format!("particle {i} and wall {}", s.wall),
                            value: format!("initial overlap {overlap:e} m"),
                            allowed: format!("overlap <= {tolerance} x the radius"),
                        });
                    }
                }
            }
        }
        Ok(())
    }

    /// Advance `n` steps.
    pub fn step(&mut self, n: u64) -> Result<()> {
        match self.pool.take() {
            Some(pool) if self.position.len() >= PARALLEL_MIN_PARTICLES => {
                let r = pool.install(|| {
                    for k in 0..n {
                        self.detail = self.record_events || k + 1 == n || self.frame_due_next();
                        self.one_step(true)?;
                    }
                    Ok(())
                });
                self.pool = Some(pool);
                r
            }
            other => {
                self.pool = other;
                for k in 0..n {
                    self.detail = self.record_events || k + 1 == n || self.frame_due_next();
                    self.one_step(false)?;
                }
                Ok(())
            }
        }
    }

    /// Advance until the simulated time reaches `t_end` (s); returns the steps taken.
    pub fn run_until(&mut self, t_end: f64) -> Result<u64> {
        if !t_end.is_finite() {
            return Err(DemfemError::invalid("t_end", t_end, "finite"));
        }
        let remaining = ((t_end - self.time) / self.dt).ceil();
        if remaining <= 0.0 {
            return Ok(0);
        }
        let n = remaining as u64;
        self.step(n)?;
        Ok(n)
    }

    // ---- accessors
    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.time
    }
    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }
    /// Time step, s.
    pub fn dt(&self) -> f64 {
        self.dt
    }
    /// The stable limit and what sets it.
    pub fn stable_step(&self) -> &StableStep {
        &self.stable
    }
    /// Whether the step runs its AVX2 build of the kernels (x86-64 CPUs with AVX2, unless the
    /// environment variable `DEMFEM_NO_AVX2` was set when the simulation was built).
    pub fn uses_avx2(&self) -> bool {
        self.avx2
    }

    /// Choose the AVX2 build (`true`, taken only if the CPU has AVX2) or the baseline build
    /// (`false`) of the step kernels; returns the build now in use. Both give bitwise the same
    /// results (a test checks it); this exists to compare their speed and to test that.
    pub fn set_avx2(&mut self, on: bool) -> bool {
        self.avx2 = on && cpu_has_avx2();
        self.avx2
    }

    /// Evaluate contacts in batches (`true`, the default; see the module documentation) or
    /// one at a time (`false`, the reference kernels). Both give bitwise the same results (a
    /// test checks it); this exists to compare their speed and to test that. Scenes with
    /// rolling resistance always run one at a time.
    pub fn set_batched(&mut self, on: bool) {
        self.batched = on;
    }

    /// Start (`true`, from zero) or stop the clock of [`Simulation::phase_times`]. Off by
    /// default: it reads the clock twice per block and phase in every step.
    pub fn set_phase_timing(&mut self, on: bool) {
        self.phase_clock.clear();
        if on {
            let blocks = self.threads.max(1);
            self.phase_clock
                .extend((0..blocks).map(|_| [AtomicU64::new(0), AtomicU64::new(0)]));
        }
    }

    /// Per block of the step (one per thread): seconds spent in the force phase and in the
    /// particle phase since [`Simulation::set_phase_timing`] turned the clock on (empty if
    /// it is off). A development aid for the balance between threads.
    pub fn phase_times(&self) -> Vec<[f64; 2]> {
        self.phase_clock
            .iter()
            .map(|c| {
                c.each_ref()
                    .map(|a| a.load(Ordering::Relaxed) as f64 * 1e-9)
            })
            .collect()
    }

    /// Where the threads' blocks of particles begin: one particle index per block after
    /// the first (empty on one thread). The cuts start from estimated costs and follow the
    /// blocks' measured times ([`Simulation::cut_blocks`]); results do not depend on them.
    pub fn block_cuts(&self) -> Vec<usize> {
        if self.threads > 1 {
            self.cut_lists.particle.clone()
        } else {
            Vec::new()
        }
    }

    /// How many particle–wall slots the AVX2 plane pass took in the last step (four particles
    /// at a time; see the module doc): a diagnostic of the kernels, 0 when the step does not
    /// use it (no AVX2, no batches, rolling resistance).
    pub fn plane_pass_slots(&self) -> usize {
        let used = self.avx2
            && self.batched
            && !self.effects.has(Effect::RollingResistance)
            && self.wall_stride <= BATCH
            && self.steps > 0;
        if !used {
            return 0;
        }
        self.wall_slots
            .iter()
            .filter(|s| s.wall != NO_WALL && s.planar_pass)
            .count()
    }

    /// How many candidate pairs out of contact the batched pair kernel will skip at the next
    /// step because they cannot have closed their gap yet (see [`Simulation::pair_wake`]); a
    /// diagnostic for tests and benchmarks.
    pub fn sleeping_pairs(&self) -> usize {
        self.pair_wake.iter().filter(|&&w| self.travel < w).count()
    }

    /// Whether the batched AVX2 pair kernel takes the uniform path: every pair indexes one
    /// Hertz or Hertz–Reissner law entry and every sphere has one radius, so the constants
    /// and radii are written into the batch once per chunk and the law is evaluated in the
    /// lanes (a diagnostic; results are bitwise those of the general path).
    pub fn uniform_pairs(&self) -> bool {
        self.avx2 && self.batched && self.pairs_uniform.is_some()
    }

    /// Whether contacts are evaluated in batches (see [`Simulation::set_batched`]).
    pub fn uses_batches(&self) -> bool {
        self.batched
    }

    /// Worker threads the simulation was built with.
    pub fn threads(&self) -> usize {
        self.threads
    }
    /// Verlet skin, m.
    pub fn skin(&self) -> f64 {
        self.skin
    }
    /// Number of neighbour-list rebuilds so far.
    pub fn rebuilds(&self) -> u64 {
        self.rebuilds
    }
    /// Candidate pairs in the Verlet list and particle–wall slots in use (a measure of the
    /// neighbour-list work per step).
    pub fn candidate_counts(&self) -> (usize, usize) {
        let slots = self.wall_slots.iter().filter(|s| s.wall != NO_WALL).count();
        (self.pairs.len(), slots)
    }
    /// Number of particles (alive or not).
    pub fn len(&self) -> usize {
        self.position.len()
    }
    /// Whether the simulation has no particle.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }
    /// Centres, m.
    pub fn positions(&self) -> &[Vec3] {
        &self.position
    }
    /// Velocities (half step), m/s.
    pub fn velocities(&self) -> &[Vec3] {
        &self.velocity
    }
    /// Angular velocities (half step), rad/s.
    pub fn angular_velocities(&self) -> &[Vec3] {
        &self.omega
    }
    /// Radii, m.
    pub fn radii(&self) -> &[f64] {
        &self.radius
    }
    /// Masses, kg.
    pub fn masses(&self) -> &[f64] {
        &self.mass
    }
    /// Moments of inertia, kg m².
    pub fn inertias(&self) -> &[f64] {
        &self.inertia
    }
    /// Tags.
    pub fn tags(&self) -> &[u32] {
        &self.tag
    }
    /// Alive flags.
    pub fn alive(&self) -> &[bool] {
        &self.alive
    }
    /// Sum of contact forces on each particle at the last step, N.
    pub fn contact_force_sums(&self) -> &[Vec3] {
        &self.contact_force_sum
    }
    /// Particle–particle coordination number of each particle at the last step.
    pub fn coordination(&self) -> &[u32] {
        &self.coordination
    }
    /// Wall contacts of each particle at the last step.
    pub fn wall_contact_counts(&self) -> &[u32] {
        &self.wall_coordination
    }
    /// Recorded frames.
    pub fn frames(&self) -> &[Frame] {
        &self.frames
    }
    /// Logged contact onsets.
    pub fn onsets(&self) -> &[ContactOnset] {
        &self.onsets
    }
    /// Drop the recorded frames, onsets and events (e.g. after copying them out).
    pub fn clear_records(&mut self) {
        self.frames.clear();
        self.onsets.clear();
        self.events.clear();
    }
    /// Effects the step runs.
    pub fn effects(&self) -> EffectSet {
        self.effects
    }
    /// Pair law of materials a and b.
    pub fn pair_law(&self, a: usize, b: usize) -> Option<&PairLaw> {
        if a < self.n_materials && b < self.n_materials {
            self.laws.get(a * self.n_materials + b)
        } else {
            None
        }
    }

    /// (time in s, particle index) of every particle removed through the outlet plane.
    pub fn removals(&self) -> &[(f64, u32)] {
        &self.removals
    }

    /// Remove particle `i` from the simulation (it stops interacting and moving).
    pub fn remove_particle(&mut self, i: usize) -> Result<()> {
        if i >= self.position.len() {
            return Err(DemfemError::invalid(
                "particle index",
                i as f64,
                &format!("< {}", self.position.len()),
            ));
        }
        self.alive[i] = false;
        self.needs_rebuild = true;
        Ok(())
    }

    /// Put removed particle `i` back at `position` (m) with `velocity` (m/s) and no spin, e.g.
    /// to re-feed the table upstream. Refused if `i` is alive, if a value is not finite, or
    /// if the particle would overlap an alive particle. Its contacts start afresh at the next neighbour-list rebuild,
    /// which is forced.
    pub fn reinsert_particle(&mut self, i: usize, position: Vec3, velocity: Vec3) -> Result<()> {
        let n = self.position.len();
        if i >= n {
            return Err(DemfemError::invalid(
                "particle index",
                i as f64,
                &format!("< {n}"),
            ));
        }
        if self.alive[i] {
            return Err(DemfemError::invalid(
                "particle index",
                i as f64,
                "a removed particle (this one is alive)",
            ));
        }
        if !(position.is_finite() && velocity.is_finite()) {
            return Err(DemfemError::InvalidParameter {
                field: "position/velocity".into(),
                value: format!("{position:?} / {velocity:?}"),
                allowed: "finite".into(),
            });
        }
        let r = self.radius[i];
        for j in 0..n {
            if j == i || !self.alive[j] {
                continue;
            }
            let gap = (self.position[j] - position).length() - (r + self.radius[j]);
            if gap < -1e-9 * r.min(self.radius[j]) {
                return Err(DemfemError::InvalidParameter {
                    field: "position".into(),
                    value: format!("{position:?}"),
                    allowed: format!("a free site (particle {i} would overlap particle {j})"),
                });
            }
        }
        self.position[i] = position;
        self.velocity[i] = velocity;
        self.omega[i] = Vec3::ZERO;
        self.alive[i] = true;
        self.needs_rebuild = true;
        Ok(())
    }

    /// Kinetic energy (translation + rotation) of the alive particles, J.
    pub fn kinetic_energy(&self) -> f64 {
        let mut e = 0.0;
        for i in 0..self.position.len() {
            if self.alive[i] {
                e += 0.5 * self.mass[i] * self.velocity[i].length_squared()
                    + 0.5 * self.inertia[i] * self.omega[i].length_squared();
            }
        }
        e
    }

    /// Largest particle–particle or particle–wall overlap at the last step, m.
    pub fn max_overlap(&self) -> f64 {
        let a = self
            .pair_active
            .iter()
            .zip(&self.pair_out)
            .filter(|(&active, _)| active)
            .map(|(_, o)| o.overlap)
            .fold(0.0, f64::max);
        let b = self
            .wall_slots
            .iter()
            .zip(&self.wall_detail)
            .filter(|(s, _)| s.wall != NO_WALL && s.active)
            .map(|(_, d)| d.overlap)
            .fold(0.0, f64::max);
        a.max(b)
    }

    /// Number of alive spheres whose centre is higher than `floor_z` + radius + `tolerance`
    /// (m): spheres that ride on top of others, which an upright cartridge cannot do.
    pub fn riding_up_count(&self, floor_z: f64, tolerance: f64) -> usize {
        (0..self.position.len())
            .filter(|&i| self.alive[i] && self.position[i].z > floor_z + self.radius[i] + tolerance)
            .count()
    }
}
