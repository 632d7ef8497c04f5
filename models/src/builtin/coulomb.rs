//! Coulomb friction.
//!
//! F = mu N sgn(v)
//!
//! | parameter | unit | default | bounds | meaning |
//! |---|---|---|---|---|
//! | `mu` | 1 | 0.2 | [0, 10] | Coulomb friction coefficient |
//!
//! Reference: C.-A. de Coulomb, *Théorie des machines simples* (1785); the oscillator with
//! Coulomb friction is the paper's Eq. (1).

use crate::error::ModelError;
use crate::model::{check_len, sgn, FrictionModel, GuessHint, ParamInfo};
use serde::{Deserialize, Serialize};

/// Coulomb friction: a constant force mu N opposing the sliding direction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Coulomb {
    /// Friction coefficient.
    pub mu: f64,
}

impl Default for Coulomb {
    fn default() -> Self {
        Self { mu: 0.2 }
    }
}

#[typetag::serde(name = "coulomb")]
impl FrictionModel for Coulomb {
    fn name(&self) -> &'static str {
        "coulomb"
    }
    fn equation(&self) -> String {
        "F = mu N sgn(v)".into()
    }
    fn param_info(&self) -> Vec<ParamInfo> {
        vec![ParamInfo::new(
            "mu",
            "1",
            0.2,
            (0.0, 10.0),
            "Coulomb friction coefficient",
        )]
    }
    fn params(&self) -> Vec<f64> {
        vec![self.mu]
    }
    fn set_params(&mut self, values: &[f64]) -> Result<(), ModelError> {
        check_len(self.name(), 1, values.len())?;
        // Indexing below is in range: check_len has just verified the length.
        self.mu = values[0];
        Ok(())
    }
    fn force(&self, v: f64, _z: &[f64], normal: f64) -> f64 {
        self.mu * normal * sgn(v)
    }
    fn static_limit(&self, normal: f64) -> Option<f64> {
        Some(self.mu * normal)
    }
    fn slip_force(&self, _v: f64, direction: f64, normal: f64) -> f64 {
        self.mu * normal * direction
    }
    fn affine_slip(&self, direction: f64, normal: f64) -> Option<(f64, f64)> {
        Some((self.mu * normal * direction, 0.0))
    }
    fn steady_state(&self, v: f64, normal: f64) -> f64 {
        self.force(v, &[], normal)
    }
    fn apply_guess(&mut self, hint: &GuessHint) {
        self.mu = hint.mu;
    }
}
