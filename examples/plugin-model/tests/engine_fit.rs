//! The plugin model through the engine's library API (no command line): fitted on the
//! committed fixture, it recovers the parameters the fixture was made with.

use frictionid_engine::data::{read_record, ReadOptions};
use frictionid_engine::identify::{fit, FitOptions};
use frictionid_engine::{Oscillator, Record};
use frictionid_plugin_example::StribeckPower;
use std::path::Path;

fn fixture_records() -> Vec<Record> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    [
        ("x10mm.csv", 0.010),
        ("x14mm.csv", 0.014),
        ("x22mm.csv", 0.022),
    ]
    .iter()
    .map(|(f, x0)| {
        let mut r = read_record(&dir.join(f), &ReadOptions::default()).unwrap();
        r.x0 = *x0;
        r
    })
    .collect()
}

#[test]
fn engine_fit_recovers_the_fixture_truth() {
    let osc = Oscillator::fmm();
    let recs = fixture_records();
    // From the model's defaults (the identifier's data-driven guess sets the start).
    let r = fit(
        &osc,
        &StribeckPower::default(),
        &recs,
        &FitOptions::default(),
    )
    .unwrap();
    assert!(r.converged, "{}", r.termination);
    // The residuals are the fixture's noise of 2e-4 m/s.
    assert!(
        (r.rms_residual - 2e-4).abs() < 0.05 * 2e-4,
        "rms {}",
        r.rms_residual
    );
    let truth = StribeckPower::fixture_truth();
    let expected = [
        ("mu_c", truth.mu_c, 0.01),
        ("mu_s", truth.mu_s, 0.01),
        ("v_s", truth.v_s, 0.03),
        ("viscous", truth.viscous, 0.03),
        ("alpha", truth.alpha, 0.02),
    ];
    for (name, value, rel_tol) in expected {
        let p = r.param(name).unwrap();
        assert!(p.free, "{name} is free");
        let err = (p.value - value).abs();
        assert!(
            err < rel_tol * value,
            "{name}: {} vs truth {value}",
            p.value
        );
        // The truth lies within four standard errors.
        let se = p.std_error.unwrap();
        assert!(
            err < 4.0 * se,
            "{name}: {} +- {se} vs truth {value}",
            p.value
        );
    }
    // v_ref stays fixed at its default.
    let v_ref = r.param("v_ref").unwrap();
    assert!(!v_ref.free);
    assert_eq!(v_ref.value, truth.v_ref);
}
