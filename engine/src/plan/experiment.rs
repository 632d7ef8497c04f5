//! A candidate experiment ([`Experiment`]): the record a planned run would take (release,
//! normal force, sample rate, duration, noise, the input of a driven axis), and its
//! noise-free record at the assumed law ([`Experiment::record`]).

use crate::error::EngineError;
use crate::oscillator::Oscillator;
use crate::record::{Channel, NormalForce, Record, TimeBase};
use crate::simulate::{simulate_driven, Initial, Input, RunInputs, SampleGrid, SimOptions};
use crate::synthetic::uniform_times;
use frictionid_models::FrictionModel;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Components of a multisine when not given.
pub const DEFAULT_COMPONENTS: usize = 8;

/// A multisine input force: `components` tones spread evenly over `band` (Hz, both ends
/// included) with Schroeder's phases (a low crest factor), scaled to the RMS `amplitude`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Multisine {
    /// RMS of the input force \[N\] (N m on a rotary axis).
    pub amplitude: f64,
    /// Lowest and highest tone \[Hz\].
    pub band: [f64; 2],
    /// Number of tones.
    #[serde(default = "default_components")]
    pub components: usize,
}

fn default_components() -> usize {
    DEFAULT_COMPONENTS
}

impl Multisine {
    /// Checks the amplitude, the band and the number of tones.
    pub fn validate(&self) -> Result<(), String> {
        let [lo, hi] = self.band;
        if !(self.amplitude.is_finite() && self.amplitude > 0.0) {
            return Err(format!(
                "multisine amplitude {} must be > 0",
                self.amplitude
            ));
        }
        if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi >= lo) {
            return Err(format!(
                "multisine band [{lo}, {hi}] Hz must be 0 < low <= high"
            ));
        }
        if self.components == 0 || (self.components > 1 && hi == lo) {
            return Err("a multisine needs at least one tone, and a band for several".into());
        }
        Ok(())
    }

    /// The tones' frequencies \[Hz\].
    pub fn frequencies(&self) -> Vec<f64> {
        let [lo, hi] = self.band;
        let n = self.components.max(1);
        if n == 1 {
            return vec![lo];
        }
        (0..n)
            .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
            .collect()
    }

    /// The force at `t`: sum_k a cos(2 pi f_k t + phi_k), phi_k = -pi k (k - 1) / K, with
    /// a = amplitude sqrt(2 / K) so that the RMS is `amplitude`.
    pub fn force(&self, t: f64) -> f64 {
        let freqs = self.frequencies();
        let n = freqs.len() as f64;
        let a = self.amplitude * (2.0 / n).sqrt();
        freqs
            .iter()
            .enumerate()
            .map(|(k, f)| {
                let k = k as f64 + 1.0;
                a * (2.0 * PI * f * t - PI * k * (k - 1.0) / n).cos()
            })
            .sum()
    }
}

/// What drives the axis during an experiment.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ExperimentInput {
    /// A multisine, sampled at the experiment's rate.
    Multisine(Multisine),
    /// A given input force (read from a file), linear between its own time stamps;
    /// serialized as its number of samples.
    #[serde(serialize_with = "input_samples")]
    Given(Input),
}

fn input_samples<S: serde::Serializer>(input: &Input, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_u64(input.time().len() as u64)
}

/// One candidate experiment.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Experiment {
    /// Its name in the report.
    pub name: String,
    /// Release displacement \[m\] (0 for a driven axis at rest).
    pub x0: f64,
    /// Release velocity \[m/s\].
    pub v0: f64,
    /// Normal force \[N\]; `None`: the oscillator's.
    pub normal_force: Option<f64>,
    /// Sample rate \[Hz\].
    pub sample_rate: f64,
    /// Record length \[s\].
    pub duration: f64,
    /// Standard deviation of the velocity noise \[m/s\]; `None`: the plan's.
    pub velocity_noise: Option<f64>,
    /// The input of a driven axis; `None`: free vibration.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub input: Option<ExperimentInput>,
}

