//! PyO3 bindings of the demfem core: array conversion, GIL release around long calls and
//! the mapping of [`demfem::DemfemError`] onto one Python exception tree. No physics here.

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyType;

use demfem::contact::{self, ForceClamp, NormalLaw};
use demfem::DemfemError;

mod dem;
mod dem_events;
mod dem_walls;
mod fem;
mod fem_contact;
mod fem_shell;
mod rigid;

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

/// Longest stretch of wall time the engine runs without the GIL between two checks of
/// Ctrl-C, s (the slices are sized from the measured speed of the previous one).
const SIGNAL_CHECK_INTERVAL_S: f64 = 0.1;

/// Advance a simulation `n` steps in chunks of `chunk`, with the GIL released while the
/// engine runs. Between chunks `after_chunk` runs with the GIL held (progress callbacks).
/// Each chunk runs in slices of about [`SIGNAL_CHECK_INTERVAL_S`] of wall time, so Ctrl-C is
/// seen within a fraction of a second whatever `chunk` is: it raises `SimulationInterrupted`
/// with the time and step count of the consistent state reached (`clock`). The one stepping
/// loop of every simulation class. Slicing does not change the result: the engine's state
/// after k steps does not depend on how they were grouped.
pub(crate) fn run_in_chunks<S: Send>(
    py: Python<'_>,
    state: &mut S,
    n: u64,
    chunk: u64,
    advance: impl Fn(&mut S, u64) -> demfem::Result<()> + Sync,
    clock: impl Fn(&S) -> (f64, u64),
    mut after_chunk: impl FnMut(&S) -> PyResult<()>,
) -> PyResult<()> {
    let chunk = chunk.max(1);
    let mut done = 0;
    // steps per slice: starts small, then follows the measured speed
    let mut slice: u64 = 8;
    let check = |py: Python<'_>, state: &S| -> PyResult<()> {
        if let Err(e) = py.check_signals() {
            if e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) {
                let (time, steps) = clock(state);
                return Err(PyDemfemError::from(DemfemError::Interrupted { time, steps }).into());
            }
            return Err(e);
        }
        Ok(())
    };
    while done < n {
        let mut left = chunk.min(n - done);
        while left > 0 {
            let k = slice.min(left);
            let start = std::time::Instant::now();
            py.detach(|| advance(&mut *state, k))
                .map_err(PyDemfemError::from)?;
            let elapsed = start.elapsed().as_secs_f64();
            left -= k;
            done += k;
            let target = if elapsed > 0.0 {
                (k as f64 * SIGNAL_CHECK_INTERVAL_S / elapsed).floor()
            } else {
                f64::INFINITY
            };
            // at most double per slice, so that one slow step cannot be followed by a huge slice
            slice = (target.min(2.0 * k as f64).max(1.0)) as u64;
            if left > 0 {
                check(py, state)?;
            }
        }
        after_chunk(state)?;
        check(py, state)?;
    }
    Ok(())
}

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

/// Whole steps of `dt` (s) from `time` to reach `t_end` (s), at least 0; `t_end` must be
/// finite.
pub(crate) fn steps_until(t_end: f64, time: f64, dt: f64) -> PyResult<u64> {
    if !t_end.is_finite() {
        return Err(PyDemfemError::from(DemfemError::InvalidParameter {
            field: "t_end".into(),
            value: t_end.to_string(),
            allowed: "finite".into(),
        })
        .into());
    }
    let remaining = ((t_end - time) / dt).ceil();
    Ok(if remaining > 0.0 { remaining as u64 } else { 0 })
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
/// Same argument order as `demfem.contact.normal_force(overlap, model, k_h, k_r, k)`; NaN or
/// infinite overlaps are refused (InvalidParameterError naming `overlap[i]`).
#[pyfunction]
#[pyo3(signature = (overlap, model, k_h=f64::NAN, k_r=f64::NAN, k=f64::NAN))]
fn normal_force<'py>(
    py: Python<'py>,
    overlap: &Bound<'py, PyAny>,
    model: &str,
    k_h: f64,
    k_r: f64,
    k: f64,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)> {
    let law = parse_law(model, k_h, k_r, k)?;
    let overlap = as_float_array(overlap, "overlap")?;
    let overlap: PyReadonlyArray1<'py, f64> = overlap.extract().map_err(|_| {
        PyErr::from(PyDemfemError::from(DemfemError::ShapeMismatch {
            field: "overlap".into(),
            detail: format!(
                "expected a 1-D array, got {} dimensions",
                overlap
                    .getattr("ndim")
                    .and_then(|d| d.extract::<usize>())
                    .unwrap_or(0)
            ),
        }))
    })?;
    let d = overlap.as_array();
    if let Some((i, x)) = d.iter().enumerate().find(|(_, x)| !x.is_finite()) {
        return Err(PyDemfemError::from(DemfemError::InvalidParameter {
            field: format!("overlap[{i}]"),
            value: x.to_string(),
            allowed: "finite (m)".into(),
        })
        .into());
    }
    let mut f = Vec::with_capacity(d.len());
    let mut s = Vec::with_capacity(d.len());
    for &x in d.iter() {
        let (fi, si) = law.force_and_stiffness(x);
        f.push(fi);
        s.push(si);
    }
    Ok((f.into_pyarray(py), s.into_pyarray(py)))
}

