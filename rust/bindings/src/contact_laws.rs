//! Python binding of the contact laws written once in the core ([`demfem::contact`]): the
//! effective quantities of a pair (eqs. 3, 4, 9), the Hertz, Reissner, series and linearised
//! stiffnesses (eqs. 2, 6, 13, 15), the normal force of a law at given overlaps, the impact
//! force, overlap and duration of a pair, Tsuji restitution and the Rayleigh time step.
//! `demfem.contact` validates its inputs by name and computes through these functions; it
//! holds no second implementation. SI units (m, N, kg, s, Pa).

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

use demfem::contact::{self, ForceClamp, NormalLaw};
use demfem::DemfemError;

use crate::convert::as_float_array;
use crate::error::{CoreResult, PyDemfemError};

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

/// `value` > 0 or +inf (a plane, a rigid or an immovable partner); NaN refused; names `field`.
fn check_positive_or_inf(field: &str, value: f64, what: &str) -> CoreResult<f64> {
    if value > 0.0 {
        Ok(value)
    } else {
        Err(DemfemError::invalid(field, value, &format!("> 0 (inf for {what})")).into())
    }
}

/// Effective modulus E* (Pa) from 1/E* = (1−ν1²)/E1 + (1−ν2²)/E2 (eq. 4); `E2 = inf` is a
/// rigid partner.
#[pyfunction]
#[allow(non_snake_case)]
#[pyo3(signature = (E1, nu1, E2, nu2))]
fn effective_modulus(E1: f64, nu1: f64, E2: f64, nu2: f64) -> PyResult<f64> {
    Ok(contact::effective_modulus(E1, nu1, E2, nu2).map_err(PyDemfemError::from)?)
}

/// Effective radius R* (m) from 1/R* = 1/R1 + 1/R2 (eq. 3); `R2 = inf` is a plane.
#[pyfunction]
#[allow(non_snake_case)]
#[pyo3(signature = (R1, R2))]
fn effective_radius(R1: f64, R2: f64) -> PyResult<f64> {
    Ok(contact::effective_radius(R1, R2).map_err(PyDemfemError::from)?)
}

/// Effective mass m* (kg) from 1/m* = 1/m1 + 1/m2 (eq. 9); `m2 = inf` is an immovable
/// partner.
#[pyfunction]
fn effective_mass(m1: f64, m2: f64) -> PyResult<f64> {
    Ok(contact::effective_mass(m1, m2).map_err(PyDemfemError::from)?)
}

/// Hertz stiffness k_H = 4/3 √R* E* (eq. 2), N/m^1.5, of a pair of effective radius R_star
/// (m) and effective modulus E_star (Pa).
#[pyfunction]
#[allow(non_snake_case)]
#[pyo3(signature = (R_star, E_star))]
fn hertz_stiffness(R_star: f64, E_star: f64) -> PyResult<f64> {
    Ok(contact::hertz_stiffness(R_star, E_star).map_err(PyDemfemError::from)?)
}

/// Reissner point-load stiffness of a thin shallow shell (eq. 6), N/m: E (Pa), nu, wall
/// thickness t (m) and mid-surface radius R (m), 0 < t < R.
#[pyfunction]
#[allow(non_snake_case)]
#[pyo3(signature = (E, nu, t, R))]
fn reissner_stiffness(E: f64, nu: f64, t: f64, R: f64) -> PyResult<f64> {
    Ok(contact::reissner_stiffness(E, nu, t, R).map_err(PyDemfemError::from)?)
}

/// Two springs in series, 1/k = 1/k1 + 1/k2 (eqs. 12 and 15), N/m; `inf` is a spring that
/// does not deflect (a wall, a solid body), and two of them give `inf`.
#[pyfunction]
fn series_stiffness(k1: f64, k2: f64) -> PyResult<f64> {
    check_positive_or_inf("k1", k1, "a rigid spring")?;
    check_positive_or_inf("k2", k2, "a rigid spring")?;
    Ok(contact::series(k1, k2))
}

/// Linearised Hertz stiffness (eq. 13), N/m:
/// k_lin = 4/3 (15/16)^{1/5} R*^{2/5} E*^{4/5} m*^{1/5} v_rel^{2/5}.
#[pyfunction]
#[allow(non_snake_case)]
#[pyo3(signature = (R_star, E_star, m_star, v_rel))]
fn linearized_hertz_stiffness(R_star: f64, E_star: f64, m_star: f64, v_rel: f64) -> PyResult<f64> {
    demfem::error::check_positive("R_star", R_star).map_err(PyDemfemError::from)?;
    demfem::error::check_positive("E_star", E_star).map_err(PyDemfemError::from)?;
    contact_checks(m_star, v_rel)?;
    Ok(contact::linearized_hertz_stiffness(
        R_star, E_star, m_star, v_rel,
    ))
}

/// Maximum overlap (m) of an undamped Hertz impact of stiffness k_h (N/m^1.5) and effective
/// mass m_star (kg) at v_rel (m/s): (5 m* v² / (4 k_H))^{2/5}.
#[pyfunction]
fn hertz_max_overlap(k_h: f64, m_star: f64, v_rel: f64) -> PyResult<f64> {
    demfem::error::check_positive("k_h", k_h).map_err(PyDemfemError::from)?;
    contact_checks(m_star, v_rel)?;
    Ok(contact::hertz_max_overlap(k_h, m_star, v_rel))
}

/// Register the contact-law functions on the extension module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(normal_force, m)?)?;
    m.add_function(wrap_pyfunction!(max_impact_force, m)?)?;
    m.add_function(wrap_pyfunction!(tsuji_restitution, m)?)?;
    m.add_function(wrap_pyfunction!(tsuji_damping_for_restitution, m)?)?;
    m.add_function(wrap_pyfunction!(rayleigh_time_step, m)?)?;
    m.add_function(wrap_pyfunction!(hertz_impact_duration, m)?)?;
    m.add_function(wrap_pyfunction!(effective_modulus, m)?)?;
    m.add_function(wrap_pyfunction!(effective_radius, m)?)?;
    m.add_function(wrap_pyfunction!(effective_mass, m)?)?;
    m.add_function(wrap_pyfunction!(hertz_stiffness, m)?)?;
    m.add_function(wrap_pyfunction!(reissner_stiffness, m)?)?;
    m.add_function(wrap_pyfunction!(series_stiffness, m)?)?;
    m.add_function(wrap_pyfunction!(linearized_hertz_stiffness, m)?)?;
    m.add_function(wrap_pyfunction!(hertz_max_overlap, m)?)?;
    Ok(())
}
