//! Engine tests with test-local friction laws (their own test binary, so the extra registered
//! models do not join the "every built-in model" tests): a law that returns NaN past a speed
//! (the engine must report the time reached, never panic or loop), and a three-state law that
//! exercises the heap-allocated state path against the one-state Dahl model it equals.

use frictionid_engine::synthetic::uniform_times;
use frictionid_engine::{simulate, EngineError, Initial, Integrator, Oscillator, SimOptions};
use frictionid_models::testing::motion::first_mismatch;
use frictionid_models::{sgn, Dahl, FrictionModel, InternalStates};
use serde::{Deserialize, Serialize};

/// Viscous friction that breaks down (NaN) below v = -0.1 m/s.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
struct Broken;

#[typetag::serde(name = "broken_test_law")]
impl FrictionModel for Broken {
    frictionid_models::declared_param_methods!(
        name: "broken_test_law",
        equation: "F = v (NaN for v < -0.1)",
        no_params
    );
    fn force(&self, v: f64, _z: &[f64], _normal: f64) -> f64 {
        if v < -0.1 {
            f64::NAN
        } else {
            v
        }
    }
    fn steady_state(&self, v: f64, normal: f64) -> f64 {
        self.force(v, &[], normal)
    }
}

/// Time at which the free oscillator (c + 1 N s/m) from 22 mm first reaches v = -0.1 m/s.
fn breakdown_time(osc: &Oscillator) -> f64 {
    // Underdamped response from rest: v(t) = -x0 wn^2 / wd e^{-zeta wn t} sin(wd t).
    let c = osc.damping + 1.0;
    let wn = osc.omega_n();
    let zeta = c / (2.0 * (osc.stiffness * osc.mass).sqrt());
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    let v = |t: f64| -0.022 * wn * wn / wd * (-zeta * wn * t).exp() * (wd * t).sin();
    let (mut a, mut b) = (0.0, std::f64::consts::FRAC_PI_2 / wd);
    for _ in 0..100 {
        let m = 0.5 * (a + b);
        if v(m) > -0.1 {
            a = m
        } else {
            b = m
        }
    }
    a
}

#[test]
fn a_non_finite_force_is_an_error_with_the_time_reached() {
    let osc = Oscillator::fmm();
    let t_break = breakdown_time(&osc);
    for integrator in [
        Integrator::Dopri5,
        Integrator::Euler {
            steps_per_period: 1e4,
        },
    ] {
        let opts = SimOptions {
            integrator,
            ..SimOptions::default()
        };
        let err = simulate(&osc, &Broken, &Initial::at_rest(0.022), 1.0, &[0.5], &opts)
            .expect_err("a NaN force must fail");
        let EngineError::Integration(failure) = &err else {
            panic!("expected an integration error, got {err}");
        };
        let (time, reason) = (failure.time(), failure.to_string());
        assert!(
            (time - t_break).abs() < 1e-3,
            "{integrator:?}: failed at {time}, the force breaks down at {t_break}: {reason}"
        );
        assert!(err.to_string().contains("t = "), "{err}");
    }
}

/// Three Dahl elements (alpha = 1) in parallel, each with stiffness `s` and saturation `fc / 3`:
/// their sum obeys a single Dahl law with sigma0 = 3 s and saturation fc.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
struct TripleDahl {
    s: f64,
    mu_c: f64,
}

#[typetag::serde(name = "triple_dahl_test_law")]
impl FrictionModel for TripleDahl {
    frictionid_models::declared_param_methods!(
        name: "triple_dahl_test_law",
        equation: "F = z1 + z2 + z3, dzi/dt = s v (1 - 3 zi sgn(v) / (mu_c N))",
        no_params
    );
    fn force(&self, _v: f64, z: &[f64], _normal: f64) -> f64 {
        z.iter().sum()
    }
    fn steady_state(&self, v: f64, normal: f64) -> f64 {
        self.mu_c * normal * sgn(v)
    }
    frictionid_models::law_groups!(states);
}

impl InternalStates for TripleDahl {
    fn n_states(&self) -> usize {
        3
    }
    fn state_derivative(&self, v: f64, z: &[f64], normal: f64, dz: &mut [f64]) {
        let fc = self.mu_c * normal / 3.0;
        for (d, zi) in dz.iter_mut().zip(z) {
            *d = self.s * v * (1.0 - zi * sgn(v) / fc);
        }
    }
    fn stored_energy(&self, z: &[f64], _normal: f64) -> f64 {
        z.iter().map(|zi| zi * zi / (2.0 * self.s)).sum()
    }
}

#[test]
fn many_state_path_matches_the_equivalent_one_state_model() {
    let osc = Oscillator::fmm();
    let times = uniform_times(2.0, 1000.0);
    let opts = SimOptions::default();
    let init = Initial::at_rest(0.022);
    let triple = TripleDahl {
        s: 1e5 / 3.0,
        mu_c: 0.2,
    };
    let single = Dahl {
        sigma0: 1e5,
        mu_c: 0.2,
        alpha: 1.0,
    };
    let a = simulate(&osc, &triple, &init, 2.0, &times, &opts).unwrap();
    let b = simulate(&osc, &single, &init, 2.0, &times, &opts).unwrap();
    assert_eq!(a.states.len(), 3);
    assert_eq!((a.x.len(), b.x.len()), (times.len(), times.len()));
    for (what, three, one, tolerance) in [
        ("x", &a.x, &b.x, 1e-8),
        ("v", &a.v, &b.v, 1e-7),
        ("F", &a.friction, &b.friction, 1e-5),
        ("stored", &a.stored, &b.stored, 1e-9),
    ] {
        assert_eq!(first_mismatch(three, one, tolerance), None, "{what}");
    }
    let sum: Vec<f64> = (0..times.len())
        .map(|i| a.states.iter().map(|z| z[i]).sum())
        .collect();
    assert_eq!(
        first_mismatch(&sum, &b.states[0], 1e-5),
        None,
        "z1 + z2 + z3"
    );
}
