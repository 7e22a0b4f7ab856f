//! Python bindings of the FEM core's functions: cartridge meshes (tets, shells, a ball) as
//! numpy arrays, the sparse static solve and stress recovery; the explicit solvers are in
//! [`crate::fem_tet`] and [`crate::fem_shell`]. SI units throughout.

use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use demfem::fem::{stress, AxisymmetricProfile, LinearElastic, TetMesh};

use crate::convert::{self, arr3, arr6, connectivity, idx_arr, required, rows3, Nodes};
use crate::error::{invalid, shape_err, PyDemfemError};

pub(crate) fn to_mesh(
    nodes: &PyReadonlyArray2<'_, f64>,
    tets: &PyReadonlyArray2<'_, i64>,
) -> PyResult<TetMesh> {
    let nodes = rows3(nodes, "nodes")?;
    let tets = connectivity::<4>(tets, "tets")?;
    let mut mesh = TetMesh { nodes, tets };
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

pub(crate) fn prescribed_list(
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

/// Register the FEM functions and classes on the extension module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fem_tet_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(fem_shell_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(fem_solve_static, m)?)?;
    m.add_function(wrap_pyfunction!(fem_element_stresses, m)?)?;
    m.add_function(wrap_pyfunction!(fem_stress_invariants, m)?)?;
    m.add_function(wrap_pyfunction!(fem_ball_mesh, m)?)?;
    Ok(())
}
