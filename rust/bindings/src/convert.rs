//! Conversions between numpy and the core's types, shared by every binding: input arrays
//! checked and converted (float64 and int64, shapes (N,), (N, 3)), counts refused when
//! negative, dict fields read with their names, and the core's arrays returned as numpy
//! (N, 3) and (N, 6) arrays. Values keep their SI units; errors name the field.

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use demfem::dem::Partner;
use demfem::geometry::Vec3;
use demfem::DemfemError;

use crate::error::{invalid, shape_err, PyDemfemError};

/// A count given from Python as a signed integer, refused when negative (instead of
/// PyO3's OverflowError without a field name).
pub(crate) fn count(field: &str, value: i64) -> PyResult<u64> {
    u64::try_from(value).map_err(|_| {
        PyDemfemError::from(DemfemError::InvalidParameter {
            field: field.into(),
            value: value.to_string(),
            allowed: "a whole number >= 0".into(),
        })
        .into()
    })
}

/// A real input array converted to float64 (integers and other real dtypes accepted);
/// anything else raises InvalidParameterError naming `field` (instead of a bare TypeError).
pub(crate) fn as_float_array<'py>(
    obj: &Bound<'py, PyAny>,
    field: &str,
) -> PyResult<Bound<'py, PyAny>> {
    as_typed_array(obj, field, "float64", "an array of real numbers")
}

/// An integer input array converted to int64 (any integer dtype accepted); anything else
/// raises InvalidParameterError naming `field`.
pub(crate) fn as_int_array<'py>(
    obj: &Bound<'py, PyAny>,
    field: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let py = obj.py();
    let np = py.import("numpy")?;
    let arr = np.call_method1("asarray", (obj,)).map_err(|_| {
        PyErr::from(PyDemfemError::from(DemfemError::InvalidParameter {
            field: field.into(),
            value: "not an array".into(),
            allowed: "an array of integers".into(),
        }))
    })?;
    let kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    let size: usize = arr.getattr("size")?.extract()?;
    if !(kind == "i" || kind == "u" || size == 0) {
        let dtype = arr.getattr("dtype")?.str()?.to_string();
        return Err(PyDemfemError::from(DemfemError::InvalidParameter {
            field: field.into(),
            value: format!("an array of dtype {dtype}"),
            allowed: "an array of integers".into(),
        })
        .into());
    }
    as_typed_array(&arr, field, "int64", "an array of integers")
}

fn as_typed_array<'py>(
    obj: &Bound<'py, PyAny>,
    field: &str,
    dtype: &str,
    allowed: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let py = obj.py();
    let np = py.import("numpy")?;
    let kwargs = pyo3::types::PyDict::new(py);
    kwargs.set_item("dtype", dtype)?;
    np.call_method("ascontiguousarray", (obj,), Some(&kwargs))
        .map_err(|e| {
            PyDemfemError::from(DemfemError::InvalidParameter {
                field: field.into(),
                value: e.value(py).to_string(),
                allowed: allowed.into(),
            })
            .into()
        })
}

/// A converted array (see [`as_float_array`]) as a 2-D float64 view.
pub(crate) fn float2<'py>(
    a: &Bound<'py, PyAny>,
    field: &str,
) -> PyResult<PyReadonlyArray2<'py, f64>> {
    a.extract().map_err(|_| {
        shape_err(
            field,
            format!("expected a 2-D array (N, 3), got {} dimensions", ndim(a)),
        )
    })
}

/// A converted array as a 1-D float64 view.
pub(crate) fn float1<'py>(
    a: &Bound<'py, PyAny>,
    field: &str,
) -> PyResult<PyReadonlyArray1<'py, f64>> {
    a.extract().map_err(|_| {
        shape_err(
            field,
            format!("expected a 1-D array, got {} dimensions", ndim(a)),
        )
    })
}

/// A converted integer array as a 1-D int64 view.
pub(crate) fn int1<'py>(
    a: &Bound<'py, PyAny>,
    field: &str,
) -> PyResult<PyReadonlyArray1<'py, i64>> {
    a.extract().map_err(|_| {
        shape_err(
            field,
            format!("expected a 1-D array, got {} dimensions", ndim(a)),
        )
    })
}

