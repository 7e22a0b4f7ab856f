//! Python binding of the DEM engine: `DemSimulation`, built from plain arrays and dicts,
//! stepping with the GIL released in chunks so Ctrl-C stops a run cleanly at a step
//! boundary; state and records come back as numpy arrays. SI units throughout.

use std::path::PathBuf;

use numpy::{IntoPyArray, PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use demfem::dem::{DemContactLaw, EffectSet, Material, ParticleInit, Scene, Simulation};
use demfem::geometry::Vec3;

use crate::convert::{
    array_n3, as_float_array, as_int_array, count, flat3, float1, float2, get_f64, int1,
    set_partner_columns, vec3s,
};
use crate::dem_events::event_columns;
use crate::dem_walls::parse_wall;
use crate::error::{invalid, shape_err, CoreResult, PyDemfemError};
use crate::run::{checked_steps, run_in_chunks, step_count_arg, steps_until};

/// Largest time step a DEM simulation accepts, s: with no particles (or no stiffness) the
/// stable limit is infinite, and a step beyond this is a mistake, not a DEM step.
pub(crate) const MAX_DT: f64 = 1.0;

fn parse_material(d: &Bound<'_, PyDict>, k: usize) -> PyResult<Material> {
    let w = format!("materials[{k}]");
    Ok(Material {
        young_modulus: get_f64(d, "young_modulus", None, &w)?,
        poisson_ratio: get_f64(d, "poisson_ratio", None, &w)?,
        density: get_f64(d, "density", None, &w)?,
        friction: get_f64(d, "friction", Some(0.0), &w)?,
        restitution: get_f64(d, "restitution", Some(1.0), &w)?,
        rolling_friction: get_f64(d, "rolling_friction", Some(0.0), &w)?,
        shell_stiffness: get_f64(d, "shell_stiffness", Some(f64::INFINITY), &w)?,
    })
}

/// Most neighbour-grid cells (of one particle diameter) the particle centres may span along
/// one axis: beyond it the scene is refused rather than searched (centres at ±1e308 m made
/// the grid build spin at 100 % CPU).
pub(crate) const MAX_GRID_CELLS_PER_AXIS: f64 = 1e7;

/// Refuse particle centres whose span along an axis exceeds [`MAX_GRID_CELLS_PER_AXIS`]
/// particle diameters (2 r_max), or overflows. Non-finite centres and bad radii are left to
/// the scene's own validation, which names them.
fn check_grid_extent(position: &[Vec3], radius: &[f64]) -> PyResult<()> {
    let r_max = radius
        .iter()
        .copied()
        .filter(|r| r.is_finite() && *r > 0.0)
        .fold(0.0f64, f64::max);
    if r_max <= 0.0 || position.len() < 2 {
        return Ok(());
    }
    let mut lo = Vec3::splat(f64::INFINITY);
    let mut hi = Vec3::splat(f64::NEG_INFINITY);
    for p in position.iter().filter(|p| p.is_finite()) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let cell = 2.0 * r_max;
    let allowed = MAX_GRID_CELLS_PER_AXIS * cell;
    let (lo, hi) = (lo.to_array(), hi.to_array());
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        let span = hi[k] - lo[k];
        // an empty set of finite centres leaves span = -inf: nothing to check
        if span > allowed || span.is_nan() {
            return Err(invalid(
                "positions",
                &format!(
                    "centres spanning {span:e} m along {axis} (from {:e} to {:e} m)",
                    lo[k], hi[k]
                ),
                &format!(
                    "an extent of at most {MAX_GRID_CELLS_PER_AXIS:e} neighbour cells of one \
                     particle diameter (2 r_max = {cell:e} m) per axis, i.e. <= {allowed:e} m"
                ),
            ));
        }
    }
    Ok(())
}

/// A DEM simulation of spheres and walls (see `demfem._core.pyi` for the full signature).
#[pyclass(module = "demfem._core")]
pub struct DemSimulation {
    sim: Simulation,
}

