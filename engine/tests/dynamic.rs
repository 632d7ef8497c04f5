//! Dynamic friction models identified from their own synthetic FMM records (known truth and
//! noise, the oracle): the
//! default configuration names only the model; the truths are independent of the fit.

use crate::util::{lugre_truth, records, rel, stiff_lugre_truth, two_element_gms, NOISE};
use frictionid_engine::identify::{
    fit, FitOptions, FitResult, Identifiability, Search, SearchOptions,
};
use frictionid_engine::Oscillator;
use frictionid_models::{Coulomb, Dahl, FrictionModel, Gms, LuGre};

/// Every free parameter of `truth` is within 3 standard errors of its true value, or the
/// fit flags it as not determined; returns (and prints) the table of errors.
fn assert_recovered(r: &FitResult, truth: &dyn FrictionModel) -> String {
    let mut all = String::new();
    for (info, t) in truth.param_info().iter().zip(truth.params()) {
        if let Some(p) = r.param(&info.name).filter(|p| p.free) {
            all += &format!(
                "{} = {:e} (truth {t:e}, se {:?}); ",
                p.name, p.value, p.std_error
            );
        }
    }
    eprintln!("{}: rms/noise {:.4}; {all}", r.model, noise_ratio(r));
    let mut table = String::new();
    for (info, t) in truth.param_info().iter().zip(truth.params()) {
        let p = r.param(&info.name).expect("every parameter is reported");
        if !p.free {
            continue;
        }
        let class = p
            .identifiability
            .expect("a fitted parameter has a standing");
        table += &format!(
            "{} = {:e} (truth {t:e}, se {:?}, {:?}); ",
            p.name, p.value, p.std_error, class
        );
        if class == Identifiability::Determined {
            let se = p
                .std_error
                .expect("a determined parameter has a standard error");
            assert!(se > 0.0);
            assert!(
                (p.value - t).abs() <= 3.0 * se,
                "{} = {} is {:.1} standard errors from the truth {t}",
                p.name,
                p.value,
                (p.value - t).abs() / se
            );
        } else {
            assert!(p.std_error.is_none(), "{}: no standard error", p.name);
        }
    }
    table
}

fn noise_ratio(r: &FitResult) -> f64 {
    r.rms_residual / NOISE
}

#[test]
fn lugre_is_recovered_from_the_default_configuration() {
    let osc = Oscillator::fmm();
    let truth = lugre_truth();
    let recs = records(&osc, &truth, NOISE, 41);
    let r = fit(&osc, &LuGre::default(), &recs, &FitOptions::default()).unwrap();
    let table = assert_recovered(&r, &truth);
    eprintln!(
        "lugre: rms/noise {:.4}, {} starts, {} at best, won by {} ({}); {table}",
        noise_ratio(&r),
        r.starts,
        r.starts_at_best,
        r.best_start,
        r.best_start_origin
    );
    assert_eq!(r.search, Search::Staged);
    assert!(r.converged, "{}", r.termination);
    // The noise level (this fit was also engine/tests/identify.rs's LuGre check).
    assert!(
        r.rms_residual <= 1.1 * NOISE,
        "rms {} vs noise {NOISE}",
        r.rms_residual
    );
    assert!(
        (noise_ratio(&r) - 1.0).abs() < 0.02,
        "rms {} vs noise {NOISE}",
        r.rms_residual
    );
    assert!(r.starts_at_best >= 1 && r.starts_at_best <= r.starts);
}