/// Maximum impact force (N) of two bodies of effective mass m_star (kg) at v_rel (m/s);
/// the physical arguments first and the law after them, as in
/// `demfem.contact.max_contact_force(a, b, v_rel, model)`.
#[pyfunction]
#[pyo3(signature = (m_star, v_rel, model, k_h=f64::NAN, k_r=f64::NAN, k=f64::NAN))]
fn max_impact_force(
    m_star: f64,
    v_rel: f64,
    model: &str,
    k_h: f64,
    k_r: f64,
    k: f64,
) -> PyResult<f64> {
    contact_checks(m_star, v_rel)?;
    Ok(match parse_law(model, k_h, k_r, k)? {
        NormalLaw::Hertz { k_h } => contact::max_force_hertz(k_h, m_star, v_rel),
        NormalLaw::Linear { k } => contact::max_force_linear(k, m_star, v_rel),
        NormalLaw::HertzReissner { k_h, k_r } => {
            contact::max_force_hertz_reissner(k_h, k_r, m_star, v_rel)
        }
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
    contact::check_tsuji_zeta(zeta).map_err(PyDemfemError::from)?;
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

/// Rayleigh time step (s) of a sphere of radius (m), E (Pa), nu and density (kg/m^3): the
/// argument order and names of `demfem.contact.rayleigh_time_step`.
#[pyfunction]
#[allow(non_snake_case)]
#[pyo3(signature = (radius, E, nu, density))]
fn rayleigh_time_step(radius: f64, E: f64, nu: f64, density: f64) -> PyResult<f64> {
    Ok(contact::rayleigh_time_step(radius, density, E, nu).map_err(PyDemfemError::from)?)
}

/// Duration (s) of an undamped Hertz impact of stiffness k_h (N/m^1.5) and effective mass
/// m_star (kg) at v_rel (m/s). (`demfem.contact.hertz_contact_duration(a, b, v_rel)` takes
/// two bodies; this one, like `max_impact_force`, takes the pair's stiffness and mass.)
#[pyfunction]
fn hertz_impact_duration(k_h: f64, m_star: f64, v_rel: f64) -> PyResult<f64> {
    demfem::error::check_positive("k_h", k_h).map_err(PyDemfemError::from)?;
    demfem::error::check_positive("m_star", m_star).map_err(PyDemfemError::from)?;
    Ok(contact::hertz_contact_duration(k_h, m_star, v_rel).map_err(PyDemfemError::from)?)
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(normal_force, m)?)?;
    m.add_function(wrap_pyfunction!(max_impact_force, m)?)?;
    m.add_function(wrap_pyfunction!(tsuji_restitution, m)?)?;
    m.add_function(wrap_pyfunction!(tsuji_damping_for_restitution, m)?)?;
    m.add_function(wrap_pyfunction!(rayleigh_time_step, m)?)?;
    m.add_function(wrap_pyfunction!(hertz_impact_duration, m)?)?;
    dem::register(m)?;
    fem::register(m)?;
    rigid::register(m)?;
    Ok(())
}
