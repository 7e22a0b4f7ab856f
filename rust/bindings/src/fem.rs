//! Python bindings of the explicit FEM core: cartridge meshes as numpy arrays, the explicit
//! tetrahedral solver (runs with the GIL released, in chunks so Ctrl-C is honoured), the
//! sparse static solve and stress recovery. SI units throughout.

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use demfem::fem::io::vtk::{write_vtu, DataArray};
use demfem::fem::stable_step::StepBound;
use demfem::fem::{
    stress, AxisymmetricProfile, ExplicitConfig, ExplicitSolver, LinearElastic, LoadHistory,
    Prescribed, PrescribedKind, TetMesh,
};
use demfem::DemfemError;

use crate::convert::{self, arr3, arr6, idx_arr, required, rows3, Nodes};
use crate::error::{invalid, shape_err, PyDemfemError};
use crate::fem_contact::{self, PyRigid};
use crate::run::run_in_chunks;
use demfem::fem::contact::ContactSettings;

fn to_mesh(
    nodes: &PyReadonlyArray2<'_, f64>,
    tets: &PyReadonlyArray2<'_, i64>,
) -> PyResult<TetMesh> {
    let nodes = rows3(nodes, "nodes")?;
    let t = tets.as_array();
    if t.ncols() != 4 {
        return Err(shape_err(
            "tets",
            format!("expected shape (n, 4), got {:?}", t.shape()),
        ));
    }
    let mut out = Vec::with_capacity(t.nrows());
    for r in t.rows() {
        if r.iter().any(|&i| i < 0) {
            return Err(shape_err("tets", "negative node index".into()));
        }
        out.push([r[0] as usize, r[1] as usize, r[2] as usize, r[3] as usize]);
    }
    let mut mesh = TetMesh { nodes, tets: out };
    // Accept either orientation (gmsh and others differ); degenerate tets still fail.
    mesh.orient();
    mesh.validate().map_err(PyDemfemError::from)?;
    Ok(mesh)
}

fn profile(
    z: PyReadonlyArray1<'_, f64>,
    r_in: PyReadonlyArray1<'_, f64>,
    r_out: PyReadonlyArray1<'_, f64>,
) -> PyResult<AxisymmetricProfile> {
    Ok(AxisymmetricProfile::new(
        z.as_array().to_vec(),
        r_in.as_array().to_vec(),
        r_out.as_array().to_vec(),
    )
    .map_err(PyDemfemError::from)?)
}

/// Revolved linear-tetrahedron mesh of an axisymmetric body (stations z, radii r_in,
/// r_out in m). Returns (nodes (N,3) m, tets (E,4) int64, quality dict).
#[pyfunction]
#[pyo3(signature = (
    z, r_in, r_out, n_theta, n_layers, target_size, min_dihedral_deg=5.0,
    max_elements=demfem::fem::mesh::MAX_TET_ELEMENTS as i64
))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn fem_tet_mesh<'py>(
    py: Python<'py>,
    z: PyReadonlyArray1<'py, f64>,
    r_in: PyReadonlyArray1<'py, f64>,
    r_out: PyReadonlyArray1<'py, f64>,
    n_theta: i64,
    n_layers: i64,
    target_size: f64,
    min_dihedral_deg: f64,
    max_elements: i64,
) -> PyResult<(Nodes<'py>, Bound<'py, PyArray2<i64>>, Bound<'py, PyDict>)> {
    // signed, so a negative count is refused by name instead of pyo3's OverflowError
    let whole = |field: &str, v: i64, lo: i64| -> PyResult<usize> {
        if v < lo {
            return Err(invalid(
                field,
                &v.to_string(),
                &format!("a whole number >= {lo}"),
            ));
        }
        usize::try_from(v).map_err(|_| invalid(field, &v.to_string(), "a whole number that fits"))
    };
    let n_theta = whole("n_theta", n_theta, 3)?;
    let n_layers = whole("n_layers", n_layers, 1)?;
    let max_elements = whole("max_elements", max_elements, 1)?;
    let p = profile(z, r_in, r_out)?;
    let rm = py
        .detach(|| p.tet_mesh_limited(n_theta, n_layers, target_size, max_elements))
        .map_err(PyDemfemError::from)?;
    let q = rm
        .mesh
        .check_quality(min_dihedral_deg)
        .map_err(PyDemfemError::from)?;
    let d = PyDict::new(py);
    d.set_item("min_dihedral_deg", q.min_dihedral_deg)?;
    d.set_item("max_dihedral_deg", q.max_dihedral_deg)?;
    d.set_item("max_aspect_ratio", q.max_aspect_ratio)?;
    d.set_item("mean_aspect_ratio", q.mean_aspect_ratio)?;
    d.set_item("min_volume", q.min_volume)?;
    d.set_item("n_elements", q.n_elements)?;
    Ok((arr3(py, &rm.mesh.nodes)?, idx_arr(py, &rm.mesh.tets)?, d))
}

