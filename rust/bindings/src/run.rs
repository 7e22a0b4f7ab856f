//! The one stepping loop of every simulation class: the engine runs with the GIL released,
//! in slices short enough that Ctrl-C is seen within a fraction of a second, and step
//! counts from Python are checked before they are run. Times in s.

use pyo3::prelude::*;

use demfem::DemfemError;

use crate::convert::count;
use crate::error::{invalid, PyDemfemError};

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

/// Steps `n` (from Python, signed) checked: >= 0, and the simulated time after them finite.
/// A step count given from Python as any integer: one that does not fit in 63 bits is an
/// error naming `n` and the limit (not Python's raw OverflowError); a non-integer keeps its
/// TypeError.
pub(crate) fn step_count_arg(n: &Bound<'_, PyAny>) -> PyResult<i64> {
    match n.extract::<i64>() {
        Ok(v) => Ok(v),
        Err(e) if n.is_instance_of::<pyo3::types::PyInt>() => {
            let shown = n
                .repr()
                .map(|r| r.to_string())
                .unwrap_or_else(|_| "?".into());
            drop(e);
            Err(invalid("n", &shown, "a whole number of steps below 2^63"))
        }
        Err(e) => Err(e),
    }
}

pub(crate) fn checked_steps(n: i64, time: f64, dt: f64) -> PyResult<u64> {
    let n = count("n", n)?;
    if !(time + n as f64 * dt).is_finite() {
        return Err(invalid(
            "n",
            &n.to_string(),
            &format!("few enough steps of dt = {dt:e} s that the simulated time stays finite"),
        ));
    }
    Ok(n)
}
