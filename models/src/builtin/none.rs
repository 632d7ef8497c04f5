//! No friction (F = 0), for identifying the oscillator itself from a free vibration without
//! friction contact (as the paper does for m, c and k).

use crate::error::ModelError;
use crate::model::{check_len, FrictionModel, ParamInfo};
use serde::{Deserialize, Serialize};

/// The zero friction force.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NoFriction {}

#[typetag::serde(name = "none")]
impl FrictionModel for NoFriction {
    fn name(&self) -> &'static str {
        "none"
    }
    fn equation(&self) -> String {
        "F = 0 (no friction contact)".into()
    }
    fn param_info(&self) -> Vec<ParamInfo> {
        Vec::new()
    }
    fn params(&self) -> Vec<f64> {
        Vec::new()
    }
    fn set_params(&mut self, values: &[f64]) -> Result<(), ModelError> {
        check_len(self.name(), 0, values.len())
    }
    fn force(&self, _v: f64, _z: &[f64], _normal: f64) -> f64 {
        0.0
    }
    fn affine_slip(&self, _direction: f64, _normal: f64) -> Option<(f64, f64)> {
        Some((0.0, 0.0))
    }
    fn steady_state(&self, _v: f64, _normal: f64) -> f64 {
        0.0
    }
}
