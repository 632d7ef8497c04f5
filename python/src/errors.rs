//! Errors as Python exceptions: bad input is a `ValueError`, a fit that failed is a
//! `frictionid.FitError`; both carry the one-line message the CLI prints.

use frictionid_engine::jobs::JobError;
use frictionid_engine::EngineError;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::PyErr;

pyo3::create_exception!(
    frictionid,
    FitError,
    PyException,
    "A fit (or the simulation inside it) failed; the message is the CLI's."
);

/// Collapses a message to one line, as the CLI does.
pub fn one_line(msg: &str) -> String {
    msg.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// A `ValueError` with `msg` on one line.
pub fn value_error(msg: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(one_line(&msg.to_string()))
}

/// Whether an engine error is about the input (records, oscillator, options) rather than a
/// computation that failed.
fn is_input_error(e: &EngineError) -> bool {
    matches!(
        e,
        EngineError::InvalidOscillator(_)
            | EngineError::Model(_)
            | EngineError::InvalidInput(_)
            | EngineError::Record { .. }
    )
}

/// An engine error: `ValueError` for bad input, `FitError` for a failed computation.
pub fn engine_error(e: EngineError) -> PyErr {
    let msg = one_line(&e.to_string());
    if is_input_error(&e) {
        PyValueError::new_err(msg)
    } else {
        FitError::new_err(msg)
    }
}

/// Whether a job's error is about its input rather than a computation that failed.
fn is_input_job_error(e: &JobError) -> bool {
    match e {
        JobError::Spec(_) | JobError::Record { .. } | JobError::Plan(_) => true,
        JobError::Simulation(inner) | JobError::ReferenceFit(inner) | JobError::Fit(inner) => {
            is_input_error(inner)
        }
        JobError::NothingFitted(_) => false,
    }
}

/// A job's error: input problems become `ValueError`, failed computations `FitError`.
pub fn job_error(e: JobError) -> PyErr {
    job_error_as(&e, e.to_string())
}

/// A job's error, of the class [`job_error`] gives it, with the message `msg` (a config
/// run's: the file's name first, as the CLI prints it).
pub fn job_error_as(e: &JobError, msg: String) -> PyErr {
    let msg = one_line(&msg);
    if is_input_job_error(e) {
        PyValueError::new_err(msg)
    } else {
        FitError::new_err(msg)
    }
}
