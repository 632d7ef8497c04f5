//! Coulomb friction.
//!
//! F = mu N sgn(v)
//!
//! | parameter | unit | default | bounds | fit | meaning |
//! |---|---|---|---|---|---|
//! | `mu` | 1 | 0.2 | [0, 10] | free | Coulomb friction coefficient |
//!
//! Reference: C.-A. de Coulomb, *Théorie des machines simples* (1785); the oscillator with
//! Coulomb friction is the paper's Eq. (1).

use crate::hints::GuessHint;
use crate::model::{sgn, FrictionModel, ParamGradients, Staging, SwitchedLaw};
use crate::start::{StartContext, StribeckLevels};

crate::declare_params! {
    /// Coulomb friction: a constant force mu N opposing the sliding direction.
    pub struct Coulomb {
        mu: new("1", 0.2, (0.0, 10.0), "Coulomb friction coefficient"),
    }
}

#[typetag::serde(name = "coulomb")]
impl FrictionModel for Coulomb {
    crate::declared_param_methods!(
        name: "coulomb",
        equation: "F = mu N sgn(v)",
    );
    fn force(&self, v: f64, _z: &[f64], normal: f64) -> f64 {
        self.mu * normal * sgn(v)
    }
    crate::law_groups!(switching, staging, param_gradients);
}

impl ParamGradients for Coulomb {
    /// dF/dmu = N sgn(v).
    fn force_param_gradient(&self, v: f64, _z: &[f64], normal: f64, out: &mut [f64]) {
        if let Some(d) = out.first_mut() {
            *d = normal * sgn(v);
        }
    }
}

impl SwitchedLaw for Coulomb {
    fn static_limit(&self, normal: f64) -> Option<f64> {
        Some(self.mu * normal)
    }
    fn slip_force(&self, _v: f64, direction: f64, normal: f64) -> f64 {
        self.mu * normal * direction
    }
    fn affine_slip(&self, direction: f64, normal: f64) -> Option<(f64, f64)> {
        Some((self.mu * normal * direction, 0.0))
    }
}

impl Staging for Coulomb {
    fn apply_guess(&mut self, hint: &GuessHint) {
        self.mu = hint.mu;
    }
    /// The Coulomb level of the fitted model (its sliding force far from any Stribeck dip).
    fn start_from(&mut self, fitted: &dyn FrictionModel, _ctx: &StartContext) -> bool {
        let Some(levels) = StribeckLevels::from_model(fitted) else {
            return false;
        };
        self.mu = levels.mu_c;
        true
    }
}