impl Experiment {
    /// A free vibration released from rest at `x0`, `duration` s at `sample_rate` Hz, named
    /// after its release in mm.
    pub fn release(x0: f64, duration: f64, sample_rate: f64) -> Self {
        Self {
            name: format!("x0 = {} mm", (x0 * 1e6).round() / 1e3),
            x0,
            v0: 0.0,
            normal_force: None,
            sample_rate,
            duration,
            velocity_noise: None,
            input: None,
        }
    }

    /// Checks the numbers a record cannot be made without.
    pub fn validate(&self) -> Result<(), String> {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !positive(self.sample_rate) || !positive(self.duration) {
            return Err(format!(
                "sample_rate ({}) and duration ({}) must be > 0",
                self.sample_rate, self.duration
            ));
        }
        if self.duration * self.sample_rate < 10.0 {
            return Err("fewer than ten samples".into());
        }
        if !(self.x0.is_finite() && self.v0.is_finite()) {
            return Err("x0 and v0 must be finite".into());
        }
        if self
            .normal_force
            .is_some_and(|n| !(n.is_finite() && n >= 0.0))
        {
            return Err("normal_force must be finite and >= 0".into());
        }
        if self.velocity_noise.is_some_and(|s| !positive(s)) {
            return Err("velocity_noise must be > 0".into());
        }
        if let Some(ExperimentInput::Multisine(m)) = &self.input {
            m.validate()?;
        }
        if self.input.is_none() && self.x0 == 0.0 && self.v0 == 0.0 {
            return Err("neither a release (x0, v0) nor an input: the axis would not move".into());
        }
        Ok(())
    }

    /// The input force on the experiment's clock, if driven.
    fn input_samples(&self, times: &[f64]) -> Option<Input> {
        match &self.input {
            None => None,
            Some(ExperimentInput::Given(input)) => Some(input.clone()),
            Some(ExperimentInput::Multisine(m)) => {
                let u = times.iter().map(|&t| m.force(t)).collect();
                Input::new(times.to_vec(), u).ok()
            }
        }
    }

    /// The noise-free velocity record of the experiment under `model` on `osc`, with its
    /// velocity noise level `sigma` declared and, when driven, its input force channel.
    pub fn record(
        &self,
        osc: &Oscillator,
        model: &dyn FrictionModel,
        sim: &SimOptions,
        sigma: f64,
    ) -> Result<Record, EngineError> {
        let times = uniform_times(self.duration, self.sample_rate);
        let input = self.input_samples(&times);
        let mut run_osc = *osc;
        if let Some(n) = self.normal_force {
            run_osc.normal_force = n;
        }
        let init = Initial {
            x0: self.x0,
            v0: self.v0,
            z0: None,
        };
        let t_end = times.last().copied().unwrap_or(0.0);
        let motion = simulate_driven(RunInputs {
            osc: &run_osc,
            model,
            init: &init,
            input: input.as_ref(),
            channels: None,
            grid: SampleGrid {
                t_end,
                sample_times: &times,
            },
            opts: sim,
        })?;
        let base = TimeBase::new(times.clone()).map_err(|e| EngineError::Record {
            record: self.name.clone(),
            reason: e.to_string(),
        })?;
        let mut record = Record::from_time_base(self.name.clone(), base)
            .with_channel(Channel::Velocity, motion.v)
            .with_noise(Channel::Velocity, sigma);
        if let Some(u) = input {
            let sampled = times.iter().map(|&t| u.at(t)).collect();
            record = record.with_channel(Channel::InputForce, sampled);
        }
        record.x0 = self.x0;
        record.v0 = self.v0;
        if let Some(n) = self.normal_force {
            record.set_normal_force(Some(NormalForce::Constant(n)));
        }
        Ok(record)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The multisine's RMS over whole periods of its tones is the amplitude asked for.
    #[test]
    fn multisine_has_the_rms_asked_for() {
        let m = Multisine {
            amplitude: 3.0,
            band: [1.0, 8.0],
            components: 8,
        };
        let n = 100_000;
        let rms = ((0..n)
            .map(|i| m.force(i as f64 / n as f64).powi(2))
            .sum::<f64>()
            / n as f64)
            .sqrt();
        assert!((rms - 3.0).abs() < 1e-6, "{rms}");
        assert!(Multisine {
            band: [0.0, 1.0],
            ..m
        }
        .validate()
        .is_err());
    }
}