fn ndim(a: &Bound<'_, PyAny>) -> usize {
    a.getattr("ndim").and_then(|d| d.extract()).unwrap_or(0)
}

/// Rows of an (N, 3) array (`n` rows when given) as vectors.
pub(crate) fn vec3s(
    field: &str,
    a: &PyReadonlyArray2<'_, f64>,
    n: Option<usize>,
) -> PyResult<Vec<Vec3>> {
    let v = a.as_array();
    let s = v.shape();
    if s[1] != 3 || n.is_some_and(|n| n != s[0]) {
        return Err(shape_err(
            field,
            format!(
                "expected ({}, 3), got ({}, {})",
                n.map_or("N".into(), |n| n.to_string()),
                s[0],
                s[1]
            ),
        ));
    }
    Ok(v.outer_iter()
        .map(|r| Vec3::new(r[0], r[1], r[2]))
        .collect())
}

/// The number `d[key]`, or `default` when absent (required when `None`); `what` names the
/// dict in errors.
pub(crate) fn get_f64(
    d: &Bound<'_, PyDict>,
    key: &str,
    default: Option<f64>,
    what: &str,
) -> PyResult<f64> {
    match d.get_item(key)? {
        Some(v) => v
            .extract::<f64>()
            .map_err(|_| invalid(&format!("{what}.{key}"), &v.to_string(), "a number")),
        None => default.ok_or_else(|| invalid(&format!("{what}.{key}"), "missing", "required")),
    }
}

/// Vectors as a flat [x0, y0, z0, x1, …] list.
pub(crate) fn flat3(v: &[Vec3]) -> Vec<f64> {
    let mut out = Vec::with_capacity(3 * v.len());
    for x in v {
        out.extend([x.x, x.y, x.z]);
    }
    out
}

/// Vectors as an (N, 3) numpy array.
pub(crate) fn array_n3<'py>(py: Python<'py>, v: &[Vec3]) -> PyResult<Bound<'py, PyAny>> {
    Ok(flat3(v).into_pyarray(py).reshape([v.len(), 3])?.into_any())
}

/// The `partner` (index) and `partner_is_wall` columns of an onset or contact table.
pub(crate) fn set_partner_columns(
    py: Python<'_>,
    d: &Bound<'_, PyDict>,
    partners: impl Iterator<Item = Partner>,
) -> PyResult<()> {
    let (partner, is_wall): (Vec<u32>, Vec<bool>) = partners
        .map(|p| match p {
            Partner::Particle(j) => (j, false),
            Partner::Wall(w) => (w, true),
        })
        .unzip();
    d.set_item("partner", partner.into_pyarray(py))?;
    d.set_item("partner_is_wall", is_wall.into_pyarray(py))?;
    Ok(())
}

/// A 2-D float64 array returned to Python.
pub(crate) type Nodes<'py> = Bound<'py, PyArray2<f64>>;

/// Rows of an (N, 3) array as `[x, y, z]`.
pub(crate) fn rows3(a: &PyReadonlyArray2<'_, f64>, field: &str) -> PyResult<Vec<[f64; 3]>> {
    let v = a.as_array();
    if v.ncols() != 3 {
        return Err(shape_err(
            field,
            format!("expected shape (n, 3), got {:?}", v.shape()),
        ));
    }
    Ok(v.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect())
}

/// `[x, y, z]` rows as an (N, 3) numpy array.
pub(crate) fn arr3<'py>(py: Python<'py>, v: &[[f64; 3]]) -> PyResult<Nodes<'py>> {
    let flat: Vec<f64> = v.iter().flatten().cloned().collect();
    let a = Array2::from_shape_vec((v.len(), 3), flat)
        .map_err(|e| shape_err("array", e.to_string()))?;
    Ok(a.into_pyarray(py))
}

/// (N, 6) values (stresses) as a numpy array.
pub(crate) fn arr6<'py>(py: Python<'py>, v: &[[f64; 6]]) -> PyResult<Nodes<'py>> {
    let flat: Vec<f64> = v.iter().flatten().cloned().collect();
    let a = Array2::from_shape_vec((v.len(), 6), flat)
        .map_err(|e| shape_err("array", e.to_string()))?;
    Ok(a.into_pyarray(py))
}

