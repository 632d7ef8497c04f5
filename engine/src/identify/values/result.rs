//! The values a fit returns.

use super::uncertainty::StdErrorComponents;

use super::outcome::{as_display, worst_status, Finding, StartOutcome, Status, TerminationReason};

use super::search::{Loss, Search};
use crate::axis::Axis;
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
    /// What the records say about it (fitted parameters only): `determined`, or a one-sided
    /// `lower_bound` / `upper_bound` (then `bound` holds the 95 % bound and there is no
    /// standard error), or `not_identifiable`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub identifiability: Option<Identifiability>,
    /// The 95 % bound of a one-sided parameter.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bound: Option<f64>,
    /// The parts of `std_error` when the oscillator's properties are uncertain (then
    /// `std_error` is their total).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub std_error_components: Option<StdErrorComponents>,
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
    /// The sliding samples compared, when `[fit.options] min_speed` selects them (force
    /// domain).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sliding: Option<SlidingSamples>,
    /// The sliding samples not compared because their target is unreliable (an inverse-dynamics
    /// acceleration differentiated one-sided at a run's end or across a reversal).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unreliable_target: Option<UnreliableSamples>,
    /// The weights a robust loss (`loss = "huber"` / `"soft_l1"`) gave the compared samples
    /// at the optimum; `None` under least squares.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub robust_weights: Option<RobustWeights>,
    /// The quantity compared (`velocity`, `force`, `energy_based_force`).
    pub channel: String,
    /// RMS of fitted - measured, in the unit of the compared quantity (m/s for velocity).
    pub rms_residual: f64,
    /// Every compared channel (the first is `channel`): its RMS residual and noise level.
    pub channels: Vec<ChannelFit>,
    /// Energy-based force check (absent when the record cannot be analysed).
    pub energy_force: Option<EnergyForce>,
    /// Time stamps and motion of the compared samples (for plots).
    #[serde(skip)]
    pub axes: SampleAxes,
    /// The measured and fitted series and the forces along the motion (for plots).
    #[serde(skip)]
    pub series: FitSeries,
}

/// The samples of a record whose target is unreliable and which the fit does not compare.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UnreliableSamples {
    /// Samples left out.
    pub count: usize,
    /// Sliding samples the target had before (those left out included).
    pub of: usize,
    /// The time ranges \[s\] of the samples left out, \[first, last\] of each contiguous run.
    pub ranges: Vec<[f64; 2]>,
    /// The time \[s\] of each sample left out (for plots).
    #[serde(skip)]
    pub times: Vec<f64>,
}

/// The weights a robust loss gave a record's compared samples (its first channel) at the
/// optimum, and the samples it down-weighted: those whose weight is below
/// [`RobustWeights::DOWN_WEIGHTED`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RobustWeights {
    /// The loss (`huber`, `soft_l1`).
    pub loss: Loss,
    /// Samples down-weighted.
    pub count: usize,
    /// Samples compared.
    pub of: usize,
    /// The least weight of any sample.
    pub least: f64,
    /// The time ranges \[s\] of the samples down-weighted, \[first, last\] of each contiguous
    /// run.
    pub ranges: Vec<[f64; 2]>,
    /// The weight of each compared sample, in the order of the record's series (for plots).
    #[serde(skip)]
    pub weights: Vec<f64>,
    /// The time \[s\] of each sample down-weighted (for plots).
    #[serde(skip)]
    pub times: Vec<f64>,
}

impl RobustWeights {
    /// A sample whose weight is below this is down-weighted (a Huber residual beyond twice
    /// the loss's scale).
    pub const DOWN_WEIGHTED: f64 = 0.5;
}

/// The samples of a force-domain record compared under `[fit.options] min_speed`: those
/// where the measured motion slides, |v| >= `min_speed`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SlidingSamples {
    /// The least speed compared \[m/s\].
    pub min_speed: f64,
    /// Samples kept.
    pub kept: usize,
    /// Samples the target defines (all of a measured force; Eq. 7's unmasked ones).
    pub of: usize,
}

/// A record's series at the compared samples, for plots and the Python package.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FitSeries {
    /// The measured series compared.
    pub measured: Vec<f64>,
    /// The fitted series (the model's prediction, nuisance applied).
    pub fitted: Vec<f64>,
    /// Energy-based friction force (NaN where masked; empty without the energy check).
    pub energy_based_force: Vec<f64>,
    /// The model's force along the measured motion (empty without the energy check).
    pub model_force: Vec<f64>,
    /// The force balance of an inverse-dynamics fit at the compared samples.
    pub balance: Option<ForceBalance>,
}

