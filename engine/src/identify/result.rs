//! The values a fit returns.

use super::energy_check::EnergyForce;
use super::outcome::{as_display, Finding, StartOutcome, TerminationReason};
use crate::oscillator::Oscillator;
use frictionid_models::FrictionModel;
use serde::Serialize;

/// One parameter of a fit result.
#[derive(Debug, Clone, Serialize)]
pub struct FittedParam {
    /// Name.
    pub name: String,
    /// Value (fitted, or fixed).
    pub value: f64,
    /// Standard error (`None` for fixed or unidentifiable parameters).
    pub std_error: Option<f64>,
    /// 95 % confidence interval.
    pub ci95: Option<[f64; 2]>,
    /// Unit.
    pub unit: String,
    /// Whether it was fitted.
    pub free: bool,
}

/// The fit of one record.
#[derive(Debug, Clone, Serialize)]
pub struct RecordFit {
    /// Record name (file).
    pub file: String,
    /// Release displacement [m].
    pub x0: f64,
    /// The release instant the record was cut at (`release = "auto"` or a time) \[s\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub release_time: Option<f64>,
    /// Samples.
    pub samples: usize,
    /// The quantity compared (`velocity`).
    pub channel: String,
    /// RMS of fitted - measured, in the unit of the compared quantity (m/s for velocity).
    pub rms_residual: f64,
    /// Energy-based force check (absent when the record cannot be analysed).
    pub energy_force: Option<EnergyForce>,
    /// Time stamps (for plots).
    #[serde(skip)]
    pub time: Vec<f64>,
    /// The measured series compared.
    #[serde(skip)]
    pub measured: Vec<f64>,
    /// The fitted series (the model's prediction, nuisance applied).
    #[serde(skip)]
    pub fitted: Vec<f64>,
    /// Energy-based friction force (NaN where masked).
    #[serde(skip)]
    pub energy_based_force: Vec<f64>,
    /// The model's force along the measured motion.
    #[serde(skip)]
    pub model_force: Vec<f64>,
}

/// A ratio the data fix even when its parts are not separately identifiable.
#[derive(Debug, Clone, Serialize)]
pub struct Derived {
    /// Name (e.g. `k/m`).
    pub name: String,
    /// Value.
    pub value: f64,
    /// Standard error by the delta method (when the covariance exists).
    pub std_error: Option<f64>,
    /// Unit.
    pub unit: String,
}

/// The result of a fit.
#[derive(Debug, Clone, Serialize)]
pub struct FitResult {
    /// Registry name of the model.
    pub model: String,
    /// The fitted model (all parameters).
    pub fitted_model: Box<dyn FrictionModel>,
    /// The oscillator (fitted where requested).
    pub oscillator: Oscillator,
    /// Every model parameter, then fitted oscillator and nuisance parameters.
    pub parameters: Vec<FittedParam>,
    /// Names of the free parameters, in the order of `correlation`.
    pub correlation_names: Vec<String>,
    /// Correlation matrix of the free parameters (rows).
    pub correlation: Vec<Vec<f64>>,
    /// Ratios the data fix (k/m, c/m) when the oscillator is fitted.
    pub derived: Vec<Derived>,
    /// Per record.
    pub records: Vec<RecordFit>,
    /// RMS residual over all records [m/s].
    pub rms_residual: f64,
    /// Half the weighted sum of squared residuals.
    pub cost: f64,
    /// Akaike information criterion.
    pub aic: f64,
    /// Bayesian information criterion.
    pub bic: f64,
    /// Samples over all records.
    pub samples: usize,
    /// Free parameters (including nuisance parameters).
    pub free_parameters: usize,
    /// Whether the best start converged.
    pub converged: bool,
    /// Why the solver stopped (a sentence in JSON).
    #[serde(serialize_with = "as_display")]
    pub termination: TerminationReason,
    /// Solver iterations over all starts.
    pub iterations: u64,
    /// Simulations over all starts and the statistics.
    pub simulations: u64,
    /// Number of starts.
    pub starts: usize,
    /// Starts that reached the best cost (within 1e-6 relative).
    pub starts_at_best: usize,
    /// What became of each start, in start order.
    pub start_outcomes: Vec<StartOutcome>,
    /// The checks of this fit, each pass, warn or fail.
    pub diagnostics: Vec<Finding>,
    /// The messages of the diagnostics that warn or fail, in order.
    pub warnings: Vec<String>,
    /// Wall time of the fit [s].
    pub wall_time_s: f64,
}

/// A fit's parameter value by name (model or oscillator), for callers and tests.
impl FitResult {
    /// The value of the parameter `name`.
    pub fn value(&self, name: &str) -> Option<f64> {
        self.parameters
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.value)
    }

    /// The parameter entry `name`.
    pub fn param(&self, name: &str) -> Option<&FittedParam> {
        self.parameters.iter().find(|p| p.name == name)
    }
}
