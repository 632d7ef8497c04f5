//! Typed errors of the engine.

use thiserror::Error;

/// Why a time integration stopped before its end time.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum IntegrationFailure {
    /// The step budget (accepted and rejected steps) was spent.
    #[error("more than max_steps = {max_steps} steps")]
    StepBudgetExceeded {
        /// Time reached [s].
        time: f64,
        /// The budget.
        max_steps: u64,
    },
    /// The adaptive step size fell below what the time's precision can resolve.
    #[error(
        "step-size underflow (the right-hand side is not finite or varies too fast to resolve; \
         step {step:e} s)"
    )]
    StepSizeTooSmall {
        /// Time reached [s].
        time: f64,
        /// The step size that was too small [s].
        step: f64,
    },
    /// The state became NaN or infinite.
    #[error("the state became non-finite ([x, v, z...] = {state:?})")]
    NonFiniteState {
        /// Time of the first non-finite state [s].
        time: f64,
        /// The state there.
        state: Vec<f64>,
    },
    /// Too many events (turning points and stick).
    #[error(
        "more than max_events = {max_events} events (the velocity keeps crossing zero; \
         raise max_events or end the simulation earlier)"
    )]
    EventBudgetExceeded {
        /// Time reached [s].
        time: f64,
        /// The budget.
        max_events: usize,
    },
    /// The closed-form propagator was asked to integrate a motion it cannot solve (not affine
    /// in v, or not underdamped).
    #[error("the closed-form propagator does not apply to this motion (it needs a law affine in v within each sliding mode and an underdamped oscillator)")]
    ClosedFormUnavailable {
        /// Start of the segment [s].
        time: f64,
    },
    /// The event function could not be evaluated while locating a turning point.
    #[error("the velocity could not be evaluated while locating a turning point")]
    EventNotLocated {
        /// Start of the step holding the event [s].
        time: f64,
    },
    /// The caller's watch of the samples stopped the run (a record of a fit's evaluation
    /// whose outcome no longer matters: a record before it failed).
    #[error("stopped by the caller's watch of the samples")]
    Halted {
        /// Time reached [s].
        time: f64,
    },
}

impl IntegrationFailure {
    /// The time the integration reached [s].
    pub fn time(&self) -> f64 {
        match self {
            Self::StepBudgetExceeded { time, .. }
            | Self::StepSizeTooSmall { time, .. }
            | Self::NonFiniteState { time, .. }
            | Self::EventBudgetExceeded { time, .. }
            | Self::ClosedFormUnavailable { time }
            | Self::EventNotLocated { time }
            | Self::Halted { time } => *time,
        }
    }
}

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
    /// The simulation's integrator failed (step budget, step-size underflow, non-finite
    /// state, too many events); [`IntegrationFailure::time`] is the time reached.
    #[error("integration failed at t = {} s: {}", .0.time(), .0)]
    Integration(#[from] IntegrationFailure),
    /// Integrating a model's internal states along a measured motion failed.
    #[error(
        "integration failed at t = {} s: model `{model}`: {failure} (integrating its states \
         along the measured velocity)",
        .failure.time()
    )]
    StateIntegration {
        /// The model's name.
        model: String,
        /// What went wrong.
        failure: IntegrationFailure,
    },
    /// A measured record cannot be analysed.
    #[error("record `{record}`: {reason}")]
    Record { record: String, reason: String },
    /// The identifier could not run.
    #[error("fit failed: {0}")]
    Fit(String),
}
