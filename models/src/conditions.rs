//! What a law may read at each instant besides the sliding speed, the normal force and its
//! own states: the displacement, the acceleration, the input force and named record channels
//! (a load torque, a temperature).
//!
//! A law names what it reads once ([`FrictionModel::conditions`](crate::FrictionModel::conditions));
//! the engine then hands it the values of those conditions, in that order, at every instant
//! ([`FrictionModel::force_in`](crate::FrictionModel::force_in)). A law that reads nothing
//! keeps its `force` and never sees this module.

use std::fmt;

/// One quantity besides v, N and the states that a law may read at each instant.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Condition {
    /// The displacement x of the axis \[m\] (an angle in rad on a rotary axis), relative to
    /// the equilibrium of the record.
    Displacement,
    /// The acceleration a of the axis [m/s^2] (rad/s^2).
    Acceleration,
    /// The input force u driving the axis \[N\] (a torque in N m).
    InputForce,
    /// A named channel of the record (`[[records]] channels = { load = "..." }`), in the SI
    /// unit its scale gives it.
    Channel(String),
}

impl Condition {
    /// The name a formula and a message use: `x`, `a`, `u`, or the channel's own name.
    pub fn name(&self) -> &str {
        match self {
            Condition::Displacement => "x",
            Condition::Acceleration => "a",
            Condition::InputForce => "u",
            Condition::Channel(name) => name,
        }
    }

    /// The condition a formula calls `name`: `x`, `a` and `u` are the motion's, any other
    /// name a record channel.
    pub fn from_name(name: &str) -> Self {
        match name {
            "x" => Condition::Displacement,
            "a" => Condition::Acceleration,
            "u" => Condition::InputForce,
            other => Condition::Channel(other.to_string()),
        }
    }

    /// Whether a simulation of the motion gives this condition itself (x and a from its
    /// states); the others come from the record's samples.
    pub fn follows_motion(&self) -> bool {
        matches!(self, Condition::Displacement | Condition::Acceleration)
    }
}

impl fmt::Display for Condition {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The value of condition `k` of `at` (as ordered by the law's `conditions`), 0 where the
/// caller gave fewer values: a law's `force` is its `force_in` at every condition 0.
#[inline]
pub fn condition_value(at: &[f64], k: usize) -> f64 {
    at.get(k).copied().unwrap_or(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for c in [
            Condition::Displacement,
            Condition::Acceleration,
            Condition::InputForce,
            Condition::Channel("load".into()),
        ] {
            assert_eq!(Condition::from_name(c.name()), c);
            assert_eq!(c.to_string(), c.name());
        }
        assert!(Condition::Displacement.follows_motion());
        assert!(!Condition::Channel("temperature".into()).follows_motion());
        assert_eq!(condition_value(&[2.0], 1), 0.0);
    }
}
