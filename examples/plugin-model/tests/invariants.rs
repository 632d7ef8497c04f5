//! The plugin model against the engine's invariants, as every model should be tested (see
//! docs/writing-a-model.md): energy never increases, mirror symmetry, and two independent
//! integrators (the paper's Euler and adaptive Dormand-Prince) converge to each other.

use frictionid_engine::synthetic::uniform_times;
use frictionid_engine::{simulate, Initial, Integrator, Oscillator, SimOptions, Trajectory};
use frictionid_models::FrictionModel;
use frictionid_plugin_example::StribeckPower;

/// Parameter sets to test: the defaults, the fixture truth, sub- and super-linear drag.
fn models() -> Vec<StribeckPower> {
    let truth = StribeckPower {
        mu_c: 0.2,
        mu_s: 0.3,
        v_s: 0.02,
        viscous: 4.0,
        alpha: 1.6,
        v_ref: 0.1,
    };
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

fn run(model: &dyn FrictionModel, x0: f64, t_end: f64, opts: &SimOptions) -> Trajectory {
    let times = uniform_times(t_end, 1000.0);
    simulate(
        &Oscillator::fmm(),
        model,
        &Initial::at_rest(x0),
        t_end,
        &times,
        opts,
    )
    .unwrap()
}

#[test]
fn energy_never_increases() {
    for m in models() {
        for x0 in [0.022, 0.014, -0.010, 0.003] {
            let sim = run(&m, x0, 2.0, &SimOptions::default());
            // KE + PE + stored (0 for a static law) may only fall.
            let total: Vec<f64> = sim
                .energy
                .iter()
                .zip(&sim.stored)
                .map(|(e, s)| e + s)
                .collect();
            for w in total.windows(2) {
                assert!(w[1] - w[0] <= 1e-9 * total[0], "{m:?} from {x0}: {w:?}");
            }
            // A static law with a breakaway limit ends at rest within the limit |k x| <= mu_s N.
            let rest = sim.rest.expect("comes to rest");
            assert!(1982.0 * rest.displacement.abs() <= m.mu_s * 14.5 + 1e-9);
        }
    }
}

#[test]
fn mirror_symmetry() {
    for m in models() {
        let a = run(&m, 0.022, 2.0, &SimOptions::default());
        let b = run(&m, -0.022, 2.0, &SimOptions::default());
        for i in 0..a.x.len() {
            assert!(
                (a.x[i] + b.x[i]).abs() < 1e-12,
                "{m:?} at t = {}",
                a.time[i]
            );
            assert!(
                (a.v[i] + b.v[i]).abs() < 1e-12,
                "{m:?} at t = {}",
                a.time[i]
            );
            assert!((a.friction[i] + b.friction[i]).abs() < 1e-9);
        }
        assert_eq!(a.events.len(), b.events.len());
    }
}

#[test]
fn euler_converges_to_dopri5() {
    for m in models() {
        let reference = run(&m, 0.022, 1.0, &SimOptions::default());
        let err = |n: f64| {
            let opts = SimOptions {
                integrator: Integrator::Euler {
                    steps_per_period: n,
                },
                ..SimOptions::default()
            };
            let sim = run(&m, 0.022, 1.0, &opts);
            sim.x
                .iter()
                .zip(&reference.x)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        };
        // First order: ten times the steps, about a tenth of the error.
        let (e4, e5) = (err(1e4), err(1e5));
        assert!(e5 < 2e-5, "{m:?}: {e5}");
        assert!(e5 < 0.2 * e4, "{m:?}: {e4} -> {e5}");
    }
}
