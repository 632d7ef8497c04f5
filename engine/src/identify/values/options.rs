//! The oscillator properties a fit may vary, and how a running fit reports its progress.

use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// An oscillator property that a fit may vary.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OscillatorParam {
    /// m [kg] (J [kg m^2] on a rotary axis, where it is called `inertia`).
    #[serde(alias = "inertia")]
    Mass,
    /// c [N s/m].
    Damping,
    /// k [N/m].
    Stiffness,
    /// The pendulum's gravity moment m g l [N m] (`restoring = { type = "pendulum" }`).
    GravityMoment,
    /// The input's offset F_0 [N] (see `Oscillator::input_offset`).
    InputOffset,
}

impl OscillatorParam {
    /// Config name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Mass => "mass",
            Self::Damping => "damping",
            Self::Stiffness => "stiffness",
            Self::GravityMoment => "gravity_moment",
            Self::InputOffset => "input_offset",
        }
    }
    /// Its name in reports on `axis`: the config name, `inertia` for the mass of a rotary
    /// axis.
    pub fn name_on(self, axis: crate::axis::Axis) -> &'static str {
        match self {
            Self::Mass => axis.inertia_name(),
            other => other.name(),
        }
    }

    /// Its unit written for a linear axis ([`crate::Axis::unit`] gives the rotary one): the
    /// gravity moment, a torque on the rotary axis it belongs to, is written as the force N.
    pub fn unit(self) -> &'static str {
        match self {
            Self::Mass => "kg",
            Self::Damping => "N s/m",
            Self::Stiffness => "N/m",
            Self::GravityMoment => "N",
            Self::InputOffset => "N",
        }
    }
    /// Parses a config name.
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "mass" | "inertia" => Some(Self::Mass),
            "damping" => Some(Self::Damping),
            "stiffness" => Some(Self::Stiffness),
            "gravity_moment" => Some(Self::GravityMoment),
            "input_offset" => Some(Self::InputOffset),
            _ => None,
        }
    }
}

/// Progress of a running fit, reported after every solver iteration.
#[derive(Debug, Clone, PartialEq)]
pub struct Progress {
    /// Model being fitted.
    pub model: String,
    /// Index of the start (multi-start).
    pub start: usize,
    /// Number of starts.
    pub starts: usize,
    /// Iterations of this start so far.
    pub iteration: u64,
    /// Iteration limit.
    pub max_iterations: u64,
    /// Best cost (half the weighted sum of squares) of this start so far.
    pub cost: f64,
}

/// A progress callback (e.g. the CLI's progress bar). Called from worker threads.
pub type ProgressFn = Arc<dyn Fn(&Progress) + Send + Sync>;

/// The step limit of each simulation during a fit. Trial parameters that make a model so
/// stiff that a record needs more steps are rejected quickly instead of being integrated
/// for seconds (the engine's own default allows 2e7 steps).
pub const FIT_MAX_STEPS: u64 = 200_000;

#[cfg(test)]
mod tests {
    use super::*;

    /// A rotary axis names its mass `inertia`: `[fit.options] oscillator = ["inertia"]` asks
    /// for the same property as `"mass"`, and reports name it after the axis.
    #[test]
    fn inertia_is_the_rotary_name_of_the_mass() {
        let asked: Vec<OscillatorParam> =
            serde_json::from_value(serde_json::json!(["inertia", "mass", "gravity_moment"]))
                .unwrap();
        assert_eq!(
            asked,
            [
                OscillatorParam::Mass,
                OscillatorParam::Mass,
                OscillatorParam::GravityMoment
            ]
        );
        assert_eq!(
            OscillatorParam::parse("inertia"),
            Some(OscillatorParam::Mass)
        );
        assert_eq!(OscillatorParam::Mass.name(), "mass");
        use crate::axis::Axis;
        assert_eq!(OscillatorParam::Mass.name_on(Axis::Rotary), "inertia");
        assert_eq!(OscillatorParam::Mass.name_on(Axis::Linear), "mass");
        assert_eq!(OscillatorParam::Damping.name_on(Axis::Rotary), "damping");
    }
}
