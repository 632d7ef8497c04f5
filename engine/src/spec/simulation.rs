//! `[simulation]` and `[simulation.integrator]`: the release state, the time grid, the
//! synthetic noise, the measured input and the integrator of a simulation.

use super::error::SpecError;
use crate::data::{RecordSource, MAX_SAMPLES};
use crate::simulate::{Integrator, SimOptions};
use serde::{Deserialize, Serialize};

/// The ODE integrator chosen in `[simulation.integrator]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum IntegratorMethod {
    /// Adaptive Dormand-Prince 5(4) with dense output and event location.
    Dopri5,
    /// Fixed-step explicit Euler (for comparison only).
    Euler,
    /// The fits' choice, and `simulate`'s default: the exact propagator for laws affine in v,
    /// Rodas4 where the motion is stiff (bristle contacts of sigma0 >= 1e6 N/m), Dopri5
    /// otherwise.
    #[default]
    Auto,
    /// The exact closed-form propagator (coulomb, viscous_coulomb, none).
    Exact,
    /// The stiff Rosenbrock method Rodas4 (bristle and element models with stiff contacts).
    Rodas,
}

/// `[simulation.integrator]`: integrator choice (default `auto`, as the fits) and tolerances
/// (the engine's defaults when absent).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IntegratorSpec {
    /// The integration method.
    pub method: IntegratorMethod,
    /// Euler only: steps per natural period.
    pub steps_per_period: Option<f64>,
    /// Relative tolerance.
    pub rtol: Option<f64>,
    /// Absolute tolerance.
    pub atol: Option<f64>,
    /// Largest number of steps.
    pub max_steps: Option<u64>,
    /// Largest number of events (turning points, sticks).
    pub max_events: Option<usize>,
}

/// Steps per natural period of the Euler integrator when neither the spec nor the engine's
/// default options name a number.
pub const EULER_STEPS_PER_PERIOD: f64 = 10_000.0;

impl IntegratorMethod {
    /// The engine's integrator (Euler with [`EULER_STEPS_PER_PERIOD`]).
    pub fn engine_integrator(self) -> Integrator {
        match self {
            IntegratorMethod::Dopri5 => Integrator::Dopri5,
            IntegratorMethod::Auto => Integrator::Auto,
            IntegratorMethod::Exact => Integrator::Exact,
            IntegratorMethod::Rodas => Integrator::Rodas,
            IntegratorMethod::Euler => Integrator::Euler {
                steps_per_period: EULER_STEPS_PER_PERIOD,
            },
        }
    }
}

impl IntegratorSpec {
    /// The engine's simulation options (engine defaults where not given).
    pub fn sim_options(&self) -> SimOptions {
        let defaults = SimOptions::default();
        let integrator = match self.method {
            IntegratorMethod::Euler => Integrator::Euler {
                steps_per_period: match (self.steps_per_period, &defaults.integrator) {
                    (Some(n), _) => n,
                    (None, Integrator::Euler { steps_per_period }) => *steps_per_period,
                    (None, _) => EULER_STEPS_PER_PERIOD,
                },
            },
            method => method.engine_integrator(),
        };
        SimOptions {
            integrator,
            rtol: self.rtol.unwrap_or(defaults.rtol),
            atol: self.atol.unwrap_or(defaults.atol),
            max_steps: self.max_steps.unwrap_or(defaults.max_steps),
            max_events: self.max_events.unwrap_or(defaults.max_events),
        }
    }
}

/// Sample rate of a simulation that does not name one \[Hz\].
pub const DEFAULT_SAMPLE_RATE: f64 = 1000.0;

/// `[simulation]`: the release state, the time grid and optional synthetic noise. Deserialized
/// through [`SimulationInput`], which fills the defaults and checks every value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "SimulationInput")]
pub struct SimulationSpec {
    /// Release displacement \[m\] (an axis driven by `input`: the start, 0 by default).
    pub x0: f64,
    /// Release velocity \[m/s\].
    pub v0: f64,
    /// Initial internal states of the model (default: the model's own).
    pub z0: Option<Vec<f64>>,
    /// Simulated time \[s\].
    pub duration: f64,
    /// Output sample rate \[Hz\].
    pub sample_rate: f64,
    /// Standard deviation of the Gaussian velocity noise of a synthetic record \[m/s\];
    /// `None`: no record.
    pub noise: Option<f64>,
    /// Seed of the noise generator.
    pub seed: u64,
    /// Integrator options.
    pub integrator: IntegratorSpec,
    /// The measured input u(t) that drives the axis: a file read as a `[[records]]` entry
    /// is (`file`, `time_column`, `input_force_column`, `input_force_scale`, `format`, ...),
    /// its `input_force` channel taken linear between samples. `None`: free vibration.
    pub input: Option<RecordSource>,
}

