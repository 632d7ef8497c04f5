//! The problem a fit solves, on the values' floor: what it compares ([`Residuals`], with its
//! two producers [`SimulatedResponse`] and [`ForceAlongMotion`]), the data-driven guess that
//! starts it, the caches and the step allowance of its evaluations, and the least-squares
//! problem over the free parameters ([`FitProblem`], argmin's `Operator` and `Jacobian`).
//! Imports the values only; knows nothing of solvers, starts or findings.

pub(crate) mod analysis_cache;
pub(crate) mod force_along_motion;
pub(crate) mod guess;
pub mod inverse_dynamics;
pub(crate) mod least_squares;
pub(crate) mod motion_check;
pub(crate) mod residuals;
pub(crate) mod simulated_response;
pub(crate) mod state_cache;
pub(crate) mod step_allowance;
pub mod unit_check;

pub use analysis_cache::AnalysisRequest;
pub use force_along_motion::{
    check_force_domain, require_mechanics, require_oscillator, ForceAlongMotion,
};
pub use guess::guess_hint;
pub use least_squares::{FitProblem, ProblemParts, Realised};
pub use motion_check::check_moves;
pub use residuals::{
    Evaluation, JacobianColumns, RecordCase, Residuals, Segment, STEPS_PER_SAMPLE,
};
pub use simulated_response::{simulated_levels, SimulatedResponse};
pub use step_allowance::StepAllowance;
