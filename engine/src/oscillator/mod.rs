//! The single-degree-of-freedom oscillator of the paper's Eq. (1), generalised to any axis:
//! J q'' + c q' + R(q) + F_f = u(t).

mod property;

pub use property::{OscillatorProperty, PropertyDomain};

use crate::axis::{Axis, Restoring};
use crate::error::EngineError;
use serde::{Deserialize, Serialize};

/// m x'' + c x' + R(x) + F_f = u, with the normal force N acting on the friction contact;
/// R is the axis's restoring law (the linear spring k x by default) and u the input (none in
/// free vibration). On a rotary axis x is an angle, m a moment of inertia and the forces are
/// torques (see [`Axis`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Oscillator {
    /// Mass m [kg] (> 0); on a rotary axis the moment of inertia J [kg m^2].
    pub mass: f64,
    /// Viscous damping c [N s/m] (>= 0).
    pub damping: f64,
    /// Stiffness k [N/m] (> 0 where the restoring law reads it).
    pub stiffness: f64,
    /// Normal force N [N] (>= 0).
    pub normal_force: f64,
    /// Linear (the default) or rotary.
    #[serde(default, skip_serializing_if = "Axis::is_linear")]
    pub axis: Axis,
    /// The restoring law R (the linear spring k x by default).
    #[serde(default, skip_serializing_if = "Restoring::is_linear_spring")]
    pub restoring: Restoring,
    /// The input's offset F_0 [N or N m]: a constant force (torque) in the balance
    /// J q'' + c q' + R(q) + F_f + F_0 = u, the "offset" of a drive's inverse-dynamics
    /// identification (u = J a + F_f(v) + offset), or gravity along an inclined axis. It acts
    /// with or without an input; 0 by default.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub input_offset: f64,
}

fn is_zero(value: &f64) -> bool {
    *value == 0.0
}

/// The oscillator's m, c, k and N as given: any of them may be absent. A force-domain fit on
/// a measured force needs none of m, c and k, and no normal force when its records carry
/// one; the fits and analyses that need them say so ([`crate::identify::require_mechanics`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartialOscillator {
    /// Mass m [kg].
    pub mass: Option<f64>,
    /// Viscous damping c [N s/m].
    pub damping: Option<f64>,
    /// Stiffness k [N/m].
    pub stiffness: Option<f64>,
    /// Normal force N [N].
    pub normal_force: Option<f64>,
}

impl PartialOscillator {
    /// The oscillator, with placeholders for the properties not given (m = k = 1, c = N = 0;
    /// no result depends on them), and those properties.
    pub fn resolve(&self) -> (Oscillator, Vec<OscillatorProperty>) {
        let mut missing = Vec::new();
        let mut take = |property: OscillatorProperty, value: Option<f64>, placeholder: f64| {
            value.unwrap_or_else(|| {
                missing.push(property);
                placeholder
            })
        };
        let osc = Oscillator {
            mass: take(OscillatorProperty::Mass, self.mass, 1.0),
            damping: take(OscillatorProperty::Damping, self.damping, 0.0),
            stiffness: take(OscillatorProperty::Stiffness, self.stiffness, 1.0),
            normal_force: take(OscillatorProperty::NormalForce, self.normal_force, 0.0),
            axis: Axis::Linear,
            restoring: Restoring::default(),
            input_offset: 0.0,
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
            axis: Axis::Linear,
            restoring: Restoring::default(),
            input_offset: 0.0,
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
            axis: Axis::Linear,
            restoring: Restoring::default(),
            input_offset: 0.0,
        }
    }

    /// The same oscillator on `axis`.
    pub fn with_axis(self, axis: Axis) -> Self {
        Self { axis, ..self }
    }

    /// The same oscillator with the restoring law `restoring`.
    pub fn with_restoring(self, restoring: Restoring) -> Self {
        Self { restoring, ..self }
    }

    /// Checks that every property is finite, m > 0 (and k > 0 where the restoring law reads
    /// it), c and N >= 0, and the restoring law's own parameters.
    pub fn validate(&self) -> Result<(), EngineError> {
        let checks = self.sign_checks();
        if !self.input_offset.is_finite() {
            return Err(EngineError::InvalidOscillator(format!(
                "`input_offset` must be finite, got {}",
                self.input_offset
            )));
        }
        self.restoring
            .check()
            .map_err(|e| EngineError::InvalidOscillator(e.to_string()))?;
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

    /// The name, value and whether it must be > 0 (else >= 0) of m, c, k and N: m > 0, k > 0
    /// where the restoring law reads it ([`OscillatorProperty::domain`]).
    fn sign_checks(&self) -> [(&'static str, f64, bool); 4] {
        let law = self.restoring.law();
        [
            OscillatorProperty::Mass,
            OscillatorProperty::Damping,
            OscillatorProperty::Stiffness,
            OscillatorProperty::NormalForce,
        ]
        .map(|p| {
            let positive = p.domain() == PropertyDomain::Positive
                && (p != OscillatorProperty::Stiffness || law.reads_stiffness());
            let value = p.value(self).unwrap_or(f64::NAN);
            (p.name_on(self.axis), value, positive)
        })
    }

    /// The restoring force (torque) R(q) [N or N m].
    #[inline]
    pub fn restoring_force(&self, q: f64) -> f64 {
        self.restoring.law().force(q, self.stiffness)
    }

    /// The restoring law's stiffness dR/dq at q [N/m or N m/rad].
    #[inline]
    pub fn restoring_stiffness(&self, q: f64) -> f64 {
        self.restoring.law().stiffness(q, self.stiffness)
    }

    /// The potential energy V(q) of the restoring law (V(0) = 0) [J].
    #[inline]
    pub fn potential(&self, q: f64) -> f64 {
        self.restoring.law().potential(q, self.stiffness)
    }

    /// The stiffness of small motions about q = 0, dR/dq(0): k for the spring, the gravity
    /// moment for the pendulum, 0 without a restoring law.
    pub fn small_motion_stiffness(&self) -> f64 {
        self.restoring_stiffness(0.0)
    }

    /// Whether the axis has a restoring law (without one the position enters no equation,
    /// and a release displacement means nothing).
    pub fn has_restoring_force(&self) -> bool {
        !matches!(self.restoring, Restoring::None(_))
    }

    /// Whether R(q) is exactly k q (the closed-form propagator applies).
    pub fn has_linear_spring(&self) -> bool {
        self.restoring.law().is_linear_spring()
    }

    /// Undamped natural angular frequency of small motions sqrt(R'(0)/m) [rad/s] (0 without
    /// a restoring law).
    pub fn omega_n(&self) -> f64 {
        (self.small_motion_stiffness() / self.mass).sqrt()
    }

    /// Undamped natural period of small motions T_n = 2 pi / omega_n [s]; infinite without
    /// a restoring law (see [`Oscillator::period`]).
    pub fn natural_period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.omega_n()
    }

    /// The natural period of small motions, if the axis has one (not without a restoring
    /// force, nor about an unstable equilibrium).
    pub fn period(&self) -> Option<f64> {
        let t = self.natural_period();
        (t.is_finite() && t > 0.0).then_some(t)
    }

    /// Viscous damping ratio of small motions zeta = c / (2 sqrt(R'(0) m)).
    pub fn damping_ratio(&self) -> f64 {
        self.damping / (2.0 * (self.small_motion_stiffness() * self.mass).sqrt())
    }
}
