//! Typed outcomes of a fit: why the solver stopped, what became of each start, and the
//! findings (checks with a pass / warn / fail status) that a report shows.

use crate::error::EngineError;
use serde::{Deserialize, Serialize, Serializer};
use std::fmt;

/// Why a Levenberg-Marquardt run (or a fit without free parameters) stopped.
///
/// `Display` gives the sentence reports show (`converged: gradient below tolerance`,
/// `iteration limit (200) reached`, ...).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "reason")]
pub enum TerminationReason {
    /// Nothing to vary: the model was evaluated as it is.
    NoFreeParameters,
    /// The scaled projected gradient fell below `gtol`.
    GradientBelowTolerance,
    /// A step changed no parameter by more than `xtol` relative.
    StepBelowTolerance,
    /// An accepted step reduced the cost by less than `ftol` relative.
    CostReductionBelowTolerance,
    /// The cost fell by less than `tolerance` relative over `window` accepted steps.
    Stagnation {
        /// Relative tolerance.
        tolerance: f64,
        /// Accepted steps judged.
        window: usize,
    },
    /// The Gauss-Newton step promised less than `resolution` decrease of the cost (a run
    /// that needs its cost only to that precision).
    WithinResolution {
        /// The absolute cost resolution.
        resolution: f64,
    },
    /// The Gauss-Newton step would move the parameters by less than `fraction` of their
    /// standard errors: iterating on would not change the estimates within their precision.
    WithinStandardErrors {
        /// The resolution, in standard errors.
        fraction: f64,
    },
    /// The damping grew past its limit without a decrease of the cost.
    DampingLimit,
    /// The iteration limit was reached before any convergence criterion.
    IterationLimit {
        /// The limit.
        limit: u64,
    },
    /// The iteration limit was reached only because the named parameters kept running
    /// towards a value the records do not bound; with them held, the others converged.
    ConvergedExceptUnbounded {
        /// The unbounded parameters.
        parameters: Vec<String>,
    },
    /// Abandoned: another start of the same fit had converged to a cost `factor` times lower
    /// or more, or (screening) the nested static law the model contains reached it
    /// ([`crate::identify::search::lm::Pace`]); this one could not have become the best within reach.
    Outpaced {
        /// The cost the other start converged to.
        best: f64,
        /// This run's cost when it was abandoned.
        cost: f64,
    },
    /// Any other stop reported by the solver framework (e.g. an interrupt).
    Other {
        /// The framework's text.
        text: String,
    },
}

impl TerminationReason {
    /// Whether this reason counts as convergence.
    pub fn is_converged(&self) -> bool {
        !matches!(
            self,
            Self::IterationLimit { .. } | Self::Outpaced { .. } | Self::Other { .. }
        )
    }
}

impl fmt::Display for TerminationReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoFreeParameters => f.write_str("converged: no free parameters"),
            Self::GradientBelowTolerance => f.write_str("converged: gradient below tolerance"),
            Self::StepBelowTolerance => f.write_str("converged: step below tolerance"),
            Self::CostReductionBelowTolerance => {
                f.write_str("converged: relative cost reduction below tolerance")
            }
            Self::Stagnation { tolerance, window } => write!(
                f,
                "converged: cost changed by less than {tolerance:e} relative over {window} steps"
            ),
            Self::WithinResolution { resolution } => write!(
                f,
                "converged: the linear model promises less than {resolution:e} further decrease of the cost"
            ),
            Self::WithinStandardErrors { fraction } => write!(
                f,
                "converged: the linear model puts the optimum within {fraction} standard errors"
            ),
            Self::DampingLimit => {
                f.write_str("converged: no further decrease possible (damping limit)")
            }
            Self::IterationLimit { limit } => write!(f, "iteration limit ({limit}) reached"),
            Self::ConvergedExceptUnbounded { parameters } => write!(
                f,
                "converged for the other parameters: `{}` kept running to a value the records do not bound",
                parameters.join("`, `")
            ),
            Self::Outpaced { best, cost } => write!(
                f,
                "abandoned at cost {cost:.6e}: another start, or the nested law it contains, reached {best:.6e}"
            ),
            Self::Other { text } => f.write_str(text),
        }
    }
}

/// Serializes a value as its `Display` text (keeps report keys plain strings).
pub(crate) fn as_display<T: fmt::Display, S: Serializer>(
    value: &T,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    serializer.collect_str(value)
}

/// What became of one start of a (multi-start) fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "outcome")]
pub enum StartOutcome {
    /// The start ran to a stop with a finite cost.
    Finished {
        /// Index of the start.
        start: usize,
        /// Half the weighted sum of squared residuals at its best point.
        cost: f64,
        /// Solver iterations (screening and continuation).
        iterations: u64,
        /// Why it stopped.
        #[serde(serialize_with = "as_display")]
        termination: TerminationReason,
    },
    /// The start ended with a non-finite cost.
    NonFiniteCost {
        /// Index of the start.
        start: usize,
    },
    /// The start failed with an error.
    Failed {
        /// Index of the start.
        start: usize,
        /// The error.
        #[serde(serialize_with = "as_display")]
        error: EngineError,
    },
    /// The start was promoted after screening and its continuation failed.
    ContinuationFailed {
        /// Index of the start.
        start: usize,
        /// The error.
        #[serde(serialize_with = "as_display")]
        error: EngineError,
    },
}

