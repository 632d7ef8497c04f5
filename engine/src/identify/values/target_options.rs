//! What a fit compares: the velocity response or a force along the measured motion, which
//! force, on which samples and along which path (`[fit.options] domain`, `force_target`,
//! `force_offset`, `min_speed`, `replay_path`), and which oscillator properties the config left unknown.

use super::option_keys::option_keys;
use crate::oscillator::OscillatorProperty;
use serde::{Deserialize, Serialize};

/// What a fit compares (`[fit.options] domain`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitDomain {
    /// The simulated free vibration against the measured velocity.
    #[default]
    Velocity,
    /// The model's force along the measured motion against a target force
    /// ([`crate::identify::problem::ForceAlongMotion`]).
    Force,
}

/// The target force of a force-domain fit (`[fit.options] force_target`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ForceTarget {
    /// The measured force channel where a record has one, else the energy-based force.
    #[default]
    Auto,
    /// The measured force channel (an error for a record without one).
    Measured,
    /// The energy-based force of Eq. 7 (needs m, c and k).
    Energy,
    /// Inverse dynamics: the measured input force u against J a + c v + R(q) + F along the
    /// measured motion, with the oscillator properties named in `oscillator` fitted jointly
    /// (the inverse-dynamics identification of drives and robot joints).
    InverseDynamics,
}

/// What a force-domain replay travels between samples (`[fit.options] replay_path`; see
/// [`crate::energy::path_interval`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReplayPath {
    /// The displacement channel's increments where a record has one, else the velocity's.
    #[default]
    Auto,
    /// The displacement channel's increments (an error for a record without one); the
    /// rate-dependent terms read the velocity channel, or the displacement's derivative.
    Displacement,
    /// The velocity channel's: the mean velocity of each interval's ends for its duration.
    Velocity,
}

/// `[fit.options] min_speed` is a speed >= 0 given for a force-domain fit (only it compares
/// samples one by one); the message otherwise. The one place of this rule.
pub fn check_min_speed(min_speed: Option<f64>, domain: FitDomain) -> Result<(), String> {
    let Some(speed) = min_speed else {
        return Ok(());
    };
    if !(speed.is_finite() && speed >= 0.0) {
        return Err(format!(
            "[fit.options] min_speed must be a speed >= 0 (m/s), got {speed}"
        ));
    }
    if domain != FitDomain::Force {
        return Err(
            "[fit.options] min_speed applies to force-domain fits only (domain = \"force\")".into(),
        );
    }
    Ok(())
}

/// What a fit compares (the problem floor's residuals read it).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TargetOptions {
    /// What the fit compares (`domain`).
    pub domain: FitDomain,
    /// The target force of a force-domain fit (`force_target`).
    pub force_target: ForceTarget,
    /// Fit a constant force offset per record (force domain: a measured force or inverse
    /// dynamics; `force_offset`).
    pub force_offset: bool,
    /// Force domain: compare only the samples where the measured motion slides, |v| >=
    /// `min_speed` \[m/s\] (stick phases at reversals hold a force below the sliding level
    /// that a static law cannot follow); `None`: every sample.
    pub min_speed: Option<f64>,
    /// What the replay travels between samples (`replay_path`).
    pub replay_path: ReplayPath,
    /// `[oscillator]` properties that were not given (their values are placeholders): fits
    /// that need them fail with a message naming them. Not a key: the spec fills it from
    /// `[oscillator]`.
    pub unknown_oscillator: Vec<OscillatorProperty>,
}

option_keys!(TargetOptions {
    fit: [],
    options: [
        "domain" => domain,
        "force_target" => force_target,
        "force_offset" => force_offset,
        "min_speed" => min_speed,
        "replay_path" => replay_path,
    ],
});

impl TargetOptions {
    /// Whether the config left the oscillator property unknown.
    pub fn is_unknown(&self, property: OscillatorProperty) -> bool {
        self.unknown_oscillator.contains(&property)
    }
}
