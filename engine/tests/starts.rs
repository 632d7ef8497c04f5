//! Starts that cannot be evaluated as given: a start outside a law's domain (its declared
//! bounds, or bounds of the configuration that reach beyond them) is projected into it before
//! the search, and the fit recovers the truth from there; a start whose residuals are not
//! finite is dropped at once, with an error naming the parameter values, the record and the
//! sample where the residuals stop being finite. The law that breaks down is local to this
//! test binary (the registry's "every built-in model" tests do not see it).

use crate::util::{free, no_oscillator_force_options, records, NOISE};
use frictionid_engine::identify::{fit, FitOptions, ParamOptions, Search};
use frictionid_engine::record::{Channel, TimeBase};
use frictionid_engine::testing::DamperStroke;
use frictionid_engine::{Oscillator, Record};
use frictionid_models::{sgn, Coulomb, Dahl, FrictionModel};
use std::f64::consts::TAU;

/// A velocity fit of Coulomb friction started below the law's domain (mu = -0.3 < 0, no
/// data-driven guess) starts at the bound and finds the truth, mu = 0.24.
#[test]
fn a_start_below_the_domain_is_projected_and_the_fit_succeeds() {
    let osc = Oscillator::fmm();
    let recs = records(&osc, &Coulomb { mu: 0.24 }, NOISE, 100);
    let opts = FitOptions {
        params: ParamOptions {
            guess: false,
            ..ParamOptions::default()
        },
        ..FitOptions::default()
    };
    let result = fit(&osc, &Coulomb { mu: -0.3 }, &recs, &opts).expect("the projected start fits");
    let mu = result.fitted_model.params()[0];
    assert!((mu - 0.24).abs() < 0.003, "mu = {mu}");
    assert!(result.converged, "{:?}", result.termination);
}

/// A friction damper's stroke: 3 mm at 2 Hz, 4 000 samples at 1 kHz, Dahl's force (alpha 1,
/// sigma0 4e5 N/m, level 50 N) in closed form along the sampled path, with 0.2 N noise.
fn damper_stroke() -> Record {
    DamperStroke::short().record(4000)
}

/// Dahl along a damper's stroke, started at a negative rest stiffness (no value near it is
/// valid: it starts at the law's default) with bounds that reach below zero (searched within
/// the law's domain, in log coordinates): both recover sigma0 and the level.
#[test]
fn a_start_and_bounds_beyond_the_domain_are_projected_into_it() {
    let record = [damper_stroke()];
    let (osc, mut base) = no_oscillator_force_options();
    base.params.free = free(&["sigma0", "mu_c"]);
    base.params.guess = false;
    base.search.strategy = Some(Search::Local);
    let wide = FitOptions {
        params: ParamOptions {
            bounds: [("sigma0".to_string(), (-1e6, 1e7))].into_iter().collect(),
            ..base.params.clone()
        },
        ..base.clone()
    };
    let start = Dahl {
        sigma0: -1e5,
        mu_c: 40.0,
        alpha: 1.0,
    };
    for opts in [base, wide] {
        let result = fit(&osc, &start, &record, &opts).expect("the projected start fits");
        let p = result.fitted_model.params();
        assert!((p[0] / 4e5 - 1.0).abs() < 0.05, "sigma0 = {}", p[0]);
        assert!((p[1] / 50.0 - 1.0).abs() < 0.01, "level = {}", p[1]);
    }
}

frictionid_models::declare_params! {
    /// Coulomb friction that breaks down (NaN) where the speed exceeds `v_max`.
    struct BreaksDown {
        mu: new("1", 0.5, (0.0, 10.0), "friction level"),
        v_max: positive("m/s", 1.0, 100.0, "speed beyond which the law is undefined"),
    }
}

#[typetag::serde(name = "breaks_down_test_law")]
impl FrictionModel for BreaksDown {
    frictionid_models::declared_param_methods!(
        name: "breaks_down_test_law",
        equation: "F = mu N sgn(v), undefined (NaN) for |v| > v_max",
    );
    fn force(&self, v: f64, _z: &[f64], normal: f64) -> f64 {
        if v.abs() > self.v_max {
            f64::NAN
        } else {
            self.mu * normal * sgn(v)
        }
    }
    fn steady_state(&self, v: f64, normal: f64) -> f64 {
        self.force(v, &[], normal)
    }
}

/// A start whose force is NaN beyond 0.05 m/s, along a motion of 0.1 sin(2 pi t) m/s
/// sampled at 100 Hz, whose speed first exceeds it at sample 9 (t = 0.09 s): the fit's only
/// start is dropped at once, and the error names the parameter values, the record, the
/// residual and its time.
#[test]
fn a_start_whose_residuals_are_not_finite_names_the_record_and_sample() {
    let time: Vec<f64> = (0..100).map(|i| i as f64 * 0.01).collect();
    let v: Vec<f64> = time.iter().map(|&t| 0.1 * (TAU * t).sin()).collect();
    let force: Vec<f64> = v.iter().map(|&v| 0.5 * sgn(v)).collect();
    let record = [
        Record::from_time_base("nan-record", TimeBase::new(time).expect("uniform time"))
            .with_channel(Channel::Velocity, v)
            .with_channel(Channel::Force, force),
    ];
    let (osc, mut opts) = no_oscillator_force_options();
    opts.params.free = free(&["mu"]);
    opts.params.guess = false;
    let law = BreaksDown {
        mu: 0.4,
        v_max: 0.05,
    };
    let e = fit(&osc, &law, &record, &opts)
        .expect_err("no start can be evaluated")
        .to_string();
    for part in [
        "the residuals at the start (mu = 4.0000e-1 N)",
        "are not finite: record `nan-record`: force residual 9 of 100 (t = 0.09 s) is NaN",
        "the start is dropped",
    ] {
        assert!(e.contains(part), "`{part}` not in: {e}");
    }
}
