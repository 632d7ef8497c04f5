//! The comparison's verdict against known truths: records made by the engine's own simulator
//! from a known law (three FMM releases, Gaussian noise of 2e-4 m/s, fixed seeds). The
//! verdict recommends the true law, never a more complex one, and sets aside a law with
//! physically inconsistent values; every ranked law carries its held-out score.

use crate::util::{records, stribeck_truth, NOISE};
use frictionid_engine::identify::{compare, Comparison, FitOptions, ValidationScheme};
use frictionid_engine::Oscillator;
use frictionid_models::{default_model, Coulomb, FrictionModel, Stribeck, ViscousCoulomb};

fn compared(truth: &dyn FrictionModel, seed: u64, names: &[&str]) -> Comparison {
    let osc = Oscillator::fmm();
    let recs = records(&osc, truth, NOISE, seed);
    let models: Vec<Box<dyn FrictionModel>> =
        names.iter().map(|n| default_model(n).unwrap()).collect();
    compare(&osc, &models, &recs, &FitOptions::default()).unwrap()
}

fn recommended(c: &Comparison) -> String {
    let v = c.verdict.as_ref().unwrap();
    v.recommended
        .clone()
        .unwrap_or_else(|| panic!("{}", v.message))
}

/// Every ranked law has a held-out score from records left out, with one RMS per fold.
fn assert_validated(c: &Comparison) {
    assert_eq!(c.validation_scheme, Some(ValidationScheme::RecordsLeftOut));
    for f in &c.ranking {
        let v = c.validation.iter().find(|v| v.model == f.model).unwrap();
        let rms = v.validation_rms.unwrap_or_else(|| panic!("{v:?}"));
        assert_eq!(v.folds.len(), 3, "{v:?}");
        // Held out, a law that follows the data scores near the noise, above its fit.
        assert!(rms.is_finite() && rms > 0.0, "{v:?}");
    }
}

#[test]
fn a_coulomb_truth_recommends_coulomb() {
    let c = compared(
        &Coulomb { mu: 0.24 },
        201,
        &["coulomb", "viscous_coulomb", "stribeck"],
    );
    assert_validated(&c);
    assert_eq!(recommended(&c), "coulomb", "{}", c.verdict.unwrap().message);
}

#[test]
fn a_stribeck_truth_recommends_stribeck() {
    let c = compared(
        &stribeck_truth(),
        211,
        &["coulomb", "viscous_coulomb", "stribeck"],
    );
    assert_validated(&c);
    let v = c.verdict.as_ref().unwrap();
    assert_eq!(recommended(&c), "stribeck", "{}", v.message);
    assert!(v.message.starts_with("use `stribeck`"), "{}", v.message);
}

#[test]
fn a_viscous_coulomb_truth_recommends_no_more_complex_law() {
    let truth = ViscousCoulomb {
        mu: 0.2,
        viscous: 4.0,
    };
    let c = compared(&truth, 221, &["coulomb", "viscous_coulomb", "stribeck"]);
    assert_validated(&c);
    assert_eq!(
        recommended(&c),
        "viscous_coulomb",
        "{}",
        c.verdict.unwrap().message
    );
}

/// Friction that rises towards rest (mu_s < mu_c): the fitted Stribeck law recovers the
/// inversion, is set aside with the reason, and the verdict recommends another law.
#[test]
fn a_law_with_its_static_level_below_its_coulomb_level_is_set_aside() {
    let truth = Stribeck {
        mu_c: 0.28,
        mu_s: 0.18,
        ..stribeck_truth()
    };
    let c = compared(&truth, 231, &["viscous_coulomb", "stribeck"]);
    let v = c.verdict.as_ref().unwrap();
    let fitted = c.ranking.iter().find(|f| f.model == "stribeck").unwrap();
    assert!(
        fitted.value("mu_s").unwrap() < fitted.value("mu_c").unwrap(),
        "{:?}",
        fitted.parameters
    );
    let aside = v.set_aside.iter().find(|s| s.model == "stribeck");
    assert!(
        aside.is_some_and(|s| s.reason.contains("mu_s")),
        "{:?}",
        v.set_aside
    );
    assert_ne!(v.recommended.as_deref(), Some("stribeck"), "{}", v.message);
    assert!(v.message.contains("stribeck"), "{}", v.message);
}
