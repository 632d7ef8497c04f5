//! What a fit varies and how.

use super::search::Search;
use super::uncertainty::PropertyUncertainty;
use crate::energy::EnergyOptions;
use crate::oscillator::OscillatorProperty;
use crate::simulate::{Integrator, SimOptions};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::sync::Arc;

/// An oscillator property that a fit may vary (the normal force excepted): one typed value
/// per property, in [`crate::oscillator`].
pub use crate::oscillator::OscillatorProperty as OscillatorParam;

/// What a fit compares (`[fit.options] domain`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitDomain {
    /// The simulated free vibration against the measured velocity.
    #[default]
    Velocity,
    /// The model's force along the measured motion against a target force
    /// ([`crate::identify::problem::ForceAlongMotion`]).
    Force,
}

/// The target force of a force-domain fit (`[fit.options] force_target`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ForceTarget {
    /// The measured force channel where a record has one, else the energy-based force.
    #[default]
    Auto,
    /// The measured force channel (an error for a record without one).
    Measured,
    /// The energy-based force of Eq. 7 (needs m, c and k).
    Energy,
    /// Inverse dynamics: the measured input force u against J a + c v + R(q) + F along the
    /// measured motion, with the oscillator properties named in `oscillator` fitted jointly
    /// (the inverse-dynamics identification of drives and robot joints).
    InverseDynamics,
}

/// `[fit.options] min_speed` is a speed >= 0 given for a force-domain fit (only it compares
/// samples one by one); the message otherwise. The one place of this rule.
pub fn check_min_speed(min_speed: Option<f64>, domain: FitDomain) -> Result<(), String> {
    let Some(speed) = min_speed else {
        return Ok(());
    };
    if !(speed.is_finite() && speed >= 0.0) {
        return Err(format!(
            "[fit.options] min_speed must be a speed >= 0 (m/s), got {speed}"
        ));
    }
    if domain != FitDomain::Force {
        return Err(
            "[fit.options] min_speed applies to force-domain fits only (domain = \"force\")".into(),
        );
    }
    Ok(())
}

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

/// The step limit of each simulation during a fit. Trial parameters that make a model so
/// stiff that a record needs more steps are rejected quickly instead of being integrated
/// for seconds (the engine's own default allows 2e7 steps).
pub const FIT_MAX_STEPS: u64 = 200_000;

/// Options of a fit.
#[derive(Clone)]
pub struct FitOptions {
    /// Model parameters to fit, by name; `None`: every parameter not fixed by default.
    pub free: Option<Vec<String>>,
    /// Bounds by parameter name (model parameters, `mass`, `damping`, `stiffness`, `offset`,
    /// `shift`, `x0` in metres); default: the model's physical bounds, none for an offset, a
    /// quarter of the natural period for a shift, 20 % of each record's x0 for x0.
    pub bounds: BTreeMap<String, (f64, f64)>,
    /// Data-driven initial values for the free model parameters (from the half-cycle energy
    /// estimate), except those named in `keep_initial`.
    pub guess: bool,
    /// Free parameters whose initial value is the model's current value even when guessing.
    pub keep_initial: Vec<String>,
    /// Oscillator properties to fit.
    pub oscillator: Vec<OscillatorParam>,
    /// Fit a velocity offset per record.
    pub velocity_offset: bool,
    /// Fit a release-time shift per record.
    pub time_shift: bool,
    /// Fit the release displacement x0 of each record, starting from its given value.
    pub x0: bool,
    /// One standard deviation of the oscillator's properties, propagated into every fitted
    /// parameter's standard error (see [`crate::identify::assessment::property_refits`]).
    pub uncertainty: PropertyUncertainty,
    /// What the fit compares.
    pub domain: FitDomain,
    /// The target force of a force-domain fit.
    pub force_target: ForceTarget,
    /// Fit a constant force offset per record (force domain: a measured force or inverse
    /// dynamics).
    pub force_offset: bool,
    /// Force domain: compare only the samples where the measured motion slides, |v| >=
    /// `min_speed` \[m/s\] (stick phases at reversals hold a force below the sliding level
    /// that a static law cannot follow); `None`: every sample.
    pub min_speed: Option<f64>,
    /// Velocity fits of models with internal states start also from the optimum of a
    /// force-domain fit to the energy-based force (the prefit).
    pub prefit: bool,
    /// `[oscillator]` properties that were not given (their values are placeholders): fits
    /// that need them fail with a message naming them.
    pub unknown_oscillator: Vec<OscillatorProperty>,
    /// Number of starts; `None`: 1 when at most two model parameters are free, else
    /// [`crate::identify::search::starts::DEFAULT_STARTS`].
    pub multistart: Option<usize>,
    /// Search strategy; `None`: `staged` for models with internal states or more than two
    /// free parameters, `local` otherwise (see [`crate::identify::search::strategy`]).
    pub search: Option<Search>,
    /// Iteration limit of each start.
    pub max_iterations: u64,
    /// Convergence tolerance on the relative cost reduction of a step (solver default 1e-9).
    pub tolerance: Option<f64>,
    /// Simulation options. The default integrator is `Auto`: the exact propagator for laws
    /// affine in v, Rodas4 for stiff bristles and elements, Dopri5 otherwise (with Dopri5 for
    /// every model, `compare` of the five classical models took 19.3 s against 6.4 s, and
    /// stiff bristle records were rejected by the step budget).
    pub sim: SimOptions,
    /// Energy-analysis options (for the energy-based force residuals).
    pub energy: EnergyOptions,
    /// Use several cores (records, Jacobian columns, starts, models).
    pub parallel: bool,
    /// Progress callback.
    pub progress: Option<ProgressFn>,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            free: None,
            bounds: BTreeMap::new(),
            guess: true,
            keep_initial: Vec::new(),
            oscillator: Vec::new(),
            velocity_offset: false,
            time_shift: false,
            x0: false,
            uncertainty: PropertyUncertainty::default(),
            domain: FitDomain::Velocity,
            force_target: ForceTarget::Auto,
            force_offset: false,
            min_speed: None,
            prefit: false,
            unknown_oscillator: Vec::new(),
            multistart: None,
            search: None,
            max_iterations: 200,
            tolerance: None,
            sim: SimOptions {
                integrator: Integrator::Auto,
                max_steps: FIT_MAX_STEPS,
                ..SimOptions::default()
            },
            energy: EnergyOptions::default(),
            parallel: true,
            progress: None,
        }
    }
}

impl std::fmt::Debug for FitOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FitOptions")
            .field("free", &self.free)
            .field("bounds", &self.bounds)
            .field("guess", &self.guess)
            .field("keep_initial", &self.keep_initial)
            .field("oscillator", &self.oscillator)
            .field("velocity_offset", &self.velocity_offset)
            .field("time_shift", &self.time_shift)
            .field("x0", &self.x0)
            .field("uncertainty", &self.uncertainty)
            .field("domain", &self.domain)
            .field("force_target", &self.force_target)
            .field("force_offset", &self.force_offset)
            .field("min_speed", &self.min_speed)
            .field("prefit", &self.prefit)
            .field("unknown_oscillator", &self.unknown_oscillator)
            .field("multistart", &self.multistart)
            .field("search", &self.search)
            .field("max_iterations", &self.max_iterations)
            .field("parallel", &self.parallel)
            .finish_non_exhaustive()
    }
}
