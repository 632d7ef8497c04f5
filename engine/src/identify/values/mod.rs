//! The values of the identifier: what a fit is asked ([`FitOptions`] in its parts:
//! [`ParamOptions`], [`TargetOptions`], [`SearchOptions`] with the [`Search`] it asks for,
//! the [`PropertyUncertainty`] of the oscillator, [`Hooks`]), the parameter layout
//! ([`FreeParam`]) and the per-record nuisance parameters ([`NuisanceKind`]), and what a fit
//! returns ([`FitResult`], its typed outcomes and findings). Nothing here imports from the
//! floors above (problem, search, assessment).

pub(crate) mod fit_options;
pub(crate) mod layout;
pub(crate) mod levels;
pub(crate) mod nuisance;
pub(crate) mod option_keys;
pub(crate) mod options;
pub(crate) mod outcome;
pub(crate) mod param_options;
pub(crate) mod result;
pub mod search;
pub(crate) mod target_options;
pub(crate) mod uncertainty;

pub use fit_options::{fit_sim_options, FitOptions, Hooks};
pub use layout::{BoundSide, FreeParam, ParamKind};
pub use levels::FrictionLevels;
pub use nuisance::{non_model_bound_keys, NuisanceKind, NuisanceValues, X0_RELATIVE_BOUND};
pub use option_keys::OptionKeys;
pub use options::{OscillatorParam, Progress, ProgressFn};
pub use outcome::{worst_status, Check, Finding, StartOutcome, Status, TerminationReason};
pub use param_options::ParamOptions;
pub use result::{
    ChannelFit, Derived, EnergyForce, EnergySkip, FitResult, FitSeries, FittedParam, ForceBalance,
    Identifiability, Rank, RecordFit, RobustWeights, SampleAxes, SlidingSamples, UnreliableSamples,
    Verdict,
};
pub use search::{fits_directly, Search, SearchOptions, DEFAULT_MAX_ITERATIONS, PROMOTED_STARTS};
pub use target_options::{check_min_speed, FitDomain, ForceTarget, ReplayPath, TargetOptions};
pub use uncertainty::{PropertyUncertainty, StdErrorComponents};
