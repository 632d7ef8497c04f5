//! The plugin model against the invariants of a model in motion, as every model should be
//! tested (see docs/writing-a-model.md): energy never increases, mirror symmetry, and two
//! independent integrators (the paper's Euler and adaptive Dormand-Prince) converge to each
//! other. The checks are the shared harness `frictionid_models::testing::motion`; this file
//! only connects it to the engine.

use frictionid_engine::synthetic::uniform_times;
use frictionid_engine::{simulate, Initial, Integrator, Oscillator, SimOptions};
use frictionid_models::testing::motion::{
    check_energy_never_increases, check_integrators_agree, check_mirror_symmetry, Integration,
    Motion, Simulator,
};
use frictionid_models::testing::{Model, Violation};
use frictionid_plugin_example::StribeckPower;

/// The FMM stage simulated by the engine, sampled at 1 kHz.
struct Fmm(Oscillator);

impl Simulator for Fmm {
    fn stiffness(&self) -> f64 {
        self.0.stiffness
    }
    fn normal_force(&self) -> f64 {
        self.0.normal_force
    }
    fn release(
        &self,
        model: &Model,
        x0: f64,
        t_end: f64,
        integration: Integration,
    ) -> Result<Motion, String> {
        let integrator = match integration {
            Integration::Adaptive => SimOptions::default().integrator,
            Integration::Euler { steps_per_period } => Integrator::Euler { steps_per_period },
        };
        let opts = SimOptions {
            integrator,
            ..SimOptions::default()
        };
        let times = uniform_times(t_end, 1000.0);
        let sim = simulate(&self.0, model, &Initial::at_rest(x0), t_end, &times, &opts)
            .map_err(|e| e.to_string())?;
        Ok(Motion {
            total_energy: sim.total_energy(),
            rest_displacement: sim.rest.map(|r| r.displacement),
            events: sim.events.len(),
            time: sim.time,
            x: sim.x,
            v: sim.v,
            friction: sim.friction,
        })
    }
}

/// Parameter sets to test: the defaults, the fixture truth, sub- and super-linear drag.
fn models() -> Vec<StribeckPower> {
    let truth = StribeckPower::fixture_truth();
    vec![
        StribeckPower::default(),
        truth.clone(),
        StribeckPower {
            alpha: 0.5,
            ..truth.clone()
        },
        StribeckPower {
            alpha: 3.0,
            viscous: 20.0,
            ..truth
        },
    ]
}

fn for_every_model(check: impl Fn(&Fmm, &StribeckPower) -> Result<(), Violation>) {
    let fmm = Fmm(Oscillator::fmm());
    for m in models() {
        if let Err(v) = check(&fmm, &m) {
            panic!("{m:?}: {v}");
        }
    }
}

#[test]
fn energy_never_increases() {
    // Also: a static law with a breakaway limit ends at rest within |k x| <= mu_s N.
    for_every_model(|fmm, m| {
        check_energy_never_increases(fmm, m, &[0.022, 0.014, -0.010, 0.003], 2.0)
    });
}

#[test]
fn mirror_symmetry() {
    for_every_model(|fmm, m| check_mirror_symmetry(fmm, m, 0.022, 2.0));
}

#[test]
fn euler_converges_to_dopri5() {
    for_every_model(|fmm, m| check_integrators_agree(fmm, m, 0.022, 1.0));
}
