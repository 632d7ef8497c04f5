//! A law without an exact step (as a plugin law usually is) fitted in the force domain: its
//! force's derivatives come from its states' sensitivities integrated with them, checked
//! against the closed-form sensitivities of the same law's exact steps.

use crate::util::{no_oscillator_force_options, three_tone_drive};
use frictionid_engine::energy::{force_derivatives_along, ForceDerivatives, MeasuredMotion};
use frictionid_engine::identify::fit;
use frictionid_engine::record::{Channel, NormalForce, TimeBase};
use frictionid_engine::synthetic::add_gaussian_noise;
use frictionid_engine::{model_force_along, Oscillator, Record};
use frictionid_models::{
    FrictionModel, InternalStates, LuGre, ModelError, ParamGradients, ParamInfo,
};
use serde::{Deserialize, Serialize};

/// LuGre with its exact step hidden (no propagator, no analytic state Jacobian), as a plugin
/// law would be; `halve` scales its states' rate gradient by one half (a wrong gradient).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(default)]
struct Unstepped {
    inner: LuGre,
    halve: bool,
}

#[typetag::serde(name = "test_laws_unstepped_lugre")]
impl FrictionModel for Unstepped {
    fn name(&self) -> &'static str {
        "test_laws_unstepped_lugre"
    }
    fn equation(&self) -> String {
        self.inner.equation()
    }
    fn param_info(&self) -> Vec<ParamInfo> {
        self.inner.param_info()
    }
    fn params(&self) -> Vec<f64> {
        self.inner.params()
    }
    fn set_params(&mut self, values: &[f64]) -> Result<(), ModelError> {
        self.inner.set_params(values)
    }
    fn force(&self, v: f64, z: &[f64], normal: f64) -> f64 {
        self.inner.force(v, z, normal)
    }
    fn steady_state(&self, v: f64, normal: f64) -> f64 {
        self.inner.steady_state(v, normal)
    }
    frictionid_models::law_groups!(states, param_gradients);
}

impl InternalStates for Unstepped {
    fn n_states(&self) -> usize {
        self.inner.n_states()
    }
    fn state_derivative(&self, v: f64, z: &[f64], normal: f64, dz: &mut [f64]) {
        self.inner.state_derivative(v, z, normal, dz);
    }
    fn sliding_states(&self, v: f64, normal: f64, out: &mut [f64]) -> bool {
        self.inner.sliding_states(v, normal, out)
    }
}

impl ParamGradients for Unstepped {
    fn force_param_gradient(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]) {
        self.inner.force_param_gradient(v, z, normal, out);
    }
    fn state_param_gradient(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]) -> bool {
        let given = self.inner.state_param_gradient(v, z, normal, out);
        if self.halve {
            out.iter_mut().for_each(|g| *g *= 0.5);
        }
        given
    }
}

/// The force's derivatives of `model` at every sample of the motion, under 14.5 N.
fn derivatives(model: &dyn FrictionModel, time: &[f64], v: &[f64]) -> ForceDerivatives {
    let normal = NormalForce::Constant(14.5);
    let samples: Vec<usize> = (0..time.len()).collect();
    force_derivatives_along(
        model,
        MeasuredMotion {
            time,
            v,
            normal: &normal,
        },
        &samples,
    )
    .expect("a checked motion")
    .expect("the force's derivatives")
}

/// The largest difference of `got` from `want` in parameter `j`'s column, over that
/// column's largest entry.
fn column_error(want: &ForceDerivatives, got: &ForceDerivatives, j: usize) -> f64 {
    let k = 0..want.force.len();
    let scale = k.clone().fold(0.0f64, |a, k| a.max(want.at(k, j).abs()));
    k.fold(0.0f64, |a, k| a.max((want.at(k, j) - got.at(k, j)).abs())) / scale
}

/// The law without an exact step gets its force's derivatives, and they are LuGre's
/// closed-form ones to 1e-5 of each parameter's largest; with its states' rate gradient
/// halved they are not (a wrong gradient is seen, by more than 1e-2 in some parameter).
#[test]
fn a_law_without_exact_steps_gets_the_exact_derivatives_from_its_gradients() {
    let (time, v) = three_tone_drive(2000);
    let exact = derivatives(&LuGre::default(), &time, &v);
    let integrated = derivatives(&Unstepped::default(), &time, &v);
    let wrong = derivatives(
        &Unstepped {
            halve: true,
            ..Unstepped::default()
        },
        &time,
        &v,
    );
    let np = exact.given.len();
    for j in (0..np).filter(|&j| exact.given[j]) {
        let error = column_error(&exact, &integrated, j);
        assert!(error <= 1e-5, "parameter {j}: {error:e}");
    }
    assert!((0..np).any(|j| column_error(&exact, &wrong, j) > 1e-2));
}

/// A force-domain fit of the law without an exact step (its truth's force by LuGre's exact
/// steps, 2 000 samples, 0.3 N of noise) lands on the fit of LuGre itself, every estimate
/// within a hundredth of its standard error, and its Jacobians take one replay each: at most
/// three replays per iteration (a trial point, its Jacobian, a rejected trial now and then),
/// where difference quotients would take one per free parameter (six) for each Jacobian.
#[test]
fn a_fit_of_a_law_without_exact_steps_takes_one_replay_per_jacobian() {
    let (time, v) = three_tone_drive(2000);
    let truth = LuGre {
        sigma0: 1e5,
        sigma1: 300.0,
        sigma2: 5.0,
        mu_c: 20.0 / 14.5,
        mu_s: 30.0 / 14.5,
        v_s: 0.01,
    };
    let mut force = model_force_along(&truth, &Oscillator::fmm(), &time, &v).expect("force");
    add_gaussian_noise(&mut force, 0.3, 17);
    let record = [
        Record::from_time_base("drive", TimeBase::new(time).expect("time"))
            .with_channel(Channel::Velocity, v)
            .with_channel(Channel::Force, force),
    ];
    let (osc, opts) = no_oscillator_force_options();
    let reference = fit(&osc, &LuGre::default(), &record, &opts).expect("lugre's fit");
    let plugin = fit(&osc, &Unstepped::default(), &record, &opts).expect("the plugin's fit");
    for (p, q) in reference.parameters.iter().zip(&plugin.parameters) {
        let se = p.std_error.expect("a standard error");
        assert!(
            (p.value - q.value).abs() <= 0.01 * se,
            "{}: {} vs {}",
            p.name,
            p.value,
            q.value
        );
    }
    assert!(
        plugin.simulations <= 3 * plugin.iterations,
        "{} replays in {} iterations",
        plugin.simulations,
        plugin.iterations
    );
}
