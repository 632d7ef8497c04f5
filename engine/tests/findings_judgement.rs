//! Findings that neither cry wolf nor pass vacuously, on records the engine simulated with
//! known truths: a noise-free record fitted by its own law to round-off raises no
//! correlation warning and passes the goodness of fit, while a wrong law on the same kind of
//! record is still told apart (the goodness of fit and the correlation of its residuals
//! flag it).

use crate::util::{lugre_truth, records};
use frictionid_engine::identify::{fit, Check, FitOptions, FitResult, Status};
use frictionid_engine::Oscillator;
use frictionid_models::Coulomb;

fn status(result: &FitResult, check: Check) -> Vec<Status> {
    result
        .diagnostics
        .iter()
        .filter(|d| d.check == check)
        .map(|d| d.status)
        .collect()
}

#[test]
fn a_noise_free_record_at_round_off_raises_no_correlation_warning() {
    let osc = Oscillator::fmm();
    let recs = records(&osc, &Coulomb { mu: 0.24 }, 0.0, 1);
    let r = fit(&osc, &Coulomb { mu: 0.2 }, &recs, &FitOptions::default()).unwrap();
    assert!(r.rms_residual < 1e-8, "{}", r.rms_residual);
    assert!(
        !status(&r, Check::NoiseCorrelation).contains(&Status::Warn),
        "{:?}",
        r.diagnostics
    );
    assert_eq!(status(&r, Check::GoodnessOfFit), [Status::Pass]);
}

#[test]
fn a_wrong_law_on_a_noise_free_record_is_still_flagged() {
    let osc = Oscillator::fmm();
    let recs = records(&osc, &lugre_truth(), 0.0, 1);
    let r = fit(&osc, &Coulomb { mu: 0.2 }, &recs, &FitOptions::default()).unwrap();
    let goodness = status(&r, Check::GoodnessOfFit);
    assert!(
        matches!(goodness[..], [Status::Warn | Status::Fail]),
        "{:?}",
        r.diagnostics
    );
}
