//! Goodness of fit: each record's residual RMS against the noise floor of its residuals.
//!
//! A law that follows the record leaves residuals that are the measurement's noise; a law
//! that cannot leaves a slow, motion-locked misfit on top of it. The noise floor is
//! estimated from the residuals' first differences, where the misfit (smooth at the sample
//! scale) vanishes and the noise stays: the median absolute first difference gives
//! sigma sqrt(1 - phi) for AR(1) noise of lag-1 correlation phi, and the first differences'
//! own lag-1 correlation, -(1 - phi) / 2, gives phi
//! ([`diagnostics::noise_correlation`]): coloured noise is not mistaken for a misfit. The
//! estimate's uncertainty (the lag-1 correlation of n differences is known to about
//! 2 / sqrt(n)) is granted to the fit, a quantised channel's floor is at least its step over
//! sqrt(12), and a noise level the record gives (`<channel>_noise`) raises the floor.
//!
//! The ratio passes up to [`FIT_WARN_RATIO`], warns up to [`FIT_FAIL_RATIO`] and fails
//! above; residuals at the simulations' numerical floor pass (a noise-free record).
//! Residuals smoother than any noise at the sample scale (low-pass filtered records, or a
//! misfit that hides the noise: [`SMOOTH_RESIDUALS`]) give only a lower bound of the floor,
//! so their ratio warns at most.
//!
//! A force compared along the measured motion is judged where the sampled motion defines it:
//! the samples within two of a change of the velocity's sign are set aside, since a switched law's
//! force there follows the sign of a velocity the noise decides (a correct Coulomb law
//! replayed along a differentiated displacement leaves a full 2 F_c step at such a sample).

use super::diagnostics::{self, NUMERICAL_FLOOR, SMOOTH_RESIDUALS};
use crate::identify::values::outcome::{Check, Finding, Status};
use crate::identify::values::result::RecordFit;
use crate::record::noise::{difference_noise, quantisation_step, rms_difference_noise};

/// A residual RMS above this many noise floors warns: the law leaves a misfit.
pub(crate) const FIT_WARN_RATIO: f64 = 2.0;
/// ... and above this many fails: the law does not follow the record.
pub(crate) const FIT_FAIL_RATIO: f64 = 4.0;
/// Fewer residuals than this cannot give a noise floor.
pub(crate) const MIN_SAMPLES: usize = 20;
/// The samples set aside on each side of a change of the velocity's sign (a force compared
/// along the motion): the noise can shift the sampled reversal by a sample or two.
const REVERSAL_BAND: usize = 2;
/// The largest lag-1 noise correlation granted (its correction is at most 10x).
const MAX_CORRELATION: f64 = 0.99;

/// How one record's residual compares with its noise floor.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum RecordGoodness {
    /// Residual RMS over the noise floor, with both.
    Ratio {
        /// The residual RMS.
        rms: f64,
        /// The noise floor.
        floor: f64,
        /// The noise's lag-1 correlation granted.
        phi: f64,
        /// Whether the residuals are smoother than noise (the floor is a lower bound).
        smooth: bool,
    },
    /// Residuals at the simulations' numerical floor (this share of the response).
    Numerical(f64),
    /// The floor cannot be estimated, and why.
    Unknown(String),
}

/// The noise floor of `residual` (see the module docs) and the lag-1 correlation granted,
/// at least `given` and the step of `measured` over sqrt(12) when quantised; `None` with
/// too few samples or residuals without differences.
pub(crate) fn noise_floor(
    residual: &[f64],
    measured: &[f64],
    given: Option<f64>,
) -> Option<(f64, f64)> {
    let n = residual.len();
    if n < MIN_SAMPLES {
        return None;
    }
    let mut first = difference_noise(residual, 1);
    if first <= 0.0 {
        // Mostly repeated values (a quantised channel at rest): the RMS counts the rest.
        first = rms_difference_noise(residual, 1);
    }
    let phi = diagnostics::noise_correlation(&[residual]);
    let granted = (phi + 2.0 / (n as f64).sqrt()).clamp(0.0, MAX_CORRELATION);
    let coloured = first / (1.0 - granted).sqrt();
    let quantum = quantisation_step(measured).map_or(0.0, |q| q / 12f64.sqrt());
    let floor = coloured.max(quantum).max(given.unwrap_or(0.0));
    (floor.is_finite() && floor > 0.0).then_some((floor, granted))
}