/// Tet mesh of a ball of `radius` m centred at the origin (a 2n×2n×2n cube mapped onto
/// the sphere). Returns (nodes (N,3) m, tets (E,4) int64).
#[pyfunction]
fn fem_ball_mesh<'py>(
    py: Python<'py>,
    radius: f64,
    n: usize,
) -> PyResult<(Nodes<'py>, Bound<'py, PyArray2<i64>>)> {
    let m = demfem::fem::mesh::ball_tet_mesh(radius, n).map_err(PyDemfemError::from)?;
    Ok((arr3(py, &m.nodes)?, idx_arr(py, &m.tets)?))
}

/// Mid-surface triangle shell mesh. Returns (nodes (N,3) m, triangles (T,3) int64,
/// thickness (T,) m).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn fem_shell_mesh<'py>(
    py: Python<'py>,
    z: PyReadonlyArray1<'py, f64>,
    r_in: PyReadonlyArray1<'py, f64>,
    r_out: PyReadonlyArray1<'py, f64>,
    n_theta: usize,
    target_size: f64,
) -> PyResult<(
    Nodes<'py>,
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray1<f64>>,
)> {
    let p = profile(z, r_in, r_out)?;
    let m = p
        .shell_mesh(n_theta, target_size)
        .map_err(PyDemfemError::from)?;
    Ok((
        arr3(py, &m.nodes)?,
        idx_arr(py, &m.triangles)?,
        m.thickness.into_pyarray(py),
    ))
}

fn prescribed_list(
    dofs: &PyReadonlyArray2<'_, i64>,
    values: &PyReadonlyArray1<'_, f64>,
) -> PyResult<Vec<(usize, usize, f64)>> {
    let d = dofs.as_array();
    let v = values.as_array();
    if d.ncols() != 2 || d.nrows() != v.len() {
        return Err(shape_err(
            "fixed_dofs",
            format!(
                "expected (k, 2) node/component pairs and k values, got {:?} and {}",
                d.shape(),
                v.len()
            ),
        ));
    }
    d.rows()
        .into_iter()
        .zip(v.iter())
        .map(|(r, &x)| {
            if r[0] < 0 || !(0..3).contains(&r[1]) {
                Err(shape_err(
                    "fixed_dofs",
                    format!("bad pair ({}, {})", r[0], r[1]),
                ))
            } else {
                Ok((r[0] as usize, r[1] as usize, x))
            }
        })
        .collect()
}

