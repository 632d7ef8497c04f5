//! Coulomb friction with a level per sliding direction, plus viscous friction.
//!
//! F = N mu_pos (v > 0), -N mu_neg (v < 0); + viscous v
//!
//! | parameter | unit | default | bounds | fit | meaning |
//! |---|---|---|---|---|---|
//! | `mu_pos` | 1 | 0.2 | [0, 10] | free | Coulomb friction coefficient sliding in +v |
//! | `mu_neg` | 1 | 0.2 | [0, 10] | free | Coulomb friction coefficient sliding in -v |
//! | `viscous` | N s/m | 0.5 | [0, inf) | free | viscous friction coefficient |
//!
//! With `mu_pos = mu_neg` it is `viscous_coulomb`, with `viscous = 0` `coulomb_asymmetric`.
//!
//! Reference: the direction-dependent static + viscous model of drive and robot-joint
//! identification, e.g. W. Khalil, E. Dombre, *Modeling, Identification and Control of
//! Robots* (2002), section 12.4; B. Armstrong-Hélouvry, P. Dupont, C. Canudas de Wit,
//! Automatica 30(7), 1994.

use super::coulomb_asymmetric::{directed_level, param_named, symmetric_level, take_if_reproduces};
use crate::hints::GuessHint;
use crate::model::{FrictionModel, ParamGradients, Staging, SwitchedLaw};
use crate::start::StartContext;

crate::declare_params! {
    /// Direction-dependent Coulomb friction with a viscous term.
    pub struct ViscousCoulombAsymmetric {
        mu_pos: new("1", 0.2, (0.0, 10.0), "Coulomb friction coefficient sliding in +v"),
        mu_neg: new("1", 0.2, (0.0, 10.0), "Coulomb friction coefficient sliding in -v"),
        viscous: non_negative("N s/m", 0.5, "viscous friction coefficient"),
    }
}

#[typetag::serde(name = "viscous_coulomb_asymmetric")]
impl FrictionModel for ViscousCoulombAsymmetric {
    crate::declared_param_methods!(
        name: "viscous_coulomb_asymmetric",
        equation: "F = N mu_pos (v > 0), -N mu_neg (v < 0); + viscous v",
    );
    fn force(&self, v: f64, _z: &[f64], normal: f64) -> f64 {
        normal * directed_level(self.mu_pos, self.mu_neg, v) + self.viscous * v
    }
    crate::law_groups!(switching, staging, param_gradients);
}

impl ParamGradients for ViscousCoulombAsymmetric {
    /// dF/dmu_pos = N (v > 0), dF/dmu_neg = -N (v < 0), dF/dviscous = v.
    fn force_param_gradient(&self, v: f64, _z: &[f64], normal: f64, out: &mut [f64]) {
        let pos = if v > 0.0 { normal } else { 0.0 };
        let neg = if v < 0.0 { -normal } else { 0.0 };
        for (o, d) in out.iter_mut().zip([pos, neg, v]) {
            *o = d;
        }
    }
}

impl SwitchedLaw for ViscousCoulombAsymmetric {
    fn static_limit(&self, normal: f64) -> Option<f64> {
        Some(0.5 * (self.mu_pos + self.mu_neg) * normal)
    }
    fn static_offset(&self, normal: f64) -> f64 {
        0.5 * (self.mu_pos - self.mu_neg) * normal
    }
    fn slip_force(&self, v: f64, direction: f64, normal: f64) -> f64 {
        normal * directed_level(self.mu_pos, self.mu_neg, direction) + self.viscous * v
    }
    fn affine_slip(&self, direction: f64, normal: f64) -> Option<(f64, f64)> {
        Some((
            normal * directed_level(self.mu_pos, self.mu_neg, direction),
            self.viscous,
        ))
    }
}

impl Staging for ViscousCoulombAsymmetric {
    fn apply_guess(&mut self, hint: &GuessHint) {
        self.mu_pos = 0.9 * hint.mu;
        self.mu_neg = 0.9 * hint.mu;
        self.viscous = 0.1 * hint.mu * hint.normal_force / hint.typical_velocity.max(1e-6);
    }
    /// From a fitted symmetric law (both levels at its level, its viscous term) or from
    /// `coulomb_asymmetric` (its levels, no viscous term), where that reproduces its curve.
    fn start_from(&mut self, fitted: &dyn FrictionModel, ctx: &StartContext) -> bool {
        let normal = ctx.normal_force;
        let read = |name: &str| param_named(fitted, name);
        let mut trial = self.clone();
        trial.viscous = read("viscous").unwrap_or(0.0);
        match (read("mu_pos"), read("mu_neg")) {
            (Some(p), Some(n)) => (trial.mu_pos, trial.mu_neg) = (p, n),
            _ => {
                let Some(level) = symmetric_level(fitted, normal) else {
                    return false;
                };
                (trial.mu_pos, trial.mu_neg) = (level, level);
            }
        }
        take_if_reproduces(self, trial, fitted, normal)
    }
}
