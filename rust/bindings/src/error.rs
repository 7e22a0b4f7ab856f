//! The one mapping of the core's [`DemfemError`] onto the Python exception tree rooted at
//! `demfem.errors.DemfemError`, and the constructors of the errors the bindings raise
//! themselves (a bad shape, a bad value, named by field).

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyType;

use demfem::DemfemError;

/// The one conversion from core errors to Python exceptions: each variant raises the class
/// of the same name from `demfem.errors` (pure Python, so that bad input is both a
/// `DemfemError` and a `ValueError`).
pub(crate) struct PyDemfemError(DemfemError);

impl From<DemfemError> for PyDemfemError {
    fn from(e: DemfemError) -> Self {
        PyDemfemError(e)
    }
}

impl From<PyDemfemError> for PyErr {
    fn from(e: PyDemfemError) -> PyErr {
        let class = match e.0 {
            DemfemError::InvalidParameter { .. } => "InvalidParameterError",
            DemfemError::UnstableTimeStep { .. } => "UnstableTimeStepError",
            DemfemError::ShapeMismatch { .. } => "ShapeError",
            DemfemError::Effect(_) => "EffectError",
            DemfemError::Numerical(_) => "NumericalError",
            DemfemError::Io { .. } => "DemfemIOError",
            DemfemError::Interrupted { .. } => "SimulationInterrupted",
        };
        let msg = e.0.to_string();
        Python::attach(|py| {
            let cls = py
                .import("demfem.errors")
                .and_then(|m| m.getattr(class))
                .and_then(|c| c.cast_into::<PyType>().map_err(PyErr::from));
            match cls {
                Ok(cls) => PyErr::from_type(cls, msg),
                Err(_) => PyValueError::new_err(msg),
            }
        })
    }
}

/// A core result whose error converts into the Python exception tree with `?`.
pub(crate) type CoreResult<T> = Result<T, PyDemfemError>;

/// A core error as the Python exception of its class.
pub(crate) fn core_err(e: DemfemError) -> PyErr {
    PyDemfemError::from(e).into()
}

/// ShapeError naming `field`.
pub(crate) fn shape_err(field: &str, detail: String) -> PyErr {
    core_err(DemfemError::ShapeMismatch {
        field: field.into(),
        detail,
    })
}

/// InvalidParameterError naming `field`, its `value` and what is `allowed`.
pub(crate) fn invalid(field: &str, value: &str, allowed: &str) -> PyErr {
    core_err(DemfemError::InvalidParameter {
        field: field.into(),
        value: value.into(),
        allowed: allowed.into(),
    })
}