/// The terms of J a + c v + R(q) + F + offset = u at a record's compared samples, at the
/// fitted values (an inverse-dynamics fit) \[N, or N m on a rotary axis\].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ForceBalance {
    /// The measured input force u.
    pub input: Vec<f64>,
    /// The inertial force J a.
    pub inertia: Vec<f64>,
    /// The damping force c v.
    pub damping: Vec<f64>,
    /// The restoring force R(q).
    pub restoring: Vec<f64>,
    /// The fitted force offset (0 when not fitted).
    pub offset: f64,
    /// The fitted friction law's force F along the motion.
    pub friction_fitted: Vec<f64>,
    /// The friction force the balance leaves: u - J a - c v - R(q) - offset.
    pub friction_balance: Vec<f64>,
}

/// The fit of one compared channel of a record.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelFit {
    /// The quantity compared (`velocity`, `displacement`, `acceleration`, `force`, ...).
    pub channel: String,
    /// Its SI unit.
    pub unit: String,
    /// Samples compared.
    pub samples: usize,
    /// RMS of fitted - measured \[unit\].
    pub rms_residual: f64,
    /// The noise level its residuals were weighted by \[unit\] (`None`: unweighted).
    pub noise: Option<f64>,
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
    /// RMS residual over all records, in `residual_unit`.
    pub rms_residual: f64,
    /// The quantity compared: `velocity`, or `force` (force-domain fits).
    pub compared: String,
    /// Unit of the residuals (`m/s`, `N`).
    pub residual_unit: String,
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
    /// Starts that reached the best cost within its statistical tolerance (a cost difference
    /// of at most chi²(1 dof, 95 %) / 2 residual variances).
    pub starts_at_best: usize,
    /// The search strategy.
    pub search: Search,
    /// The start that won (index into `start_outcomes`).
    pub best_start: usize,
    /// Where the winning start came from (`staged from stribeck`, `data-driven guess`, ...).
    pub best_start_origin: String,
    /// What became of each start, in start order.
    pub start_outcomes: Vec<StartOutcome>,
    /// The checks of this fit, each pass, warn or fail.
    pub diagnostics: Vec<Finding>,
    /// The messages of the diagnostics that warn or fail, in order.
    pub warnings: Vec<String>,
    /// Wall time of the fit [s].
    pub wall_time_s: f64,
    /// Its place in a model comparison (set by [`crate::identify::compare::compare`]; its keys join the
    /// fit's in JSON).
    #[serde(flatten)]
    pub rank: Option<Rank>,
}

/// The abscissae of a record's compared samples (one value per sample).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SampleAxes {
    /// Time stamps \[s\].
    pub time: Vec<f64>,
    /// Displacement of the motion \[m\] (empty when not known).
    pub displacement: Vec<f64>,
    /// Velocity of the motion [m/s] (empty when not known).
    pub velocity: Vec<f64>,
}

/// The energy-based force check of one record: the Eq. 7 force's time mean against the
/// model's over the same samples, and the energy the friction dissipates over the complete
/// half-cycles as the record measures it against the model's along the measured motion
/// (energies against energies).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EnergyForce {
    /// Mean of the Eq. 7 force against the motion, F sgn(v), over the unmasked oscillating
    /// samples (its mean |F| where it opposes the motion) [N].
    pub mean_abs: f64,
    /// The reference level [N]: the model's mean force against the motion along the measured
    /// motion over the same samples (mu N for Coulomb), or the given level.
    pub reference: f64,
    /// 100 (mean_abs - reference) / reference.
    pub percent_difference: f64,
    /// RMS of the energy-based minus model force [N] (NaN, `null` in JSON, for a level).
    pub residual_rms: f64,
    /// Samples compared (where the energy-based force is defined).
    pub samples: usize,
    /// Standard deviation of the Eq. 7 force from the record's noise and quantisation [N].
    pub force_noise: f64,
    /// Mean friction force of the half-cycles (energy balance, no differentiation) [N].
    pub half_cycle_mean: f64,
    /// Complete half-cycles compared.
    pub half_cycles: usize,
    /// Energy the friction dissipated over them, as measured: the drop of m v^2 / 2 +
    /// k x^2 / 2 between turning points less the viscous work c int v^2 dt [J].
    pub dissipated: f64,
    /// Energy the model dissipates over the same half-cycles along the measured motion,
    /// int F v dt (the level times the distance for a given level) [J].
    pub model_dissipated: f64,
    /// 100 (dissipated - model_dissipated) / model_dissipated (NaN without a complete
    /// half-cycle).
    pub dissipation_percent_difference: f64,
    /// Why the Eq. 7 comparison was not judged, when it was not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub eq7_skipped: Option<EnergySkip>,
    /// Why the dissipated energies were not judged, when they were not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dissipation_skipped: Option<EnergySkip>,
}