impl StartOutcome {
    /// The warning a report gives for this outcome (`None` for a finished start).
    pub fn warning(&self) -> Option<String> {
        match self {
            Self::Finished { .. } => None,
            Self::NonFiniteCost { start } => {
                Some(format!("start {start} ended with a non-finite cost"))
            }
            Self::Failed { start, error } => Some(format!("start {start} failed: {error}")),
            Self::ContinuationFailed { error, .. } => {
                Some(format!("a promoted start failed: {error}"))
            }
        }
    }
}

/// The status of a check.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// The check passed.
    Pass,
    /// The check could not judge (the message says why): neither a pass nor a problem
    /// with the result, but a check the reader does not have.
    Skipped,
    /// The result may be doubtful: read the message.
    Warn,
    /// The result cannot be trusted.
    Fail,
}

/// What a finding checks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Check {
    /// The model's mean force against the energy-based force (Eq. 7).
    EnergyBalance,
    /// Whether residuals are locked to the motion (sgn v, x, the period).
    ResidualStructure,
    /// A fitted parameter sits at one of its bounds.
    ParameterAtBound,
    /// A free parameter that changes no residual at the optimum (its Jacobian column is zero
    /// everywhere): the records say nothing about it.
    ParameterWithoutEffect,
    /// Whether standard errors could be computed.
    StandardErrors,
    /// Two free parameters are strongly correlated.
    Correlation,
    /// A combination of free parameters the data cannot separate.
    Identifiability,
    /// Whether the starts of a multi-start fit agree.
    StartAgreement,
    /// A start failed.
    StartFailure,
    /// Whether the solver converged.
    Convergence,
    /// Autocorrelated residuals and the widening of the standard errors it calls for.
    NoiseCorrelation,
    /// The force-domain prefit that gave a velocity fit one of its starts.
    Prefit,
    /// A velocity fit of a record that sticks whose residual stays far above the noise after
    /// the search's further starts: the optimum may be a neighbouring count of half-cycles.
    SuspectOptimum,
    /// The fitted model is physically doubtful (e.g. mu_s < mu_c).
    PhysicalConsistency,
    /// Samples whose target is unreliable, left out of the fit.
    UnreliableTarget,
    /// Samples a robust loss down-weighted at the optimum (spikes, a target the law cannot
    /// follow there).
    DownWeighted,
    /// The residual RMS against the records' noise floor: a law that follows the records
    /// leaves only their noise.
    GoodnessOfFit,
    /// A value the configuration left out and the run assumed (no damping given: c = 0),
    /// stated so the reader knows what the numbers rest on.
    Assumption,
}

/// One diagnostic of a fit: a check, its status, the value it judged and a plain message.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Finding {
    /// The check.
    pub check: Check,
    /// Pass, warn or fail.
    pub status: Status,
    /// The value judged (e.g. a percentage or a correlation), when there is one.
    pub value: Option<f64>,
    /// What it means, for a person.
    pub message: String,
    /// The parameter it is about, when it is about one (a parameter at its bound).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parameter: Option<String>,
}

impl Finding {
    /// A finding.
    pub fn new(check: Check, status: Status, value: Option<f64>, message: String) -> Self {
        Self {
            check,
            status,
            value,
            message,
            parameter: None,
        }
    }

    /// The finding, about the parameter `name`.
    pub fn about(mut self, name: &str) -> Self {
        self.parameter = Some(name.to_string());
        self
    }

    /// A warning.
    pub fn warn(check: Check, value: Option<f64>, message: String) -> Self {
        Self::new(check, Status::Warn, value, message)
    }

    /// A check that could not judge, and why.
    pub fn skipped(check: Check, message: String) -> Self {
        Self::new(check, Status::Skipped, None, message)
    }
}

/// The worst status among `findings` (`Pass` when there are none).
pub fn worst_status(findings: &[Finding]) -> Status {
    findings
        .iter()
        .map(|f| f.status)
        .max()
        .unwrap_or(Status::Pass)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reasons_read_as_before_and_say_whether_they_converged() {
        let stall = TerminationReason::Stagnation {
            tolerance: 1e-6,
            window: 10,
        };
        assert_eq!(
            stall.to_string(),
            "converged: cost changed by less than 1e-6 relative over 10 steps"
        );
        assert!(stall.is_converged());
        let limit = TerminationReason::IterationLimit { limit: 200 };
        assert_eq!(limit.to_string(), "iteration limit (200) reached");
        assert!(!limit.is_converged());
        assert!(TerminationReason::DampingLimit.is_converged());
    }

    #[test]
    fn findings_serialize_with_plain_keys() {
        let f = Finding::new(Check::EnergyBalance, Status::Fail, None, "x".into());
        let v = serde_json::to_value(&f).unwrap();
        assert_eq!(v["check"], "energy_balance");
        assert_eq!(v["status"], "fail");
        assert!(v["value"].is_null());
        assert_eq!(worst_status(&[]), Status::Pass);
        let w = Finding::warn(Check::Correlation, Some(0.99), "y".into());
        assert_eq!(worst_status(&[w, f]), Status::Fail);
    }

    #[test]
    fn start_outcomes_give_the_warnings_reports_show() {
        let failed = StartOutcome::Failed {
            start: 2,
            error: EngineError::Fit("boom".into()),
        };
        assert_eq!(
            failed.warning().unwrap(),
            "start 2 failed: fit failed: boom"
        );
        let v = serde_json::to_value(&failed).unwrap();
        assert_eq!(v["outcome"], "failed");
        assert_eq!(v["error"], "fit failed: boom");
    }
}