/// The force-domain prefit (opt-in, `prefit = true`) gives a local search a start from the
/// Eq. 7 force, and with it the fit of the 14 mm record reaches the noise level (when the
/// prefit was built, the default starts alone ended at mu_s < mu_c, 1.29 times the noise).
#[test]
fn the_prefit_start_brings_a_local_lugre_fit_to_the_noise_level() {
    let osc = Oscillator::fmm();
    let truth = lugre_truth();
    let recs = records(&osc, &truth, NOISE, 41);
    let opts = FitOptions {
        search: SearchOptions {
            strategy: Some(Search::Local),
            prefit: true,
            ..SearchOptions::default()
        },
        ..FitOptions::default()
    };
    let r = fit(&osc, &LuGre::default(), &recs[1..2], &opts).unwrap();
    let prefit = r
        .diagnostics
        .iter()
        .find(|d| d.check == frictionid_engine::identify::Check::Prefit)
        .expect("a prefit finding");
    eprintln!("{}; rms/noise {:.4}", prefit.message, noise_ratio(&r));
    assert!(r.converged, "{}", r.termination);
    assert!(
        (noise_ratio(&r) - 1.0).abs() < 0.02,
        "rms {}",
        r.rms_residual
    );
}

/// LuGre or Dahl on Coulomb records: converged, the sliding level within 0.5 % (and mu_c
/// within its statistics), and sigma0 a lower bound without a standard error.
fn presliding_is_a_lower_bound_on_coulomb_records(
    model: &(dyn FrictionModel + 'static),
) -> FitResult {
    let osc = Oscillator::fmm();
    let mu = 0.24;
    let recs = records(&osc, &Coulomb { mu }, NOISE, 51);
    let r = fit(&osc, model, &recs, &FitOptions::default()).unwrap();
    let sigma0 = r.param("sigma0").unwrap();
    eprintln!(
        "{} on coulomb: {}, mu_c {:?}, mu_s {:?}, v_s {:?}, sigma0 {:e} {:?} bound {:?}, rms/noise {:.4}",
        r.model,
        r.termination,
        r.param("mu_c"),
        r.param("mu_s"),
        r.param("v_s"),
        sigma0.value,
        sigma0.identifiability,
        sigma0.bound,
        noise_ratio(&r)
    );
    assert!(r.converged, "{}", r.termination);
    // The Coulomb level the records see: the fitted sliding force at 1 to 10 cm/s within
    // 0.5 % of mu N. mu_c itself is LuGre's level far above its Stribeck velocity; when the
    // records leave v_s free (not identifiable) it trades against mu_s and sigma2 and is held
    // to its own statistics: within 3 standard errors of the truth. (On the bundled fixture
    // cli/tests/fit_compare.rs holds mu_c itself to 0.5 %.)
    for v in [0.01, 0.03, 0.1] {
        let level = r.fitted_model.steady_state(v, osc.normal_force) / osc.normal_force;
        assert!(rel(level, mu) < 0.005, "sliding level {level} at {v} m/s");
    }
    let mu_c = r.param("mu_c").unwrap();
    match mu_c.std_error {
        Some(se) if mu_c.identifiability == Some(Identifiability::Determined) => {
            assert!((mu_c.value - mu).abs() <= 3.0 * se, "{mu_c:?}")
        }
        _ => assert!(mu_c.identifiability != Some(Identifiability::Determined)),
    }
    assert_eq!(sigma0.identifiability, Some(Identifiability::LowerBound));
    let bound = sigma0.bound.expect("a lower bound states its value");
    assert!(bound > 0.0 && bound <= sigma0.value);
    assert!(sigma0.std_error.is_none() && sigma0.ci95.is_none());
    for p in r.parameters.iter().filter(|p| p.free) {
        assert!(
            p.std_error.is_none_or(|s| s > 0.0),
            "{}: zero error",
            p.name
        );
    }
    assert!(r
        .diagnostics
        .iter()
        .any(|f| f.message.starts_with("sigma0 >") && f.message.contains("at 95 %")));
    r
}

#[test]
fn lugre_on_coulomb_records_bounds_sigma0_from_below() {
    presliding_is_a_lower_bound_on_coulomb_records(&LuGre::default());
}

/// Dahl's shape exponent acts only through presliding (any alpha gives Coulomb's law as
/// sigma0 grows): not identifiable when the records do not reject that limit.
#[test]
fn dahl_on_coulomb_records_bounds_sigma0_from_below() {
    let r = presliding_is_a_lower_bound_on_coulomb_records(&Dahl::default());
    let alpha = r.param("alpha").unwrap();
    assert_eq!(
        alpha.identifiability,
        Some(Identifiability::NotIdentifiable),
        "{alpha:?}"
    );
}

#[test]
fn dahl_is_recovered_from_its_own_records() {
    let osc = Oscillator::fmm();
    let truth = Dahl {
        sigma0: 2e4,
        mu_c: 0.21,
        alpha: 1.0,
    };
    let recs = records(&osc, &truth, NOISE, 61);
    let r = fit(&osc, &Dahl::default(), &recs, &FitOptions::default()).unwrap();
    let table = assert_recovered(&r, &truth);
    eprintln!("dahl: rms/noise {:.4}; {table}", noise_ratio(&r));
    assert!(r.converged, "{}", r.termination);
    assert!((noise_ratio(&r) - 1.0).abs() < 0.02);
    let sigma0 = r.param("sigma0").unwrap();
    assert_eq!(sigma0.identifiability, Some(Identifiability::Determined));
}

/// GMS recovered from its own records: two elements from the default configuration (every parameter
/// free, delta and sharpness too), the noise level and each determined parameter within 3
/// standard errors of the truth (the undamped elements' sigma_i are flagged, not determined).
/// It failed with finite-difference force gradients in the Rodas4 Jacobian (k_1 18 standard
/// errors off at rms/noise 1.006); with GMS's closed-form gradients the fit reaches 0.998 and
/// k_1 lies 1.6 standard errors from the truth. It is sensitive to the path: writing the state
/// Jacobian's d/dz in the gradients' algebraically equal form (m p / load for m load^(m-1))
/// made it fail again.
#[test]
fn gms_with_two_elements_is_recovered_from_its_own_records() {
    let osc = Oscillator::fmm();
    let truth = Gms {
        viscous: 1.0,
        ..two_element_gms()
    };
    let recs = records(&osc, &truth, NOISE, 71);
    let r = fit(&osc, &Gms::with_elements(2), &recs, &FitOptions::default()).unwrap();
    let table = assert_recovered(&r, &truth);
    eprintln!("gms: rms/noise {:.4}; {table}", noise_ratio(&r));
    assert!(r.converged, "{}", r.termination);
    assert!((noise_ratio(&r) - 1.0).abs() < 0.02);
}

/// Stiff bristles (sigma0 1e7, the stiff LuGre truth) from the default configuration (the
/// fits' simulations on `integrator = "auto"`: Rodas4 for these bristles): the noise level,
/// and sigma0 within a factor of 2 or a bound that contains the truth.
#[test]
fn stiff_lugre_is_recovered_or_bounded() {
    let osc = Oscillator::fmm();
    let recs = records(&osc, &stiff_lugre_truth(), NOISE, 81);
    let r = fit(&osc, &LuGre::default(), &recs, &FitOptions::default()).unwrap();
    eprintln!(
        "stiff lugre: rms/noise {:.4}, {:?}, sigma0 {:?}",
        noise_ratio(&r),
        r.termination,
        r.param("sigma0")
    );
    assert!((noise_ratio(&r) - 1.0).abs() < 0.05);
    let sigma0 = r.param("sigma0").unwrap();
    match (sigma0.identifiability, sigma0.bound) {
        (Some(Identifiability::Determined), _) => {
            assert!(sigma0.value > 5e6 && sigma0.value < 2e7)
        }
        (Some(Identifiability::LowerBound), Some(b)) => assert!(b < 1e7),
        (Some(Identifiability::UpperBound), Some(b)) => assert!(b > 1e7),
        other => panic!("sigma0 {other:?}"),
    }
}