/// Why a part of the energy check cannot judge a record.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "reason", rename_all = "snake_case")]
pub enum EnergySkip {
    /// No complete half-cycle between two turning points.
    NoHalfCycle,
    /// Too few samples per half-cycle (the median) to differentiate or integrate over it.
    FewSamples {
        /// Samples in the median half-cycle.
        per_half_cycle: usize,
        /// The fewest the check needs.
        needed: usize,
    },
    /// The displacement's quantisation step makes the energies at the turning points
    /// uncertain by this share of the dissipated energy.
    Quantised {
        /// The step [m].
        step: f64,
        /// k |x| step / 2 at both ends of every half-cycle over the energy dissipated.
        share: f64,
    },
    /// The model's force replayed along the measured velocity follows its noise more than
    /// the friction level (stiff, strongly damped bristles: sigma1 times the noise's rate).
    NoisyReplay {
        /// The replayed force's noise level [N].
        force_noise: f64,
        /// The friction level [N].
        level: f64,
    },
    /// The noise of the Eq. 7 force dominates the friction level.
    NoisyDerivative {
        /// Its standard deviation [N].
        force_noise: f64,
        /// The friction level [N].
        level: f64,
    },
    /// The friction's part is a remainder after the viscous part of a fitted damping, whose
    /// standard error alone moves it by this share (an ill-conditioned remainder).
    IllConditioned {
        /// The fitted property.
        property: String,
        /// The share of the friction's part its standard error moves.
        share: f64,
    },
}

impl EnergySkip {
    /// The reason in words, its forces and lengths in the units of `axis` (N m and rad on a
    /// rotary axis).
    pub fn describe(&self, axis: Axis) -> String {
        let n = axis.force_unit();
        let m = axis.displacement_unit();
        match self {
            Self::NoHalfCycle => "no complete half-cycle".to_string(),
            Self::FewSamples {
                per_half_cycle,
                needed,
            } => format!("{per_half_cycle} samples per half-cycle, at least {needed} needed"),
            Self::Quantised { step, share } => format!(
                "the {}'s quantisation step {step:.3e} {m} makes the energies at the turning points uncertain by {:.1} % of the energy dissipated",
                axis.coordinate_name(),
                100.0 * share
            ),
            Self::NoisyReplay { force_noise, level } => format!(
                "the model's force replayed along the measured velocity carries {force_noise:.3} {n} of its noise, more than a third of the friction level ({level:.3} {n})"
            ),
            Self::NoisyDerivative { force_noise, level } => format!(
                "the noise of the Eq. 7 force ({force_noise:.3} {n}) is more than a third of the friction level ({level:.3} {n})"
            ),
            Self::IllConditioned { property, share } => format!(
                "the friction's part is what remains after the viscous part of the fitted {property}, whose standard error alone moves it by {:.1} %: an ill-conditioned remainder the check cannot judge",
                100.0 * share
            ),
        }
    }
}

impl std::fmt::Display for EnergySkip {
    /// The reason on a linear axis; [`EnergySkip::describe`] gives it on any axis.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.describe(Axis::Linear))
    }
}

/// What the records say about a fitted parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Identifiability {
    /// Bounded on both sides: the value and its standard error stand.
    Determined,
    /// Only smaller values are excluded (at 95 %): the parameter exceeds `bound`.
    LowerBound,
    /// Only larger values are excluded: the parameter is below `bound`.
    UpperBound,
    /// Neither side is bounded within the profile.
    NotIdentifiable,
}

impl Identifiability {
    /// Config-style name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Determined => "determined",
            Self::LowerBound => "lower_bound",
            Self::UpperBound => "upper_bound",
            Self::NotIdentifiable => "not_identifiable",
        }
    }
}

/// A fit's standing in a model comparison.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Rank {
    /// AIC minus the best AIC (0 for the best).
    pub delta_aic: f64,
    /// exp(-delta_aic / 2), normalised over the ranking: the weight of evidence for this
    /// model among those compared.
    pub akaike_weight: f64,
    /// Within [`crate::identify::compare::INDISTINGUISHABLE_DELTA_AIC`] of the best: the data do not
    /// tell it from the best.
    pub indistinguishable: bool,
}

/// What a fit's outcome means for whoever decides an exit status: the CLI maps `Ok` to 0,
/// `NotConverged` to 2 and `DiagnosticFailed` to 3 (1 is an error, no result at all).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Converged, and no diagnostic failed (warnings allowed).
    Ok,
    /// The solver did not converge.
    NotConverged,
    /// Converged, but at least one diagnostic failed.
    DiagnosticFailed,
}

impl Verdict {
    /// The verdict of a fit that `converged` with `findings`.
    pub fn of(converged: bool, findings: &[Finding]) -> Self {
        if !converged {
            Self::NotConverged
        } else if worst_status(findings) == Status::Fail {
            Self::DiagnosticFailed
        } else {
            Self::Ok
        }
    }
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

    /// Converged and clean, not converged, or a diagnostic failed.
    pub fn verdict(&self) -> Verdict {
        Verdict::of(self.converged, &self.diagnostics)
    }

    /// The diagnostics that warn or fail.
    pub fn problems(&self) -> impl Iterator<Item = &Finding> {
        self.diagnostics.iter().filter(|f| f.status != Status::Pass)
    }
}
