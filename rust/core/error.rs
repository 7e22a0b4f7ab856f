//! The one error type of the core. Every failure a user can provoke is an `Err`, never a
//! panic; the Python bindings map each variant to one exception class.

use thiserror::Error;

/// Result alias used throughout the core.
pub type Result<T> = std::result::Result<T, DemfemError>;

/// Errors reported by the demfem core.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum DemfemError {
    /// A user-supplied value is outside its allowed range (or is NaN / infinite).
    #[error("invalid {field} = {value}: must be {allowed}")]
    InvalidParameter {
        /// Name of the offending argument or field.
        field: String,
        /// The value that was given, formatted.
        value: String,
        /// Human-readable description of the allowed range.
        allowed: String,
    },
    /// A requested time step is above the stable limit of the active laws.
    #[error("time step dt = {dt:e} s exceeds the stable limit {limit:e} s ({reason})")]
    UnstableTimeStep {
        /// Requested time step, s.
        dt: f64,
        /// Stable limit, s.
        limit: f64,
        /// Which law or element sets the limit.
        reason: String,
    },
    /// Array shapes or lengths that do not fit together.
    #[error("shape mismatch for {field}: {detail}")]
    ShapeMismatch {
        /// Name of the offending array.
        field: String,
        /// What was expected and what was found.
        detail: String,
    },
    /// A scene that needs an effect it did not name, or names one it cannot use.
    #[error("effect error: {0}")]
    Effect(String),
    /// The simulation produced a non-finite value or lost stability.
    #[error("numerical failure: {0}")]
    Numerical(String),
    /// Reading or writing a file failed.
    #[error("i/o error on {path}: {detail}")]
    Io {
        /// Path of the file.
        path: String,
        /// The operating-system message.
        detail: String,
    },
    /// The run was interrupted (e.g. Ctrl-C) at a step boundary; state is consistent.
    #[error("interrupted at t = {time} s after {steps} steps")]
    Interrupted {
        /// Simulated time reached, s.
        time: f64,
        /// Steps completed.
        steps: u64,
    },
}

impl DemfemError {
    /// Shorthand for [`DemfemError::InvalidParameter`].
    pub fn invalid(field: &str, value: f64, allowed: &str) -> Self {
        DemfemError::InvalidParameter {
            field: field.to_string(),
            value: format!("{value}"),
            allowed: allowed.to_string(),
        }
    }
}

/// Check `lo < value < hi` (open interval) and finiteness; name the field in the error.
pub fn check_open(field: &str, value: f64, lo: f64, hi: f64) -> Result<f64> {
    if value.is_finite() && value > lo && value < hi {
        Ok(value)
    } else {
        Err(DemfemError::invalid(
            field,
            value,
            &format!("finite and in ({lo}, {hi})"),
        ))
    }
}

/// Check `value > 0` and finite.
pub fn check_positive(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(DemfemError::invalid(field, value, "finite and > 0"))
    }
}

/// Check that every component of a vector (or any list of values) named `field` is finite.
pub fn check_finite(field: &str, values: &[f64]) -> Result<()> {
    if values.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(DemfemError::InvalidParameter {
            field: field.into(),
            value: format!("{values:?}"),
            allowed: "finite components".into(),
        })
    }
}

/// Check `value >= 0` and finite.
pub fn check_non_negative(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(DemfemError::invalid(field, value, "finite and >= 0"))
    }
}
