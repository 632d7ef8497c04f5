//! The measured quantities a record can hold besides time, and the normal force.

use serde::{Deserialize, Serialize};
use std::fmt;

/// A measured quantity sampled on a record's time base. Values are in SI units after the
/// reader's scale has been applied.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Channel {
    /// Velocity of the mass [m/s] (laser vibrometer).
    Velocity,
    /// Displacement of the mass \[m\] (interferometer, LVDT, tribometer position).
    Displacement,
    /// Acceleration of the mass [m/s^2] (accelerometer).
    Acceleration,
    /// Friction force \[N\] in the sign convention of Eq. 1 (the force the contact exerts is
    /// `-F`; a force of the opposite convention is read with a negative scale).
    Force,
    /// Normal force of the contact \[N\].
    NormalForce,
    /// The force (a torque on a rotary axis) driving the axis \[N\]: a drive's motor force,
    /// the u of J q'' + c q' + R(q) + F = u.
    InputForce,
}

impl Channel {
    /// Every channel, in the order readers look for them.
    pub const ALL: [Channel; 6] = [
        Channel::Velocity,
        Channel::Displacement,
        Channel::Acceleration,
        Channel::Force,
        Channel::NormalForce,
        Channel::InputForce,
    ];

    /// The channel's name: its configuration key prefix and default column name.
    pub fn name(self) -> &'static str {
        match self {
            Channel::Velocity => "velocity",
            Channel::Displacement => "displacement",
            Channel::Acceleration => "acceleration",
            Channel::Force => "force",
            Channel::NormalForce => "normal_force",
            Channel::InputForce => "input_force",
        }
    }

    /// The SI unit of the channel's values.
    pub fn unit(self) -> &'static str {
        match self {
            Channel::Velocity => "m/s",
            Channel::Displacement => "m",
            Channel::Acceleration => "m/s^2",
            Channel::Force | Channel::NormalForce | Channel::InputForce => "N",
        }
    }

    /// Whether the channel measures the oscillator's response (velocity, displacement,
    /// acceleration), which a simulation predicts.
    pub fn is_response(self) -> bool {
        matches!(
            self,
            Channel::Velocity | Channel::Displacement | Channel::Acceleration
        )
    }

    /// The difference order its noise level is estimated from: the response channels are
    /// smooth between reversals ([`super::noise::RESPONSE_ORDER`]); a force jumps at every
    /// reversal and is judged on first differences.
    pub fn noise_order(self) -> usize {
        if self.is_response() {
            super::noise::RESPONSE_ORDER
        } else {
            1
        }
    }

    /// The channel called `name` ([`Channel::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.name() == name)
    }
}

impl fmt::Display for Channel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The normal force of a record's contact: one value, or one value per sample.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NormalForce {
    /// The same normal force throughout \[N\].
    Constant(f64),
    /// The normal force at each sample of the time base \[N\].
    Sampled(Vec<f64>),
}

impl NormalForce {
    /// The normal force at sample `index` (the last sample's value past the end).
    pub fn at(&self, index: usize) -> f64 {
        match self {
            NormalForce::Constant(n) => *n,
            NormalForce::Sampled(values) => values
                .get(index)
                .or(values.last())
                .copied()
                .unwrap_or(f64::NAN),
        }
    }

    /// The mean normal force \[N\].
    pub fn mean(&self) -> f64 {
        match self {
            NormalForce::Constant(n) => *n,
            NormalForce::Sampled(values) if values.is_empty() => f64::NAN,
            NormalForce::Sampled(values) => values.iter().sum::<f64>() / values.len() as f64,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for c in Channel::ALL {
            assert_eq!(Channel::from_name(c.name()), Some(c));
            assert_eq!(c.to_string(), c.name());
        }
        assert_eq!(Channel::from_name("speed"), None);
    }

    #[test]
    fn normal_force_values() {
        assert_eq!(NormalForce::Constant(14.5).at(99), 14.5);
        let n = NormalForce::Sampled(vec![1.0, 2.0, 6.0]);
        assert_eq!((n.at(1), n.at(7), n.mean()), (2.0, 6.0, 3.0));
        assert!(NormalForce::Sampled(vec![]).mean().is_nan());
    }
}
