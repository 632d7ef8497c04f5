//! The verdict of a comparison: the law to use. It is the simplest law whose held-out error
//! is within the folds' noise of the best held-out error, among laws with nothing against
//! them (a search that did not converge, a free parameter the data leave unidentifiable, or
//! physically inconsistent values); information criteria are shown as information.

use super::validation::{spread, LawValidation};
use crate::identify::assessment::diagnostics::noise_correlation;
use crate::identify::values::layout::is_friction_level;
use crate::identify::values::result::{FitResult, Identifiability};
use serde::Serialize;

/// A held-out error within this share of the best is within its noise whatever the folds say.
pub(crate) const VALIDATION_FLOOR: f64 = 0.01;

/// A law the verdict does not recommend, and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SetAside {
    /// The law.
    pub model: String,
    /// Why.
    pub reason: String,
}

/// What stands against recommending `fit` (`None` when nothing does).
pub(crate) fn set_aside_reason(fit: &FitResult) -> Option<String> {
    if !fit.converged {
        return Some(format!("its search did not converge ({})", fit.termination));
    }
    let unidentified: Vec<&str> = fit
        .parameters
        .iter()
        .filter(|p| p.free && p.identifiability == Some(Identifiability::NotIdentifiable))
        .map(|p| p.name.as_str())
        .collect();
    if !unidentified.is_empty() {
        return Some(format!(
            "the data do not identify {}",
            unidentified
                .iter()
                .map(|n| format!("`{n}`"))
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    inconsistency(fit)
}

/// A physically inconsistent value of `fit`: a static level below the Coulomb level, a
/// negative friction level, a Stribeck velocity below the records' velocity resolution.
fn inconsistency(fit: &FitResult) -> Option<String> {
    let value = |name: &str| {
        fit.parameters
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.value)
    };
    if let (Some(s), Some(c)) = (value("mu_s"), value("mu_c")) {
        if s < c {
            return Some(format!(
                "its static level mu_s = {s:.4e} is below its Coulomb level mu_c = {c:.4e} (friction rising with speed near zero)"
            ));
        }
    }
    if let Some(p) = fit
        .parameters
        .iter()
        .find(|p| p.value < 0.0 && is_friction_level(&p.name, &p.unit))
    {
        return Some(format!(
            "its level `{}` = {:.4e} is negative",
            p.name, p.value
        ));
    }
    let resolution = velocity_resolution(fit);
    match value("v_s") {
        Some(v_s) if v_s.abs() < resolution => {
            let unit = fit.oscillator.axis.unit("m/s");
            Some(format!(
                "its Stribeck velocity v_s = {v_s:.3e} {unit} is below the records' velocity resolution {resolution:.3e} {unit}"
            ))
        }
        _ => None,
    }
}

/// The smallest step between consecutive velocity samples of the fit's records (0 when
/// none is known): the finest speed the records resolve.
fn velocity_resolution(fit: &FitResult) -> f64 {
    let step = fit
        .records
        .iter()
        .flat_map(|r| r.axes.velocity.windows(2).map(|w| (w[1] - w[0]).abs()))
        .filter(|d| *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    if step.is_finite() {
        step
    } else {
        0.0
    }
}

/// Whether `law`'s held-out error is within the folds' noise of `best`'s: the mean of their
/// fold-wise differences is at most its standard error (the one-standard-error rule, on
/// paired folds), or within [`VALIDATION_FLOOR`] of the best.
pub(crate) fn within_noise(law: &LawValidation, best: &LawValidation) -> bool {
    let (Some(l), Some(b)) = (law.validation_rms, best.validation_rms) else {
        return false;
    };
    if l <= b * (1.0 + VALIDATION_FLOOR) {
        return true;
    }
    let diffs: Vec<f64> = law
        .folds
        .iter()
        .zip(&best.folds)
        .map(|(a, c)| a - c)
        .collect();
    if diffs.len() < 2 {
        return false;
    }
    let mean = diffs.iter().sum::<f64>() / diffs.len() as f64;
    mean <= spread(&diffs) / (diffs.len() as f64).sqrt()
}

/// Why the information criteria are shown only as information: the lag-one correlation of
/// `best`'s residuals and the effective sample size it leaves.
pub(crate) fn information_note(best: &FitResult) -> String {
    let residuals: Vec<Vec<f64>> = best
        .records
        .iter()
        .map(|r| {
            r.series
                .measured
                .iter()
                .zip(&r.series.fitted)
                .map(|(m, f)| m - f)
                .collect()
        })
        .collect();
    let phi = noise_correlation(&residuals);
    let n = best.samples as f64;
    let n_eff = (n * (1.0 - phi) / (1.0 + phi)).max(1.0);
    format!(
        "AIC and BIC count {} samples as independent; the residuals' lag-one correlation {phi:.2} leaves about {n_eff:.0} effective samples, and samples the law cannot follow weigh in full: they are shown as information, the recommendation rests on held-out validation",
        best.samples
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scored(model: &str, folds: &[f64]) -> LawValidation {
        let n = folds.len() as f64;
        let rms = (folds.iter().map(|f| f * f).sum::<f64>() / n).sqrt();
        LawValidation {
            model: model.into(),
            validation_rms: Some(rms),
            validation_rms_spread: Some(spread(folds)),
            folds: folds.to_vec(),
            error: None,
        }
    }

    #[test]
    fn a_law_worse_on_every_fold_by_more_than_the_folds_scatter_is_not_within_noise() {
        let best = scored("best", &[1.0, 2.0, 3.0]);
        // Paired differences 0.5, 0.6, 0.4: mean 0.5, standard error 0.058.
        assert!(!within_noise(&scored("worse", &[1.5, 2.6, 3.4]), &best));
        // Differences -0.3, 0.6, 0.0: mean 0.1, standard error 0.26.
        assert!(within_noise(&scored("scattered", &[0.7, 2.6, 3.0]), &best));
        // Within 1 % of the best's RMS whatever the folds say.
        assert!(within_noise(&scored("close", &[1.01, 2.01, 3.01]), &best));
    }

    #[test]
    fn a_law_without_a_score_is_never_within_noise() {
        let best = scored("best", &[1.0, 2.0]);
        let unscored = LawValidation {
            validation_rms: None,
            ..scored("x", &[1.0, 2.0])
        };
        assert!(!within_noise(&unscored, &best));
    }
}