/// Linear static solve K u = f, E = `young_modulus` (Pa; `youngs_modulus` is its old name).
/// `fixed_dofs` (k,2): node, component; `fixed_values` (k,) m. Every argument but the alias
/// is required. Returns (u (N,3) m, reactions (N,3) N).
#[pyfunction]
#[pyo3(signature = (nodes, tets, young_modulus=None, poisson_ratio=None, loads=None, fixed_dofs=None, fixed_values=None, *, youngs_modulus=None))]
#[allow(clippy::too_many_arguments)]
fn fem_solve_static<'py>(
    py: Python<'py>,
    nodes: PyReadonlyArray2<'py, f64>,
    tets: PyReadonlyArray2<'py, i64>,
    young_modulus: Option<f64>,
    poisson_ratio: Option<f64>,
    loads: Option<PyReadonlyArray2<'py, f64>>,
    fixed_dofs: Option<PyReadonlyArray2<'py, i64>>,
    fixed_values: Option<PyReadonlyArray1<'py, f64>>,
    youngs_modulus: Option<f64>,
) -> PyResult<(Nodes<'py>, Nodes<'py>)> {
    let e = convert::young_modulus(young_modulus, youngs_modulus)?;
    let nu = required("poisson_ratio", poisson_ratio)?;
    let loads = required("loads", loads)?;
    let fixed_dofs = required("fixed_dofs", fixed_dofs)?;
    let fixed_values = required("fixed_values", fixed_values)?;
    let mesh = to_mesh(&nodes, &tets)?;
    let mat = LinearElastic::new(e, nu, 1.0).map_err(PyDemfemError::from)?;
    let f = rows3(&loads, "loads")?;
    let fixed = prescribed_list(&fixed_dofs, &fixed_values)?;
    let sol = py
        .detach(|| demfem::fem::static_solve::solve_static(&mesh, &mat, &f, &fixed))
        .map_err(PyDemfemError::from)?;
    Ok((arr3(py, &sol.displacement)?, arr3(py, &sol.reaction)?))
}

/// Element stresses (E,6) Pa, order xx, yy, zz, yz, xz, xy, for displacements u (N,3) m;
/// E = `young_modulus` (Pa; `youngs_modulus` is its old name). Every argument but the alias
/// is required.
#[pyfunction]
#[pyo3(signature = (nodes, tets, young_modulus=None, poisson_ratio=None, u=None, *, youngs_modulus=None))]
fn fem_element_stresses<'py>(
    py: Python<'py>,
    nodes: PyReadonlyArray2<'py, f64>,
    tets: PyReadonlyArray2<'py, i64>,
    young_modulus: Option<f64>,
    poisson_ratio: Option<f64>,
    u: Option<PyReadonlyArray2<'py, f64>>,
    youngs_modulus: Option<f64>,
) -> PyResult<Nodes<'py>> {
    let e = convert::young_modulus(young_modulus, youngs_modulus)?;
    let nu = required("poisson_ratio", poisson_ratio)?;
    let u = required("u", u)?;
    let mesh = to_mesh(&nodes, &tets)?;
    let mat = LinearElastic::new(e, nu, 1.0).map_err(PyDemfemError::from)?;
    let u = rows3(&u, "u")?;
    let s = stress::element_stresses(&mesh, &mat, &u).map_err(PyDemfemError::from)?;
    arr6(py, &s)
}

/// Principal stresses (M,3) Pa, σ1 ≥ σ2 ≥ σ3, and von Mises (M,) Pa of stresses (M,6).
#[pyfunction]
fn fem_stress_invariants<'py>(
    py: Python<'py>,
    s: PyReadonlyArray2<'py, f64>,
) -> PyResult<(Nodes<'py>, Bound<'py, PyArray1<f64>>)> {
    let a = s.as_array();
    if a.ncols() != 6 {
        return Err(shape_err(
            "stress",
            format!("expected shape (m, 6), got {:?}", a.shape()),
        ));
    }
    let mut p = Vec::with_capacity(a.nrows());
    let mut vm = Vec::with_capacity(a.nrows());
    for r in a.rows() {
        let t = [r[0], r[1], r[2], r[3], r[4], r[5]];
        p.push(stress::principal_stresses(&t));
        vm.push(stress::von_mises(&t));
    }
    Ok((arr3(py, &p)?, vm.into_pyarray(py)))
}

