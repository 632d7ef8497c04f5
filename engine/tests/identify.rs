//! The identifier against known truths: synthetic FMM records made by the engine from a known
//! model, with Gaussian noise of 2e-4 m/s and fixed seeds.

mod common;

use common::{records, NOISE};
use frictionid_engine::identify::{compare, fit, FitOptions, OscillatorParam};
use frictionid_engine::Oscillator;
use frictionid_models::{default_model, Coulomb, FrictionModel, LuGre, NoFriction, Stribeck};

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn coulomb_mu_is_recovered_from_any_start() {
    let osc = Oscillator::fmm();
    let recs = records(&osc, &Coulomb { mu: 0.24 }, NOISE, 11);
    for start in [0.05, 0.1, 0.24, 0.5, 0.8] {
        let opts = FitOptions {
            guess: false,
            ..FitOptions::default()
        };
        let r = fit(&osc, &Coulomb { mu: start }, &recs, &opts).unwrap();
        let mu = r.value("mu").unwrap();
        assert!(rel(mu, 0.24) < 1e-3, "start {start}: mu = {mu}");
        assert!(r.converged, "start {start}: {}", r.termination);
        let p = r.param("mu").unwrap();
        let [lo, hi] = p.ci95.unwrap();
        assert!(lo < 0.24 && 0.24 < hi, "CI [{lo}, {hi}]");
        // Residuals are the noise: the RMS is within 5 % of 2e-4.
        assert!(rel(r.rms_residual, NOISE) < 0.05, "rms {}", r.rms_residual);
        // The energy-based force check is reported for every record.
        for rec in &r.records {
            let ef = rec.energy_force.as_ref().unwrap();
            assert!(rel(ef.reference, mu * osc.normal_force) < 1e-9);
            assert!(
                ef.percent_difference.abs() < 5.0,
                "{}",
                ef.percent_difference
            );
        }
    }
}

#[test]
fn data_driven_start_needs_only_the_model_name() {
    let osc = Oscillator::fmm();
    let recs = records(&osc, &Coulomb { mu: 0.24 }, NOISE, 21);
    let r = fit(&osc, &Coulomb::default(), &recs, &FitOptions::default()).unwrap();
    assert!(rel(r.value("mu").unwrap(), 0.24) < 1e-3);
    assert!(r.iterations < 20, "{} iterations", r.iterations);
}

#[test]
fn stribeck_parameters_are_recovered_and_the_comparison_ranks_it_first() {
    let osc = Oscillator::fmm();
    let truth = Stribeck {
        mu_c: 0.20,
        mu_s: 0.28,
        v_s: 0.02,
        delta: 2.0,
        viscous: 3.0,
    };
    let recs = records(&osc, &truth, NOISE, 31);
    let r = fit(&osc, &Stribeck::default(), &recs, &FitOptions::default()).unwrap();
    let (mu_c, mu_s, visc) = (
        r.value("mu_c").unwrap(),
        r.value("mu_s").unwrap(),
        r.value("viscous").unwrap(),
    );
    assert!(rel(mu_c, 0.20) < 0.03, "mu_c {mu_c}");
    assert!(rel(mu_s, 0.28) < 0.03, "mu_s {mu_s}");
    assert!(rel(visc, 3.0) < 0.10, "viscous {visc}");
    assert_eq!(r.value("delta"), Some(2.0));
    assert!(!r.param("delta").unwrap().free);

    let models: Vec<Box<dyn FrictionModel>> =
        ["coulomb", "viscous_coulomb", "stribeck", "dahl", "lugre"]
            .iter()
            .map(|n| default_model(n).unwrap())
            .collect();
    let c = compare(&osc, &models, &recs, &FitOptions::default()).unwrap();
    let order: Vec<&str> = c.ranking.iter().map(|f| f.model.as_str()).collect();
    assert!(
        order[0] == "stribeck" || order[0] == "lugre",
        "ranking {order:?}"
    );
    let pos = |n: &str| order.iter().position(|m| *m == n).unwrap();
    assert!(pos("viscous_coulomb") < pos("coulomb"), "ranking {order:?}");
    for w in c.ranking.windows(2) {
        assert!(w[0].aic <= w[1].aic);
    }
}

