//! GMS fitted along a measured motion by its exact steps (at a sharpness without closed form,
//! the relaxation integrated in ln|1 - load| with its sensitivities) against the same law
//! without a propagator (the engine's numerical replay and difference columns), on a force
//! record GMS itself made (sharpness 3, noise added): both fits end at the same values within
//! their standard errors, and near the truth.

use frictionid_engine::energy::model_force_with_normal;
use frictionid_engine::identify::{fit, FitDomain, FitOptions, ParamOptions, TargetOptions};
use frictionid_engine::oscillator::OscillatorProperty;
use frictionid_engine::record::{Channel, NormalForce, TimeBase};
use frictionid_engine::synthetic::add_gaussian_noise;
use frictionid_engine::{Oscillator, Record};
use frictionid_models::{
    FrictionModel, Gms, GmsElement, InternalStates, Jacobians, ModelError, ParamGradients,
    ParamInfo,
};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// GMS without its exact steps: every method the law's own but the propagator.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct GmsWithoutSteps(Gms);

#[typetag::serde(name = "test_gms_without_steps")]
impl FrictionModel for GmsWithoutSteps {
    fn name(&self) -> &'static str {
        "test_gms_without_steps"
    }
    fn equation(&self) -> String {
        self.0.equation()
    }
    fn param_info(&self) -> Vec<ParamInfo> {
        self.0.param_info()
    }
    fn params(&self) -> Vec<f64> {
        self.0.params()
    }
    fn set_params(&mut self, values: &[f64]) -> Result<(), ModelError> {
        self.0.set_params(values)
    }
    fn force(&self, v: f64, z: &[f64], normal: f64) -> f64 {
        self.0.force(v, z, normal)
    }
    fn steady_state(&self, v: f64, normal: f64) -> f64 {
        self.0.steady_state(v, normal)
    }
    fn states(&self) -> Option<&dyn InternalStates> {
        Some(self)
    }
    fn param_gradients(&self) -> Option<&dyn ParamGradients> {
        Some(self)
    }
}

impl InternalStates for GmsWithoutSteps {
    fn n_states(&self) -> usize {
        self.0.n_states()
    }
    fn state_derivative(&self, v: f64, z: &[f64], normal: f64, dz: &mut [f64]) {
        self.0.state_derivative(v, z, normal, dz);
    }
    fn sliding_states(&self, v: f64, normal: f64, out: &mut [f64]) -> bool {
        self.0.sliding_states(v, normal, out)
    }
    fn force_only_params(&self) -> Vec<usize> {
        self.0.force_only_params()
    }
    fn jacobians(&self) -> Option<&dyn Jacobians> {
        Some(self)
    }
}

impl Jacobians for GmsWithoutSteps {
    fn state_jacobian(&self, v: f64, z: &[f64], normal: f64, jac: &mut [f64]) {
        self.0.state_jacobian(v, z, normal, jac);
    }
    fn force_gradient(&self, v: f64, z: &[f64], normal: f64, dfdz: &mut [f64]) -> f64 {
        self.0.force_gradient(v, z, normal, dfdz)
    }
    fn state_velocity_derivative(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]) {
        self.0.state_velocity_derivative(v, z, normal, out);
    }
}

impl ParamGradients for GmsWithoutSteps {
    fn force_param_gradient(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]) {
        self.0.force_param_gradient(v, z, normal, out);
    }
}

/// Two elements at sharpness 3 (no closed-form step).
fn truth() -> Gms {
    Gms {
        elements: vec![
            GmsElement {
                stiffness: 4e5,
                weight: 0.6,
                damping: 0.0,
            },
            GmsElement {
                stiffness: 5e4,
                weight: 0.4,
                damping: 0.0,
            },
        ],
        mu_c: 0.2,
        mu_s: 0.3,
        v_s: 0.01,
        delta: 2.0,
        sharpness: 3.0,
        viscous: 0.5,
    }
}

/// 0.7 s at 1 kHz of a reversing stroke (0.3 mm at 2.3 Hz with a slower 0.1 mm swing) and
/// the truth's force along it with 0.02 N of noise, at N = 14.5 N.
fn record() -> Record {
    let time: Vec<f64> = (0..700).map(|i| i as f64 * 1e-3).collect();
    let v: Vec<f64> = time
        .iter()
        .map(|t| {
            3e-4 * 2.0 * PI * 2.3 * (2.0 * PI * 2.3 * t).cos()
                + 1e-4 * 2.0 * PI * 0.7 * (2.0 * PI * 0.7 * t).cos()
        })
        .collect();
    let mut force = model_force_with_normal(&truth(), &time, &v, &NormalForce::Constant(14.5))
        .expect("the truth's force");
    add_gaussian_noise(&mut force, 0.02, 41);
    Record::from_time_base("gms", TimeBase::new(time).expect("time base"))
        .with_channel(Channel::Velocity, v)
        .with_channel(Channel::Force, force)
}

#[test]
fn exact_and_numerical_replays_fit_gms_to_the_same_values() {
    let opts = FitOptions {
        target: TargetOptions {
            domain: FitDomain::Force,
            unknown_oscillator: vec![
                OscillatorProperty::Mass,
                OscillatorProperty::Damping,
                OscillatorProperty::Stiffness,
            ],
            ..TargetOptions::default()
        },
        params: ParamOptions {
            free: Some(
                ["k_1", "mu_c", "sharpness"]
                    .iter()
                    .map(|s| s.to_string())
                    .collect(),
            ),
            ..ParamOptions::default()
        },
        ..FitOptions::default()
    };
    let osc = Oscillator {
        normal_force: 14.5,
        ..Oscillator::fmm()
    };
    let records = [record()];
    let mut start = truth();
    start.elements[0].stiffness = 2.5e5;
    start.mu_c = 0.18;
    start.sharpness = 2.5;
    let exact = fit(&osc, &start, &records, &opts).expect("the exact fit");
    let numerical = fit(&osc, &GmsWithoutSteps(start), &records, &opts).expect("the numerical fit");
    let want = truth();
    let truth_of = |name: &str| {
        let names: Vec<String> = want.param_info().into_iter().map(|p| p.name).collect();
        want.params()[names.iter().position(|n| n == name).expect("a parameter")]
    };
    for name in ["k_1", "mu_c", "sharpness"] {
        let (a, b) = (
            exact.param(name).expect("exact"),
            numerical.param(name).expect("numerical"),
        );
        let se = a.std_error.expect("a standard error");
        assert!(
            (a.value - b.value).abs() <= se,
            "{name}: exact {} vs numerical {} (standard error {se})",
            a.value,
            b.value
        );
        assert!(
            (a.value - truth_of(name)).abs() <= 4.0 * se,
            "{name}: {} +- {se} against the truth {}",
            a.value,
            truth_of(name)
        );
    }
}
