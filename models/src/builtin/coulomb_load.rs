//! Coulomb friction whose level grows with the load the contact transmits, plus viscous
//! friction: the friction of a gearbox (strain-wave, cycloid, planetary) under torque.
//!
//! F = (mu N + mu_load |load|) sgn(v) + viscous v
//!
//! | parameter | unit | default | bounds | fit | meaning |
//! |---|---|---|---|---|---|
//! | `mu` | 1 | 0.2 | [0, 10] | free | Coulomb friction coefficient without load |
//! | `mu_load` | 1 | 0.05 | [0, 10] | free | growth of the Coulomb level per unit of load magnitude |
//! | `viscous` | N s/m | 0.5 | [0, inf) | free | viscous friction coefficient |
//!
//! `mu` is multiplied by N like every friction coefficient: without a normal force (N = 1)
//! it is the unloaded level Tc itself, in N (N m on a rotary axis). `load` is the record's
//! named channel of that name (`[[records]] channels = { load =
//! "Load torque [N m]" }`), a force or torque in the unit of the friction force. With
//! `mu_load = 0` it is `viscous_coulomb`, which a comparison holds it to.
//!
//! Reference: the load-dependent Coulomb friction of gear transmissions, e.g. M. Hamon,
//! M. Gautier, P. Garrec, "New dry friction model with load- and velocity-dependence and
//! dynamic identification of multi-DOF robots", IEEE ICRA 2011; N. Kircanski, A. Goldenberg,
//! "An experimental study of nonlinear stiffness, hysteresis, and friction effects in robot
//! joints with harmonic drives and torque sensors", IJRR 16(2), 1997.

use crate::conditions::{condition_value, Condition};
use crate::hints::GuessHint;
use crate::model::{sgn, FrictionModel, ParamGradients, Staging, SwitchedLaw};
use crate::start::{StartContext, StribeckLevels};

/// The named channel the law reads.
pub const LOAD_CHANNEL: &str = "load";

crate::declare_params! {
    /// Coulomb friction growing with the transmitted load, with a viscous term.
    pub struct CoulombLoad {
        mu: new("1", 0.2, (0.0, 10.0), "Coulomb friction coefficient without load"),
        mu_load: new("1", 0.05, (0.0, 10.0), "growth of the Coulomb level per unit of load magnitude"),
        viscous: non_negative("N s/m", 0.5, "viscous friction coefficient"),
    }
}

impl CoulombLoad {
    /// The force at load `load`.
    fn force_at(&self, v: f64, normal: f64, load: f64) -> f64 {
        self.level(normal, load) * sgn(v) + self.viscous * v
    }

    /// The Coulomb level at load `load`: mu N + mu_load |load|.
    fn level(&self, normal: f64, load: f64) -> f64 {
        self.mu * normal + self.mu_load * load.abs()
    }
}

#[typetag::serde(name = "coulomb_load")]
impl FrictionModel for CoulombLoad {
    crate::declared_param_methods!(
        name: "coulomb_load",
        equation: "F = (mu N + mu_load |load|) sgn(v) + viscous v",
    );
    /// The force without load.
    fn force(&self, v: f64, _z: &[f64], normal: f64) -> f64 {
        self.force_at(v, normal, 0.0)
    }
    fn conditions(&self) -> Vec<Condition> {
        vec![Condition::Channel(LOAD_CHANNEL.into())]
    }
    fn force_in(&self, v: f64, _z: &[f64], normal: f64, at: &[f64]) -> f64 {
        self.force_at(v, normal, condition_value(at, 0))
    }
    crate::law_groups!(switching, staging, param_gradients);
}

impl ParamGradients for CoulombLoad {
    // Without load: dF/dmu = N sgn(v), dF/dmu_load = 0, dF/dviscous = v.
    crate::at_no_conditions!(param_gradients);
    /// dF/dmu = N sgn(v), dF/dmu_load = |load| sgn(v), dF/dviscous = v.
    fn force_param_gradient_in(
        &self,
        v: f64,
        _z: &[f64],
        normal: f64,
        at: &[f64],
        out: &mut [f64],
    ) {
        let load = condition_value(at, 0).abs();
        for (o, d) in out.iter_mut().zip([normal * sgn(v), load * sgn(v), v]) {
            *o = d;
        }
    }
}

/// A simulation sticks the joint while the force it holds is within the level at the current
/// load, and slips at that level in the slip direction.
impl SwitchedLaw for CoulombLoad {
    crate::at_no_conditions!(switching);
    fn static_limit_in(&self, normal: f64, at: &[f64]) -> Option<f64> {
        Some(self.level(normal, condition_value(at, 0)))
    }
    fn slip_force_in(&self, v: f64, direction: f64, normal: f64, at: &[f64]) -> f64 {
        direction * self.level(normal, condition_value(at, 0)) + self.viscous * v
    }
}

impl Staging for CoulombLoad {
    fn apply_guess(&mut self, hint: &GuessHint) {
        self.mu = 0.9 * hint.mu;
        self.mu_load = 0.0;
        self.viscous = 0.1 * hint.mu * hint.normal_force / hint.typical_velocity.max(1e-6);
    }
    /// The load-free law's level and viscous term, no load dependence: exactly the fitted
    /// `coulomb` or `viscous_coulomb`.
    fn start_from(&mut self, fitted: &dyn FrictionModel, _ctx: &StartContext) -> bool {
        let Some((mu, viscous)) = StribeckLevels::of_coulomb_law(fitted) else {
            return false;
        };
        (self.mu, self.mu_load, self.viscous) = (mu, 0.0, viscous);
        true
    }
}
