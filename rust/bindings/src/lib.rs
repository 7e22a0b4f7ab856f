//! PyO3 bindings of the demfem core: array conversion, GIL release around long calls and
//! the mapping of [`demfem::DemfemError`] onto one Python exception tree. No physics here.

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;

use demfem::contact::{self, ForceClamp, NormalLaw};
use demfem::DemfemError;

mod fem;

create_exception!(_core, DemfemErrorPy, PyException, "Base class of every demfem error.");
create_exception!(_core, InvalidParameterError, PyValueError, "A value outside its allowed range (also a ValueError).");
create_exception!(_core, UnstableTimeStepError, PyValueError, "A time step above the stable limit (also a ValueError).");
create_exception!(_core, ShapeError, PyValueError, "Arrays whose shapes do not fit together (also a ValueError).");
create_exception!(_core, EffectError, PyValueError, "A scene needs an effect it did not name (also a ValueError).");
create_exception!(_core, NumericalError, PyException, "The simulation produced a non-finite value.");
create_exception!(_core, DemfemIOError, PyException, "Reading or writing a file failed.");
create_exception!(_core, SimulationInterrupted, PyException, "A run stopped cleanly at a step boundary (Ctrl-C).");

/// The one conversion from core errors to Python exceptions.
pub(crate) struct PyDemfemError(DemfemError);

impl From<DemfemError> for PyDemfemError {
    fn from(e: DemfemError) -> Self {
        PyDemfemError(e)
    }
}

impl From<PyDemfemError> for PyErr {
    fn from(e: PyDemfemError) -> PyErr {
        let msg = e.0.to_string();
        match e.0 {
            DemfemError::InvalidParameter { .. } => InvalidParameterError::new_err(msg),
            DemfemError::UnstableTimeStep { .. } => UnstableTimeStepError::new_err(msg),
            DemfemError::ShapeMismatch { .. } => ShapeError::new_err(msg),
            DemfemError::Effect(_) => EffectError::new_err(msg),
            DemfemError::Numerical(_) => NumericalError::new_err(msg),
            DemfemError::Io { .. } => DemfemIOError::new_err(msg),
            DemfemError::Interrupted { .. } => SimulationInterrupted::new_err(msg),
        }
    }
}

pub(crate) type CoreResult<T> = Result<T, PyDemfemError>;

fn parse_law(law: &str, k_h: f64, k_r: f64, k: f64) -> CoreResult<NormalLaw> {
    let l = match law {
        "hertz" => NormalLaw::Hertz { k_h },
        "linear" => NormalLaw::Linear { k },
        "hertz_reissner" => NormalLaw::HertzReissner { k_h, k_r },
        other => {
            return Err(DemfemError::InvalidParameter {
                field: "law".into(),
                value: other.into(),
                allowed: "one of 'hertz', 'linear', 'hertz_reissner'".into(),
            }
            .into())
        }
    };
    Ok(l.validated()?)
}

/// Normal force (N) and tangent stiffness (N/m) of a law at each overlap (m).
#[pyfunction]
#[pyo3(signature = (law, overlap, k_h=f64::NAN, k_r=f64::NAN, k=f64::NAN))]
fn normal_force<'py>(
    py: Python<'py>,
    law: &str,
    overlap: PyReadonlyArray1<'py, f64>,
    k_h: f64,
    k_r: f64,
    k: f64,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)> {
    let law = parse_law(law, k_h, k_r, k)?;
    let d = overlap.as_array();
    let mut f = Vec::with_capacity(d.len());
    let mut s = Vec::with_capacity(d.len());
    for &x in d.iter() {
        let (fi, si) = law.force_and_stiffness(x);
        f.push(fi);
        s.push(si);
    }
    Ok((f.into_pyarray(py), s.into_pyarray(py)))
}

