//! Which quantities a fit varies, their bounds and the internal coordinates the solver sees.
//!
//! Strictly positive parameters (lower bound 0 excluded, e.g. sigma0, v_s) are fitted in
//! log coordinates, so that a parameter spanning decades is as well conditioned as a
//! coefficient near 1; all others are divided by a scale (their starting magnitude). Bounds
//! map to bounds of the internal coordinates, which the projected Levenberg-Marquardt keeps.

use super::nuisance::NuisanceKind;
use crate::oscillator::OscillatorProperty;
use serde::Serialize;

/// What a free parameter is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind", content = "index")]
pub enum ParamKind {
    /// The model parameter at this index of `FrictionModel::params`.
    Model(usize),
    /// An oscillator property.
    Property(OscillatorProperty),
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

    /// A start's value projected into the parameter's domain: `p` clipped into the bounds,
    /// or `fallback` (a valid value: the law's default, the fit's own start) clipped where
    /// `p` has no nearest valid value (not finite, or at or below the open lower bound 0 of a
    /// log-coordinate parameter, where any positive value is as near as another).
    pub fn project(&self, p: f64, fallback: f64) -> f64 {
        let lost = !p.is_finite() || (self.log && p <= 0.0);
        self.clip(if lost { fallback } else { p })
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

    /// The bound the physical value `p` sits at: within 1e-6 (relative, at least absolute)
    /// of it in internal coordinates, so that a value a rounding short of its bound (1e12
    /// read back as 999999999999.999) counts as at the bound; a log-coordinate parameter
    /// whose value collapsed to the smallest normal double or below ([`Self::collapsed`])
    /// sits at its lower bound 0.
    pub fn bound_side(&self, p: f64) -> Option<BoundSide> {
        if self.collapsed(p) {
            return Some(BoundSide::Lower);
        }
        let u = self.to_internal(p);
        let (lo, hi) = self.internal_bounds();
        let near = |b: f64| b.is_finite() && (u - b).abs() <= 1e-6 * b.abs().max(1.0);
        if near(lo) {
            Some(BoundSide::Lower)
        } else if near(hi) {
            Some(BoundSide::Upper)
        } else {
            None
        }
    }
}

impl FreeParam {
    /// Whether `p` is a log-coordinate parameter that ran down to its open lower bound 0:
    /// at or below the smallest normal double (where [`Self::to_internal`] clips it), the
    /// value is 0 in all but name.
    pub fn collapsed(&self, p: f64) -> bool {
        self.log && self.lower <= 0.0 && p <= f64::MIN_POSITIVE
    }

    /// The value to report for `p`: its lower bound when it collapsed onto it, else `p`.
    pub fn reported(&self, p: f64) -> f64 {
        if self.collapsed(p) {
            self.lower.max(0.0)
        } else {
            p
        }
    }

    /// The bound on `side`.
    pub fn bound(&self, side: BoundSide) -> f64 {
        match side {
            BoundSide::Lower => self.lower,
            BoundSide::Upper => self.upper,
        }
    }
}

/// Whether a model parameter named `name` in `unit` is a friction level: a coefficient
/// (`mu`, `mu_c`, `mu_s`, ...) that the normal force turns into a force, so that a level at
/// its bound may be a missing normal force. The one place of this rule.
pub(crate) fn is_friction_level(name: &str, unit: &str) -> bool {
    unit == "1" && (name == "mu" || name.starts_with("mu_"))
}

/// Which bound a parameter sits at.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoundSide {
    /// Its lower bound.
    Lower,
    /// Its upper bound.
    Upper,
}

impl BoundSide {
    /// `lower` or `upper`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Lower => "lower",
            Self::Upper => "upper",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A value outside the bounds is clipped to the nearest bound; one with no nearest valid
    /// value (not finite, or not positive in log coordinates) takes the fallback.
    #[test]
    fn a_start_is_projected_into_the_domain() {
        let linear = FreeParam::linear("mu".into(), "1", ParamKind::Model(0), (0.1, 0.5), 0.2, 1.0);
        assert_eq!(linear.project(0.05, 0.3), 0.1);
        assert_eq!(linear.project(0.7, 0.3), 0.5);
        assert_eq!(linear.project(0.25, 0.3), 0.25);
        assert_eq!(linear.project(f64::NAN, 0.3), 0.3);
        let log = FreeParam {
            log: true,
            ..FreeParam::linear(
                "sigma0".into(),
                "N/m",
                ParamKind::Model(0),
                (0.0, 1e9),
                1e5,
                1.0,
            )
        };
        assert_eq!(log.project(-1e5, 1e5), 1e5);
        assert_eq!(log.project(0.0, 1e5), 1e5);
        assert_eq!(log.project(2e9, 1e5), 1e9);
        assert_eq!(log.project(3e4, 1e5), 3e4);
    }

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

    #[test]
    fn a_value_a_rounding_short_of_its_bound_is_at_it() {
        let stiffness = FreeParam {
            log: true,
            ..FreeParam::linear(
                "s".into(),
                "N/m",
                ParamKind::Model(0),
                (0.0, 1e12),
                1e5,
                1.0,
            )
        };
        let read_back = (1e12f64.ln()).exp();
        assert!(read_back < 1e12);
        assert_eq!(stiffness.bound_side(read_back), Some(BoundSide::Upper));
        assert_eq!(stiffness.bound_side(0.99e12), None);
        let mu = FreeParam::linear("mu".into(), "1", ParamKind::Model(0), (0.0, 10.0), 0.3, 1.0);
        assert_eq!(mu.bound_side(0.0), Some(BoundSide::Lower));
        assert_eq!(mu.bound_side(1e-3), None);
    }
}
