//! The search strategy a fit asks for (`[fit.options] search`) and the rule that picks one
//! when it asks for none (the strategies themselves: [`crate::identify::search::strategy`]).

use frictionid_models::FrictionModel;
use serde::{Deserialize, Serialize};

/// How a fit searches for its optimum.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Search {
    /// Starts around the data-driven guess.
    Local,
    /// Static laws first; their optima start the target (the default for models with
    /// internal states or more than two free parameters).
    Staged,
    /// Staged starts plus a Latin hypercube over the physical box.
    Global,
}

/// Starts continued to convergence after the screening phase by a local search (the best
/// one; see `Search::promoted`).
pub const PROMOTED_STARTS: usize = 1;

impl Search {
    /// Config name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Local => "local",
            Self::Staged => "staged",
            Self::Global => "global",
        }
    }

    /// The strategy asked for, else, for a model with internal states or more than two free
    /// parameters, `staged` (fitted by simulating the response or a dynamic law along the
    /// measured motion) or `global` (a static law along the measured motion,
    /// [`fits_directly`]: its evaluations cost microseconds, and the Stribeck velocity's
    /// plateaus trap a single start); `local` otherwise (a Coulomb fit stays one start, one
    /// run).
    pub fn resolve(
        asked: Option<Self>,
        model: &dyn FrictionModel,
        n_model_free: usize,
        simulated: bool,
    ) -> Self {
        let wide = model.n_states() > 0 || n_model_free > 2;
        asked.unwrap_or(match (wide, fits_directly(model, simulated)) {
            (false, _) => Self::Local,
            (true, false) => Self::Staged,
            (true, true) => Self::Global,
        })
    }

    /// Screened starts continued to convergence.
    pub fn promoted(self) -> usize {
        match self {
            Self::Local => PROMOTED_STARTS,
            Self::Staged => 2,
            Self::Global => 3,
        }
    }
}

/// Whether `model` is a static law fitted without simulating the response (`simulated`
/// false: the force domain). Its residuals are the law itself at the measured velocities,
/// cheap to evaluate, so its default is one local run from the data-driven guess (no screening)
/// and, with more than two free parameters, a `global` search ([`Search::resolve`]).
pub fn fits_directly(model: &dyn FrictionModel, simulated: bool) -> bool {
    !simulated && model.n_states() == 0
}
