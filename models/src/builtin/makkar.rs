//! The continuously differentiable friction model of Makkar, Dixon, Sawyer and Hu.
//!
//! F = g1 (tanh(g2 v) - tanh(g3 v)) + g4 tanh(g5 v) + g6 v
//!
//! | parameter | unit | default | bounds | fit | meaning |
//! |---|---|---|---|---|---|
//! | `g1` | N | 1.9 | [0, inf) | free | amplitude of the Stribeck term |
//! | `g2` | s/m | 200 | [0, inf) | free | rise rate of the Stribeck term |
//! | `g3` | s/m | 20 | [0, inf) | free | decay rate of the Stribeck term (g3 < g2) |
//! | `g4` | N | 2.9 | [0, inf) | free | Coulomb level |
//! | `g5` | s/m | 1000 | [0, inf) | free | steepness of the smoothed Coulomb term |
//! | `g6` | N s/m | 0.5 | [0, inf) | free | viscous friction coefficient |
//!
//! g4 tanh(g5 v) is a smoothed Coulomb force; g1 (tanh(g2 v) - tanh(g3 v)) is a bump that
//! vanishes at rest and at high speed and peaks in between (the Stribeck effect) when
//! g2 > g3; g3 > g2 turns it into a dip and is reported as a warning. The forces g1 and g4 are
//! in newtons, not coefficients: the law does not scale with the normal force. The defaults
//! fit the paper's FMM stage (N = 14.5 N, mu ~ 0.2): a Coulomb level of 2.9 N and a Stribeck
//! bump of about 1.46 N (0.769 g1) peaking near 9 mm/s.
//!
//! The law is smooth and odd with F(0) = 0, so there is no set-valued force at rest
//! (`static_limit` is `None`): the engine integrates it like any smooth law.
//!
//! Reference: C. Makkar, W. E. Dixon, W. G. Sawyer, G. Hu, "A new continuously differentiable
//! friction model for control systems design", Proc. IEEE/ASME Int. Conf. on Advanced
//! Intelligent Mechatronics (AIM), Monterey, 2005, pp. 600-605.

use crate::error::ModelError;
use crate::hints::GuessHint;
use crate::model::{FrictionModel, ParamGradients, Staging};

crate::declare_params! {
    /// Makkar et al.'s smooth friction law with Stribeck, Coulomb and viscous terms.
    pub struct Makkar {
        g1: non_negative("N", 1.9, "amplitude of the Stribeck term"),
        g2: non_negative("s/m", 200.0, "rise rate of the Stribeck term"),
        g3: non_negative("s/m", 20.0, "decay rate of the Stribeck term (g3 < g2)"),
        g4: non_negative("N", 2.9, "Coulomb level"),
        g5: non_negative("s/m", 1000.0, "steepness of the smoothed Coulomb term"),
        g6: non_negative("N s/m", 0.5, "viscous friction coefficient"),
    }
}

#[typetag::serde(name = "makkar")]
impl FrictionModel for Makkar {
    crate::declared_param_methods!(
        name: "makkar",
        equation: "F = g1 (tanh(g2 v) - tanh(g3 v)) + g4 tanh(g5 v) + g6 v",
    );
    fn force(&self, v: f64, _z: &[f64], _normal: f64) -> f64 {
        self.g1 * ((self.g2 * v).tanh() - (self.g3 * v).tanh())
            + self.g4 * (self.g5 * v).tanh()
            + self.g6 * v
    }
    crate::law_groups!(staging, param_gradients);
    fn validate(&self) -> Result<Vec<String>, ModelError> {
        let mut warnings = Vec::new();
        if self.g1 > 0.0 && self.g3 > self.g2 {
            warnings.push(format!(
                "model `makkar`: g3 = {} exceeds g2 = {} (the Stribeck term is a dip, not a bump)",
                self.g3, self.g2
            ));
        }
        Ok(warnings)
    }
}

impl ParamGradients for Makkar {
    /// The derivatives of each tanh term: d tanh(g v)/dg = v (1 - tanh(g v)^2).
    fn force_param_gradient(&self, v: f64, _z: &[f64], _normal: f64, out: &mut [f64]) {
        let (t2, t3, t5) = (
            (self.g2 * v).tanh(),
            (self.g3 * v).tanh(),
            (self.g5 * v).tanh(),
        );
        let gradient = [
            t2 - t3,
            self.g1 * v * (1.0 - t2 * t2),
            -self.g1 * v * (1.0 - t3 * t3),
            t5,
            self.g4 * v * (1.0 - t5 * t5),
            v,
        ];
        for (o, d) in out.iter_mut().zip(gradient) {
            *o = d;
        }
    }
}

impl Staging for Makkar {
    fn apply_guess(&mut self, hint: &GuessHint) {
        // Coulomb level from the energy estimate, a bump of a third of it peaking near a
        // fifth of the typical speed (tanh(a x) - tanh(a x / 10) peaks at a x = 1.84).
        let v = hint.typical_velocity.max(1e-6);
        let level = hint.mu * hint.normal_force;
        self.g4 = 0.9 * level;
        self.g5 = 50.0 / v;
        self.g1 = 0.3 * level / 0.769;
        self.g2 = 1.84 / (0.2 * v);
        self.g3 = 0.1 * self.g2;
        self.g6 = 0.05 * level / v;
    }
}
