//! Python binding of the explicit solver of linear tetrahedra (`FemTetSolver`): lumped
//! mass, Rayleigh damping, certified stable step, prescribed dofs and ramped loads, contact,
//! stresses and VTK output. The methods it shares with the shell solver are written once in
//! [`crate::fem_solver`]. SI units.

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use demfem::fem::contact::FemContact;
use demfem::fem::io::vtk::{write_vtu, DataArray};
use demfem::fem::stable_step::StepBound;
use demfem::fem::{
    stress, ExplicitConfig, ExplicitSolver, LinearElastic, LoadHistory, Prescribed, PrescribedKind,
    TetMesh,
};

use crate::convert::{self, arr6, required, rows3, Nodes};
use crate::error::{core_err, invalid};
use crate::fem::{prescribed_list, to_mesh};
use crate::fem_solver::explicit_solver_methods;

/// Explicit central-difference solver for linear tetrahedra (lumped mass, Rayleigh
/// damping, certified stable step). Times in s, lengths in m, forces in N.
#[pyclass(module = "demfem._core")]
struct FemTetSolver {
    inner: ExplicitSolver,
    mesh: TetMesh,
    material: LinearElastic,
}

explicit_solver_methods!(
FemTetSolver,
contact(s, body, region, settings) =>
    FemContact::new(&s.mesh, body, region, &s.material, settings),
{
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
        let material = LinearElastic::new(e, nu, density)
            .map_err(core_err)?;
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
            .map_err(core_err)?;
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
                return Err(invalid("kind", other, "'displacement' or 'velocity'"))
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
        self
            .inner
            .set_prescribed(&p, h)
            .map_err(core_err)
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
        self.inner.set_loads(f, h).map_err(core_err)
    }

    /// Extra nodal forces (N,3) N held until changed (e.g. contact forces).
    fn set_extra_loads(&mut self, loads: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        let f = rows3(&loads, "extra_loads")?;
        self
            .inner
            .set_extra_loads(&f)
            .map_err(core_err)
    }

    /// Initial displacement (N,3) m (before the first step).
    fn set_initial_displacement(&mut self, u: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        let u = rows3(&u, "displacement")?;
        self
            .inner
            .set_initial_displacement(&u)
            .map_err(core_err)
    }

    /// Mass added by mass scaling, kg.
    #[getter]
    fn added_mass(&self) -> f64 {
        self.inner.added_mass()
    }

    /// Element stresses (E,6) Pa, order xx, yy, zz, yz, xz, xy.
    fn element_stresses<'py>(&self, py: Python<'py>) -> PyResult<Nodes<'py>> {
        let s = stress::element_stresses(&self.mesh, &self.material, self.inner.displacement())
            .map_err(core_err)?;
        arr6(py, &s)
    }
    /// Nodal (volume-averaged) stresses (N,6) Pa.
    fn nodal_stresses<'py>(&self, py: Python<'py>) -> PyResult<Nodes<'py>> {
        let s = stress::element_stresses(&self.mesh, &self.material, self.inner.displacement())
            .map_err(core_err)?;
        let n = stress::nodal_stresses(&self.mesh, &s).map_err(core_err)?;
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
            .map_err(core_err)?;
        let ns = stress::nodal_stresses(&self.mesh, &es).map_err(core_err)?;
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
        .map_err(core_err)?;
        Ok(())
    }
}
);

/// Register the tet solver class on the extension module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<FemTetSolver>()?;
    Ok(())
}
