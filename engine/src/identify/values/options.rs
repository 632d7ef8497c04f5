//! The oscillator properties a fit may vary, and how a running fit reports its progress.

use std::sync::Arc;

/// An oscillator property that a fit may vary (the normal force excepted): one typed value
/// per property, in [`crate::oscillator`].
pub use crate::oscillator::OscillatorProperty as OscillatorParam;

/// Progress of a running fit, reported after every solver iteration.
#[derive(Debug, Clone, PartialEq)]
pub struct Progress {
    /// Model being fitted.
    pub model: String,
    /// Index of the start (multi-start).
    pub start: usize,
    /// Number of starts.
    pub starts: usize,
    /// Iterations of this start so far.
    pub iteration: u64,
    /// Iteration limit.
    pub max_iterations: u64,
    /// Best cost (half the weighted sum of squares) of this start so far.
    pub cost: f64,
}

/// A progress callback (e.g. the CLI's progress bar). Called from worker threads.
pub type ProgressFn = Arc<dyn Fn(&Progress) + Send + Sync>;
