//! Typed errors of the engine.

use thiserror::Error;

/// Errors of the oscillator, the simulation, the energy analysis and the identifier.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum EngineError {
    /// An oscillator property is out of range.
    #[error("invalid oscillator: {0}")]
    InvalidOscillator(String),
    /// A friction model rejected its parameters.
    #[error(transparent)]
    Model(#[from] frictionid_models::ModelError),
    /// Invalid simulation or analysis input (initial conditions, sample times, options).
    #[error("invalid input: {0}")]
    InvalidInput(String),
    /// The integrator failed (step-size underflow, too many steps, non-finite state).
    #[error("integration failed at t = {time} s: {reason}")]
    Integration { time: f64, reason: String },
    /// A measured record cannot be analysed.
    #[error("record `{record}`: {reason}")]
    Record { record: String, reason: String },
    /// The identifier could not run.
    #[error("fit failed: {0}")]
    Fit(String),
}
