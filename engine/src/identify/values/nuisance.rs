//! The per-record nuisance parameters a residual producer adds to a fit (a velocity offset,
//! a release-time shift, the release displacement, a force offset) and their values.

use crate::oscillator::{Oscillator, OscillatorProperty};
use crate::record::Record;
use serde::{Deserialize, Serialize};

/// A per-record parameter that is not part of the friction law or the oscillator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NuisanceKind {
    /// A constant added to the predicted velocity (an instrument's DC offset) [m/s].
    VelocityOffset,
    /// The release instant relative to the record's release time (its first time stamp unless
    /// it was cut at a release found or given between samples) [s].
    ReleaseShift,
    /// The displacement at release [m], when the record's x0 is known only approximately.
    StartDisplacement,
    /// A constant added to the predicted force (a load cell's zero) \[N\].
    ForceOffset,
}

impl NuisanceKind {
    /// The key of its bounds in `FitOptions::bounds` and the prefix of its reported name
    /// (`offset[x14mm.csv]`).
    pub fn key(self) -> &'static str {
        match self {
            Self::VelocityOffset => "offset",
            Self::ReleaseShift => "shift",
            Self::StartDisplacement => "x0",
            Self::ForceOffset => "force_offset",
        }
    }

    /// Its unit written for a linear axis ([`crate::Axis::unit`] gives the rotary one).
    pub fn unit(self) -> &'static str {
        match self {
            Self::VelocityOffset => "m/s",
            Self::ReleaseShift => "s",
            Self::StartDisplacement => "m",
            Self::ForceOffset => "N",
        }
    }

    /// The scale of its internal coordinate when its start value is 0.
    pub fn typical(self) -> f64 {
        match self {
            Self::VelocityOffset => 1e-4,
            Self::ReleaseShift => 1e-3,
            Self::StartDisplacement => 1e-3,
            Self::ForceOffset => 1e-2,
        }
    }

    /// Bounds when the options give none: no bound for an offset; a quarter of the natural
    /// period either way for a release shift (a later release is the next turning point's
    /// business); x0 within 20 % of the record's value.
    pub fn default_bounds(self, record: &Record, osc: &Oscillator) -> (f64, f64) {
        match self {
            Self::VelocityOffset | Self::ForceOffset => (f64::NEG_INFINITY, f64::INFINITY),
            Self::ReleaseShift => {
                let quarter = 0.5 * std::f64::consts::PI / osc.omega_n();
                (-quarter, quarter)
            }
            Self::StartDisplacement => {
                let half_width = X0_RELATIVE_BOUND * record.x0.abs();
                (record.x0 - half_width, record.x0 + half_width)
            }
        }
    }

    /// The value a fit starts from (before clipping to the bounds): 0, or the record's x0.
    pub fn start(self, record: &Record) -> f64 {
        match self {
            Self::VelocityOffset | Self::ReleaseShift | Self::ForceOffset => 0.0,
            Self::StartDisplacement => record.x0,
        }
    }

    /// Every kind, in the order a record's nuisance parameters are laid out.
    pub const ALL: [NuisanceKind; 4] = [
        Self::VelocityOffset,
        Self::ReleaseShift,
        Self::StartDisplacement,
        Self::ForceOffset,
    ];
}

/// Default half-width of the bounds of a fitted x0, relative to the record's value.
pub const X0_RELATIVE_BOUND: f64 = 0.2;

/// The nuisance values of one record (0, or the record's own x0, for those not fitted).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct NuisanceValues {
    /// Velocity offset [m/s].
    pub offset: f64,
    /// Release-time shift [s].
    pub shift: f64,
    /// Fitted displacement at release [m] (`None`: the record's x0).
    pub x0: Option<f64>,
    /// Force offset \[N\].
    pub force_offset: f64,
}

impl NuisanceValues {
    /// The value of `kind` (`None` for an x0 that is not fitted).
    pub fn get(&self, kind: NuisanceKind) -> Option<f64> {
        match kind {
            NuisanceKind::VelocityOffset => Some(self.offset),
            NuisanceKind::ReleaseShift => Some(self.shift),
            NuisanceKind::StartDisplacement => self.x0,
            NuisanceKind::ForceOffset => Some(self.force_offset),
        }
    }

    /// Sets the value of `kind`.
    pub fn set(&mut self, kind: NuisanceKind, value: f64) {
        match kind {
            NuisanceKind::VelocityOffset => self.offset = value,
            NuisanceKind::ReleaseShift => self.shift = value,
            NuisanceKind::StartDisplacement => self.x0 = Some(value),
            NuisanceKind::ForceOffset => self.force_offset = value,
        }
    }

    /// The release displacement of `record` with these values.
    pub fn x0_of(&self, record: &Record) -> f64 {
        self.x0.unwrap_or(record.x0)
    }
}

/// Bound keys that are not model parameters: the oscillator properties a fit may vary (the
/// mass under either of its names), then every nuisance parameter's key.
pub fn non_model_bound_keys() -> Vec<&'static str> {
    let mut keys: Vec<&'static str> = OscillatorProperty::bound_keys().collect();
    keys.extend(NuisanceKind::ALL.map(NuisanceKind::key));
    keys
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default bounds: a quarter of the natural period 2 pi sqrt(m/k) for a shift, 20 %
    /// of the stated x0 for x0.
    #[test]
    fn default_nuisance_bounds_come_from_the_record_and_the_oscillator() {
        let osc = Oscillator::fmm();
        let record = Record::new("r", vec![0.0, 1e-3], vec![0.0, 0.0], -0.014);
        let quarter = 0.25 * 2.0 * std::f64::consts::PI * (osc.mass / osc.stiffness).sqrt();
        let (lo, hi) = NuisanceKind::ReleaseShift.default_bounds(&record, &osc);
        assert!((hi - quarter).abs() < 1e-12 && (lo + quarter).abs() < 1e-12);
        let (lo, hi) = NuisanceKind::StartDisplacement.default_bounds(&record, &osc);
        assert!((lo + 0.0168).abs() < 1e-12 && (hi + 0.0112).abs() < 1e-12);
        assert_eq!(NuisanceKind::StartDisplacement.start(&record), -0.014);
    }
}
