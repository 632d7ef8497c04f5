//! The least-squares identifier: fits any registered friction model (any subset of its
//! parameters, optionally the oscillator and per-record nuisance parameters) to one or more
//! measured records, and compares models on the same records.
//!
//! Four floors, each importing only the ones below it:
//! - [`values`]: options, the search asked for, the parameter layout, the nuisance kinds, the
//!   property uncertainties, typed outcomes and findings, and the fit's result.
//! - [`problem`]: what a fit compares ([`Residuals`]: [`SimulatedResponse`] simulates the free
//!   vibration and compares every response channel, each weighted by its noise;
//!   [`ForceAlongMotion`] replays the measured motion and compares a force), the data-driven
//!   guess, the caches and the least-squares problem (argmin's `Operator` and `Jacobian`).
//! - [`search`]: the free parameters, the bounded Levenberg-Marquardt solver, the multi-start
//!   runs, the strategies (`local`, `staged`, `global`) and the prefit's options.
//! - [`assessment`]: statistics, identifiability, diagnostics, the energy-balance check, the
//!   sum-up into a [`FitResult`] and the property-uncertainty refits.
//!
//! On top, [`fit`] is the one place a fit runs (and re-runs: the prefit and the property
//! refits are computed below and run here), and [`compare`] fits several models.

pub mod assessment;
pub(crate) mod compare;
pub(crate) mod fit;
pub mod problem;
pub mod search;
pub mod values;

pub use assessment::{energy_force_check, ForceReference};
pub use compare::{
    compare, Comparison, ComparisonVerdict, FailedFit, LawValidation, SetAside, ValidationScheme,
};
pub use fit::{fit, fit_force, fit_with};
pub use problem::{guess_hint, require_mechanics, require_oscillator, ForceAlongMotion};
pub use problem::{Evaluation, Residuals, Segment, SimulatedResponse};
pub use search::LevenbergMarquardt;
pub use values::{
    check_min_speed, fit_sim_options, non_model_bound_keys, worst_status, Check, Derived,
    EnergyForce, Finding, FitDomain, FitOptions, FitResult, FitSeries, FittedParam, ForceBalance,
    ForceTarget, FrictionLevels, Hooks, Identifiability, NuisanceKind, NuisanceValues, OptionKeys,
    OscillatorParam, ParamOptions, Progress, ProgressFn, PropertyUncertainty, Rank, RecordFit,
    ReplayPath, RobustWeights, Search, SearchOptions, SlidingSamples, StartOutcome, Status,
    StdErrorComponents, TargetOptions, TerminationReason, Verdict, DEFAULT_MAX_ITERATIONS,
};
