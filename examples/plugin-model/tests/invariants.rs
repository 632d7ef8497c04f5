//! The plugin model against the invariants of a model in motion, as every model should be
//! tested (see docs/writing-a-model.md): energy never increases, mirror symmetry, and two
//! independent integrators (the paper's Euler and adaptive Dormand-Prince) converge to each
//! other. The checks are the shared harness `frictionid_models::testing::motion`; this file
//! only connects it to the engine.

use frictionid_engine::testing::EngineSimulator;
use frictionid_engine::Oscillator;
use frictionid_models::testing::motion::{
    check_energy_never_increases, check_integrators_agree, check_mirror_symmetry,
};
use frictionid_models::testing::Violation;
use frictionid_plugin_example::StribeckPower;

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

fn for_every_model(check: impl Fn(&EngineSimulator, &StribeckPower) -> Result<(), Violation>) {
    let fmm = EngineSimulator(Oscillator::fmm());
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
