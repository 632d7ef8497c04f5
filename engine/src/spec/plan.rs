//! `[plan]`: the experiment design of `plan` (see [`crate::plan`]): the candidates, how many
//! records to take, the parameters whose standard errors to minimise, the criterion, the
//! noise (given, or estimated from a measured record), the reach and where the assumed law
//! comes from (`[model]`, or a previous fit's report as `prior`).
//!
//! ```toml
//! [plan]
//! parameters = ["v_s", "mu_s"]   # default: every free parameter
//! choose = 2
//! criterion = "D"                # or "A"
//! velocity_noise = 2e-4          # m/s (or noise_record = { file = "quiet.csv" })
//! candidates = [
//!   { x0 = 0.004, duration = 2.0, sample_rate = 1000.0 },
//!   { x0 = 0.010, duration = 2.0, sample_rate = 1000.0, normal_force = 10.0 },
//!   { duration = 2.0, multisine = { amplitude = 10.0, band = [1.0, 5.0] } },
//! ]
//! ```

use super::SpecError;
use crate::data::RecordSource;
use crate::plan::{Criterion, Experiment, ExperimentInput, Multisine, DEFAULT_REACH};
use crate::record::{Channel, Record};
use crate::simulate::Input;
use frictionid_models::FrictionModel;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::path::PathBuf;

/// `[plan]` as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanSpec {
    /// The parameters whose standard errors the design minimises; empty: every free one.
    #[serde(default)]
    pub parameters: Vec<String>,
    /// The candidate experiments.
    pub candidates: Vec<CandidateSpec>,
    /// How many records to take.
    #[serde(default = "one")]
    pub choose: usize,
    /// `"D"` (default) or `"A"`.
    #[serde(default)]
    pub criterion: Criterion,
    /// Standard deviation of the velocity noise \[m/s\] (a candidate's own wins).
    pub velocity_noise: Option<f64>,
    /// Lag-one correlation of the noise, in [0, 1).
    #[serde(default)]
    pub noise_correlation: f64,
    /// A measured record whose velocity noise level (estimated) the candidates take when
    /// `velocity_noise` is not given: a `[[records]]` entry.
    pub noise_record: Option<RecordSource>,
    /// A previous `fit` (or `compare`) report whose fitted law is the assumed point,
    /// instead of `[model]`'s values.
    pub prior: Option<PathBuf>,
    /// The relative standard error above which a parameter is out of reach (default 0.5).
    #[serde(default = "default_reach")]
    pub reach: f64,
    /// Look for the smallest change that brings an out-of-reach parameter within reach
    /// (simulates the changed records; default true).
    #[serde(default = "yes")]
    pub suggest: bool,
}

fn one() -> usize {
    1
}

fn yes() -> bool {
    true
}

fn default_reach() -> f64 {
    DEFAULT_REACH
}

/// One `[plan] candidates` entry as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CandidateSpec {
    /// Its name in the report (default: from its release or input).
    pub name: Option<String>,
    /// Release displacement \[m\] (default 0: a driven axis at rest).
    #[serde(default)]
    pub x0: f64,
    /// Release velocity \[m/s\].
    #[serde(default)]
    pub v0: f64,
    /// Normal force \[N\] (default: the oscillator's).
    pub normal_force: Option<f64>,
    /// Sample rate \[Hz\] (default 1000).
    #[serde(default = "default_rate")]
    pub sample_rate: f64,
    /// Record length \[s\].
    pub duration: f64,
    /// Velocity noise \[m/s\] (default: the plan's).
    pub velocity_noise: Option<f64>,
    /// A multisine input force.
    pub multisine: Option<Multisine>,
    /// A measured input force read as a `[[records]]` entry (its `input_force` channel).
    pub input: Option<RecordSource>,
}

fn default_rate() -> f64 {
    super::DEFAULT_SAMPLE_RATE
}

