//! Coulomb friction with a level that ripples with the position, plus viscous friction: a
//! lead screw, a guide or a motor's cogging that rubs harder at some positions.
//!
//! F = (mu + ripple sin(2 pi x / period + phase)) N sgn(v) + viscous v
//!
//! | parameter | unit | default | bounds | fit | meaning |
//! |---|---|---|---|---|---|
//! | `mu` | 1 | 0.2 | [0, 10] | free | mean Coulomb friction coefficient |
//! | `ripple` | 1 | 0.02 | [0, 10] | free | amplitude of the level's ripple |
//! | `period` | m | 0.01 | (0, inf) | free | period of the ripple along the travel |
//! | `phase` | 1 | 0 | [-7, 7] | free | phase angle of the ripple at x = 0 |
//! | `viscous` | N s/m | 0.5 | [0, inf) | free | viscous friction coefficient |
//!
//! The period is in rad on a rotary axis. The phase may run a little over a turn either way,
//! so that a phase near +-pi is reached from either side. x is the displacement of the record (measured, or its velocity integrated). The period
//! is a nonlinear parameter: start it near the mechanism's own (a screw's lead, a pole pitch,
//! a gear's tooth pitch); the fit then finds it to a fraction of a percent. With `ripple = 0`
//! it is `viscous_coulomb`, which a comparison holds it to.
//!
//! Reference: position-dependent friction of ball-screw and guide axes, e.g. Y. Altintas,
//! A. Verl, C. Brecher, L. Uriarte, G. Pritschow, "Machine tool feed drives", CIRP Annals
//! 60(2), 2011; B. Armstrong-Hélouvry, P. Dupont, C. Canudas de Wit, "A survey of models,
//! analysis tools and compensation methods for the control of machines with friction",
//! Automatica 30(7), 1994 (position dependence).

use crate::conditions::{condition_value, Condition};
use crate::hints::GuessHint;
use crate::model::{sgn, FrictionModel, ParamGradients, Staging, SwitchedLaw};
use crate::start::{StartContext, StribeckLevels};
use std::f64::consts::PI;

crate::declare_params! {
    /// Coulomb friction with a sinusoidal ripple of its level along the travel, with a
    /// viscous term.
    pub struct PositionRipple {
        mu: new("1", 0.2, (0.0, 10.0), "mean Coulomb friction coefficient"),
        ripple: new("1", 0.02, (0.0, 10.0), "amplitude of the level's ripple"),
        period: positive("m", 0.01, f64::INFINITY, "period of the ripple along the travel"),
        phase: new("1", 0.0, (-7.0, 7.0), "phase angle of the ripple at x = 0"),
        viscous: non_negative("N s/m", 0.5, "viscous friction coefficient"),
    }
}

impl PositionRipple {
    /// The ripple's angle at displacement `x`.
    fn angle(&self, x: f64) -> f64 {
        2.0 * PI * x / self.period + self.phase
    }

    /// The force at displacement `x`.
    fn force_at(&self, v: f64, normal: f64, x: f64) -> f64 {
        self.level(normal, x) * sgn(v) + self.viscous * v
    }

    /// The Coulomb level at displacement `x`: (mu + ripple sin(theta)) N.
    fn level(&self, normal: f64, x: f64) -> f64 {
        (self.mu + self.ripple * self.angle(x).sin()) * normal
    }
}

#[typetag::serde(name = "position_ripple")]
impl FrictionModel for PositionRipple {
    crate::declared_param_methods!(
        name: "position_ripple",
        equation: "F = (mu + ripple sin(2 pi x / period + phase)) N sgn(v) + viscous v",
    );
    /// The force at x = 0.
    fn force(&self, v: f64, _z: &[f64], normal: f64) -> f64 {
        self.force_at(v, normal, 0.0)
    }
    fn conditions(&self) -> Vec<Condition> {
        vec![Condition::Displacement]
    }
    fn force_in(&self, v: f64, _z: &[f64], normal: f64, at: &[f64]) -> f64 {
        self.force_at(v, normal, condition_value(at, 0))
    }
    crate::law_groups!(switching, staging, param_gradients);
    /// A ripple larger than the mean level makes the level negative at some positions: the
    /// friction would push along the motion there.
    fn validate(&self) -> Result<Vec<String>, crate::error::ModelError> {
        if self.ripple > self.mu {
            return Ok(vec![format!(
                "position_ripple: ripple {} exceeds mu {}: the friction level turns negative \
                 at some positions",
                self.ripple, self.mu
            )]);
        }
        Ok(Vec::new())
    }
}

impl ParamGradients for PositionRipple {
    // The gradient at x = 0.
    crate::at_no_conditions!(param_gradients);
    /// With s = N sgn(v) and theta the ripple's angle: dF/dmu = s, dF/dripple = s sin(theta),
    /// dF/dperiod = -ripple s cos(theta) 2 pi x / period^2, dF/dphase = ripple s cos(theta),
    /// dF/dviscous = v.
    fn force_param_gradient_in(
        &self,
        v: f64,
        _z: &[f64],
        normal: f64,
        at: &[f64],
        out: &mut [f64],
    ) {
        let x = condition_value(at, 0);
        let s = normal * sgn(v);
        let (sin, cos) = self.angle(x).sin_cos();
        let d_phase = self.ripple * s * cos;
        let d_period = -d_phase * 2.0 * PI * x / (self.period * self.period);
        for (o, d) in out.iter_mut().zip([s, s * sin, d_period, d_phase, v]) {
            *o = d;
        }
    }
}

/// A simulation sticks the axis while the force it holds is within the level at the current
/// position (never below 0: a ripple larger than the mean level holds nothing there), and
/// slips at that level in the slip direction.
impl SwitchedLaw for PositionRipple {
    crate::at_no_conditions!(switching);
    fn static_limit_in(&self, normal: f64, at: &[f64]) -> Option<f64> {
        Some(self.level(normal, condition_value(at, 0)).max(0.0))
    }
    fn slip_force_in(&self, v: f64, direction: f64, normal: f64, at: &[f64]) -> f64 {
        direction * self.level(normal, condition_value(at, 0)) + self.viscous * v
    }
}

impl Staging for PositionRipple {
    fn apply_guess(&mut self, hint: &GuessHint) {
        self.mu = 0.9 * hint.mu;
        self.ripple = 0.1 * hint.mu;
        self.viscous = 0.1 * hint.mu * hint.normal_force / hint.typical_velocity.max(1e-6);
    }
    /// The ripple-free law's level and viscous term, no ripple (its period and phase kept):
    /// exactly the fitted `coulomb` or `viscous_coulomb`.
    fn start_from(&mut self, fitted: &dyn FrictionModel, _ctx: &StartContext) -> bool {
        let Some((mu, viscous)) = StribeckLevels::of_coulomb_law(fitted) else {
            return false;
        };
        (self.mu, self.ripple, self.viscous) = (mu, 0.0, viscous);
        true
    }
}
