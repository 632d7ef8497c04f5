//! The force-domain prefit of velocity fits of dynamic models (the paper's own route).
//!
//! Eq. 7 gives the friction force along the measured motion without any fit. Fitting a
//! model's force along that motion to it (a force-domain fit with the energy-based target,
//! run by [`crate::identify::fit`] with the options [`prefit_options`] gives) needs no
//! simulation of the mechanics and has no phase errors to trap the optimiser, so its optimum
//! is a good start for the velocity fit of a model with internal states, whose default
//! starts often end in a poor local minimum. The velocity fit runs its usual starts plus
//! this one (planned by [`super::strategy::plan_fit_starts`]); the report says which start
//! won. Static laws (no internal states) are not prefitted: their fit stays one start, one
//! run.

use crate::error::EngineError;
use crate::identify::values::fit_options::FitOptions;
use crate::identify::values::outcome::{Check, Finding, Status};
use crate::identify::values::param_options::ParamOptions;
use crate::identify::values::result::FitResult;
use crate::identify::values::target_options::{FitDomain, ForceTarget, TargetOptions};
use frictionid_models::FrictionModel;

/// The prefit's optimum and what it cost.
pub(crate) struct Prefit {
    /// The fitted model.
    pub model: Box<dyn FrictionModel>,
    /// RMS of the model force against the energy-based force \[N\].
    pub rms_force: f64,
    /// Wall time of the prefit \[s\].
    pub wall_time_s: f64,
}

impl Prefit {
    /// The prefit's optimum and cost out of its force-domain fit.
    pub(crate) fn of(result: FitResult) -> Self {
        Self {
            model: result.fitted_model,
            rms_force: result.rms_residual,
            wall_time_s: result.wall_time_s,
        }
    }
}

/// The options of the prefit of `model`, when `opts` asks for it and the model has internal
/// states (`None` otherwise): the force domain against the energy-based force, nothing but
/// the model's parameters free, no uncertainty refits, no progress.
pub(crate) fn prefit_options(model: &dyn FrictionModel, opts: &FitOptions) -> Option<FitOptions> {
    if !opts.search.prefit || model.n_states() == 0 {
        return None;
    }
    Some(FitOptions {
        target: TargetOptions {
            domain: FitDomain::Force,
            force_target: ForceTarget::Energy,
            force_offset: false,
            min_speed: None,
            ..opts.target.clone()
        },
        params: ParamOptions {
            velocity_offset: false,
            time_shift: false,
            x0: false,
            oscillator: Vec::new(),
            ..opts.params.clone()
        },
        uncertainty: Default::default(),
        hooks: opts.hooks.quiet(),
        ..opts.clone()
    })
}

/// The origin a fit reports for the start the prefit gave.
pub(crate) const PREFIT_ORIGIN: &str = "force-domain prefit";

/// What the prefit gave the velocity fit `result`: its start (the last) and whether it won.
pub(crate) fn prefit_finding(seed: &Result<Prefit, EngineError>, result: &FitResult) -> Finding {
    let p = match seed {
        Ok(p) => p,
        Err(e) => {
            return Finding::warn(
                Check::Prefit,
                None,
                format!("the force-domain prefit failed ({e}); the velocity fit ran without it"),
            )
        }
    };
    let prefit_start = result.starts.saturating_sub(1);
    let who = if result.best_start_origin == PREFIT_ORIGIN {
        "the prefit start reached the best cost".to_string()
    } else {
        format!(
            "start {} of the default starts reached the best cost",
            result.best_start + 1
        )
    };
    Finding::new(
        Check::Prefit,
        Status::Pass,
        Some(p.rms_force),
        format!(
            "force-domain prefit on the energy-based force (RMS {:.4} N, {:.3} s) gave start {} of {}; {who}",
            p.rms_force,
            p.wall_time_s,
            prefit_start + 1,
            result.starts
        ),
    )
}