/// `[simulation]` as written: every key optional; [`SimulationSpec`] is built from it.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationInput {
    x0: Option<f64>,
    #[serde(default)]
    v0: f64,
    z0: Option<Vec<f64>>,
    duration: Option<f64>,
    sample_rate: Option<f64>,
    noise: Option<f64>,
    #[serde(default)]
    seed: u64,
    #[serde(default)]
    integrator: IntegratorSpec,
    input: Option<RecordSource>,
}

fn positive(what: &str, value: f64) -> Result<f64, SpecError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(SpecError::Simulation(format!(
            "`{what}` must be a positive number, got {value}"
        )))
    }
}

fn finite(what: &str, value: f64) -> Result<f64, SpecError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(SpecError::Simulation(format!(
            "`{what}` must be finite, got {value}"
        )))
    }
}

fn required(what: &str, meaning: &str, value: Option<f64>) -> Result<f64, SpecError> {
    value.ok_or_else(|| SpecError::Simulation(format!("missing `{what}` ({meaning})")))
}

/// The displacement the simulation starts from: a free vibration needs its release `x0`; an
/// axis driven by a measured input starts at rest where it is, at 0 unless `x0` is given.
fn start_displacement(x0: Option<f64>, driven: bool) -> Result<f64, SpecError> {
    match x0 {
        Some(x0) => Ok(x0),
        None if driven => Ok(0.0),
        None => required("x0", "the release displacement, m", None),
    }
}

impl TryFrom<SimulationInput> for SimulationSpec {
    type Error = SpecError;

    fn try_from(s: SimulationInput) -> Result<Self, SpecError> {
        let x0 = start_displacement(s.x0, s.input.is_some())?;
        let duration = required("duration", "the simulated time, s", s.duration)?;
        if let Some(n) = s.noise.filter(|n| !(n.is_finite() && *n >= 0.0)) {
            return Err(SpecError::Simulation(format!(
                "`noise` must be >= 0, got {n}"
            )));
        }
        let duration = positive("duration", duration)?;
        let sample_rate = positive("sample_rate", s.sample_rate.unwrap_or(DEFAULT_SAMPLE_RATE))?;
        // The output holds duration * sample_rate + 1 samples: bound it before allocating.
        let samples = duration * sample_rate;
        if samples >= MAX_SAMPLES as f64 {
            return Err(SpecError::Simulation(format!(
                "duration * sample_rate = {samples:e} samples; at most {MAX_SAMPLES} are written"
            )));
        }
        Ok(Self {
            x0: finite("x0", x0)?,
            v0: finite("v0", s.v0)?,
            z0: s.z0,
            duration,
            sample_rate,
            noise: s.noise,
            seed: s.seed,
            integrator: s.integrator,
            input: s.input,
        })
    }
}

impl SimulationSpec {
    /// The engine's simulation options.
    pub fn sim_options(&self) -> SimOptions {
        self.integrator.sim_options()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A free vibration needs its release; a driven axis starts at 0 unless told otherwise.
    #[test]
    fn only_a_free_vibration_needs_its_release_displacement() {
        let free: Result<SimulationSpec, _> =
            serde_json::from_value(serde_json::json!({"duration": 1.0}));
        let e = free.unwrap_err().to_string();
        assert!(e.contains("missing `x0`"), "{e}");
        let input = serde_json::json!({"file": "drive.csv", "input_force_column": "u"});
        let driven: SimulationSpec =
            serde_json::from_value(serde_json::json!({"duration": 1.0, "input": input}))
                .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(driven.x0, 0.0);
        let placed: SimulationSpec = serde_json::from_value(
            serde_json::json!({"duration": 1.0, "x0": 0.02, "input": input}),
        )
        .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(placed.x0, 0.02);
    }

    #[test]
    fn integrator_spec_maps_onto_engine_options() {
        let d = SimOptions::default();
        // `simulate` integrates as the fits do by default: `auto`, with the engine's
        // tolerances and limits.
        let auto = SimOptions {
            integrator: Integrator::Auto,
            ..d
        };
        assert_eq!(IntegratorSpec::default().sim_options(), auto);
        let o = IntegratorSpec {
            method: IntegratorMethod::Euler,
            steps_per_period: Some(1e5),
            rtol: Some(1e-6),
            max_events: Some(7),
            ..IntegratorSpec::default()
        }
        .sim_options();
        assert_eq!(
            o.integrator,
            Integrator::Euler {
                steps_per_period: 1e5
            }
        );
        assert_eq!((o.rtol, o.atol, o.max_events), (1e-6, d.atol, 7));
    }
}
