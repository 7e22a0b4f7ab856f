//! Python binding of the explicit shell solver with contact: flat CST + DKT shells (6 dof
//! per node) in central-difference dynamics, two-sided penalty contact offset by half the
//! thickness, rigid surfaces, no-tension springs, gravity, checkpoints. SI units.

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use demfem::fem::contact::ContactSettings;
use demfem::fem::shell::{ShellExplicit, ShellModel};
use demfem::fem::{LinearElastic, TriMesh};
use demfem::DemfemError;

use crate::convert::{self, arr3, required, rows3, Nodes};
use crate::error::{core_err as e, shape_err};
use crate::fem_contact::{self, PyRigid};
use crate::run::run_in_chunks;

/// Explicit dynamics of shell bodies in contact.
#[pyclass(module = "demfem._core")]
pub struct FemShellSolver {
    model: ShellModel,
    inner: ShellExplicit,
}

#[pymethods]
impl FemShellSolver {
    /// Shell mesh: mid-surface nodes (N,3) m, triangles (T,3), thickness (T,) m; material
    /// `young_modulus` E (Pa; `youngs_modulus` is its old name), ν, density (kg/m³), all
    /// required; fixed dofs as (node, dof 0–5) pairs (K,2); a fixed step
    /// dt (s) or None for 0.9 × the certified bound.
    #[new]
    #[pyo3(signature = (nodes, triangles, thickness, young_modulus=None, poisson_ratio=None, density=None, fixed=None, dt=None, *, youngs_modulus=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        nodes: PyReadonlyArray2<'_, f64>,
        triangles: PyReadonlyArray2<'_, i64>,
        thickness: PyReadonlyArray1<'_, f64>,
        young_modulus: Option<f64>,
        poisson_ratio: Option<f64>,
        density: Option<f64>,
        fixed: Option<PyReadonlyArray2<'_, i64>>,
        dt: Option<f64>,
        youngs_modulus: Option<f64>,
    ) -> PyResult<Self> {
        let young_modulus = convert::young_modulus(young_modulus, youngs_modulus)?;
        let poisson_ratio = required("poisson_ratio", poisson_ratio)?;
        let density = required("density", density)?;
        let nodes = rows3(&nodes, "nodes")?;
        let t = triangles.as_array();
        if t.ncols() != 3 {
            return Err(shape_err(
                "triangles",
                format!("expected shape (n, 3), got {:?}", t.shape()),
            ));
        }
        let mut tris = Vec::with_capacity(t.nrows());
        for r in t.rows() {
            if r.iter().any(|&i| i < 0) {
                return Err(shape_err("triangles", "negative node index".into()));
            }
            tris.push([r[0] as usize, r[1] as usize, r[2] as usize]);
        }
        let mesh = TriMesh {
            nodes,
            triangles: tris,
            thickness: thickness.as_array().to_vec(),
        };
        for (k, &h) in mesh.thickness.iter().enumerate() {
            if !(h > 0.0) || !h.is_finite() {
                return Err(e(DemfemError::InvalidParameter {
                    field: "thickness".into(),
                    value: format!("{h:e} m at triangle {k}"),
                    allowed: "finite and > 0".into(),
                }));
            }
        }
        let material = LinearElastic::new(young_modulus, poisson_ratio, density).map_err(e)?;
        let mut fx = Vec::new();
        if let Some(f) = fixed {
            let f = f.as_array();
            if f.ncols() != 2 {
                return Err(shape_err(
                    "fixed",
                    format!("expected shape (k, 2), got {:?}", f.shape()),
                ));
            }
            for r in f.rows() {
                if r[0] < 0 || !(0..6).contains(&r[1]) {
                    return Err(shape_err(
                        "fixed",
                        format!("({}, {}) is not a (node, dof 0-5) pair", r[0], r[1]),
                    ));
                }
                fx.push((r[0] as usize, r[1] as usize));
            }
        }
        let model = ShellModel::new(mesh, material).map_err(e)?;
        let inner = ShellExplicit::new(&model, &fx, dt).map_err(e)?;
        Ok(Self { model, inner })
    }

    /// Initial velocity (N,3) m/s of the translations, or (N,6) with the rotations (rad/s).
    fn set_initial_velocity(&mut self, v: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        let a = v.as_array();
        let n = self.model.mesh.nodes.len();
        if a.nrows() != n || (a.ncols() != 3 && a.ncols() != 6) {
            return Err(shape_err(
                "v0",
                format!("expected shape ({n}, 3) or ({n}, 6), got {:?}", a.shape()),
            ));
        }
        let mut all = vec![0.0; 6 * n];
        for i in 0..n {
            for c in 0..a.ncols() {
                all[6 * i + c] = a[[i, c]];
            }
        }
        self.inner.set_initial_velocity(&all).map_err(e)
    }

    /// Add the weight of the lumped masses in the acceleration `g` (m/s²) to the loads.
    fn add_gravity(&mut self, g: [f64; 3]) -> PyResult<()> {
        self.inner.add_gravity(g).map_err(e)
    }

    /// Attach contact (before the first step); the arguments are those of
    /// FemTetSolver.set_contact, the penalty is k = s·E·t per face. The stable step is
    /// re-certified with the contact included.
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
        let c = fem_contact::build_shell(
            &self.model.mesh,
            &self.model.material,
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
        py.detach(|| inner.set_contact(c)).map_err(e)
    }

    /// Advance `n_steps` with the GIL released, in chunks (Ctrl-C stops cleanly with
    /// SimulationInterrupted); `progress(steps, time_s)` after each chunk.
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

    /// Contact output channels (party a, party b, region of a), a < b.
    fn contact_channels(&self) -> Vec<(usize, usize, usize)> {
        self.inner
            .contact()
            .map(|c| c.channels())
            .unwrap_or_default()
    }
    /// Contact history (samples, 1 + 4·channels), as FemTetSolver.contact_history.
    fn contact_history<'py>(&self, py: Python<'py>) -> PyResult<Nodes<'py>> {
        let (h, w) = match self.inner.contact() {
            Some(c) => (c.history().to_vec(), 1 + 4 * c.channels().len()),
            None => (Vec::new(), 1),
        };
        let rows = h.len() / w;
        let a = numpy::ndarray::Array2::from_shape_vec((rows, w), h)
            .map_err(|x| shape_err("contact history", x.to_string()))?;
        Ok(a.into_pyarray(py))
    }
    /// Contact pressure per node in the last step (normal force over one side's tributary
    /// area), Pa (N,).
    fn contact_pressure<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let p = self
            .inner
            .contact()
            .map(|c| c.pressure())
            .unwrap_or_else(|| vec![0.0; self.model.mesh.nodes.len()]);
        p.into_pyarray(py)
    }
    /// Contact energies and counters, as FemTetSolver.contact_info.
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
    /// Translational lumped mass per node (N,), kg.
    fn mass<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.node_mass().into_pyarray(py)
    }
    /// The run's dynamic state (contact included) as bytes.
    fn save_state<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.inner.save_state())
    }
    /// Restore a state from save_state into a solver built from the same inputs.
    fn restore_state(&mut self, state: &[u8]) -> PyResult<()> {
        self.inner.restore_state(state).map_err(e)
    }
    /// Time step in use, s.
    #[getter]
    fn dt(&self) -> f64 {
        self.inner.dt()
    }
    /// Certified stable-step bound (contact included once attached), s.
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
    /// Translations (N,3), m.
    fn displacement<'py>(&self, py: Python<'py>) -> PyResult<Nodes<'py>> {
        arr3(py, &self.inner.node_displacement())
    }
    /// Translational velocity at the last half step (N,3), m/s.
    fn velocity<'py>(&self, py: Python<'py>) -> PyResult<Nodes<'py>> {
        let v: Vec<[f64; 3]> = self
            .inner
            .velocity()
            .chunks_exact(6)
            .map(|x| [x[0], x[1], x[2]])
            .collect();
        arr3(py, &v)
    }
    /// All dofs (N·6,): translations m, rotations rad.
    fn dofs<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.displacement().to_vec().into_pyarray(py)
    }
    /// Energies (J) at the start of the last step: kinetic, internal, external_work (loads,
    /// reactions and contact), damping_work (0), initial, relative_balance_error (contact
    /// energy and friction work included).
    fn energy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let r = self.inner.energy_report();
        let [k, i, w, e0] = self.inner.energy;
        let d = PyDict::new(py);
        d.set_item("time", self.inner.time())?;
        d.set_item("kinetic", k)?;
        d.set_item("internal", i)?;
        d.set_item("external_work", w)?;
        d.set_item("damping_work", 0.0)?;
        d.set_item("initial", e0)?;
        d.set_item("relative_balance_error", r.relative_balance_error())?;
        Ok(d)
    }
    /// Maximum principal in-plane stress σ1 (E,3) Pa of each triangle at its bottom
    /// (−t/2 along the triangle's normal), middle and top (+t/2) surfaces.
    fn surface_sigma1<'py>(&self, py: Python<'py>) -> PyResult<Nodes<'py>> {
        let s = self
            .model
            .max_principal_stresses(self.inner.displacement())
            .map_err(e)?;
        arr3(py, &s)
    }
    /// Unit normal of each triangle in the reference configuration (E,3).
    fn triangle_normals<'py>(&self, py: Python<'py>) -> PyResult<Nodes<'py>> {
        let m = &self.model.mesh;
        let n: Vec<[f64; 3]> = m
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.nodes[i]);
                let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
                let x = [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ];
                let l = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
                [x[0] / l, x[1] / l, x[2] / l]
            })
            .collect();
        arr3(py, &n)
    }
}

/// Register the shell solver class on the extension module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<FemShellSolver>()?;
    Ok(())
}
