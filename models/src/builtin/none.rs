//! No friction (F = 0), for identifying the oscillator itself from a free vibration without
//! friction contact (as the paper does for m, c and k).

use crate::model::FrictionModel;
use serde::{Deserialize, Serialize};

crate::declare_params! {
    /// The zero friction force.
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(default, deny_unknown_fields)]
    pub struct NoFriction {}
}

#[typetag::serde(name = "none")]
impl FrictionModel for NoFriction {
    crate::declared_param_methods!();

    fn name(&self) -> &'static str {
        "none"
    }
    fn equation(&self) -> String {
        "F = 0 (no friction contact)".into()
    }
    fn force(&self, _v: f64, _z: &[f64], _normal: f64) -> f64 {
        0.0
    }
    fn steady_state(&self, _v: f64, _normal: f64) -> f64 {
        0.0
    }
}
