//! Which quantities a fit varies, their bounds and the internal coordinates the solver sees.
//!
//! Strictly positive parameters (lower bound 0 excluded, e.g. sigma0, v_s) are fitted in
//! log coordinates, so that a parameter spanning decades is as well conditioned as a
//! coefficient near 1; all others are divided by a scale (their starting magnitude). Bounds
//! map to bounds of the internal coordinates, which the projected Levenberg-Marquardt keeps.

use super::residuals::NuisanceKind;
use serde::Serialize;

/// What a free parameter is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind", content = "index")]
pub enum ParamKind {
    /// The model parameter at this index of `FrictionModel::params`.
    Model(usize),
    /// The oscillator mass.
    Mass,
    /// The oscillator damping.
    Damping,
    /// The oscillator stiffness.
    Stiffness,
    /// A nuisance parameter of one record.
    Nuisance {
        /// What it is.
        kind: NuisanceKind,
        /// The record's index.
        record: usize,
    },
}

/// One free parameter of a fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FreeParam {
    /// Display name (e.g. `mu`, `mass`, `offset[x14mm.csv]`).
    pub name: String,
    /// Unit.
    pub unit: String,
    /// What it is.
    pub kind: ParamKind,
    /// Lower bound (physical).
    pub lower: f64,
    /// Upper bound (physical).
    pub upper: f64,
    /// Fitted in log coordinates.
    pub log: bool,
    /// Scale of the linear coordinate.
    pub scale: f64,
}

impl FreeParam {
    /// A linear-coordinate parameter with a scale taken from its start value.
    pub fn linear(
        name: String,
        unit: &str,
        kind: ParamKind,
        bounds: (f64, f64),
        start: f64,
        typical: f64,
    ) -> Self {
        let scale = if start.abs() > 0.0 {
            start.abs()
        } else {
            typical
        };
        Self {
            name,
            unit: unit.to_string(),
            kind,
            lower: bounds.0,
            upper: bounds.1,
            log: false,
            scale,
        }
    }

    /// Physical value to internal coordinate.
    pub fn to_internal(&self, p: f64) -> f64 {
        if self.log {
            p.max(f64::MIN_POSITIVE).ln()
        } else {
            p / self.scale
        }
    }

    /// Internal coordinate to physical value.
    pub fn to_physical(&self, u: f64) -> f64 {
        if self.log {
            u.exp()
        } else {
            u * self.scale
        }
    }

    /// d(internal)/d(physical) at the physical value `p`.
    pub fn internal_derivative(&self, p: f64) -> f64 {
        if self.log {
            1.0 / p
        } else {
            1.0 / self.scale
        }
    }

    /// A physical value clipped into the bounds (strictly positive for log coordinates).
    pub fn clip(&self, p: f64) -> f64 {
        let lo = if self.log {
            self.lower.max(f64::MIN_POSITIVE)
        } else {
            self.lower
        };
        p.clamp(lo, self.upper)
    }

    /// The bounds in internal coordinates.
    pub fn internal_bounds(&self) -> (f64, f64) {
        if self.log {
            let lo = if self.lower > 0.0 {
                self.lower.ln()
            } else {
                f64::NEG_INFINITY
            };
            let hi = if self.upper.is_finite() {
                self.upper.ln()
            } else {
                f64::INFINITY
            };
            (lo, hi)
        } else {
            (self.lower / self.scale, self.upper / self.scale)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coordinates_round_trip() {
        let lin = FreeParam::linear("mu".into(), "1", ParamKind::Model(0), (0.0, 10.0), 0.3, 1.0);
        for p in [0.0, 0.24, 7.5] {
            assert!((lin.to_physical(lin.to_internal(p)) - p).abs() < 1e-15);
        }
        assert_eq!(lin.internal_bounds(), (0.0, 10.0 / 0.3));
        let log = FreeParam {
            log: true,
            ..lin.clone()
        };
        for p in [1e-3, 1.0, 1e5] {
            assert!((log.to_physical(log.to_internal(p)) / p - 1.0).abs() < 1e-14);
            // chain rule: d ln p / dp = 1/p
            assert!((log.internal_derivative(p) * p - 1.0).abs() < 1e-15);
        }
        assert_eq!(log.internal_bounds().0, f64::NEG_INFINITY);
    }
}
