//! Coulomb plus viscous friction.
//!
//! F = mu N sgn(v) + b v
//!
//! | parameter | unit | default | bounds | meaning |
//! |---|---|---|---|---|
//! | `mu` | 1 | 0.2 | [0, 10] | Coulomb friction coefficient |
//! | `viscous` | N s/m | 0.5 | [0, inf) | viscous friction coefficient b |
//!
//! Reference: the classical static + viscous friction law, e.g. B. Armstrong-Hélouvry,
//! P. Dupont, C. Canudas de Wit, "A survey of models, analysis tools and compensation methods
//! for the control of machines with friction", Automatica 30(7), 1994.

use crate::error::ModelError;
use crate::model::{check_len, sgn, FrictionModel, GuessHint, ParamInfo};
use serde::{Deserialize, Serialize};

/// Coulomb friction with a viscous term proportional to the sliding velocity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ViscousCoulomb {
    /// Coulomb friction coefficient.
    pub mu: f64,
    /// Viscous coefficient [N s/m].
    pub viscous: f64,
}

impl Default for ViscousCoulomb {
    fn default() -> Self {
        Self {
            mu: 0.2,
            viscous: 0.5,
        }
    }
}

#[typetag::serde(name = "viscous_coulomb")]
impl FrictionModel for ViscousCoulomb {
    fn name(&self) -> &'static str {
        "viscous_coulomb"
    }
    fn equation(&self) -> String {
        "F = mu N sgn(v) + viscous v".into()
    }
    fn param_info(&self) -> Vec<ParamInfo> {
        vec![
            ParamInfo::new("mu", "1", 0.2, (0.0, 10.0), "Coulomb friction coefficient"),
            ParamInfo::new(
                "viscous",
                "N s/m",
                0.5,
                (0.0, f64::INFINITY),
                "viscous friction coefficient",
            ),
        ]
    }
    fn params(&self) -> Vec<f64> {
        vec![self.mu, self.viscous]
    }
    fn set_params(&mut self, values: &[f64]) -> Result<(), ModelError> {
        check_len(self.name(), 2, values.len())?;
        // Indexing below is in range: check_len has just verified the length.
        self.mu = values[0];
        self.viscous = values[1];
        Ok(())
    }
    fn force(&self, v: f64, _z: &[f64], normal: f64) -> f64 {
        self.mu * normal * sgn(v) + self.viscous * v
    }
    fn static_limit(&self, normal: f64) -> Option<f64> {
        Some(self.mu * normal)
    }
    fn slip_force(&self, v: f64, direction: f64, normal: f64) -> f64 {
        self.mu * normal * direction + self.viscous * v
    }
    fn affine_slip(&self, direction: f64, normal: f64) -> Option<(f64, f64)> {
        Some((self.mu * normal * direction, self.viscous))
    }
    fn steady_state(&self, v: f64, normal: f64) -> f64 {
        self.force(v, &[], normal)
    }
    fn apply_guess(&mut self, hint: &GuessHint) {
        self.mu = 0.9 * hint.mu;
        self.viscous = 0.1 * hint.mu * hint.normal_force / hint.typical_velocity.max(1e-6);
    }
}