/// The goodness of fit of one record's compared channel (its first), with `given` the
/// noise level the record gives for it.
pub(crate) fn record_goodness(fit: &RecordFit, given: Option<f64>) -> RecordGoodness {
    let (measured, fitted) = defined_samples(fit);
    let residual: Vec<f64> = fitted.iter().zip(&measured).map(|(f, m)| f - m).collect();
    let rms = root_mean_square(&residual);
    let response = root_mean_square(&fitted).max(root_mean_square(&measured));
    if response > 0.0 && rms <= NUMERICAL_FLOOR * response {
        return RecordGoodness::Numerical(rms / response);
    }
    match noise_floor(&residual, &measured, given) {
        Some((floor, phi)) => RecordGoodness::Ratio {
            rms,
            floor,
            phi,
            smooth: diagnostics::residual_smoothness(&[&residual]) >= SMOOTH_RESIDUALS,
        },
        None => RecordGoodness::Unknown(format!(
            "{} residuals, too few (or too uniform) to estimate a noise floor",
            residual.len()
        )),
    }
}

/// The measured and fitted values of `fit` where its compared quantity is defined by the
/// sampled motion: a force compared along the motion loses the samples within
/// [`REVERSAL_BAND`] of a change of the velocity's sign (module docs); any other channel
/// keeps every sample.
fn defined_samples(fit: &RecordFit) -> (Vec<f64>, Vec<f64>) {
    let (measured, fitted) = (&fit.series.measured, &fit.series.fitted);
    let v = &fit.axes.velocity;
    if !fit.channel.ends_with("force") || v.len() != measured.len() || v.len() < 2 {
        return (measured.clone(), fitted.clone());
    }
    let mut defined = vec![true; v.len()];
    for i in 1..v.len() {
        if v[i - 1] * v[i] <= 0.0 {
            let band = i.saturating_sub(REVERSAL_BAND)..(i + REVERSAL_BAND).min(v.len());
            defined[band].iter_mut().for_each(|d| *d = false);
        }
    }
    (0..v.len())
        .filter(|&i| defined[i])
        .filter_map(|i| Some((*measured.get(i)?, *fitted.get(i)?)))
        .unzip()
}

fn root_mean_square(values: &[f64]) -> f64 {
    (values.iter().map(|v| v * v).sum::<f64>() / values.len().max(1) as f64).sqrt()
}

fn status_of(ratio: f64, smooth: bool) -> Status {
    if ratio > FIT_FAIL_RATIO && !smooth {
        Status::Fail
    } else if ratio > FIT_WARN_RATIO {
        Status::Warn
    } else {
        Status::Pass
    }
}

/// A judged record: its name, compared channel and unit, and its [`RecordGoodness`].
pub(crate) type JudgedRecord = (String, String, String, RecordGoodness);

/// The goodness-of-fit finding over the records: `judged` holds each record's name, its
/// compared channel and unit, and its [`RecordGoodness`]. The worst judged record decides;
/// with none judged, the finding is skipped with the reasons.
pub(crate) fn goodness_of_fit(judged: &[JudgedRecord]) -> Finding {
    let mut worst: Option<(f64, Status, String)> = None;
    let mut flagged = Vec::new();
    let mut skipped = Vec::new();
    let mut numerical = None::<f64>;
    for (record, channel, unit, g) in judged {
        match g {
            RecordGoodness::Ratio {
                rms,
                floor,
                phi,
                smooth,
            } => {
                let ratio = rms / floor;
                let status = status_of(ratio, *smooth);
                let bound = if *smooth {
                    ", a lower bound: the residuals are smoother than noise at the sample scale (filtered data, or a misfit that hides the noise), so it warns at most"
                } else {
                    ""
                };
                let line = format!(
                    "record `{record}`: {channel} residual RMS {rms:.3e} {unit} is {ratio:.2} times its noise floor {floor:.3e} {unit} (noise lag-1 correlation {phi:.2} allowed{bound})"
                );
                if status != Status::Pass {
                    flagged.push(line.clone());
                }
                if worst
                    .as_ref()
                    .is_none_or(|(w, s, _)| (status, ratio) > (*s, *w))
                {
                    worst = Some((ratio, status, line));
                }
            }
            RecordGoodness::Numerical(share) => {
                numerical = Some(numerical.map_or(*share, |s: f64| s.max(*share)));
            }
            RecordGoodness::Unknown(why) => skipped.push(format!("record `{record}`: {why}")),
        }
    }
    let not_judged = if skipped.is_empty() {
        String::new()
    } else {
        format!(" (not judged: {})", skipped.join("; "))
    };
    let Some((ratio, status, line)) = worst else {
        if let Some(share) = numerical {
            return Finding::new(
                Check::GoodnessOfFit,
                Status::Pass,
                Some(0.0),
                format!(
                    "residuals are {share:.1e} of the response, at the simulations' numerical floor: the law follows the noise-free records{not_judged}"
                ),
            );
        }
        return Finding::skipped(
            Check::GoodnessOfFit,
            format!(
                "no noise floor to judge the residuals against: {}",
                skipped.join("; ")
            ),
        );
    };
    let message = match status {
        Status::Pass => format!("residuals are at the noise floor: worst {line}{not_judged}"),
        Status::Warn => format!(
            "{}: the law leaves a misfit above the noise (a law that does not quite follow the record, or a local optimum){not_judged}",
            flagged.join("; ")
        ),
        _ => format!(
            "{}: the law does not follow the record (a wrong law, a local optimum, wrong units or an unmodelled input){not_judged}",
            flagged.join("; ")
        ),
    };
    Finding::new(Check::GoodnessOfFit, status, Some(ratio), message)
}