#[pymethods]
impl DemSimulation {
    #[new]
    #[pyo3(signature = (
        positions, radii, materials, walls, effects, *, velocities=None, angular_velocities=None,
        material_ids=None, tags=None, gravity=(0.0, 0.0, -9.81), model="hertz_mindlin",
        linear_stiffness=None, clamp_normal_force=true, dt=None, dt_safety=0.2,
        expected_max_speed=1.0, skin=None, threads=1, overlap_tolerance=0.01, record_every=0,
        record_onsets=false, removal_plane=None, record_events=false
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        positions: &Bound<'_, PyAny>,
        radii: &Bound<'_, PyAny>,
        materials: &Bound<'_, PyList>,
        walls: &Bound<'_, PyList>,
        effects: Vec<String>,
        velocities: Option<&Bound<'_, PyAny>>,
        angular_velocities: Option<&Bound<'_, PyAny>>,
        material_ids: Option<&Bound<'_, PyAny>>,
        tags: Option<&Bound<'_, PyAny>>,
        gravity: (f64, f64, f64),
        model: &str,
        linear_stiffness: Option<(f64, f64)>,
        clamp_normal_force: bool,
        dt: Option<f64>,
        dt_safety: f64,
        expected_max_speed: f64,
        skin: Option<f64>,
        threads: i64,
        overlap_tolerance: f64,
        record_every: i64,
        record_onsets: bool,
        removal_plane: Option<((f64, f64, f64), (f64, f64, f64))>,
        record_events: bool,
    ) -> PyResult<Self> {
        if threads < 1 {
            return Err(invalid(
                "threads",
                &threads.to_string(),
                "a whole number >= 1",
            ));
        }
        let threads = usize::try_from(threads)
            .map_err(|_| invalid("threads", &threads.to_string(), "a whole number >= 1"))?;
        let record_every = count("record_every", record_every)?;
        if let Some(step) = dt {
            if !(step.is_finite() && step > 0.0 && step <= MAX_DT) {
                return Err(invalid(
                    "dt",
                    &format!("{step:e}"),
                    &format!("finite, > 0 and <= {MAX_DT} s (a DEM time step)"),
                ));
            }
        }
        let positions = float2(&as_float_array(positions, "positions")?, "positions")?;
        let position = vec3s("positions", &positions, None)?;
        let n = position.len();
        let radii = float1(&as_float_array(radii, "radii")?, "radii")?;
        let radius: Vec<f64> = radii.as_array().to_vec();
        if radius.len() != n {
            return Err(shape_err(
                "radii",
                format!("{} entries for {n} particles", radius.len()),
            ));
        }
        check_grid_extent(&position, &radius)?;
        let mut p = ParticleInit::at_rest(position, radius);
        if let Some(v) = velocities {
            let v = float2(&as_float_array(v, "velocities")?, "velocities")?;
            p.velocity = vec3s("velocities", &v, Some(n))?;
        }
        if let Some(w) = angular_velocities {
            let w = float2(
                &as_float_array(w, "angular_velocities")?,
                "angular_velocities",
            )?;
            p.angular_velocity = vec3s("angular_velocities", &w, Some(n))?;
        }
        if let Some(m) = material_ids {
            let m = int1(&as_int_array(m, "material_ids")?, "material_ids")?;
            let m = m.as_array();
            if m.len() != n {
                return Err(shape_err(
                    "material_ids",
                    format!("{} entries for {n} particles", m.len()),
                ));
            }
            p.material = m
                .iter()
                .map(|&x| {
                    usize::try_from(x).map_err(|_| invalid("material_ids", &x.to_string(), ">= 0"))
                })
                .collect::<PyResult<_>>()?;
        }
        if let Some(t) = tags {
            let t = int1(&as_int_array(t, "tags")?, "tags")?;
            let t = t.as_array();
            if t.len() != n {
                return Err(shape_err(
                    "tags",
                    format!("{} entries for {n} particles", t.len()),
                ));
            }
            p.tag = t
                .iter()
                .map(|&x| {
                    u32::try_from(x).map_err(|_| invalid("tags", &x.to_string(), "in [0, 2^32)"))
                })
                .collect::<PyResult<_>>()?;
        }
        let mut mats = Vec::new();
        for (k, m) in materials.iter().enumerate() {
            let d = m
                .cast_into::<PyDict>()
                .map_err(|_| invalid(&format!("materials[{k}]"), "not a dict", "a dict"))?;
            mats.push(parse_material(&d, k)?);
        }
        let mut ws = Vec::new();
        for (k, w) in walls.iter().enumerate() {
            let d = w
                .cast_into::<PyDict>()
                .map_err(|_| invalid(&format!("walls[{k}]"), "not a dict", "a dict"))?;
            ws.push(parse_wall(&d, k)?);
        }
        let effects = EffectSet::parse(&effects).map_err(PyDemfemError::from)?;
        let mut scene = Scene::new(p, mats, ws, effects);
        scene.gravity = Vec3::new(gravity.0, gravity.1, gravity.2);
        scene.model = match (model, linear_stiffness) {
            ("hertz_mindlin", _) => DemContactLaw::HertzMindlin,
            ("hertz_reissner_mindlin", _) => DemContactLaw::HertzReissnerMindlin,
            ("linear", Some((kn, kt))) => DemContactLaw::LinearSpringDashpot {
                normal_stiffness: kn,
                tangential_stiffness: kt,
            },
            ("linear", None) => {
                return Err(invalid(
                    "linear_stiffness",
                    "None",
                    "(k_n, k_t) in N/m for model='linear'",
                ))
            }
            (other, _) => {
                return Err(invalid(
                    "model",
                    other,
                    "'hertz_mindlin', 'hertz_reissner_mindlin' or 'linear'",
                ))
            }
        };
        scene.clamp_normal_force = clamp_normal_force;
        scene.time_step = dt;
        scene.time_step_safety = dt_safety;
        scene.expected_max_speed = expected_max_speed;
        scene.skin = skin;
        scene.threads = threads;
        scene.initial_overlap_tolerance = overlap_tolerance;
        scene.record_every = record_every;
        scene.record_onsets = record_onsets;
        scene.record_events = record_events;
        scene.removal_plane =
            removal_plane.map(|(p, n)| (Vec3::new(p.0, p.1, p.2), Vec3::new(n.0, n.1, n.2)));
        let sim = py
            .detach(|| Simulation::new(&scene))
            .map_err(PyDemfemError::from)?;
        Ok(DemSimulation { sim })
    }

    /// Benchmark fixture, not part of the API: the anchor accumulation table of
    /// `shared/anchors/dem/scene.py`, built exactly as Yade and LIGGGHTS build it for
    /// `benches/dem_anchor_ratio.py` (840 glass spheres of 16 mm, belt 0.2 m/s, funnel with
    /// closed outlet, dt = 0.5 r √(ρ/E)) at Young's modulus `young_modulus` (Pa). `start`:
    /// "square" (scene.py's 1 %-gap square packing at rest) or "packed" (dense hexagonal
    /// packing against the funnel); `initial_vx` (m/s) sets every sphere's x velocity. Users
    /// build tables with `demfem.scenes.AccumulationTable` and `demfem.dem.from_scene`.
    #[staticmethod]
    #[pyo3(name = "_anchor_table", signature = (young_modulus=45e9, start="square", threads=1, initial_vx=0.0, record_every=0, record_onsets=false))]
    fn anchor_table(
        py: Python<'_>,
        young_modulus: f64,
        start: &str,
        threads: usize,
        initial_vx: f64,
        record_every: u64,
        record_onsets: bool,
    ) -> PyResult<Self> {
        use demfem::dem::table::{anchor_scene, TableStart};
        let start = match start {
            "square" => TableStart::SquarePacking,
            "packed" => TableStart::PackedIntoFunnel,
            other => return Err(invalid("start", other, "'square' or 'packed'")),
        };
        let mut scene = anchor_scene(young_modulus, start).map_err(PyDemfemError::from)?;
        for v in scene.particles.velocity.iter_mut() {
            v.x = initial_vx;
        }
        scene.threads = threads;
        scene.record_every = record_every;
        scene.record_onsets = record_onsets;
        let sim = py
            .detach(|| Simulation::new(&scene))
            .map_err(PyDemfemError::from)?;
        Ok(DemSimulation { sim })
    }

    /// Particles removed through the outlet plane: (times (s), indices).
    fn removals<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<u32>>) {
        let (t, i): (Vec<f64>, Vec<u32>) = self.sim.removals().iter().copied().unzip();
        (t.into_pyarray(py), i.into_pyarray(py))
    }

    /// Advance `n` steps, releasing the GIL in chunks of `chunk` steps; Ctrl-C between chunks
    /// raises SimulationInterrupted with the state consistent at a step boundary.
    #[pyo3(signature = (n, chunk=2000))]
    fn step(&mut self, py: Python<'_>, n: &Bound<'_, PyAny>, chunk: i64) -> PyResult<()> {
        self.step_count(py, step_count_arg(n)?, chunk)
    }

    /// Advance until the simulated time reaches `t_end` (s); returns the steps taken.
    #[pyo3(signature = (t_end, chunk=2000))]
    fn run_until(&mut self, py: Python<'_>, t_end: f64, chunk: i64) -> PyResult<u64> {
        let n = steps_until(t_end, self.sim.time(), self.sim.dt())?;
        let steps = i64::try_from(n)
            .map_err(|_| invalid("t_end", &t_end.to_string(), "reachable in < 2^63 steps"))?;
        self.step_count(py, steps, chunk)?;
        Ok(n)
    }

    /// Simulated time, s.
    #[getter]
    fn time(&self) -> f64 {
        self.sim.time()
    }
    /// Steps taken.
    #[getter]
    fn steps(&self) -> u64 {
        self.sim.steps()
    }
    /// Time step, s.
    #[getter]
    fn dt(&self) -> f64 {
        self.sim.dt()
    }
    /// Stable time-step limit, s.
    #[getter]
    fn stable_dt(&self) -> f64 {
        self.sim.stable_step().limit
    }
    /// What sets the stable limit.
    #[getter]
    fn stable_dt_reason(&self) -> String {
        self.sim.stable_step().reason.clone()
    }
    /// Number of particles.
    fn __len__(&self) -> usize {
        self.sim.len()
    }
    /// Effect names the step runs.
    #[getter]
    fn effects(&self) -> Vec<&'static str> {
        self.sim.effects().names()
    }

    /// Centres, m, shape (N, 3).
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        array_n3(py, self.sim.positions())
    }
    /// Velocities (half step), m/s, shape (N, 3).
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        array_n3(py, self.sim.velocities())
    }
    /// Angular velocities (half step), rad/s, shape (N, 3).
    fn angular_velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        array_n3(py, self.sim.angular_velocities())
    }
    /// Sum of contact forces per particle at the last step, N, shape (N, 3).
    fn contact_force_sums<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        array_n3(py, self.sim.contact_force_sums())
    }
    /// Radii, m.
    fn radii<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.sim.radii().to_vec().into_pyarray(py)
    }
    /// Masses, kg.
    fn masses<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.sim.masses().to_vec().into_pyarray(py)
    }
    /// Particle–particle coordination number of each particle.
    fn coordination<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        self.sim.coordination().to_vec().into_pyarray(py)
    }
    /// Wall contacts of each particle.
    fn wall_contacts<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        self.sim.wall_contact_counts().to_vec().into_pyarray(py)
    }
    /// Tags.
    fn tags<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        self.sim.tags().to_vec().into_pyarray(py)
    }
    /// Alive flags.
    fn alive<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        self.sim.alive().to_vec().into_pyarray(py)
    }
    /// Kinetic energy (translation + rotation), J.
    fn kinetic_energy(&self) -> f64 {
        self.sim.kinetic_energy()
    }
    /// Largest overlap at the last step, m.
    fn max_overlap(&self) -> f64 {
        self.sim.max_overlap()
    }
    /// Spheres whose centre is above floor_z + radius + tolerance (m).
    #[pyo3(signature = (floor_z=0.0, tolerance=0.002))]
    fn riding_up_count(&self, floor_z: f64, tolerance: f64) -> usize {
        self.sim.riding_up_count(floor_z, tolerance)
    }
    /// Remove particle `i` (it stops moving and interacting).
    fn remove_particle(&mut self, i: usize) -> CoreResult<()> {
        Ok(self.sim.remove_particle(i)?)
    }

    /// Put removed particle `i` back at `position` (m) with `velocity` (m/s), no spin;
    /// refused if it is alive, a value is not finite, or the site overlaps an alive particle.
    fn reinsert_particle(
        &mut self,
        i: usize,
        position: (f64, f64, f64),
        velocity: (f64, f64, f64),
    ) -> CoreResult<()> {
        Ok(self.sim.reinsert_particle(
            i,
            Vec3::new(position.0, position.1, position.2),
            Vec3::new(velocity.0, velocity.1, velocity.2),
        )?)
    }

    /// Recorded frames as a dict of stacked arrays: time (F,), step (F,), positions,
    /// velocities, angular_velocities, contact_force_sums (F, N, 3), coordination,
    /// wall_contacts (F, N).
    fn frames<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let fr = self.sim.frames();
        let n = self.sim.len();
        let d = PyDict::new(py);
        d.set_item(
            "time",
            fr.iter()
                .map(|f| f.time)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        d.set_item(
            "step",
            fr.iter()
                .map(|f| f.step)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        let stack3 =
            |get: &dyn Fn(&demfem::dem::Frame) -> &Vec<Vec3>| -> PyResult<Bound<'py, PyAny>> {
                let mut flat = Vec::with_capacity(fr.len() * n * 3);
                for f in fr {
                    flat.extend(flat3(get(f)));
                }
                Ok(flat.into_pyarray(py).reshape([fr.len(), n, 3])?.into_any())
            };
        d.set_item("positions", stack3(&|f| &f.position)?)?;
        d.set_item("velocities", stack3(&|f| &f.velocity)?)?;
        d.set_item("angular_velocities", stack3(&|f| &f.angular_velocity)?)?;
        d.set_item("contact_force_sums", stack3(&|f| &f.contact_force_sum)?)?;
        let stack_u =
            |get: &dyn Fn(&demfem::dem::Frame) -> &Vec<u32>| -> PyResult<Bound<'py, PyAny>> {
                let mut flat = Vec::with_capacity(fr.len() * n);
                for f in fr {
                    flat.extend_from_slice(get(f));
                }
                Ok(flat.into_pyarray(py).reshape([fr.len(), n])?.into_any())
            };
        d.set_item("coordination", stack_u(&|f| &f.coordination)?)?;
        d.set_item("wall_contacts", stack_u(&|f| &f.wall_contacts)?)?;
        Ok(d)
    }

    /// Every contact onset: time, step, particle, partner, partner_is_wall, normal_speed,
    /// tangential_speed (m/s), position, partner_position (K, 3) (m).
    fn onsets<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let o = self.sim.onsets();
        let d = PyDict::new(py);
        d.set_item(
            "time",
            o.iter()
                .map(|x| x.time)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        d.set_item(
            "step",
            o.iter()
                .map(|x| x.step)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        d.set_item(
            "particle",
            o.iter()
                .map(|x| x.particle)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        set_partner_columns(py, &d, o.iter().map(|x| x.partner))?;
        d.set_item(
            "normal_speed",
            o.iter()
                .map(|x| x.normal_speed)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        d.set_item(
            "tangential_speed",
            o.iter()
                .map(|x| x.tangential_speed)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        d.set_item(
            "position",
            array_n3(py, &o.iter().map(|x| x.position).collect::<Vec<_>>())?,
        )?;
        d.set_item(
            "partner_position",
            array_n3(
                py,
                &o.iter().map(|x| x.partner_position).collect::<Vec<_>>(),
            )?,
        )?;
        Ok(d)
    }

    /// Active contacts: particle, partner, partner_is_wall, normal (K, 3), normal_force (N),
    /// tangential_force (K, 3) (N), overlap (m), point (K, 3) (m).
    fn contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = self.sim.contacts();
        let d = PyDict::new(py);
        d.set_item(
            "particle",
            c.iter()
                .map(|x| x.particle)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        set_partner_columns(py, &d, c.iter().map(|x| x.partner))?;
        d.set_item(
            "normal",
            array_n3(py, &c.iter().map(|x| x.normal).collect::<Vec<_>>())?,
        )?;
        d.set_item(
            "normal_force",
            c.iter()
                .map(|x| x.normal_force)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        d.set_item(
            "tangential_force",
            array_n3(
                py,
                &c.iter().map(|x| x.tangential_force).collect::<Vec<_>>(),
            )?,
        )?;
        d.set_item(
            "overlap",
            c.iter()
                .map(|x| x.overlap)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        d.set_item(
            "point",
            array_n3(py, &c.iter().map(|x| x.point).collect::<Vec<_>>())?,
        )?;
        Ok(d)
    }

    /// Every whole contact that ended (recorded with `record_events=True`): see
    /// `demfem.dem` for the columns (time, duration, particle, partner, partner_is_wall,
    /// onset speeds, positions, peak_normal_force, normal_impulse, peak_tangential_force,
    /// max_overlap, complete), SI units.
    fn events<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        event_columns(py, self.sim.events())
    }

    /// The contacts open now, as events so far (`complete` False); the log is unchanged.
    fn open_events<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        event_columns(py, &self.sim.open_events())
    }

    /// Drop recorded frames, onsets and events.
    fn clear_records(&mut self) {
        self.sim.clear_records();
    }

    /// Start (`True`, from zero) or stop the per-thread clock of the two phases of a step
    /// (diagnostics; off by default, and the results are the same either way).
    fn set_phase_timing(&mut self, on: bool) {
        self.sim.set_phase_timing(on);
    }

    /// Wall time of each engine thread's block in the force phase and in the particle
    /// phase since `set_phase_timing(True)`, s: one `(force_s, particle_s)` per block.
    fn phase_times(&self) -> Vec<(f64, f64)> {
        self.sim
            .phase_times()
            .into_iter()
            .map(|[force, particle]| (force, particle))
            .collect()
    }

    /// Where the engine's threads' blocks of particles begin (particle indices, one per
    /// thread after the first; empty on one thread). The cuts follow each block's measured
    /// time; they never change the results.
    fn block_cuts(&self) -> Vec<usize> {
        self.sim.block_cuts()
    }

    /// Write a checkpoint atomically to `path`.
    fn save_checkpoint(&self, py: Python<'_>, path: PathBuf) -> CoreResult<()> {
        let sim = &self.sim;
        Ok(py.detach(|| sim.save_checkpoint(&path))?)
    }

    /// Restore a checkpoint written by a simulation built from the same scene.
    fn load_checkpoint(&mut self, py: Python<'_>, path: PathBuf) -> CoreResult<()> {
        let sim = &mut self.sim;
        Ok(py.detach(|| sim.load_checkpoint(&path))?)
    }

    fn __repr__(&self) -> String {
        format!(
            "DemSimulation(n={}, t={} s, steps={}, dt={:e} s, effects={:?})",
            self.sim.len(),
            self.sim.time(),
            self.sim.steps(),
            self.sim.dt(),
            self.sim.effects().names()
        )
    }
}

impl DemSimulation {
    /// Advance `n` steps (a count checked against the finite time), `chunk` at a time.
    fn step_count(&mut self, py: Python<'_>, n: i64, chunk: i64) -> PyResult<()> {
        let n = checked_steps(n, self.sim.time(), self.sim.dt())?;
        let chunk = count("chunk", chunk)?;
        run_in_chunks(
            py,
            &mut self.sim,
            n,
            chunk,
            |sim, k| sim.step(k),
            |sim| (sim.time(), sim.steps()),
            |_| Ok(()),
        )
    }
}

/// Register the DEM classes on the extension module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<DemSimulation>()?;
    Ok(())
}
