//! Python binding of the explicit shell solver (`FemShellSolver`): flat CST + DKT shells
//! (6 dof per node) in central-difference dynamics, two-sided penalty contact offset by
//! half the thickness, rigid surfaces, no-tension springs, gravity, checkpoints, σ1 on both
//! faces. The methods it shares with the tet solver are written once in
//! [`crate::fem_solver`]. SI units.

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use demfem::fem::contact::FemContact;
use demfem::fem::shell::ShellModel;
use demfem::fem::{LinearElastic, ShellExplicit, TriMesh};
use demfem::DemfemError;

use crate::convert::{self, arr3, required, rows3, Nodes};
use crate::error::{core_err as e, shape_err};
use crate::fem_solver::explicit_solver_methods;

/// Explicit dynamics of shell bodies in contact.
#[pyclass(module = "demfem._core")]
pub struct FemShellSolver {
    model: ShellModel,
    inner: ShellExplicit,
}

explicit_solver_methods!(
FemShellSolver,
contact(s, body, region, settings) =>
    FemContact::new_shell(&s.model.mesh, body, region, &s.model.material, settings),
{
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
        let triangles = convert::connectivity::<3>(&triangles, "triangles")?;
        let mesh = TriMesh {
            nodes,
            triangles,
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

    /// All dofs (N·6,): translations m, rotations rad.
    fn dofs<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.displacement().as_flattened().to_vec().into_pyarray(py)
    }
    /// Maximum principal in-plane stress σ1 (E,3) Pa of each triangle at its bottom
    /// (−t/2 along the triangle's normal), middle and top (+t/2) surfaces.
    fn surface_sigma1<'py>(&self, py: Python<'py>) -> PyResult<Nodes<'py>> {
        let s = self
            .model
            .max_principal_stresses(self.inner.displacement().as_flattened())
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
);

/// Register the shell solver class on the extension module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<FemShellSolver>()?;
    Ok(())
}