/// The judged record of `fit`: its name, channel, unit and goodness, with `given` the noise
/// level the record gives for its channel.
pub(crate) fn judged_record(fit: &RecordFit, given: Option<f64>) -> JudgedRecord {
    let unit = fit
        .channels
        .first()
        .map_or_else(String::new, |c| c.unit.clone());
    (
        fit.file.clone(),
        fit.channel.clone(),
        unit,
        record_goodness(fit, given),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::assessment::fixtures::{ar1_noise as ar1, record_fit_of};

    fn record(channel: &str, measured: Vec<f64>, fitted: Vec<f64>) -> RecordFit {
        record_fit_of(channel, 0.0, Vec::new(), measured, fitted)
    }

    fn fit_of(signal: &[f64], noise: &[f64], misfit: &[f64]) -> RecordFit {
        let measured: Vec<f64> = signal.iter().zip(noise).map(|(s, e)| s + e).collect();
        let fitted: Vec<f64> = signal.iter().zip(misfit).map(|(s, d)| s + d).collect();
        record("velocity", measured, fitted)
    }

    fn sine(n: usize, amplitude: f64, cycles: f64) -> Vec<f64> {
        (0..n)
            .map(|i| amplitude * (std::f64::consts::TAU * cycles * i as f64 / n as f64).sin())
            .collect()
    }

    fn ratio(g: &RecordGoodness) -> f64 {
        match g {
            RecordGoodness::Ratio { rms, floor, .. } => rms / floor,
            other => panic!("{other:?}"),
        }
    }

    /// A Coulomb force along a noisy velocity: where the noise flips the velocity's sign next
    /// to a reversal the fitted force steps by 2 F_c, a sample the motion does not define;
    /// set aside, the correct law passes, and a missing viscous term still fails.
    #[test]
    fn a_force_is_judged_where_the_motion_defines_its_sign() {
        let n = 2000;
        let v: Vec<f64> = sine(n, 0.01, 8.0)
            .iter()
            .zip(ar1(n, 1e-4, 0.0, 11))
            .map(|(v, e)| v + e)
            .collect();
        let noise = ar1(n, 0.05, 0.0, 12);
        let truth: Vec<f64> = sine(n, 0.01, 8.0)
            .iter()
            .map(|v| 3.0 * v.signum())
            .collect();
        let along = |viscous: f64| -> Vec<f64> {
            v.iter().map(|v| 3.0 * v.signum() + viscous * v).collect()
        };
        let measured: Vec<f64> = truth.iter().zip(&noise).map(|(t, e)| t + e).collect();
        let mut fit = record("force", measured, along(0.0));
        fit.axes.velocity = v.clone();
        assert!(fit.series.fitted.iter().zip(&truth).any(|(f, t)| f != t));
        assert_eq!(
            goodness_of_fit(&[judged_record(&fit, None)]).status,
            Status::Pass
        );
        // The record's force has a viscous term the fitted law lacks.
        let measured: Vec<f64> = along(100.0)
            .iter()
            .zip(&noise)
            .map(|(t, e)| t + e)
            .collect();
        let mut wrong = record("force", measured, along(0.0));
        wrong.axes.velocity = v;
        assert_eq!(
            goodness_of_fit(&[judged_record(&wrong, None)]).status,
            Status::Fail
        );
    }

    /// White and AR(1) noise (0.6, 0.9, 0.95) around the right curve pass: the ratio stays
    /// below 1.5 for every seed (and above 0.3: the allowance for the colour's uncertainty
    /// lowers it most for the most strongly coloured noise).
    #[test]
    fn noise_alone_passes_whatever_its_colour() {
        let signal = sine(3000, 0.3, 3.0);
        let zero = vec![0.0; 3000];
        for (seed, phi) in [(1, 0.0), (2, 0.6), (3, 0.9), (4, 0.95), (5, 0.0), (6, 0.9)] {
            let fit = fit_of(&signal, &ar1(3000, 2e-4, phi, seed), &zero);
            let r = ratio(&record_goodness(&fit, None));
            assert!((0.3..1.5).contains(&r), "phi {phi}: {r}");
            let f = goodness_of_fit(&[judged_record(&fit, None)]);
            assert_eq!(f.status, Status::Pass, "{}", f.message);
        }
    }

    /// A slow misfit of 6 noise levels on white noise fails; of 3, warns; a given noise level
    /// that covers it passes.
    #[test]
    fn a_misfit_above_the_noise_warns_or_fails() {
        let signal = sine(3000, 0.3, 3.0);
        let noise = ar1(3000, 2e-4, 0.0, 9);
        let six = fit_of(&signal, &noise, &sine(3000, 6.0 * 2e-4 * 2f64.sqrt(), 6.0));
        let f = goodness_of_fit(&[judged_record(&six, None)]);
        assert_eq!(f.status, Status::Fail, "{}", f.message);
        assert!(f.value.unwrap() > 5.0, "{}", f.message);
        let three = fit_of(&signal, &noise, &sine(3000, 3.0 * 2e-4 * 2f64.sqrt(), 6.0));
        let f = goodness_of_fit(&[judged_record(&three, None)]);
        assert_eq!(f.status, Status::Warn, "{}", f.message);
        let f = goodness_of_fit(&[judged_record(&three, Some(1e-3))]);
        assert_eq!(f.status, Status::Pass, "{}", f.message);
    }

    /// Low-pass filtered noise around a misfit of 10 floors: smoother than noise, so the
    /// floor is a lower bound and the finding warns, not fails; the same misfit on white
    /// noise fails.
    #[test]
    fn residuals_smoother_than_noise_warn_at_most() {
        let signal = sine(3000, 0.3, 3.0);
        let white = ar1(3000, 2e-4, 0.0, 12);
        let filtered: Vec<f64> = (0..3000)
            .map(|i: usize| white[i.saturating_sub(15)..=i].iter().sum::<f64>() / 16.0)
            .collect();
        let misfit = sine(3000, 10.0 * 2e-4, 6.0);
        let f = goodness_of_fit(&[judged_record(&fit_of(&signal, &filtered, &misfit), None)]);
        assert_eq!(f.status, Status::Warn, "{}", f.message);
        assert!(f.message.contains("lower bound"), "{}", f.message);
        let f = goodness_of_fit(&[judged_record(&fit_of(&signal, &white, &misfit), None)]);
        assert_eq!(f.status, Status::Fail, "{}", f.message);
    }

    /// A quantised channel (counts of 5 um, long rests) is judged against its step; a
    /// noise-free record at round-off passes; too short a record is skipped.
    #[test]
    fn quantised_noise_free_and_short_records() {
        let q = 5e-6;
        let x: Vec<f64> = (0..3000)
            .map(|i| {
                if i < 1500 {
                    0.01 * (i as f64 * 0.01).cos()
                } else {
                    1e-3
                }
            })
            .collect();
        let counts: Vec<f64> = x.iter().map(|v| (v / q).round() * q).collect();
        let fit = record("displacement", counts, x.clone());
        let f = goodness_of_fit(&[judged_record(&fit, None)]);
        assert_eq!(f.status, Status::Pass, "{}", f.message);
        let clean = fit_of(&x, &vec![1e-15; 3000], &vec![0.0; 3000]);
        let f = goodness_of_fit(&[judged_record(&clean, None)]);
        assert_eq!(f.status, Status::Pass, "{}", f.message);
        assert!(f.message.contains("numerical floor"), "{}", f.message);
        let short = fit_of(&x[..5], &ar1(5, 1e-4, 0.0, 1), &[0.0; 5]);
        let f = goodness_of_fit(&[judged_record(&short, None)]);
        assert_eq!(f.status, Status::Skipped, "{}", f.message);
    }
}
