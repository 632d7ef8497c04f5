//! How a fit searches for its optimum: the options the search floor reads (`[fit]
//! max_iterations`, `tolerance`; `[fit.options] multistart`, `search`, `prefit`, `loss`,
//! `f_scale`), the
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
    /// The loss of the residuals (`loss`).
    pub loss: Loss,
    /// The loss's scale C in units of each record's noise level (`f_scale`); `None`:
    /// [`DEFAULT_F_SCALE`].
    pub f_scale: Option<f64>,
}

/// The loss of the residuals (`[fit.options] loss`), with SciPy `least_squares`'s meaning:
/// the fit minimises 1/2 C^2 sum rho((r_i / C)^2), r_i the residuals in units of their
/// record's noise level and C = `f_scale`. A robust loss (`huber`, `soft_l1`) grows only
/// linearly beyond C, so a few samples with a wrong target (spikes) pull the fit less.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Loss {
    /// rho(z) = z: least squares.
    #[default]
    Linear,
    /// rho(z) = z for z <= 1, 2 sqrt(z) - 1 beyond.
    Huber,
    /// rho(z) = 2 (sqrt(1 + z) - 1).
    SoftL1,
}

impl Loss {
    /// Config name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Linear => "linear",
            Self::Huber => "huber",
            Self::SoftL1 => "soft_l1",
        }
    }
}

/// The loss's default scale in units of the record's noise level: Huber's constant of 95 %
/// efficiency under Gaussian noise.
pub const DEFAULT_F_SCALE: f64 = 1.345;

/// `[fit.options] f_scale` is a finite number > 0; the message otherwise.
pub fn check_f_scale(f_scale: Option<f64>) -> Result<(), String> {
    match f_scale {
        Some(c) if !(c.is_finite() && c > 0.0) => Err(format!(
            "[fit.options] f_scale must be a number > 0 (in units of the record's noise), got {c}"
        )),
        _ => Ok(()),
    }
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
            loss: Loss::Linear,
            f_scale: None,
        }
    }
}

option_keys!(SearchOptions {
    fit: ["max_iterations" => max_iterations, "tolerance" => tolerance],
    options: [
        "multistart" => multistart,
        "search" => strategy,
        "prefit" => prefit,
        "loss" => loss,
        "f_scale" => f_scale,
    ],
});

impl SearchOptions {
    /// The loss the fit minimises, at its scale.
    pub fn robust_loss(&self) -> RobustLoss {
        RobustLoss {
            loss: self.loss,
            scale: self.f_scale.unwrap_or(DEFAULT_F_SCALE),
        }
    }

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

/// A loss at its scale C: the residual transform r -> C sgn(r) sqrt(rho((r / C)^2)), whose
/// half sum of squares is the loss's cost, so that a least-squares solver minimises it (the
/// Jacobian's rows scale by the transform's derivative).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RobustLoss {
    /// The loss.
    pub loss: Loss,
    /// Its scale C (in the residuals' unit).
    pub scale: f64,
}

impl RobustLoss {
    /// Least squares.
    pub fn linear() -> Self {
        Self {
            loss: Loss::Linear,
            scale: DEFAULT_F_SCALE,
        }
    }

    /// Whether the transform is the identity.
    pub fn is_linear(&self) -> bool {
        self.loss == Loss::Linear
    }

    /// rho(z) and rho'(z).
    fn rho(&self, z: f64) -> (f64, f64) {
        match self.loss {
            Loss::Linear => (z, 1.0),
            Loss::Huber if z <= 1.0 => (z, 1.0),
            Loss::Huber => (2.0 * z.sqrt() - 1.0, 1.0 / z.sqrt()),
            // 2 (sqrt(1 + z) - 1) without its cancellation at small z.
            Loss::SoftL1 => (2.0 * z / ((1.0 + z).sqrt() + 1.0), 1.0 / (1.0 + z).sqrt()),
        }
    }

    /// The weight rho'((r / C)^2) the loss gives residual `r` in iteratively reweighted least
    /// squares: 1 within the scale, less beyond (Huber: C / |r|); 1 under least squares.
    pub fn weight(&self, r: f64) -> f64 {
        self.rho((r / self.scale).powi(2)).1
    }

    /// The transformed residual C sgn(r) sqrt(rho((r / C)^2)) (NaN stays NaN).
    pub fn residual(&self, r: f64) -> f64 {
        if self.is_linear() {
            return r;
        }
        let z = (r / self.scale).powi(2);
        self.scale * r.signum() * self.rho(z).0.sqrt()
    }

    /// The transform's derivative at `r`: rho'(z) |r| / (C sqrt(rho(z))), 1 at r = 0 (the
    /// weight of the residual's Jacobian row).
    pub fn derivative(&self, r: f64) -> f64 {
        if self.is_linear() {
            return 1.0;
        }
        let z = (r / self.scale).powi(2);
        let (rho, slope) = self.rho(z);
        if rho <= 0.0 {
            return 1.0;
        }
        slope * z.sqrt() / rho.sqrt()
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The transformed residuals' half square is the loss's cost 1/2 C^2 rho((r / C)^2)
    /// (SciPy's `least_squares`), and the derivative is the transform's slope.
    #[test]
    fn the_transform_carries_the_loss_and_its_slope() {
        let c = 0.7;
        for loss in [Loss::Linear, Loss::Huber, Loss::SoftL1] {
            let robust = RobustLoss { loss, scale: c };
            for r in [-5.0, -0.3, 0.0, 0.2, 0.69, 3.0, 40.0] {
                let z: f64 = (r / c) * (r / c);
                let rho = match loss {
                    Loss::Linear => z,
                    Loss::Huber if z <= 1.0 => z,
                    Loss::Huber => 2.0 * z.sqrt() - 1.0,
                    Loss::SoftL1 => 2.0 * ((1.0 + z).sqrt() - 1.0),
                };
                let t = robust.residual(r);
                assert!(
                    (t * t - c * c * rho).abs() <= 1e-12 * (1.0 + c * c * rho),
                    "{loss:?} {r}"
                );
                assert!(t * r >= 0.0);
                let h = 1e-6;
                let slope = (robust.residual(r + h) - robust.residual(r - h)) / (2.0 * h);
                assert!((robust.derivative(r) - slope).abs() < 1e-5, "{loss:?} {r}");
            }
        }
        assert!(RobustLoss::linear().is_linear());
        assert!(check_f_scale(Some(0.0)).is_err() && check_f_scale(Some(2.0)).is_ok());
    }
}
