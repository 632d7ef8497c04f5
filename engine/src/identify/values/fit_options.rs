//! The options of a fit, resolved once and handed out in parts: each floor of the identifier
//! takes the part it reads ([`ParamOptions`]: what is free and where it starts;
//! [`TargetOptions`]: what the fit compares; [`SearchOptions`]: how the optimum is searched
//! for; [`SimOptions`]: how the trial simulations integrate; [`EnergyOptions`]: the energy
//! analysis; [`PropertyUncertainty`]: the oscillator's standard deviations; [`Hooks`]:
//! progress and parallelism). Each part's `Default` is the one place of its defaults, and
//! each part reads its own `[fit]` and `[fit.options]` keys (`OptionKeys`): the config's
//! tables are made of the parts themselves (`crate::spec::FitSpec`).

use super::options::ProgressFn;
use super::param_options::ParamOptions;
use super::search::SearchOptions;
use super::target_options::TargetOptions;
use super::uncertainty::PropertyUncertainty;
use crate::energy::EnergyOptions;
use crate::simulate::{Integrator, SimOptions};

/// Run-time hooks of a fit: how it reports progress and whether it uses several cores. Not
/// part of a config (`crate::spec::Spec` leaves them to the front end).
#[derive(Clone)]
pub struct Hooks {
    /// Called after every solver iteration (from worker threads).
    pub progress: Option<ProgressFn>,
    /// Use several cores (records, Jacobian columns, starts, models).
    pub parallel: bool,
}

impl Default for Hooks {
    fn default() -> Self {
        Self {
            progress: None,
            parallel: true,
        }
    }
}

impl Hooks {
    /// The same parallelism, without progress (the refits and stages a fit runs inside).
    pub fn quiet(&self) -> Self {
        Self {
            progress: None,
            parallel: self.parallel,
        }
    }
}

impl std::fmt::Debug for Hooks {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Hooks")
            .field("progress", &self.progress.is_some())
            .field("parallel", &self.parallel)
            .finish()
    }
}

/// The simulation options of a fit: the `auto` integrator (the exact propagator for laws
/// affine in v, Rodas4 for stiff bristles and elements, Dopri5 otherwise; with Dopri5 for
/// every model, `compare` of the five classical models took 19.3 s against 6.4 s, and stiff
/// bristle records were rejected by the step budget), with the engine's step limit: a
/// fit's simulations are held per sample instead
/// (`identify::problem::residuals::STEPS_PER_SAMPLE` and the start point's allowance), so a
/// long record may take the steps per sample a short one may. A fixed limit of 200 000
/// steps held a 19 000-sample drive record to 10.5 steps per sample and dropped every
/// start of its LuGre fit (the first needs 11).
pub fn fit_sim_options() -> SimOptions {
    SimOptions {
        integrator: Integrator::Auto,
        ..SimOptions::default()
    }
}

/// Options of a fit, in the parts the floors of the identifier read. Build one with
/// `FitOptions::default()` and set the parts' public fields (`opts.params.x0 = true`), or
/// from a config with `crate::spec::Spec::fit_options`.
#[derive(Debug, Clone)]
pub struct FitOptions {
    /// Which model, oscillator and nuisance parameters are free, their bounds and starts.
    pub params: ParamOptions,
    /// What the fit compares.
    pub target: TargetOptions,
    /// Starts, strategy, iteration limit, tolerance and prefit.
    pub search: SearchOptions,
    /// The trial simulations' options (default [`fit_sim_options`]).
    pub sim: SimOptions,
    /// Energy-analysis options (the guess, the energy-based force, the energy check).
    pub energy: EnergyOptions,
    /// One standard deviation of the oscillator's properties, propagated into every fitted
    /// parameter's standard error (see [`crate::identify::assessment::property_refits`]).
    pub uncertainty: PropertyUncertainty,
    /// Progress and parallelism.
    pub hooks: Hooks,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            params: ParamOptions::default(),
            target: TargetOptions::default(),
            search: SearchOptions::default(),
            sim: fit_sim_options(),
            energy: EnergyOptions::default(),
            uncertainty: PropertyUncertainty::default(),
            hooks: Hooks::default(),
        }
    }
}
