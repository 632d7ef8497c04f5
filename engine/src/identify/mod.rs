//! The least-squares identifier: fits any registered friction model (any subset of its
//! parameters, optionally the oscillator and per-record nuisance parameters) to one or more
//! measured velocity records, and compares models on the same records.
//!
//! The problem (`problem::FitProblem`) implements argmin's `Operator` and `Jacobian`; the
//! solver is our bounded Levenberg-Marquardt (`lm::LevenbergMarquardt`), an argmin `Solver`,
//! run by argmin's `Executor` with an observer for progress.

pub mod compare;
pub mod fit;
pub mod layout;
pub mod lm;
pub mod options;
pub mod problem;
pub mod stats;

pub use compare::{compare, Comparison, FailedFit};
pub use fit::{fit, guess_hint, Derived, EnergyForce, FitResult, FittedParam, RecordFit};
pub use lm::LevenbergMarquardt;
pub use options::{FitOptions, OscillatorParam, Progress, ProgressFn};