/// Connectivity (E, K) as an int64 numpy array.
pub(crate) fn idx_arr<'py, const K: usize>(
    py: Python<'py>,
    v: &[[usize; K]],
) -> PyResult<Bound<'py, PyArray2<i64>>> {
    let flat: Vec<i64> = v.iter().flatten().map(|&i| i as i64).collect();
    let a = Array2::from_shape_vec((v.len(), K), flat)
        .map_err(|e| shape_err("array", e.to_string()))?;
    Ok(a.into_pyarray(py))
}

/// Ids per node (`n` of them, each in [0, 2^32)), e.g. the body or region of each node.
pub(crate) fn ids(a: &PyReadonlyArray1<'_, i64>, field: &str, n: usize) -> PyResult<Vec<u32>> {
    let v = a.as_array();
    if v.len() != n {
        return Err(shape_err(
            field,
            format!("{} entries for {n} nodes", v.len()),
        ));
    }
    v.iter()
        .map(|&x| {
            u32::try_from(x).map_err(|_| invalid(field, &x.to_string(), "integers in [0, 2^32)"))
        })
        .collect()
}

/// Young's modulus E (Pa) given as `young_modulus` (the documented name) or by its old
/// name `youngs_modulus` (still accepted as an alias): exactly one of the two.
pub(crate) fn young_modulus(value: Option<f64>, alias: Option<f64>) -> PyResult<f64> {
    match (value, alias) {
        (Some(e), None) | (None, Some(e)) => Ok(e),
        (Some(_), Some(_)) => Err(PyTypeError::new_err(
            "give young_modulus or its old name youngs_modulus, not both",
        )),
        (None, None) => Err(PyTypeError::new_err(
            "missing required argument: 'young_modulus' (Pa)",
        )),
    }
}

/// An argument that is required although the signature gives it a default (it follows
/// `young_modulus`, which has one so that its alias can stand in for it).
pub(crate) fn required<T>(name: &str, value: Option<T>) -> PyResult<T> {
    value.ok_or_else(|| PyTypeError::new_err(format!("missing required argument: '{name}'")))
}

/// Per-node dof vectors from an (`n`, 3) array (the translations; other dofs 0) or an
/// (`n`, D) array (every dof, e.g. a shell node's 3 translations and 3 rotations).
pub(crate) fn node_dofs<const D: usize>(
    a: &PyReadonlyArray2<'_, f64>,
    field: &str,
    n: usize,
) -> PyResult<Vec<[f64; D]>> {
    let v = a.as_array();
    if v.nrows() != n || (v.ncols() != 3 && v.ncols() != D) {
        let allowed = if D == 3 {
            format!("({n}, 3)")
        } else {
            format!("({n}, 3) or ({n}, {D})")
        };
        return Err(shape_err(
            field,
            format!("expected shape {allowed}, got {:?}", v.shape()),
        ));
    }
    Ok(v.rows()
        .into_iter()
        .map(|r| {
            let mut x = [0.0; D];
            for (xi, ri) in x.iter_mut().zip(r.iter()) {
                *xi = *ri;
            }
            x
        })
        .collect())
}

/// Element connectivity from an (E, `K`) integer array (node indices ≥ 0; that they exist
/// is left to the mesh's own validation).
pub(crate) fn connectivity<const K: usize>(
    a: &PyReadonlyArray2<'_, i64>,
    field: &str,
) -> PyResult<Vec<[usize; K]>> {
    let t = a.as_array();
    if t.ncols() != K {
        return Err(shape_err(
            field,
            format!("expected shape (n, {K}), got {:?}", t.shape()),
        ));
    }
    let mut out = Vec::with_capacity(t.nrows());
    for r in t.rows() {
        let mut e = [0usize; K];
        for (ei, &i) in e.iter_mut().zip(r.iter()) {
            *ei = usize::try_from(i).map_err(|_| shape_err(field, "negative node index".into()))?;
        }
        out.push(e);
    }
    Ok(out)
}
