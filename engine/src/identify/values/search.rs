//! How a fit searches for its optimum: the options the search floor reads (`[fit]
//! max_iterations`, `tolerance`; `[fit.options] multistart`, `search`, `prefit`), the
//! strategy a fit asks for and the rule that picks one when it asks for none (the strategies
//! themselves: [`crate::identify::search::strategy`]).

use super::option_keys::option_keys;
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

/// How a fit searches for its optimum (the search floor reads it).
#[derive(Debug, Clone, PartialEq)]
pub struct SearchOptions {
    /// Number of starts; `None`: 1 when at most two model parameters are free, else
    /// [`crate::identify::search::starts::DEFAULT_STARTS`].
    pub multistart: Option<usize>,
    /// Search strategy (`search`); `None`: `staged` for models with internal states or more
    /// than two free parameters, `local` otherwise (see [`Search::resolve`]).
    pub strategy: Option<Search>,
    /// Iteration limit of each start.
    pub max_iterations: u64,
    /// Convergence tolerance on the relative cost reduction of a step (solver default 1e-9).
    pub tolerance: Option<f64>,
    /// Velocity fits of models with internal states start also from the optimum of a
    /// force-domain fit to the energy-based force (the prefit).
    pub prefit: bool,
}

/// Iteration limit of each start when `[fit] max_iterations` is not given.
pub const DEFAULT_MAX_ITERATIONS: u64 = 200;

impl Default for SearchOptions {
    fn default() -> Self {
        Self {
            multistart: None,
            strategy: None,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            tolerance: None,
            prefit: false,
        }
    }
}

option_keys!(SearchOptions {
    fit: ["max_iterations" => max_iterations, "tolerance" => tolerance],
    options: [
        "multistart" => multistart,
        "search" => strategy,
        "prefit" => prefit,
    ],
});

impl SearchOptions {
    /// The options of a fit that starts once where it is told (a refit from an optimum, a
    /// stage): one start, a local search when `local`, else the strategy asked for.
    pub fn one_start(&self, local: bool) -> Self {
        Self {
            multistart: Some(1),
            strategy: if local {
                Some(Search::Local)
            } else {
                self.strategy
            },
            ..self.clone()
        }
    }
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
