//! The whole-contact event table of a DEM run ([`ContactEvent`]) as a dict of numpy columns.

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use demfem::dem::ContactEvent;

use crate::convert::{array_n3, set_partner_columns};

/// Columns: time (s, first step in contact), duration (s), particle, partner,
/// partner_is_wall, normal_speed and tangential_speed at onset (m/s), position and
/// partner_position at onset (K, 3) (m), peak_normal_force (N), normal_impulse (N·s),
/// peak_tangential_force (N), max_overlap (m), complete (bool).
pub(crate) fn event_columns<'py>(
    py: Python<'py>,
    ev: &[ContactEvent],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let col = |name: &str, f: &dyn Fn(&ContactEvent) -> f64| -> PyResult<()> {
        d.set_item(
            name,
            ev.iter().map(f).collect::<Vec<f64>>().into_pyarray(py),
        )
    };
    col("time", &|e| e.time)?;
    col("duration", &|e| e.duration)?;
    col("normal_speed", &|e| e.normal_speed)?;
    col("tangential_speed", &|e| e.tangential_speed)?;
    col("peak_normal_force", &|e| e.peak_normal_force)?;
    col("normal_impulse", &|e| e.normal_impulse)?;
    col("peak_tangential_force", &|e| e.peak_tangential_force)?;
    col("max_overlap", &|e| e.max_overlap)?;
    d.set_item(
        "particle",
        ev.iter()
            .map(|e| e.particle)
            .collect::<Vec<u32>>()
            .into_pyarray(py),
    )?;
    set_partner_columns(py, &d, ev.iter().map(|e| e.partner))?;
    d.set_item(
        "position",
        array_n3(py, &ev.iter().map(|e| e.position).collect::<Vec<_>>())?,
    )?;
    d.set_item(
        "partner_position",
        array_n3(
            py,
            &ev.iter().map(|e| e.partner_position).collect::<Vec<_>>(),
        )?,
    )?;
    d.set_item(
        "complete",
        ev.iter()
            .map(|e| e.complete)
            .collect::<Vec<bool>>()
            .into_pyarray(py),
    )?;
    Ok(d)
}