/// Maximum impact force (N) of two bodies of effective mass m_star (kg) at v_rel (m/s).
#[pyfunction]
#[pyo3(signature = (law, m_star, v_rel, k_h=f64::NAN, k_r=f64::NAN, k=f64::NAN))]
fn max_impact_force(law: &str, m_star: f64, v_rel: f64, k_h: f64, k_r: f64, k: f64) -> PyResult<f64> {
    contact_checks(m_star, v_rel)?;
    Ok(match parse_law(law, k_h, k_r, k)? {
        NormalLaw::Hertz { k_h } => contact::max_force_hertz(k_h, m_star, v_rel),
        NormalLaw::Linear { k } => contact::max_force_linear(k, m_star, v_rel),
        NormalLaw::HertzReissner { k_h, k_r } => contact::max_force_hertz_reissner(k_h, k_r, m_star, v_rel),
    })
}

fn contact_checks(m_star: f64, v_rel: f64) -> CoreResult<()> {
    demfem::error::check_positive("m_star", m_star)?;
    demfem::error::check_non_negative("v_rel", v_rel)?;
    Ok(())
}

fn parse_clamp(clamp: bool) -> ForceClamp {
    if clamp {
        ForceClamp::NonNegative
    } else {
        ForceClamp::None
    }
}

/// Restitution of a Hertz impact with Tsuji damping parameter zeta (dimensionless).
#[pyfunction]
#[pyo3(signature = (zeta, clamp=false))]
fn tsuji_restitution(py: Python<'_>, zeta: f64, clamp: bool) -> PyResult<f64> {
    demfem::error::check_non_negative("zeta", zeta).map_err(PyDemfemError::from)?;
    Ok(py.detach(|| contact::tsuji_restitution(zeta, parse_clamp(clamp))))
}

/// Tsuji damping parameter zeta (dimensionless) that realises restitution e in (0, 1].
#[pyfunction]
#[pyo3(signature = (e, clamp=false))]
fn tsuji_damping_for_restitution(py: Python<'_>, e: f64, clamp: bool) -> PyResult<f64> {
    Ok(py
        .detach(|| contact::tsuji_damping_for_restitution(e, parse_clamp(clamp)))
        .map_err(PyDemfemError::from)?)
}

/// Rayleigh time step (s) of a sphere of radius (m), density (kg/m^3), E (Pa), nu.
#[pyfunction]
fn rayleigh_time_step(radius: f64, density: f64, e: f64, nu: f64) -> PyResult<f64> {
    Ok(contact::rayleigh_time_step(radius, density, e, nu).map_err(PyDemfemError::from)?)
}

/// Duration (s) of an undamped Hertz impact.
#[pyfunction]
fn hertz_contact_duration(k_h: f64, m_star: f64, v_rel: f64) -> PyResult<f64> {
    demfem::error::check_positive("k_h", k_h).map_err(PyDemfemError::from)?;
    demfem::error::check_positive("m_star", m_star).map_err(PyDemfemError::from)?;
    Ok(contact::hertz_contact_duration(k_h, m_star, v_rel).map_err(PyDemfemError::from)?)
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("DemfemError", py.get_type::<DemfemErrorPy>())?;
    m.add("InvalidParameterError", py.get_type::<InvalidParameterError>())?;
    m.add("UnstableTimeStepError", py.get_type::<UnstableTimeStepError>())?;
    m.add("ShapeError", py.get_type::<ShapeError>())?;
    m.add("EffectError", py.get_type::<EffectError>())?;
    m.add("NumericalError", py.get_type::<NumericalError>())?;
    m.add("DemfemIOError", py.get_type::<DemfemIOError>())?;
    m.add("SimulationInterrupted", py.get_type::<SimulationInterrupted>())?;
    m.add_function(wrap_pyfunction!(normal_force, m)?)?;
    m.add_function(wrap_pyfunction!(max_impact_force, m)?)?;
    m.add_function(wrap_pyfunction!(tsuji_restitution, m)?)?;
    m.add_function(wrap_pyfunction!(tsuji_damping_for_restitution, m)?)?;
    m.add_function(wrap_pyfunction!(rayleigh_time_step, m)?)?;
    m.add_function(wrap_pyfunction!(hertz_contact_duration, m)?)?;
    fem::register(m)?;
    Ok(())
}