#[test]
fn lugre_fit_reaches_the_noise_level() {
    let osc = Oscillator::fmm();
    let truth = LuGre {
        sigma0: 1e5,
        sigma1: 500.0,
        sigma2: 1.0,
        mu_c: 0.22,
        mu_s: 0.30,
        v_s: 0.01,
    };
    let recs = records(&osc, &truth, NOISE, 41);
    let r = fit(&osc, &LuGre::default(), &recs, &FitOptions::default()).unwrap();
    assert!(
        r.rms_residual <= 1.1 * NOISE,
        "rms {} vs noise {NOISE}",
        r.rms_residual
    );
}

#[test]
fn oscillator_is_identified_from_friction_free_records() {
    let truth = Oscillator::fmm();
    let recs = records(&truth, &NoFriction {}, NOISE, 51);
    // Start from a wrong stiffness and damping, mass fixed.
    let start = Oscillator {
        stiffness: 1900.0,
        damping: 0.5,
        ..truth
    };
    let opts = FitOptions {
        oscillator: vec![OscillatorParam::Damping, OscillatorParam::Stiffness],
        ..FitOptions::default()
    };
    let r = fit(&start, &NoFriction {}, &recs, &opts).unwrap();
    let km = r.derived.iter().find(|d| d.name == "k/m").unwrap().value;
    let cm = r.derived.iter().find(|d| d.name == "c/m").unwrap().value;
    assert!(rel(km, truth.stiffness / truth.mass) < 5e-4, "k/m {km}");
    assert!(rel(cm, truth.damping / truth.mass) < 1e-2, "c/m {cm}");

    // With the mass free too, the report says what the data cannot separate.
    let opts3 = FitOptions {
        oscillator: vec![
            OscillatorParam::Mass,
            OscillatorParam::Damping,
            OscillatorParam::Stiffness,
        ],
        ..FitOptions::default()
    };
    let r3 = fit(&start, &NoFriction {}, &recs, &opts3).unwrap();
    assert!(
        r3.warnings.iter().any(|w| w.contains("not m")),
        "{:?}",
        r3.warnings
    );
    let km3 = r3.derived.iter().find(|d| d.name == "k/m").unwrap().value;
    assert!(rel(km3, truth.stiffness / truth.mass) < 5e-4, "k/m {km3}");
}

#[test]
fn nuisance_offset_and_release_shift_are_recovered() {
    let osc = Oscillator::fmm();
    let mut recs = records(&osc, &Coulomb { mu: 0.24 }, NOISE, 61);
    // A constant vibrometer offset of 3e-4 m/s on every record.
    for r in &mut recs {
        for v in r.velocity_mut() {
            *v += 3e-4;
        }
    }
    let opts = FitOptions {
        velocity_offset: true,
        ..FitOptions::default()
    };
    let r = fit(&osc, &Coulomb::default(), &recs, &opts).unwrap();
    for p in r.parameters.iter().filter(|p| p.name.starts_with("offset")) {
        assert!((p.value - 3e-4).abs() < 2e-5, "{} = {}", p.name, p.value);
    }
    assert!(rel(r.value("mu").unwrap(), 0.24) < 2e-3);
}

#[test]
fn bad_fit_requests_are_clear_errors() {
    let osc = Oscillator::fmm();
    let recs = records(&osc, &Coulomb { mu: 0.24 }, NOISE, 71);
    let opts = FitOptions {
        free: Some(vec!["muu".into()]),
        ..FitOptions::default()
    };
    let e = fit(&osc, &Coulomb::default(), &recs, &opts)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`muu`") && e.contains("did you mean `mu`"),
        "{e}"
    );
    let e = fit(&osc, &Coulomb::default(), &[], &FitOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("at least one record"), "{e}");
    let mut bad = recs.clone();
    bad[1].velocity_mut()[5] = f64::NAN;
    let e = fit(&osc, &Coulomb::default(), &bad, &FitOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("x14mm") && e.contains("not finite"), "{e}");
}
