//! Coulomb plus viscous friction.
//!
//! F = mu N sgn(v) + viscous v
//!
//! | parameter | unit | default | bounds | fit | meaning |
//! |---|---|---|---|---|---|
//! | `mu` | 1 | 0.2 | [0, 10] | free | Coulomb friction coefficient |
//! | `viscous` | N s/m | 0.5 | [0, inf) | free | viscous friction coefficient |
//!
//! Reference: the classical static + viscous friction law, e.g. B. Armstrong-Hélouvry,
//! P. Dupont, C. Canudas de Wit, "A survey of models, analysis tools and compensation methods
//! for the control of machines with friction", Automatica 30(7), 1994.

use crate::hints::GuessHint;
use crate::model::{sgn, FrictionModel, ParamGradients, Staging, SwitchedLaw};

crate::declare_params! {
    /// Coulomb friction with a viscous term proportional to the sliding velocity.
    pub struct ViscousCoulomb {
        mu: new("1", 0.2, (0.0, 10.0), "Coulomb friction coefficient"),
        viscous: non_negative("N s/m", 0.5, "viscous friction coefficient"),
    }
}

#[typetag::serde(name = "viscous_coulomb")]
impl FrictionModel for ViscousCoulomb {
    crate::declared_param_methods!(
        name: "viscous_coulomb",
        equation: "F = mu N sgn(v) + viscous v",
    );
    fn force(&self, v: f64, _z: &[f64], normal: f64) -> f64 {
        self.mu * normal * sgn(v) + self.viscous * v
    }
    crate::law_groups!(switching, staging, param_gradients);
}

impl ParamGradients for ViscousCoulomb {
    /// dF/dmu = N sgn(v), dF/dviscous = v.
    fn force_param_gradient(&self, v: f64, _z: &[f64], normal: f64, out: &mut [f64]) {
        for (o, d) in out.iter_mut().zip([normal * sgn(v), v]) {
            *o = d;
        }
    }
}

impl SwitchedLaw for ViscousCoulomb {
    fn static_limit(&self, normal: f64) -> Option<f64> {
        Some(self.mu * normal)
    }
    fn slip_force(&self, v: f64, direction: f64, normal: f64) -> f64 {
        self.mu * normal * direction + self.viscous * v
    }
    fn affine_slip(&self, direction: f64, normal: f64) -> Option<(f64, f64)> {
        Some((self.mu * normal * direction, self.viscous))
    }
}

impl Staging for ViscousCoulomb {
    fn apply_guess(&mut self, hint: &GuessHint) {
        self.mu = 0.9 * hint.mu;
        self.viscous = 0.1 * hint.mu * hint.normal_force / hint.typical_velocity.max(1e-6);
    }
}
