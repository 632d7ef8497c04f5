//! No friction (F = 0), for identifying the oscillator itself from a free vibration without
//! friction contact (as the paper does for m, c and k).

use crate::model::{FrictionModel, ParamGradients, SwitchedLaw};

crate::declare_params! {
    /// The zero friction force.
    pub struct NoFriction {}
}

#[typetag::serde(name = "none")]
impl FrictionModel for NoFriction {
    crate::declared_param_methods!(
        name: "none",
        equation: "F = 0 (no friction contact)",
    );
    fn force(&self, _v: f64, _z: &[f64], _normal: f64) -> f64 {
        0.0
    }
    fn steady_state(&self, _v: f64, _normal: f64) -> f64 {
        0.0
    }
    crate::law_groups!(switching, param_gradients);
}

/// No parameters: nothing to write.
impl ParamGradients for NoFriction {
    fn force_param_gradient(&self, _v: f64, _z: &[f64], _normal: f64, _out: &mut [f64]) {}
}

impl SwitchedLaw for NoFriction {
    fn affine_slip(&self, _direction: f64, _normal: f64) -> Option<(f64, f64)> {
        Some((0.0, 0.0))
    }
}
