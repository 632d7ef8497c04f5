//! The least-squares identifier: fits any registered friction model (any subset of its
//! parameters, optionally the oscillator and per-record nuisance parameters) to one or more
//! measured records, and compares models on the same records.
//!
//! The seams:
//! - [`residuals::Residuals`]: what a fit compares. [`residuals::VelocityResponse`] simulates
//!   the free vibration and compares every response channel (velocity, displacement,
//!   acceleration, each weighted by its noise); each producer declares the per-record
//!   nuisance parameters ([`residuals::NuisanceKind`]) it adds.
//!   [`force::ForceAlongMotion`] replays the measured motion and compares the model's force
//!   with a measured or the energy-based force (fits in the force domain).
//! - [`problem::FitProblem`]: generic over the producer; implements argmin's `Operator` and
//!   `Jacobian`, so the solver, our bounded Levenberg-Marquardt ([`lm::LevenbergMarquardt`],
//!   an argmin `Solver`), knows nothing of friction.
//! - [`starts`]: the multi-start runs; [`strategy`]: where the starts come from (`local`,
//!   `staged`, `global`); [`identifiability`]: which parameters the records determine;
//!   [`setup`]: options to free parameters.
//! - [`outcome`]: typed outcomes ([`outcome::TerminationReason`], [`outcome::StartOutcome`])
//!   and the findings ([`outcome::Finding`]) every [`FitResult`] carries.
//! - [`energy_check::energy_force_check`]: the energy-balance check, shared with the
//!   `energy` command.

pub mod analysis_cache;
pub mod budget;
pub mod compare;
pub mod diagnostics;
pub mod energy_check;
pub mod fit;
pub mod force;
pub mod identifiability;
pub mod layout;
pub mod lm;
pub mod options;
pub mod outcome;
pub mod prefit;
pub mod problem;
pub mod residuals;
pub mod response;
pub mod result;
pub mod setup;
pub mod starts;
pub mod state_cache;
pub mod stats;
pub mod strategy;
pub mod work;

pub use budget::{PropertyUncertainty, StdErrorComponents};
pub use compare::{compare, Comparison, ComparisonVerdict, FailedFit};
pub use energy_check::{energy_force_check, EnergyForce, ForceReference};
pub use fit::{fit, fit_with, guess_hint, Derived, FitResult, FitSeries, FittedParam, RecordFit};
pub use force::{fit_force, require_mechanics, require_oscillator, ForceAlongMotion};
pub use identifiability::Identifiability;
pub use lm::LevenbergMarquardt;
pub use options::{FitDomain, FitOptions, ForceTarget, OscillatorParam, Progress, ProgressFn};
pub use outcome::{worst_status, Check, Finding, StartOutcome, Status, TerminationReason};
pub use residuals::{
    Evaluation, NuisanceKind, NuisanceValues, Residuals, Segment, VelocityResponse,
};
pub use result::{Rank, Verdict};
pub use strategy::Search;