/// Explicit central-difference solver for linear tetrahedra (lumped mass, Rayleigh
/// damping, certified stable step). Times in s, lengths in m, forces in N.
#[pyclass(module = "demfem._core")]
struct FemTetSolver {
    inner: ExplicitSolver,
    mesh: TetMesh,
    material: LinearElastic,
}

#[pymethods]
impl FemTetSolver {
    /// Tet mesh: nodes (N,3) m, tets (E,4); material `young_modulus` E (Pa; `youngs_modulus`
    /// is its old name), ν, density (kg/m³), all required; the step and damping settings.
    #[new]
    #[pyo3(signature = (nodes, tets, young_modulus=None, poisson_ratio=None, density=None, dt=None, safety_factor=0.9, rayleigh_alpha=0.0, rayleigh_beta=0.0, mass_scaling_dt=None, certified_step=true, energy_interval=100, *, youngs_modulus=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        nodes: PyReadonlyArray2<'_, f64>,
        tets: PyReadonlyArray2<'_, i64>,
        young_modulus: Option<f64>,
        poisson_ratio: Option<f64>,
        density: Option<f64>,
        dt: Option<f64>,
        safety_factor: f64,
        rayleigh_alpha: f64,
        rayleigh_beta: f64,
        mass_scaling_dt: Option<f64>,
        certified_step: bool,
        energy_interval: usize,
        youngs_modulus: Option<f64>,
    ) -> PyResult<Self> {
        let e = convert::young_modulus(young_modulus, youngs_modulus)?;
        let nu = required("poisson_ratio", poisson_ratio)?;
        let density = required("density", density)?;
        let mesh = to_mesh(&nodes, &tets)?;
        let material = LinearElastic::new(e, nu, density).map_err(PyDemfemError::from)?;
        let mut cfg = ExplicitConfig::new(material);
        cfg.dt = dt;
        cfg.safety_factor = safety_factor;
        cfg.rayleigh_alpha = rayleigh_alpha;
        cfg.rayleigh_beta = rayleigh_beta;
        cfg.mass_scaling_dt = mass_scaling_dt;
        cfg.energy_interval = energy_interval;
        if !certified_step {
            cfg.step_bound = StepBound::ElementEigenvalue;
        }
        let inner = py
            .detach(|| ExplicitSolver::new(&mesh, cfg))
            .map_err(PyDemfemError::from)?;
        Ok(Self {
            inner,
            mesh,
            material,
        })
    }

    /// Prescribe dofs: `dofs` (k,2) node/component, `values` (k,), `kind` 'displacement'
    /// (m, scaled by a linear ramp over `rise_time` s if > 0) or 'velocity' (m/s).
    #[pyo3(signature = (dofs, values, kind="displacement", rise_time=0.0))]
    fn set_prescribed(
        &mut self,
        dofs: PyReadonlyArray2<'_, i64>,
        values: PyReadonlyArray1<'_, f64>,
        kind: &str,
        rise_time: f64,
    ) -> PyResult<()> {
        let list = prescribed_list(&dofs, &values)?;
        let mk: fn(f64) -> PrescribedKind = match kind {
            "displacement" => PrescribedKind::Displacement,
            "velocity" => PrescribedKind::Velocity,
            other => {
                return Err(PyDemfemError::from(DemfemError::InvalidParameter {
                    field: "kind".into(),
                    value: other.into(),
                    allowed: "'displacement' or 'velocity'".into(),
                })
                .into())
            }
        };
        let p: Vec<Prescribed> = list
            .into_iter()
            .map(|(node, component, v)| Prescribed {
                node,
                component,
                kind: mk(v),
            })
            .collect();
        let h = if rise_time > 0.0 {
            LoadHistory::Ramp { rise_time }
        } else {
            LoadHistory::Constant
        };
        Ok(self
            .inner
            .set_prescribed(&p, h)
            .map_err(PyDemfemError::from)?)
    }

    /// Nodal loads (N,3) N, applied suddenly or with a smooth ramp over `rise_time` s.
    #[pyo3(signature = (loads, rise_time=0.0))]
    fn set_loads(&mut self, loads: PyReadonlyArray2<'_, f64>, rise_time: f64) -> PyResult<()> {
        let f = rows3(&loads, "loads")?;
        let h = if rise_time > 0.0 {
            LoadHistory::SmoothRamp { rise_time }
        } else {
            LoadHistory::Constant
        };
        Ok(self.inner.set_loads(f, h).map_err(PyDemfemError::from)?)
    }

    /// Extra nodal forces (N,3) N held until changed (e.g. contact forces).
    fn set_extra_loads(&mut self, loads: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        let f = rows3(&loads, "extra_loads")?;
        Ok(self
            .inner
            .set_extra_loads(&f)
            .map_err(PyDemfemError::from)?)
    }

    /// Initial velocity (N,3) m/s (before the first step).
    fn set_initial_velocity(&mut self, v: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        let v = rows3(&v, "velocity")?;
        Ok(self
            .inner
            .set_initial_velocity(&v)
            .map_err(PyDemfemError::from)?)
    }

    /// Initial displacement (N,3) m (before the first step).
    fn set_initial_displacement(&mut self, u: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        let u = rows3(&u, "displacement")?;
        Ok(self
            .inner
            .set_initial_displacement(&u)
            .map_err(PyDemfemError::from)?)
    }

    /// Advance `n_steps` with the GIL released, in chunks of `chunk` steps; after each
    /// chunk `progress(steps, time_s)` is called if given, and Ctrl-C stops cleanly with
    /// SimulationInterrupted (the state stays consistent at a step boundary).
    #[pyo3(signature = (n_steps, chunk=1000, progress=None))]
    fn run(
        &mut self,
        py: Python<'_>,
        n_steps: u64,
        chunk: u64,
        progress: Option<Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        run_in_chunks(
            py,
            &mut self.inner,
            n_steps,
            chunk,
            |inner, k| inner.run(k),
            |inner| (inner.time(), inner.steps()),
            |inner| {
                if let Some(cb) = &progress {
                    cb.call1((inner.steps(), inner.time()))?;
                }
                Ok(())
            },
        )
    }

    /// Attach contact (before the first step): bodies numbered per node (`body_of_node`),
    /// output regions per node, penalty scale s (k = s·K·A²/V), friction μ between bodies,
    /// broad-phase margin (m), rigid surfaces as tuples ("plane", point, normal,
    /// surface_velocity, μ), ("sphere", centre, radius, velocity, μ) or ("cylinder", point,
    /// radius, axis, μ), and optional no-tension springs (nodes, anchors (m,3) m, stiffness
    /// N/m, rest length m). The stable step is re-certified with the contact included.
    #[pyo3(signature = (body_of_node, region_of_node, penalty_scale=1.0, friction=0.2, margin=None, contacts_per_node=1.0, initial_overlap_tolerance=1e-9, output_interval=10, rigid_surfaces=Vec::new(), spring_nodes=None, spring_anchors=None, spring_stiffness=None, spring_rest_length=None))]
    #[allow(clippy::too_many_arguments)]
    fn set_contact(
        &mut self,
        py: Python<'_>,
        body_of_node: PyReadonlyArray1<'_, i64>,
        region_of_node: PyReadonlyArray1<'_, i64>,
        penalty_scale: f64,
        friction: f64,
        margin: Option<f64>,
        contacts_per_node: f64,
        initial_overlap_tolerance: f64,
        output_interval: usize,
        rigid_surfaces: Vec<PyRigid>,
        spring_nodes: Option<PyReadonlyArray1<'_, i64>>,
        spring_anchors: Option<PyReadonlyArray2<'_, f64>>,
        spring_stiffness: Option<PyReadonlyArray1<'_, f64>>,
        spring_rest_length: Option<PyReadonlyArray1<'_, f64>>,
    ) -> PyResult<()> {
        let settings = ContactSettings {
            penalty_scale,
            friction,
            margin,
            contacts_per_node,
            initial_overlap_tolerance,
            output_interval,
        };
        let c = fem_contact::build(
            &self.mesh,
            &self.material,
            body_of_node,
            region_of_node,
            settings,
            rigid_surfaces,
            spring_nodes,
            spring_anchors,
            spring_stiffness,
            spring_rest_length,
        )?;
        let inner = &mut self.inner;
        py.detach(|| inner.set_contact(c))
            .map_err(PyDemfemError::from)?;
        Ok(())
    }

    /// Contact output channels: list of (party a, party b, region of a), a < b (bodies
    /// first, then rigid surfaces in the order given).
    fn contact_channels(&self) -> Vec<(usize, usize, usize)> {
        self.inner
            .contact()
            .map(|c| c.channels())
            .unwrap_or_default()
    }
    /// Contact history (samples, 1 + 4·channels): time s, then per channel the normal and
    /// tangential resultant force N, contact area m², largest penetration m.
    fn contact_history<'py>(&self, py: Python<'py>) -> PyResult<Nodes<'py>> {
        let (h, w) = match self.inner.contact() {
            Some(c) => (c.history().to_vec(), 1 + 4 * c.channels().len()),
            None => (Vec::new(), 1),
        };
        let rows = h.len() / w;
        let a = Array2::from_shape_vec((rows, w), h)
            .map_err(|e| shape_err("contact history", e.to_string()))?;
        Ok(a.into_pyarray(py))
    }
    /// Contact pressure per node in the last step, Pa (N,).
    fn contact_pressure<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let p = self
            .inner
            .contact()
            .map(|c| c.pressure())
            .unwrap_or_else(|| vec![0.0; self.mesh.nodes.len()]);
        p.into_pyarray(py)
    }
    /// Contact energies (J) and counters: elastic_energy, spring_energy, friction_work,
    /// rigid_work, contact_work, bookkeeping_error, active_contacts, broad_phase_builds,
    /// eigenvalue_allowance (1/s²), max_contact_eigenvalue (1/s²), dt_limit_without_contact (s).
    fn contact_info<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        match self.inner.contact() {
            Some(c) => Ok(Some(fem_contact::info(
                py,
                c,
                self.inner.dt_limit_without_contact(),
            )?)),
            None => Ok(None),
        }
    }
    /// Lumped nodal masses (N,), kg.
    fn mass<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.mass().to_vec().into_pyarray(py)
    }

    /// The run's dynamic state (contact included) as bytes, for an exact checkpoint.
    fn save_state<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.inner.save_state())
    }

    /// Restore a state from :meth:`save_state` into a solver built from the same inputs;
    /// a state of another model raises ShapeError and changes nothing.
    fn restore_state(&mut self, state: &[u8]) -> PyResult<()> {
        Ok(self
            .inner
            .restore_state(state)
            .map_err(PyDemfemError::from)?)
    }

    /// Time step in use, s.
    #[getter]
    fn dt(&self) -> f64 {
        self.inner.dt()
    }
    /// Proven stable-step bound, s.
    #[getter]
    fn dt_limit(&self) -> f64 {
        self.inner.dt_limit()
    }
    /// Current time, s.
    #[getter]
    fn time(&self) -> f64 {
        self.inner.time()
    }
    /// Steps taken.
    #[getter]
    fn steps(&self) -> u64 {
        self.inner.steps()
    }
    /// Mass added by mass scaling, kg.
    #[getter]
    fn added_mass(&self) -> f64 {
        self.inner.added_mass()
    }
    /// Displacement (N,3), m.
    fn displacement<'py>(&self, py: Python<'py>) -> PyResult<Nodes<'py>> {
        arr3(py, self.inner.displacement())
    }
    /// Velocity at the last half step (N,3), m/s.
    fn velocity<'py>(&self, py: Python<'py>) -> PyResult<Nodes<'py>> {
        arr3(py, self.inner.velocity())
    }
    /// Energies (J) at the start of the last step: time, kinetic, internal, external_work,
    /// damping_work, initial, relative_balance_error.
    fn energy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let e = self.inner.energy();
        let d = PyDict::new(py);
        d.set_item("time", e.time)?;
        d.set_item("kinetic", e.kinetic)?;
        d.set_item("internal", e.internal)?;
        d.set_item("external_work", e.external_work)?;
        d.set_item("damping_work", e.damping_work)?;
        d.set_item("initial", e.initial)?;
        d.set_item("relative_balance_error", e.relative_balance_error())?;
        Ok(d)
    }
    /// Element stresses (E,6) Pa, order xx, yy, zz, yz, xz, xy.
    fn element_stresses<'py>(&self, py: Python<'py>) -> PyResult<Nodes<'py>> {
        let s = stress::element_stresses(&self.mesh, &self.material, self.inner.displacement())
            .map_err(PyDemfemError::from)?;
        arr6(py, &s)
    }
    /// Nodal (volume-averaged) stresses (N,6) Pa.
    fn nodal_stresses<'py>(&self, py: Python<'py>) -> PyResult<Nodes<'py>> {
        let s = stress::element_stresses(&self.mesh, &self.material, self.inner.displacement())
            .map_err(PyDemfemError::from)?;
        let n = stress::nodal_stresses(&self.mesh, &s).map_err(PyDemfemError::from)?;
        arr6(py, &n)
    }
    /// Write the current state to a .vtu file (displacement, velocity, nodal stress, σ1).
    fn write_vtu(&self, path: std::path::PathBuf) -> PyResult<()> {
        let u: Vec<f64> = self
            .inner
            .displacement()
            .iter()
            .flatten()
            .cloned()
            .collect();
        let v: Vec<f64> = self.inner.velocity().iter().flatten().cloned().collect();
        let es = stress::element_stresses(&self.mesh, &self.material, self.inner.displacement())
            .map_err(PyDemfemError::from)?;
        let ns = stress::nodal_stresses(&self.mesh, &es).map_err(PyDemfemError::from)?;
        let s1: Vec<f64> = ns.iter().map(stress::max_principal_stress).collect();
        let s1e: Vec<f64> = es.iter().map(stress::max_principal_stress).collect();
        let nsf: Vec<f64> = ns.iter().flatten().cloned().collect();
        let pressure = self
            .inner
            .contact()
            .map(|c| c.pressure())
            .unwrap_or_else(|| vec![0.0; self.mesh.nodes.len()]);
        write_vtu(
            &path,
            &self.mesh.nodes,
            &self.mesh.tets,
            &[
                DataArray {
                    name: "displacement",
                    n_components: 3,
                    values: &u,
                },
                DataArray {
                    name: "velocity",
                    n_components: 3,
                    values: &v,
                },
                DataArray {
                    name: "stress",
                    n_components: 6,
                    values: &nsf,
                },
                DataArray {
                    name: "sigma1",
                    n_components: 1,
                    values: &s1,
                },
                DataArray {
                    name: "contact_pressure",
                    n_components: 1,
                    values: &pressure,
                },
            ],
            &[DataArray {
                name: "sigma1_element",
                n_components: 1,
                values: &s1e,
            }],
        )
        .map_err(PyDemfemError::from)?;
        Ok(())
    }
}

/// Register the FEM functions and classes on the extension module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fem_tet_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(fem_shell_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(fem_solve_static, m)?)?;
    m.add_function(wrap_pyfunction!(fem_element_stresses, m)?)?;
    m.add_function(wrap_pyfunction!(fem_stress_invariants, m)?)?;
    m.add_function(wrap_pyfunction!(fem_ball_mesh, m)?)?;
    m.add_class::<FemTetSolver>()?;
    Ok(())
}
