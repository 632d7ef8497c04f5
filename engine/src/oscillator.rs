//! The single-degree-of-freedom oscillator of the paper's Eq. (1).

use crate::error::EngineError;
use serde::{Deserialize, Serialize};

/// m x'' + c x' + k x + F_f = 0, with the normal force N acting on the friction contact.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Oscillator {
    /// Mass m [kg] (> 0).
    pub mass: f64,
    /// Viscous damping c [N s/m] (>= 0).
    pub damping: f64,
    /// Stiffness k [N/m] (> 0).
    pub stiffness: f64,
    /// Normal force N [N] (>= 0).
    pub normal_force: f64,
}

/// `[oscillator]` as written: every key optional. A force-domain fit on a measured force
/// needs none of m, c and k, and no normal force when its records carry one; the fits and
/// analyses that need them say so ([`crate::identify::require_mechanics`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OscillatorInput {
    /// Mass m [kg].
    pub mass: Option<f64>,
    /// Viscous damping c [N s/m].
    pub damping: Option<f64>,
    /// Stiffness k [N/m].
    pub stiffness: Option<f64>,
    /// Normal force N [N].
    pub normal_force: Option<f64>,
}

impl OscillatorInput {
    /// The oscillator, with placeholders for the keys not given (m = k = 1, c = N = 0; no
    /// result depends on them), and the names of those keys.
    pub fn resolve(&self) -> (Oscillator, Vec<String>) {
        let mut missing = Vec::new();
        let mut take = |name: &str, value: Option<f64>, placeholder: f64| {
            value.unwrap_or_else(|| {
                missing.push(name.to_string());
                placeholder
            })
        };
        let osc = Oscillator {
            mass: take("mass", self.mass, 1.0),
            damping: take("damping", self.damping, 0.0),
            stiffness: take("stiffness", self.stiffness, 1.0),
            normal_force: take("normal_force", self.normal_force, 0.0),
        };
        (osc, missing)
    }
}

impl Oscillator {
    /// Builds and validates an oscillator.
    pub fn new(
        mass: f64,
        damping: f64,
        stiffness: f64,
        normal_force: f64,
    ) -> Result<Self, EngineError> {
        let o = Self {
            mass,
            damping,
            stiffness,
            normal_force,
        };
        o.validate()?;
        Ok(o)
    }

    /// The paper's FMM flexure stage (m = 10.391 kg, c = 0.275 N s/m, k = 1982 N/m) with the
    /// PTFE pin loaded by N = 14.5 N.
    pub fn fmm() -> Self {
        Self {
            mass: 10.391,
            damping: 0.275,
            stiffness: 1982.0,
            normal_force: 14.5,
        }
    }

    /// Checks that every property is finite, m and k > 0, c and N >= 0.
    pub fn validate(&self) -> Result<(), EngineError> {
        let checks = [
            ("mass", self.mass, true),
            ("damping", self.damping, false),
            ("stiffness", self.stiffness, true),
            ("normal_force", self.normal_force, false),
        ];
        for (name, value, strictly_positive) in checks {
            if !value.is_finite() {
                return Err(EngineError::InvalidOscillator(format!(
                    "`{name}` must be finite, got {value}"
                )));
            }
            if strictly_positive && value <= 0.0 {
                return Err(EngineError::InvalidOscillator(format!(
                    "`{name}` must be > 0, got {value}"
                )));
            }
            if !strictly_positive && value < 0.0 {
                return Err(EngineError::InvalidOscillator(format!(
                    "`{name}` must be >= 0, got {value}"
                )));
            }
        }
        Ok(())
    }

    /// Undamped natural angular frequency sqrt(k/m) [rad/s].
    pub fn omega_n(&self) -> f64 {
        (self.stiffness / self.mass).sqrt()
    }

    /// Undamped natural period T_n = 2 pi / omega_n [s].
    pub fn natural_period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.omega_n()
    }

    /// Viscous damping ratio zeta = c / (2 sqrt(k m)).
    pub fn damping_ratio(&self) -> f64 {
        self.damping / (2.0 * (self.stiffness * self.mass).sqrt())
    }
}