impl CandidateSpec {
    /// The experiment, with the input record `given` read from `input` (the front end reads
    /// the file).
    pub fn experiment(
        &self,
        index: usize,
        given: Option<&Record>,
    ) -> Result<Experiment, SpecError> {
        let err = |m: String| SpecError::Plan(format!("candidate {}: {m}", index + 1));
        if self.multisine.is_some() && self.input.is_some() {
            return Err(err("give a multisine or an input file, not both".into()));
        }
        let input = match (&self.multisine, given) {
            (Some(m), _) => {
                m.validate().map_err(err)?;
                Some(ExperimentInput::Multisine(m.clone()))
            }
            (None, Some(record)) => Some(ExperimentInput::Given(input_of(record).map_err(err)?)),
            (None, None) if self.input.is_some() => {
                return Err(err("its input file was not read".into()))
            }
            (None, None) => None,
        };
        let name = self
            .name
            .clone()
            .unwrap_or_else(|| default_name(self, index));
        Ok(Experiment {
            name,
            x0: self.x0,
            v0: self.v0,
            normal_force: self.normal_force,
            sample_rate: self.sample_rate,
            duration: self.duration,
            velocity_noise: self.velocity_noise,
            input,
        })
    }
}

/// "x0 = 10 mm", "multisine 1-5 Hz", "input 2", each with the rate when not 1 kHz.
fn default_name(c: &CandidateSpec, index: usize) -> String {
    let what = match (&c.multisine, &c.input) {
        (Some(m), _) => format!("multisine {}-{} Hz", m.band[0], m.band[1]),
        (None, Some(_)) => format!("input {}", index + 1),
        (None, None) => format!("x0 = {} mm", (c.x0 * 1e6).round() / 1e3),
    };
    let mut parts = vec![what];
    if c.sample_rate != super::DEFAULT_SAMPLE_RATE {
        parts.push(format!("{} Hz", c.sample_rate));
    }
    if let Some(n) = c.normal_force {
        parts.push(format!("N = {n} N"));
    }
    parts.join(", ")
}

/// The input force of `record` (its `input_force` channel on its time base).
fn input_of(record: &Record) -> Result<Input, String> {
    let u = record.channel(Channel::InputForce).ok_or_else(|| {
        format!(
            "the input file `{}` has no input_force channel",
            record.name
        )
    })?;
    Input::new(record.time().to_vec(), u.to_vec()).map_err(|e| e.to_string())
}

impl PlanSpec {
    /// The experiments, with the input records the front end read (one per candidate, `None`
    /// where it names no file).
    pub fn experiments(&self, inputs: &[Option<Record>]) -> Result<Vec<Experiment>, SpecError> {
        self.candidates
            .iter()
            .enumerate()
            .map(|(i, c)| c.experiment(i, inputs.get(i).and_then(Option::as_ref)))
            .collect()
    }
}

/// The fitted law of a `fit` report's JSON (`model_parameters`), or of a `compare` report's
/// recommended law: the assumed point of a plan.
pub fn prior_model(report: &Value) -> Result<Box<dyn FrictionModel>, SpecError> {
    let err = |m: &str| SpecError::Plan(format!("prior: {m}"));
    let fit = match report.get("ranking").and_then(Value::as_array) {
        None => report,
        Some(ranking) => {
            let name = report
                .pointer("/verdict/recommended")
                .and_then(Value::as_str);
            ranking
                .iter()
                .find(|f| name.is_some() && f.get("model").and_then(Value::as_str) == name)
                .or_else(|| ranking.first())
                .ok_or_else(|| err("the comparison ranks no law"))?
        }
    };
    let parameters = fit
        .get("model_parameters")
        .ok_or_else(|| err("no fitted law (`model_parameters`) in the report"))?;
    serde_json::from_value(parameters.clone()).map_err(|e| err(&e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plan_table_reads_candidates_with_defaults_and_refuses_unknown_keys() {
        let spec: PlanSpec = serde_json::from_value(serde_json::json!({
            "parameters": ["v_s"], "choose": 2, "criterion": "A", "velocity_noise": 2e-4,
            "candidates": [
                {"x0": 0.01, "duration": 2.0},
                {"duration": 2.0, "multisine": {"amplitude": 5.0, "band": [1.0, 5.0]}}
            ]
        }))
        .unwrap();
        assert_eq!(
            (spec.choose, spec.criterion, spec.reach),
            (2, Criterion::A, 0.5)
        );
        let e = spec.experiments(&[]).unwrap();
        assert_eq!(e[0].name, "x0 = 10 mm");
        assert_eq!(e[0].sample_rate, 1000.0);
        assert_eq!(e[1].name, "multisine 1-5 Hz");
        let bad = serde_json::from_value::<PlanSpec>(serde_json::json!({
            "candidates": [{"x0": 0.01, "duration": 2.0, "rate": 5.0}]
        }))
        .unwrap_err()
        .to_string();
        assert!(bad.contains("unknown field `rate`"), "{bad}");
    }
}
