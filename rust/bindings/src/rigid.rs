//! Python binding of the rigid-body scenes: `RigidSimulation`, cartridges as bead clumps or
//! exact parry shapes on a belt between plane and polygon walls (the table's gate included),
//! built from plain arrays and dicts, stepping with the GIL released in chunks so Ctrl-C
//! stops a run at a step boundary. SI units throughout.
//!
//! Conventions. Positions are centres of mass (m). Orientations are unit quaternions
//! (w, x, y, z) turning the cartridge frame of the shape description (axis z) into the world
//! frame. Angular velocities are in the world frame (rad/s).

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use numpy::{IntoPyArray, PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use demfem::geometry::Vec3;
use demfem::rigid::{
    BeadClump, ContactMaterial, ExactShape, RevolutionProfile, RevolutionShape, RigidScene,
    RigidSceneConfig, RigidShape, RigidWall,
};
use demfem::DemfemError;

use crate::convert::{array_n3, count, get_f64, vec3s};
use crate::dem_walls::parse_wall;
use crate::error::{invalid, shape_err, PyDemfemError};
use crate::run::{checked_steps, run_in_chunks, steps_until};

/// Effects a rigid scene can run (the table's, without "planar" and "rolling_resistance").
const RIGID_EFFECTS: [&str; 6] = [
    "gravity",
    "belt",
    "moving_walls",
    "friction",
    "rotation",
    "damping",
];

/// Overlap tolerated between bodies of revolution (or a body and a wall) at the start, m.
const START_OVERLAP_TOLERANCE: f64 = 1e-9;

/// The shape kinds `RigidSimulation` takes.
const SHAPE_KINDS: &str = "'clump', 'exact' or 'revolution'";

fn to_na(v: Vec3) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

fn from_na(v: &Vector3<f64>) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

fn array_1d(field: &str, d: &Bound<'_, PyDict>, key: &str) -> PyResult<Vec<f64>> {
    match d.get_item(key)? {
        Some(v) => v.extract::<Vec<f64>>().map_err(|_| {
            invalid(
                &format!("{field}.{key}"),
                &v.to_string(),
                "a 1-D array of numbers",
            )
        }),
        None => Err(invalid(&format!("{field}.{key}"), "missing", "required")),
    }
}

/// The shape dict: {"kind": "clump", "centers" (n, 3) m, "radii" (n,) m, "masses" (n,) kg},
/// {"kind": "exact", "z", "r_in", "r_out" (stations, m)} (parry compound) or
/// {"kind": "revolution", same stations} (the fast exact body of revolution), with the
/// density of `material`.
/// Returns the scene shape, its mass properties and the rotation from the principal (body)
/// frame to the cartridge frame.
fn parse_shape(
    d: &Bound<'_, PyDict>,
    density: f64,
) -> PyResult<(
    RigidShape,
    demfem::rigid::MassProperties,
    UnitQuaternion<f64>,
)> {
    let kind: String = match d.get_item("kind")? {
        Some(k) => k
            .extract()
            .map_err(|_| invalid("shape.kind", &k.to_string(), SHAPE_KINDS))?,
        None => return Err(invalid("shape.kind", "missing", SHAPE_KINDS)),
    };
    match kind.as_str() {
        "clump" => {
            let centers: Vec<Vec<f64>> = match d.get_item("centers")? {
                Some(v) => v
                    .extract()
                    .map_err(|_| invalid("shape.centers", &v.to_string(), "an (n, 3) array"))?,
                None => return Err(invalid("shape.centers", "missing", "required")),
            };
            let mut c = Vec::with_capacity(centers.len());
            for row in centers {
                if row.len() != 3 {
                    return Err(shape_err(
                        "shape.centers",
                        format!("rows of 3 coordinates, got {}", row.len()),
                    ));
                }
                c.push(Vector3::new(row[0], row[1], row[2]));
            }
            let radii = array_1d("shape", d, "radii")?;
            let masses = array_1d("shape", d, "masses")?;
            let (clump, mass) =
                BeadClump::from_beads(&c, &radii, &masses).map_err(PyDemfemError::from)?;
            let frame = clump.principal_frame;
            Ok((RigidShape::Clump(clump), mass, frame))
        }
        "exact" | "revolution" => {
            let profile = RevolutionProfile::new(
                array_1d("shape", d, "z")?,
                array_1d("shape", d, "r_in")?,
                array_1d("shape", d, "r_out")?,
            )
            .map_err(PyDemfemError::from)?;
            let mass = profile
                .mass_properties(density)
                .map_err(PyDemfemError::from)?;
            let shape = if kind == "exact" {
                RigidShape::Exact(
                    ExactShape::from_profile(&profile, mass.center_of_mass.z)
                        .map_err(PyDemfemError::from)?,
                )
            } else {
                RigidShape::Revolution(
                    RevolutionShape::from_profile(&profile, mass.center_of_mass.z)
                        .map_err(PyDemfemError::from)?,
                )
            };
            Ok((shape, mass, UnitQuaternion::identity()))
        }
        other => Err(invalid("shape.kind", other, SHAPE_KINDS)),
    }
}

/// Rigid cartridges (bead clumps or exact shapes) between walls (see `demfem._core.pyi`).
#[pyclass(module = "demfem._core")]
pub struct RigidSimulation {
    scene: RigidScene,
    /// Principal (body) frame → cartridge frame of the cartridges.
    principal_frame: UnitQuaternion<f64>,
    /// Which bodies are equivalent spheres (one-bead bodies) rather than cartridges.
    sphere: Vec<bool>,
}

#[pymethods]
impl RigidSimulation {
    #[new]
    #[pyo3(signature = (
        positions, orientations, shape, material, walls, effects, *, velocities=None,
        angular_velocities=None, wall_material=None, gravity=(0.0, 0.0, -9.81), dt=None,
        expected_max_speed=1.0, removal_plane=None, record_onsets=false, spheres=None,
        sphere_radius=None, threads=1
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        positions: PyReadonlyArray2<'_, f64>,
        orientations: PyReadonlyArray2<'_, f64>,
        shape: &Bound<'_, PyDict>,
        material: &Bound<'_, PyDict>,
        walls: &Bound<'_, PyList>,
        effects: Vec<String>,
        velocities: Option<PyReadonlyArray2<'_, f64>>,
        angular_velocities: Option<PyReadonlyArray2<'_, f64>>,
        wall_material: Option<&Bound<'_, PyDict>>,
        gravity: (f64, f64, f64),
        dt: Option<f64>,
        expected_max_speed: f64,
        removal_plane: Option<((f64, f64, f64), (f64, f64, f64))>,
        record_onsets: bool,
        spheres: Option<PyReadonlyArray1<'_, bool>>,
        sphere_radius: Option<f64>,
        threads: i64,
    ) -> PyResult<Self> {
        let threads = usize::try_from(threads)
            .ok()
            .filter(|&t| t >= 1)
            .ok_or_else(|| invalid("threads", &threads.to_string(), "a whole number >= 1"))?;
        for e in &effects {
            if !RIGID_EFFECTS.contains(&e.as_str()) {
                return Err(PyDemfemError::from(DemfemError::Effect(format!(
                    "the rigid-body scene cannot run effect {e:?}; it runs {RIGID_EFFECTS:?}"
                )))
                .into());
            }
        }
        let has = |name: &str| effects.iter().any(|e| e == name);
        let position = vec3s("positions", &positions, None)?;
        let n = position.len();
        let q = orientations.as_array();
        if q.shape()[0] != n || q.shape()[1] != 4 {
            return Err(shape_err(
                "orientations",
                format!(
                    "expected ({n}, 4) quaternions (w, x, y, z), got {:?}",
                    q.shape()
                ),
            ));
        }
        let velocity = match velocities {
            Some(v) => vec3s("velocities", &v, Some(n))?,
            None => vec![Vec3::ZERO; n],
        };
        let omega = match angular_velocities {
            Some(w) => vec3s("angular_velocities", &w, Some(n))?,
            None => vec![Vec3::ZERO; n],
        };
        let density = get_f64(material, "density", None, "material")?;
        let body_material = ContactMaterial {
            young_modulus: get_f64(material, "young_modulus", None, "material")?,
            poisson_ratio: get_f64(material, "poisson_ratio", None, "material")?,
        };
        let plane_material = match wall_material {
            Some(w) => ContactMaterial {
                young_modulus: get_f64(w, "young_modulus", None, "wall_material")?,
                poisson_ratio: get_f64(w, "poisson_ratio", None, "wall_material")?,
            },
            None => body_material,
        };
        let friction = get_f64(material, "friction", Some(0.0), "material")?;
        let restitution = get_f64(material, "restitution", Some(1.0), "material")?;
        let mut rigid_walls = Vec::new();
        for (k, w) in walls.iter().enumerate() {
            let d = w
                .cast_into::<PyDict>()
                .map_err(|_| invalid(&format!("walls[{k}]"), "not a dict", "a dict"))?;
            let wall = parse_wall(&d, k)?;
            rigid_walls.push(RigidWall {
                shape: wall.shape,
                motion: wall.motion,
                surface_velocity: to_na(wall.surface_velocity),
            });
        }
        let (body_shape, mass, principal_frame) = parse_shape(shape, density)?;
        let config = RigidSceneConfig {
            gravity: if has("gravity") {
                Vector3::new(gravity.0, gravity.1, gravity.2)
            } else {
                Vector3::zeros()
            },
            planes: Vec::new(),
            body_material,
            plane_material,
            restitution: if has("damping") { restitution } else { 1.0 },
            friction: if has("friction") { friction } else { 0.0 },
            max_expected_speed: expected_max_speed,
            time_step: dt,
            walls: rigid_walls,
            removal_plane: removal_plane
                .map(|(p, n)| (Vector3::new(p.0, p.1, p.2), Vector3::new(n.0, n.1, n.2))),
            record_onsets,
            threads,
        };
        let mut scene = RigidScene::new(config).map_err(PyDemfemError::from)?;
        let sphere: Vec<bool> = match &spheres {
            Some(mask) => {
                let mask = mask.as_array();
                if mask.len() != n {
                    return Err(shape_err(
                        "spheres",
                        format!("expected {n} flags (one per body), got {}", mask.len()),
                    ));
                }
                mask.to_vec()
            }
            None => vec![false; n],
        };
        // an equivalent sphere: one bead at the centre of mass, the cartridge's mass, a solid
        // sphere's inertia 2/5 m r²
        let sphere_id = if sphere.iter().any(|&s| s) {
            let radius = match sphere_radius {
                Some(r) if r.is_finite() && r > 0.0 => r,
                Some(r) => {
                    return Err(invalid(
                        "sphere_radius",
                        &r.to_string(),
                        "finite and > 0 (m)",
                    ))
                }
                None => {
                    return Err(invalid(
                        "sphere_radius",
                        "missing",
                        "required (m) when spheres flags any body",
                    ))
                }
            };
            let (bead, bead_mass) =
                BeadClump::from_beads(&[Vector3::zeros()], &[radius], &[mass.mass])
                    .map_err(PyDemfemError::from)?;
            Some(
                scene
                    .add_shape(RigidShape::Clump(bead), bead_mass)
                    .map_err(PyDemfemError::from)?,
            )
        } else {
            None
        };
        let id = scene
            .add_shape(body_shape, mass)
            .map_err(PyDemfemError::from)?;
        for i in 0..n {
            let raw = Quaternion::new(q[[i, 0]], q[[i, 1]], q[[i, 2]], q[[i, 3]]);
            let norm = raw.norm();
            if !(norm.is_finite() && norm > 0.0) {
                return Err(invalid(
                    &format!("orientations[{i}]"),
                    &format!("{raw:?}"),
                    "a finite non-zero quaternion (w, x, y, z)",
                ));
            }
            let user = UnitQuaternion::from_quaternion(raw);
            let (shape_id, body) = match sphere_id {
                Some(s) if sphere[i] => (s, user),
                _ => (id, user * principal_frame),
            };
            let w_body = body.inverse_transform_vector(&to_na(omega[i]));
            scene
                .add_body(
                    shape_id,
                    to_na(position[i]),
                    body,
                    to_na(velocity[i]),
                    w_body,
                )
                .map_err(PyDemfemError::from)?;
        }
        // bodies of revolution must not start overlapping (the check evaluates the forces
        // as the first step would)
        scene
            .check_start_overlaps(START_OVERLAP_TOLERANCE)
            .map_err(PyDemfemError::from)?;
        let _ = py;
        Ok(RigidSimulation {
            scene,
            principal_frame,
            sphere,
        })
    }

    /// Advance `n` steps, releasing the GIL in chunks of `chunk` steps; Ctrl-C between chunks
    /// raises SimulationInterrupted with the state consistent at a step boundary.
    #[pyo3(signature = (n, chunk=2000))]
    fn step(&mut self, py: Python<'_>, n: i64, chunk: i64) -> PyResult<()> {
        let n = checked_steps(n, self.scene.time(), self.scene.time_step())?;
        let chunk = count("chunk", chunk)?;
        run_in_chunks(
            py,
            &mut self.scene,
            n,
            chunk,
            |scene, k| scene.run(k),
            |scene| (scene.time(), scene.steps()),
            |_| Ok(()),
        )
    }

    /// Advance until the simulated time reaches `t_end` (s); returns the steps taken.
    #[pyo3(signature = (t_end, chunk=2000))]
    fn run_until(&mut self, py: Python<'_>, t_end: f64, chunk: i64) -> PyResult<u64> {
        let n = steps_until(t_end, self.scene.time(), self.scene.time_step())?;
        let steps = i64::try_from(n)
            .map_err(|_| invalid("t_end", &t_end.to_string(), "reachable in < 2^63 steps"))?;
        self.step(py, steps, chunk)?;
        Ok(n)
    }

    /// Simulated time, s.
    #[getter]
    fn time(&self) -> f64 {
        self.scene.time()
    }
    /// Steps taken.
    #[getter]
    fn steps(&self) -> u64 {
        self.scene.steps()
    }
    /// Time step, s.
    #[getter]
    fn dt(&self) -> f64 {
        self.scene.time_step()
    }
    /// Stable time-step limit, s.
    #[getter]
    fn stable_dt(&self) -> PyResult<f64> {
        Ok(self.scene.time_step_limit().map_err(PyDemfemError::from)?)
    }
    /// Number of bodies (removed ones included).
    fn __len__(&self) -> usize {
        self.scene.bodies.len()
    }
    /// Mass of one body (cartridges and spheres alike), kg.
    #[getter]
    fn body_mass(&self) -> f64 {
        self.scene.bodies.mass.first().copied().unwrap_or(0.0)
    }

    /// Centres of mass, m, shape (N, 3).
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v: Vec<Vec3> = self.scene.bodies.position.iter().map(from_na).collect();
        array_n3(py, &v)
    }
    /// Velocities of the centres of mass (half step), m/s, shape (N, 3).
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v: Vec<Vec3> = self.scene.bodies.velocity.iter().map(from_na).collect();
        array_n3(py, &v)
    }
    /// Angular velocities in the world frame (half step), rad/s, shape (N, 3).
    fn angular_velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let b = &self.scene.bodies;
        let v: Vec<Vec3> = (0..b.len())
            .map(|i| from_na(&b.angular_velocity_world(i)))
            .collect();
        array_n3(py, &v)
    }
    /// Orientations of the cartridge frames, quaternions (w, x, y, z), shape (N, 4).
    fn orientations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let mut flat = Vec::with_capacity(4 * self.scene.bodies.len());
        for (q, &sphere) in self.scene.bodies.orientation.iter().zip(&self.sphere) {
            let user = if sphere {
                *q
            } else {
                q * self.principal_frame.inverse()
            };
            flat.extend([user.w, user.i, user.j, user.k]);
        }
        let n = self.scene.bodies.len();
        Ok(flat.into_pyarray(py).reshape([n, 4])?.into_any())
    }
    /// Cartridge axes (the frame's z, bottom to top) in the world frame, shape (N, 3); NaN
    /// for spheres.
    fn axes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v: Vec<Vec3> = self.axes_na().iter().map(from_na).collect();
        array_n3(py, &v)
    }
    /// Angle between each cartridge axis and the vertical +z, rad (0: upright); NaN for
    /// spheres.
    fn tilt_angles<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.axes_na()
            .iter()
            .map(|a| a.z.clamp(-1.0, 1.0).acos())
            .collect::<Vec<_>>()
            .into_pyarray(py)
    }
    /// Whether each body is an equivalent sphere (True) or a cartridge.
    fn is_sphere<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        self.sphere.clone().into_pyarray(py)
    }
    /// Whether each body is still on the table (not removed through the outlet).
    fn alive<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        self.scene.alive().to_vec().into_pyarray(py)
    }
    /// Bodies removed through the outlet: (times (s), indices).
    fn removals<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<u32>>) {
        let (t, i): (Vec<f64>, Vec<u32>) = self.scene.removals().iter().copied().unzip();
        (t.into_pyarray(py), i.into_pyarray(py))
    }
    /// Bodies each body touched at the last step (coordination number).
    fn coordination<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        self.scene.coordination().to_vec().into_pyarray(py)
    }
    /// Walls each body touched at the last step.
    fn wall_contacts<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        self.scene.wall_contacts().to_vec().into_pyarray(py)
    }
    /// Kinetic energy (translation + rotation) of the bodies on the table, J.
    fn kinetic_energy(&self) -> f64 {
        let b = &self.scene.bodies;
        (0..b.len())
            .filter(|&i| self.scene.alive()[i])
            .map(|i| b.kinetic_energy(i))
            .sum()
    }
    /// Largest overlap at the last step, m.
    fn max_overlap(&self) -> f64 {
        self.scene.max_overlap_last_step()
    }
    /// Contact points at the last step.
    fn contact_points(&self) -> usize {
        self.scene.contacts_last_step()
    }
    /// Remove body `i` (it stops moving and touching anything).
    fn remove_body(&mut self, i: usize) -> PyResult<()> {
        if i >= self.scene.bodies.len() {
            return Err(invalid(
                "i",
                &i.to_string(),
                &format!("< {} bodies", self.scene.bodies.len()),
            ));
        }
        self.scene.remove_body(i);
        Ok(())
    }

    /// Put removed body `i` back at `position` (m, centre of mass) with `orientation` (unit
    /// quaternion (w, x, y, z) of its frame, as the constructor's) and `velocity` (m/s), without
    /// spin. Refused naming the field when `i` is out of range or alive, a value is not
    /// finite, the quaternion is not unit, or the body would touch an alive body or a wall
    /// there (the engine's exact contact test); with `if_free`, an occupied pose returns
    /// False instead (the body stays removed). Returns True when put back.
    #[pyo3(signature = (i, position, orientation, velocity, *, if_free=false))]
    fn reinsert_body(
        &mut self,
        i: i64,
        position: (f64, f64, f64),
        orientation: (f64, f64, f64, f64),
        velocity: (f64, f64, f64),
        if_free: bool,
    ) -> PyResult<bool> {
        let n = self.scene.bodies.len();
        let index = usize::try_from(i)
            .ok()
            .filter(|&k| k < n)
            .ok_or_else(|| invalid("i", &i.to_string(), &format!("in [0, {n})")))?;
        let user = Quaternion::new(orientation.0, orientation.1, orientation.2, orientation.3);
        // the engine turns the principal frame; spheres have none
        let body = if self.sphere.get(index).copied().unwrap_or(false) {
            user
        } else {
            user * self.principal_frame.into_inner()
        };
        let x = Vector3::new(position.0, position.1, position.2);
        let v = Vector3::new(velocity.0, velocity.1, velocity.2);
        if if_free {
            let obstacle = self
                .scene
                .reinsert_body_if_free(index, x, body, v)
                .map_err(PyDemfemError::from)?;
            Ok(obstacle.is_none())
        } else {
            self.scene
                .reinsert_body(index, x, body, v)
                .map_err(PyDemfemError::from)?;
            Ok(true)
        }
    }

    /// Bodies put back so far: (times (s), indices).
    fn reinsertions<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<u32>>) {
        let (t, i): (Vec<f64>, Vec<u32>) = self.scene.reinsertions().iter().copied().unzip();
        (t.into_pyarray(py), i.into_pyarray(py))
    }

    /// Every contact onset (first step of a new body–body or body–wall contact): time (s),
    /// body, partner, partner_is_wall, normal_speed (> 0 approaching), tangential_speed
    /// (m/s), and where it touched (see `demfem._core.pyi`): point, normal, point_body,
    /// point_partner (cartridge frames), axis_angle.
    fn onsets<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let o = self.scene.onsets();
        let d = PyDict::new(py);
        macro_rules! column {
            ($name:expr, $f:expr) => {
                d.set_item($name, o.iter().map($f).collect::<Vec<_>>().into_pyarray(py))?;
            };
        }
        column!("time", |x| x.time);
        column!("body", |x| x.body);
        column!("partner", |x| x.partner);
        column!("partner_is_wall", |x| x.partner_is_wall);
        column!("normal_speed", |x| x.normal_speed);
        column!("tangential_speed", |x| x.tangential_speed);
        let rows = |f: &dyn Fn(&demfem::rigid::RigidOnset) -> Vector3<f64>| -> Vec<Vec3> {
            o.iter().map(|x| from_na(&f(x))).collect()
        };
        d.set_item("point", array_n3(py, &rows(&|x| x.point))?)?;
        d.set_item("normal", array_n3(py, &rows(&|x| x.normal))?)?;
        let nan = Vector3::repeat(f64::NAN);
        // a world point in the cartridge frame of body i at the pose it had then
        let local = |i: u32, pose: &demfem::rigid::BodyPose, p: &Vector3<f64>| {
            if self.sphere.get(i as usize).copied().unwrap_or(true) {
                nan
            } else {
                self.principal_frame
                    * pose
                        .orientation
                        .inverse_transform_vector(&(p - pose.position))
            }
        };
        let axis_of = |i: u32, pose: &demfem::rigid::BodyPose| {
            if self.sphere.get(i as usize).copied().unwrap_or(true) {
                nan
            } else {
                pose.orientation * self.principal_frame.inverse_transform_vector(&Vector3::z())
            }
        };
        d.set_item(
            "point_body",
            array_n3(py, &rows(&|x| local(x.body, &x.body_pose, &x.point)))?,
        )?;
        d.set_item(
            "point_partner",
            array_n3(
                py,
                &rows(&|x| match (&x.partner_pose, x.partner_is_wall) {
                    (Some(pose), false) => local(x.partner, pose, &x.point),
                    _ => nan,
                }),
            )?,
        )?;
        column!("axis_angle", |x| {
            let a = axis_of(x.body, &x.body_pose);
            // (f64::min would drop the NaN of a sphere's axis)
            let clamp = |c: f64| if c.is_nan() { c } else { c.abs().min(1.0) };
            match (&x.partner_pose, x.partner_is_wall) {
                (Some(pose), false) => clamp(a.dot(&axis_of(x.partner, pose))).acos(),
                _ => clamp(a.dot(&x.normal)).asin(),
            }
        });
        Ok(d)
    }

    /// Drop the logged onsets.
    fn clear_records(&mut self) {
        self.scene.clear_onsets();
    }

    fn __repr__(&self) -> String {
        format!(
            "RigidSimulation(n={}, t={} s, steps={}, dt={:e} s)",
            self.scene.bodies.len(),
            self.scene.time(),
            self.scene.steps(),
            self.scene.time_step()
        )
    }
}

impl RigidSimulation {
    fn axes_na(&self) -> Vec<Vector3<f64>> {
        let axis_body = self.principal_frame.inverse_transform_vector(&Vector3::z());
        self.scene
            .bodies
            .orientation
            .iter()
            .zip(&self.sphere)
            .map(|(q, &sphere)| {
                if sphere {
                    Vector3::repeat(f64::NAN)
                } else {
                    q * axis_body
                }
            })
            .collect()
    }
}

/// Register the rigid-body classes on the extension module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<RigidSimulation>()?;
    Ok(())
}
