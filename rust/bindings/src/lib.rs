//! PyO3 bindings of the demfem core: the extension module `demfem._core` and its parts.
//! No physics here: [`convert`] turns numpy arrays into the core's types and back,
//! [`run`] steps a simulation with the GIL released, [`error`] maps
//! [`demfem::DemfemError`] onto one Python exception tree; one module a binding.

use pyo3::prelude::*;

mod contact_laws;
mod convert;
mod dem;
mod dem_events;
mod dem_walls;
mod error;
mod fem;
mod fem_contact;
mod fem_shell;
mod fem_solver;
mod fem_tet;
mod rigid;
mod run;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    contact_laws::register(m)?;
    dem::register(m)?;
    fem::register(m)?;
    fem_tet::register(m)?;
    fem_shell::register(m)?;
    rigid::register(m)?;
    Ok(())
}
