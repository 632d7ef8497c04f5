//! The values of the identifier: what a fit is asked ([`FitOptions`], the [`Search`] it
//! asks for, the [`PropertyUncertainty`] of the oscillator), the parameter layout
//! ([`FreeParam`]) and the per-record nuisance parameters ([`NuisanceKind`]), and what a fit
//! returns ([`FitResult`], its typed outcomes and findings). Nothing here imports from the
//! floors above (problem, search, assessment).

pub mod layout;
pub mod levels;
pub mod nuisance;
pub mod options;
pub mod outcome;
pub mod result;
pub mod search;
pub mod uncertainty;

pub use layout::{BoundSide, FreeParam, ParamKind};
pub use levels::FrictionLevels;
pub use nuisance::{non_model_bound_keys, NuisanceKind, NuisanceValues, X0_RELATIVE_BOUND};
pub use options::{
    check_min_speed, FitDomain, FitOptions, ForceTarget, OscillatorParam, Progress, ProgressFn,
    FIT_MAX_STEPS,
};
pub use outcome::{worst_status, Check, Finding, StartOutcome, Status, TerminationReason};
pub use result::{
    ChannelFit, Derived, EnergyForce, EnergySkip, FitResult, FitSeries, FittedParam, ForceBalance,
    Identifiability, Rank, RecordFit, SampleAxes, SlidingSamples, Verdict,
};
pub use search::{fits_directly, Search, PROMOTED_STARTS};
pub use uncertainty::{PropertyUncertainty, StdErrorComponents};
