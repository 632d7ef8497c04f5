//! Diagnostics on every fit: each check turns part of a fit into a [`Finding`] with a pass,
//! warn or fail status, so that a result that cannot be trusted says so.
//!
//! - Energy balance: the model's mean force against Eq. 7's over the same samples, and the
//!   energy the model dissipates over the half-cycles along the measured motion against the
//!   energy the record loses there: warn above [`ENERGY_WARN_PERCENT`], fail above
//!   [`ENERGY_FAIL_PERCENT`]; a part the record cannot support is skipped with its reason
//!   (both skipped: the finding is `skipped`).
//! - Residual structure: residuals locked to the motion (correlated with sgn v or x, repeating
//!   with the oscillation period, or with a mean) betray a wrong model, an offset or a missed
//!   release. Significance is judged with the effective sample size of autocorrelated
//!   residuals, so coloured measurement noise alone (correlated over short lags only) passes
//!   or at most warns; a failure also needs a large effect ([`STRUCTURE_FAIL_EFFECT`]).
//! - Parameters at a bound, standard errors that cannot be computed, starts that disagree,
//!   non-convergence.

use super::identifiability::{slots_without_effect, PROFILE_DELTA};
use super::stats::autocorrelation;
use crate::axis::Axis;
use crate::energy::cumulative_trapezoid;
use crate::identify::values::layout::{is_friction_level, FreeParam, ParamKind};
use crate::identify::values::outcome::{Check, Finding, StartOutcome, Status, TerminationReason};
use crate::identify::values::result::EnergyForce;
use crate::identify::values::result::{FittedParam, RecordFit};
use crate::oscillator::Oscillator;
use crate::record::noise::{difference_noise, quantisation_step, RESPONSE_ORDER};

/// An energy-balance difference above this many percent warns.
pub(crate) const ENERGY_WARN_PERCENT: f64 = 5.0;
/// An energy-balance difference above this many percent fails.
pub(crate) const ENERGY_FAIL_PERCENT: f64 = 20.0;
/// A residual-structure statistic (in standard errors under no structure, with the effective
/// sample size) above this warns.
pub(crate) const STRUCTURE_WARN_Z: f64 = 4.0;
/// ... and above this fails, when the effect is also at least [`STRUCTURE_FAIL_EFFECT`].
pub(crate) const STRUCTURE_FAIL_Z: f64 = 5.0;
/// The smallest correlation (or mean / RMS) that fails the residual-structure check.
pub(crate) const STRUCTURE_FAIL_EFFECT: f64 = 0.3;
/// A converged start whose SSR exceeds the best by more than this many residual variances
/// ended in a different minimum.
pub(crate) const START_DISAGREEMENT: f64 = 4.0;

fn status_of(value: f64, warn: f64, fail: f64) -> Status {
    if value > fail {
        Status::Fail
    } else if value > warn {
        Status::Warn
    } else {
        Status::Pass
    }
}

/// The energy-balance finding of one record: the larger of the Eq. 7 and the dissipated
/// energy differences (in percent) decides among the parts that can judge; with neither,
/// the finding is skipped with the reasons. Forces in the units of `axis`.
pub(crate) fn energy_balance(record: &str, ef: &EnergyForce, axis: Axis) -> Finding {
    let eq7 = ef.percent_difference.abs();
    let energies = ef.dissipation_percent_difference.abs();
    let judged = [
        (eq7, ef.eq7_skipped.is_none()),
        (energies, ef.dissipation_skipped.is_none()),
    ];
    let worst = judged
        .iter()
        .filter(|(d, judged)| *judged && !d.is_nan())
        .map(|(d, _)| *d)
        .fold(f64::NAN, f64::max);
    let skipped = energy_skips(ef, axis);
    if worst.is_nan() {
        let why = if skipped.is_empty() {
            "neither comparison is defined".to_string()
        } else {
            skipped.join("; ")
        };
        return Finding::skipped(
            Check::EnergyBalance,
            format!("record `{record}`: the energy balance cannot judge this record: {why}"),
        );
    }
    let status = status_of(worst, ENERGY_WARN_PERCENT, ENERGY_FAIL_PERCENT);
    let not_judged = if skipped.is_empty() {
        String::new()
    } else {
        format!(" (not judged: {})", skipped.join("; "))
    };
    let n = axis.unit("N");
    let message = format!(
        "record `{record}`: energy-based friction differs from the model's by {:.1} % (Eq. 7 mean {:.4} {n} vs {:.4} {n}) and {:.1} % (energy dissipated over {} half-cycles {:.4e} J vs {:.4e} J){not_judged}{}",
        ef.percent_difference,
        ef.mean_abs,
        ef.reference,
        ef.dissipation_percent_difference,
        ef.half_cycles,
        ef.dissipated,
        ef.model_dissipated,
        match status {
            Status::Pass | Status::Skipped => "",
            Status::Warn => ": the fitted law does not quite dissipate the energy the record loses",
            Status::Fail => ": the fitted law does not explain the energy the record loses (wrong units, model, offset or release?)",
        }
    );
    Finding::new(Check::EnergyBalance, status, Some(worst), message)
}

/// The parts of an energy check that could not judge, each with its reason in the units of
/// `axis`.
fn energy_skips(ef: &EnergyForce, axis: Axis) -> Vec<String> {
    [
        ("Eq. 7", &ef.eq7_skipped),
        ("dissipated energy", &ef.dissipation_skipped),
    ]
    .into_iter()
    .filter_map(|(part, skip)| {
        skip.as_ref()
            .map(|s| format!("{part}: {}", s.describe(axis)))
    })
    .collect()
}

/// Lag-1 correlation (from the residuals' differences, [`residual_smoothness`]) at or above
/// which the residuals are smoother than measurement noise: a model error (or low-pass
/// filtered data), reported as such instead of corrected for.
pub(crate) const SMOOTH_RESIDUALS: f64 = 0.98;

/// The lag-1 correlation phi of the noise in the residuals, assuming AR(1) noise, from the
/// residuals' first differences (for AR(1), their lag-1 autocorrelation is -(1 - phi) / 2).
/// Differencing removes the slow, motion-locked part, which would otherwise pass for
/// strongly coloured noise and hide itself.
pub(crate) fn noise_correlation<S: AsRef<[f64]>>(segments: &[S]) -> f64 {
    residual_smoothness(segments).clamp(0.0, 0.999)
}

/// 1 + 2 times the lag-1 autocorrelation of the residuals' first differences: the lag-1
/// correlation of AR(1) noise ([`noise_correlation`] unclamped). Above 1 (differences
/// positively correlated) no AR(1) noise can explain the residuals: they are smoother than
/// noise at the sample scale.
pub(crate) fn residual_smoothness<S: AsRef<[f64]>>(segments: &[S]) -> f64 {
    let differences: Vec<Vec<f64>> = segments
        .iter()
        .map(|s| s.as_ref().windows(2).map(|w| w[1] - w[0]).collect())
        .collect();
    1.0 + 2.0 * autocorrelation(&differences, 1)
}

/// The lag-1 autocorrelation of residual segments (pairs within a segment only).
pub(crate) fn lag_one_correlation<S: AsRef<[f64]>>(segments: &[S]) -> f64 {
    autocorrelation(segments, 1)
}

/// Pearson correlation of already demeaned series `a` and `b` of the moving parts, pooled
/// (from the sums over the parts: nothing is copied).
fn pooled_correlation(
    moving: &[Moving],
    a: fn(&Moving) -> &[f64],
    b: fn(&Moving) -> &[f64],
) -> f64 {
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for m in moving {
        let (a, b) = (a(m), b(m));
        sab += a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        saa += a.iter().map(|x| x * x).sum::<f64>();
        sbb += b.iter().map(|y| y * y).sum::<f64>();
    }
    if saa > 0.0 && sbb > 0.0 {
        sab / (saa * sbb).sqrt()
    } else {
        0.0
    }
}

/// `v` less its mean (in place: on a long record each series is as large as the record).
fn demeaned(mut v: Vec<f64>) -> Vec<f64> {
    let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
    v.iter_mut().for_each(|x| *x -= mean);
    v
}

/// Noise levels of the velocity read above which a sample counts as moving.
pub(crate) const MOVING_NOISE_LEVELS: f64 = 5.0;

/// The speed above which a record's velocity `v` counts as moving: the `configured`
/// threshold, raised to [`MOVING_NOISE_LEVELS`] noise levels of `v` (from its third
/// differences, blind to the motion: a noisy velocity's rest is not motion); on a record
/// that never moves faster than that (a slow tribometer stroke) the noise levels alone, at
/// least 1e-3 of its top speed.
fn moving_threshold(v: &[f64], configured: f64) -> f64 {
    let noise = MOVING_NOISE_LEVELS * difference_noise(v, RESPONSE_ORDER);
    let top = v.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let raised = configured.max(noise);
    if top > raised {
        raised
    } else {
        noise.max(1e-3 * top)
    }
}

/// The moving part of a record fit: from its first sample to the last one whose fitted speed
/// exceeds `threshold` ([`moving_threshold`]).
struct Moving {
    residual: Vec<f64>,
    sign: Vec<f64>,
    x: Vec<f64>,
    period_samples: usize,
}

fn moving_part(r: &RecordFit, osc: &Oscillator, threshold: f64) -> Result<Moving, String> {
    let (v, x) = motion_of(r)?;
    let threshold = moving_threshold(&v, threshold);
    let Some(last) = v.iter().rposition(|v| v.abs() > threshold) else {
        return Err(format!(
            "record `{}` never moves faster than {threshold:e}",
            r.file
        ));
    };
    let end = last + 1;
    if end < 3 || r.axes.time.len() < end || r.series.measured.len() < end {
        return Err(format!("record `{}` moves over too few samples", r.file));
    }
    let residual: Vec<f64> = (0..end)
        .map(|i| r.series.fitted[i] - r.series.measured[i])
        .collect();
    within_quantisation(r, &residual)?;
    let dt = (r.axes.time[end - 1] - r.axes.time[0]) / (end - 1) as f64;
    let wd = osc.omega_n() * (1.0 - osc.damping_ratio().powi(2)).max(0.0).sqrt();
    let period = 2.0 * std::f64::consts::PI / wd / dt;
    Ok(Moving {
        residual: demeaned(residual),
        sign: demeaned(v[..end].iter().map(|v| v.signum()).collect()),
        x: demeaned(x[..end].to_vec()),
        period_samples: if period.is_finite() && period >= 1.0 {
            period.round() as usize
        } else {
            0
        },
    })
}

/// The reason a record's residuals cannot be judged when they lie within its channel's
/// quantisation step (an encoder's counts): the rounding error of a noise-free channel is
/// locked to the motion by construction.
fn within_quantisation(r: &RecordFit, residual: &[f64]) -> Result<(), String> {
    let Some(step) = quantisation_step(&r.series.measured) else {
        return Ok(());
    };
    let rms = (residual.iter().map(|e| e * e).sum::<f64>() / residual.len().max(1) as f64).sqrt();
    if rms <= step {
        return Err(format!(
            "record `{}`: its residuals (RMS {rms:.3e}) lie within the channel's quantisation step {step:.3e}, whose rounding error follows the motion by construction",
            r.file
        ));
    }
    Ok(())
}

/// The velocity and displacement of a record fit's motion, sample by sample: the fitted
/// series where it is the velocity (with its integral) or the displacement (with its
/// derivative), else the motion the record's sample axes give (a fit along the measured
/// motion); the reason when none is known.
fn motion_of(r: &RecordFit) -> Result<(Vec<f64>, Vec<f64>), String> {
    let n = r.series.fitted.len();
    let time = &r.axes.time;
    if time.len() < n {
        return Err(format!("record `{}` has no time for its samples", r.file));
    }
    match r.channel.as_str() {
        "velocity" => {
            let x = cumulative_trapezoid(&time[..n], &r.series.fitted, r.x0);
            return Ok((r.series.fitted.clone(), x));
        }
        "displacement" => {
            let v = derivative(&time[..n], &r.series.fitted);
            return Ok((v, r.series.fitted.clone()));
        }
        _ => {}
    }
    let axes = &r.axes;
    if axes.velocity.len() != n {
        return Err(format!(
            "record `{}` compares `{}` without the motion's velocity",
            r.file, r.channel
        ));
    }
    let x = if axes.displacement.len() == n {
        axes.displacement.clone()
    } else {
        cumulative_trapezoid(&time[..n], &axes.velocity, 0.0)
    };
    Ok((axes.velocity.clone(), x))
}

/// The derivative of `x` at `time`: central differences inside, one-sided at the ends.
fn derivative(time: &[f64], x: &[f64]) -> Vec<f64> {
    let n = x.len().min(time.len());
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
            let dt = time[b] - time[a];
            if dt > 0.0 {
                (x[b] - x[a]) / dt
            } else {
                0.0
            }
        })
        .collect()
}

/// One statistic of the residual-structure check.
struct Statistic {
    name: &'static str,
    effect: f64,
    z: f64,
}

/// Residual structure over all records: correlation with sgn(v) and with x, autocorrelation
/// at one oscillation period (on the moving parts), and the residual mean (whole records).
/// `threshold` is the speed below which the mass counts as at rest.
pub(crate) fn residual_structure(
    records: &[RecordFit],
    osc: &Oscillator,
    threshold: f64,
) -> Finding {
    let mut moving = Vec::new();
    let mut unjudged = Vec::new();
    for r in records {
        match moving_part(r, osc, threshold) {
            Ok(m) => moving.push(m),
            Err(why) => unjudged.push(why),
        }
    }
    let residuals: Vec<&[f64]> = moving.iter().map(|m| m.residual.as_slice()).collect();
    let n = residuals.iter().map(|r| r.len()).sum::<usize>() as f64;
    if n < 10.0 {
        let why = if unjudged.is_empty() {
            String::new()
        } else {
            format!(": {}", unjudged.join("; "))
        };
        return Finding::skipped(
            Check::ResidualStructure,
            format!("{n} moving samples, too few to judge the residual structure{why}"),
        );
    }
    if let Some(share) = at_numerical_floor(&moving, records) {
        return Finding::new(
            Check::ResidualStructure,
            Status::Pass,
            Some(0.0),
            format!(
                "residuals are {share:.1e} of the response, at the simulations' numerical floor: no structure to judge (a noise-free record)"
            ),
        );
    }
    // AR(1) effective sample sizes: for a correlation with a smooth regressor and for an
    // autocorrelation coefficient.
    let phi = noise_correlation(&residuals);
    let n_eff = (n * (1.0 - phi) / (1.0 + phi)).max(3.0);
    let n_eff_acf = (n * (1.0 - phi * phi) / (1.0 + phi * phi)).max(3.0);
    let mut stats = Vec::new();
    let sign: fn(&Moving) -> &[f64] = |m| &m.sign;
    let x: fn(&Moving) -> &[f64] = |m| &m.x;
    for (name, series) in [("sgn(v)", sign), ("x", x)] {
        let rho = pooled_correlation(&moving, |m| &m.residual, series);
        stats.push(Statistic {
            name,
            effect: rho.abs(),
            z: rho.abs() * n_eff.sqrt(),
        });
    }
    if let Some(lag) = moving
        .iter()
        .map(|m| m.period_samples)
        .min()
        .filter(|&l| l > 0)
    {
        let rho = autocorrelation(&residuals, lag);
        stats.push(Statistic {
            name: "the oscillation period",
            effect: rho,
            z: rho * n_eff_acf.sqrt(),
        });
    }
    stats.push(mean_statistic(records, phi));
    structure_finding(&stats)
}

/// The largest residual RMS, as a share of the fitted response's RMS, that is the
/// simulations' own round-off and tolerance (the noise floor of a noise-free record):
/// residuals that small are locked to the motion by construction.
pub(crate) const NUMERICAL_FLOOR: f64 = 1e-6;

/// The residuals' RMS over the fitted response's on the moving parts, when at most
/// [`NUMERICAL_FLOOR`].
fn at_numerical_floor(moving: &[Moving], records: &[RecordFit]) -> Option<f64> {
    let residual: f64 = moving.iter().flat_map(|m| &m.residual).map(|r| r * r).sum();
    let response: f64 = records
        .iter()
        .flat_map(|r| &r.series.fitted)
        .map(|f| f * f)
        .sum();
    let share = (residual / response).sqrt();
    (share <= NUMERICAL_FLOOR).then_some(share)
}

/// The residual mean over whole records, relative to the residual RMS.
fn mean_statistic(records: &[RecordFit], phi: f64) -> Statistic {
    let (mut count, mut sum, mut sum_sq) = (0usize, 0.0, 0.0);
    for r in records {
        for (f, m) in r.series.fitted.iter().zip(&r.series.measured) {
            let residual = f - m;
            count += 1;
            sum += residual;
            sum_sq += residual * residual;
        }
    }
    let n = count.max(1) as f64;
    let mean = sum / n;
    let rms = (sum_sq / n).sqrt();
    let n_eff = (n * (1.0 - phi) / (1.0 + phi)).max(3.0);
    let effect = if rms > 0.0 { mean.abs() / rms } else { 0.0 };
    Statistic {
        name: "a constant (their mean)",
        effect,
        z: effect * n_eff.sqrt(),
    }
}

fn structure_finding(stats: &[Statistic]) -> Finding {
    let status_of = |s: &Statistic| {
        if s.z > STRUCTURE_FAIL_Z && s.effect >= STRUCTURE_FAIL_EFFECT {
            Status::Fail
        } else if s.z > STRUCTURE_WARN_Z {
            Status::Warn
        } else {
            Status::Pass
        }
    };
    let status = stats.iter().map(status_of).max().unwrap_or(Status::Pass);
    let value = stats.iter().map(|s| s.effect).fold(0.0, f64::max);
    let flagged: Vec<String> = stats
        .iter()
        .filter(|s| status_of(s) != Status::Pass)
        .map(|s| format!("{} ({:.2}, {:.1} standard errors)", s.name, s.effect, s.z))
        .collect();
    let message = if flagged.is_empty() {
        "residuals show no structure locked to the motion".to_string()
    } else {
        format!(
            "residuals are locked to the motion: they follow {}; a wrong friction law (compare others), an unmodelled offset (`[fit.options] velocity_offset = true`) or a missed release (`[fit.options] time_shift = true`) leaves such a pattern",
            flagged.join(", ")
        )
    };
    Finding::new(Check::ResidualStructure, status, Some(value), message)
}

/// A warning per free parameter that ended at one of its (finite) bounds, or collapsed onto
/// its open lower bound 0 (reported as 0, never as a fitted 2.2e-308), saying what to do.
pub(crate) fn parameters_at_bounds(layout: &[FreeParam], values: &[f64]) -> Vec<Finding> {
    let mut out = Vec::new();
    for (f, &p) in layout.iter().zip(values) {
        let Some(side) = f.bound_side(p) else {
            continue;
        };
        let bound = f.bound(side);
        let shown = f.reported(p);
        out.push(
            Finding::warn(
                Check::ParameterAtBound,
                Some(shown),
                format!(
                    "`{}` = {shown:.4e}{} is at its {} bound {bound:.4e}: the data push it further; {}",
                    f.name,
                    unit_suffix(&f.unit),
                    side.name(),
                    at_bound_advice(f)
                ),
            )
            .about(&f.name),
        );
    }
    out
}

/// " <unit>" after a value, nothing for a dimensionless one ("1").
fn unit_suffix(unit: &str) -> String {
    if unit == "1" || unit.is_empty() {
        String::new()
    } else {
        format!(" {unit}")
    }
}

/// A failure naming the free parameters whose Jacobian column `jac` (physical coordinates,
/// weighted residuals) is zero everywhere at `values`: changed by their own magnitude (or
/// scale, when zero), none moves a residual by `NO_EFFECT` (in `identifiability/flat.rs`) of its noise. `None` when every
/// parameter acts on the records.
pub(crate) fn parameters_without_effect(
    layout: &[FreeParam],
    values: &[f64],
    jac: &nalgebra::DMatrix<f64>,
) -> Option<Finding> {
    let dead: Vec<String> = slots_without_effect(layout, values, jac)
        .into_iter()
        .map(|j| format!("`{}` = {:e} {}", layout[j].name, values[j], layout[j].unit))
        .collect();
    (!dead.is_empty()).then(|| {
        Finding::new(
            Check::ParameterWithoutEffect,
            Status::Fail,
            Some(dead.len() as f64),
            format!(
                "{} changes no residual at the optimum: the records say nothing about it (speeds outside the range where it acts, or a formula it does not enter); fix it at a known value or fit records that exercise it",
                dead.join(", ")
            ),
        )
    })
}

/// What to do about a parameter at its bound.
fn at_bound_advice(f: &FreeParam) -> String {
    let widen = format!("widen it in [fit] bounds = {{ {} = [lo, hi] }}", f.name);
    if matches!(f.kind, ParamKind::Model(_)) && is_friction_level(&f.name, &f.unit) {
        format!("{widen} or set the normal force (a friction coefficient is the level over N)")
    } else {
        format!("{widen}, or check the units and the model")
    }
}

/// Whether every free parameter has a standard error; a rank-deficient Jacobian is named as
/// such.
pub(crate) fn standard_errors(parameters: &[FittedParam], singular: bool) -> Finding {
    let missing: Vec<&str> = parameters
        .iter()
        .filter(|p| p.free && p.std_error.is_none())
        .map(|p| p.name.as_str())
        .collect();
    if singular {
        return Finding::warn(
            Check::StandardErrors,
            None,
            "the Jacobian is rank-deficient: some free parameters are not separately identifiable from these records (no standard errors)".into(),
        );
    }
    if missing.is_empty() {
        return Finding::new(
            Check::StandardErrors,
            Status::Pass,
            None,
            "standard errors computed for every free parameter".into(),
        );
    }
    Finding::warn(
        Check::StandardErrors,
        Some(missing.len() as f64),
        format!(
            "no standard error for {}: the data do not constrain them at the optimum (the identifiability findings say on which side they are bounded)",
            missing
                .iter()
                .map(|n| format!("`{n}`"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    )
}

/// Whether converged starts agree on the minimum: a start that converged with an SSR more
/// than [`START_DISAGREEMENT`] residual variances above the best found another minimum.
/// `None` for a single start.
pub(crate) fn start_agreement(
    outcomes: &[StartOutcome],
    best_cost: f64,
    residual_variance: f64,
) -> Option<Finding> {
    if outcomes.len() < 2 {
        return None;
    }
    let worse: Vec<(usize, f64)> = outcomes
        .iter()
        .filter_map(|o| match o {
            StartOutcome::Finished {
                start,
                cost,
                termination,
                ..
            } if termination.is_converged() => {
                Some((*start, 2.0 * (cost - best_cost) / residual_variance))
            }
            _ => None,
        })
        .filter(|(_, d)| *d > START_DISAGREEMENT)
        .collect();
    if worse.is_empty() {
        return Some(Finding::new(
            Check::StartAgreement,
            Status::Pass,
            Some(0.0),
            "no converged start ended in a worse minimum".into(),
        ));
    }
    Some(Finding::warn(
        Check::StartAgreement,
        Some(worse.len() as f64),
        format!(
            "{} converged start(s) ended in a worse minimum (start {}): the problem has several minima; the best was kept (more starts may find a better one)",
            worse.len(),
            worse
                .iter()
                .map(|(s, _)| s.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    ))
}

/// Pass when the solver converged, else fail.
pub(crate) fn convergence(termination: &TerminationReason, model_params: &[String]) -> Finding {
    if let TerminationReason::ConvergedExceptUnbounded { parameters } = termination {
        let settled = model_params
            .iter()
            .filter(|p| !parameters.contains(p))
            .count();
        if settled == 0 {
            return Finding::new(
                Check::Convergence,
                Status::Warn,
                None,
                format!(
                    "no model parameter settled: every one (`{}`) kept running to a value the records do not bound, and the fit converged only with them held; the fitted curve stands, its parameter values are points on the bounds of the identifiability findings",
                    parameters.join("`, `")
                ),
            );
        }
    }
    if termination.is_converged() {
        Finding::new(
            Check::Convergence,
            Status::Pass,
            None,
            termination.to_string(),
        )
    } else {
        Finding::new(
            Check::Convergence,
            Status::Fail,
            None,
            format!("the fit did not converge ({termination})"),
        )
    }
}

/// Starts whose cost is within the statistical tolerance of the best: a cost difference of
/// at most chi²(1 dof, 95 %) / 2 residual variances (at least 1: the best itself).
pub(crate) fn starts_at_best(
    outcomes: &[StartOutcome],
    best_cost: f64,
    residual_variance: f64,
) -> usize {
    let tolerance = if residual_variance.is_finite() && residual_variance > 0.0 {
        PROFILE_DELTA * residual_variance
    } else {
        1e-6 * best_cost.abs()
    };
    outcomes
        .iter()
        .filter(
            |o| matches!(o, StartOutcome::Finished { cost, .. } if *cost - best_cost <= tolerance),
        )
        .count()
        .max(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::coulomb_free_vibration;
    use crate::identify::assessment::fixtures::{ar1_noise, record_fit_of};
    use crate::identify::values::layout::ParamKind;
    use crate::identify::values::result::EnergySkip;

    const NOISE: f64 = 2e-4;

    fn exact_v(osc: &Oscillator, mu: f64, time: &[f64]) -> Vec<f64> {
        coulomb_free_vibration(osc, mu * osc.normal_force, 0.014, time)
            .unwrap()
            .v
    }

    /// A record fit whose model is Coulomb with `mu_fit` and whose measurement is the exact
    /// Coulomb motion with `mu_true` plus `noise` plus `offset`.
    fn record_fit(mu_true: f64, mu_fit: f64, noise: &[f64], offset: f64) -> RecordFit {
        let osc = Oscillator::fmm();
        let time: Vec<f64> = (0..noise.len()).map(|i| i as f64 * 1e-3).collect();
        let truth = exact_v(&osc, mu_true, &time);
        let fitted = exact_v(&osc, mu_fit, &time);
        let measured = truth
            .iter()
            .zip(noise)
            .map(|(v, e)| v + e + offset)
            .collect();
        record_fit_of("velocity", 0.014, time, measured, fitted)
    }

    fn structure(fits: &[RecordFit]) -> Finding {
        residual_structure(fits, &Oscillator::fmm(), 1e-3)
    }

    #[test]
    fn white_noise_around_the_right_model_passes() {
        for seed in 0..5 {
            let fit = record_fit(0.24, 0.24, &ar1_noise(2000, NOISE, 0.0, seed), 0.0);
            let f = structure(&[fit]);
            assert_eq!(f.status, Status::Pass, "seed {seed}: {}", f.message);
        }
    }

    /// Coloured noise (correlated over a few tens of samples) around the right model warns at
    /// most, however strongly coloured.
    #[test]
    fn coloured_noise_around_the_right_model_never_fails() {
        for (seed, phi) in [(1, 0.5), (2, 0.9), (3, 0.97), (4, 0.99), (5, 0.95)] {
            let fit = record_fit(0.24, 0.24, &ar1_noise(2000, NOISE, phi, seed), 0.0);
            let f = structure(&[fit]);
            assert_ne!(f.status, Status::Fail, "phi {phi}: {}", f.message);
        }
    }

    #[test]
    fn a_wrong_friction_level_or_an_offset_fails() {
        let noise = ar1_noise(2000, NOISE, 0.0, 9);
        let wrong = structure(&[record_fit(0.24, 0.20, &noise, 0.0)]);
        assert_eq!(wrong.status, Status::Fail, "{}", wrong.message);
        let offset = structure(&[record_fit(0.24, 0.24, &noise, 3e-3)]);
        assert_eq!(offset.status, Status::Fail, "{}", offset.message);
        assert!(offset.message.contains("mean"), "{}", offset.message);
    }

    /// The same record compared as a displacement, or as a force along the measured motion,
    /// is judged, not passed for want of a velocity (a wrong level's smooth displacement
    /// misfit is the goodness of fit's to catch: the structure statistics grant smooth
    /// residuals few effective samples); a record without a known motion is skipped with the
    /// reason.
    #[test]
    fn displacement_and_force_records_are_judged_and_unknown_motion_is_skipped() {
        let noise = ar1_noise(2000, NOISE, 0.0, 9);
        let as_displacement = |mu_fit: f64| {
            let mut r = record_fit(0.24, mu_fit, &noise, 0.0);
            let time = r.axes.time.clone();
            let x = |v: &[f64]| cumulative_trapezoid(&time, v, 0.014);
            let truth = exact_v(&Oscillator::fmm(), 0.24, &time);
            r.series.fitted = x(&r.series.fitted);
            r.series.measured = x(&truth)
                .iter()
                .zip(&noise)
                .map(|(x, e)| x + 1e-3 * e)
                .collect();
            r.channel = "displacement".into();
            r
        };
        let right = structure(&[as_displacement(0.24)]);
        assert_eq!(right.status, Status::Pass, "{}", right.message);
        assert!(right.value.is_some(), "{}", right.message);
        let wrong = structure(&[as_displacement(0.20)]);
        assert_ne!(wrong.status, Status::Skipped, "{}", wrong.message);
        assert!(wrong.value.is_some(), "{}", wrong.message);
        let mut force = record_fit(0.24, 0.20, &noise, 0.0);
        force.axes.velocity = force.series.measured.clone();
        force.channel = "force".into();
        let f = structure(&[force.clone()]);
        assert_ne!(f.status, Status::Pass, "{}", f.message);
        force.axes.velocity.clear();
        let f = structure(&[force]);
        assert_eq!(f.status, Status::Skipped, "{}", f.message);
        assert!(
            f.message.contains("without the motion's velocity"),
            "{}",
            f.message
        );
    }

    /// A force record along a slow stroke (peak 0.2 mm/s, below the configured 1 mm/s) is
    /// judged with a threshold that follows its velocity's noise: the right law passes, a
    /// wrong level is caught; before, both were skipped for never moving.
    #[test]
    fn a_slow_force_record_is_judged_with_a_threshold_from_its_noise() {
        let noise = ar1_noise(2000, NOISE, 0.0, 9);
        let slow = |mu_fit: f64| {
            let mut force = record_fit(0.24, mu_fit, &noise, 0.0);
            let truth = exact_v(&Oscillator::fmm(), 0.24, &force.axes.time);
            force.axes.velocity = truth.iter().map(|v| 3e-3 * v).collect();
            force.channel = "force".into();
            force
        };
        let right = structure(&[slow(0.24)]);
        assert_eq!(right.status, Status::Pass, "{}", right.message);
        assert!(right.value.is_some(), "{}", right.message);
        let wrong = structure(&[slow(0.20)]);
        assert!(
            matches!(wrong.status, Status::Warn | Status::Fail),
            "{}",
            wrong.message
        );
        // A noisy velocity at rest is not motion: the threshold rises to its noise.
        let jitter: Vec<f64> = ar1_noise(2000, 1e-3, 0.0, 4);
        assert!(moving_threshold(&jitter, 1e-3) > 3e-3);
        assert_eq!(moving_threshold(&[0.0, 0.5, 0.1, -0.4], 1e-3), 1e-3);
    }

    fn energy_force(eq7: f64, energies: f64) -> EnergyForce {
        EnergyForce {
            mean_abs: 3.48 * (1.0 + eq7 / 100.0),
            reference: 3.48,
            percent_difference: eq7,
            residual_rms: 0.1,
            samples: 100,
            force_noise: 0.05,
            half_cycle_mean: 3.48,
            half_cycles: 4,
            dissipated: 0.1 * (1.0 + energies / 100.0),
            model_dissipated: 0.1,
            dissipation_percent_difference: energies,
            eq7_skipped: None,
            dissipation_skipped: None,
        }
    }

    #[test]
    fn energy_balance_thresholds_are_five_and_twenty_percent() {
        let status =
            |eq7, energies| energy_balance("r", &energy_force(eq7, energies), Axis::Linear).status;
        assert_eq!(status(1.0, -2.0), Status::Pass);
        assert_eq!(status(-6.0, 1.0), Status::Warn);
        assert_eq!(status(1.0, 12.0), Status::Warn);
        assert_eq!(status(38112.0, 1.0), Status::Fail);
        assert_eq!(status(1.0, f64::NAN), Status::Pass);
        let f = energy_balance("x14.csv", &energy_force(-25.0, 3.0), Axis::Linear);
        assert_eq!(f.value, Some(25.0));
        assert!(f.message.contains("x14.csv"));
    }

    /// A part that cannot judge is left out of the status and named; with both left out the
    /// finding is skipped, never failed.
    #[test]
    fn an_energy_part_that_cannot_judge_is_skipped_with_its_reason() {
        let mut ef = energy_force(150.0, 1.0);
        ef.eq7_skipped = Some(EnergySkip::NoisyDerivative {
            force_noise: 2.0,
            level: 3.48,
        });
        let f = energy_balance("r", &ef, Axis::Linear);
        assert_eq!(f.status, Status::Pass, "{}", f.message);
        assert!(f.message.contains("not judged: Eq. 7"), "{}", f.message);
        ef.dissipation_skipped = Some(EnergySkip::FewSamples {
            per_half_cycle: 8,
            needed: 20,
        });
        let f = energy_balance("r", &ef, Axis::Linear);
        assert_eq!(f.status, Status::Skipped, "{}", f.message);
        assert!(
            f.message.contains("8 samples per half-cycle"),
            "{}",
            f.message
        );
    }

    /// On a rotary axis the reason a part cannot judge speaks of torques: N m, never N.
    #[test]
    fn a_skipped_part_on_a_rotary_axis_gives_its_noise_in_newton_metres() {
        let mut ef = energy_force(150.0, 1.0);
        ef.eq7_skipped = Some(EnergySkip::NoisyReplay {
            force_noise: 0.02,
            level: 0.03,
        });
        let rotary = energy_balance("r", &ef, Axis::Rotary).message;
        assert!(rotary.contains("0.020 N m of its noise"), "{rotary}");
        assert!(rotary.contains("(0.030 N m)"), "{rotary}");
        let linear = energy_balance("r", &ef, Axis::Linear).message;
        assert!(linear.contains("0.020 N of its noise"), "{linear}");
    }

    #[test]
    fn a_parameter_at_its_bound_warns() {
        let mu = FreeParam::linear("mu".into(), "1", ParamKind::Model(0), (0.0, 5.0), 0.3, 1.0);
        assert_eq!(
            parameters_at_bounds(std::slice::from_ref(&mu), &[0.24]).len(),
            0
        );
        let at = parameters_at_bounds(std::slice::from_ref(&mu), &[5.0]);
        assert_eq!(at.len(), 1);
        assert_eq!(at[0].status, Status::Warn);
        assert!(at[0].message.contains("upper"));
        let log = FreeParam {
            log: true,
            lower: 1e-3,
            ..mu
        };
        assert!(parameters_at_bounds(std::slice::from_ref(&log), &[1e-3])[0]
            .message
            .contains("lower"));
        // Collapsed onto the open lower bound 0: reported as 0, with the way out.
        let open = FreeParam { lower: 0.0, ..log };
        let collapsed = parameters_at_bounds(&[open], &[f64::MIN_POSITIVE]);
        assert_eq!(collapsed[0].value, Some(0.0));
        assert_eq!(collapsed[0].parameter.as_deref(), Some("mu"));
        assert!(
            !collapsed[0].message.contains("e-308"),
            "{}",
            collapsed[0].message
        );
        assert!(collapsed[0].message.contains("normal force"));
    }

    #[test]
    fn missing_standard_errors_warn_and_computed_ones_pass() {
        let p = |name: &str, se: Option<f64>| FittedParam {
            name: name.into(),
            value: 1.0,
            std_error: se,
            ci95: None,
            unit: "1".into(),
            free: true,
            identifiability: None,
            bound: None,
            std_error_components: None,
        };
        let ok = standard_errors(&[p("mu", Some(0.01))], false);
        assert_eq!(ok.status, Status::Pass);
        let missing = standard_errors(&[p("mu", None), p("v_s", Some(1.0))], false);
        assert_eq!(missing.status, Status::Warn);
        assert!(missing.message.contains("`mu`") && !missing.message.contains("v_s"));
        assert_eq!(standard_errors(&[], true).status, Status::Warn);
    }

    #[test]
    fn a_start_converged_in_a_worse_minimum_warns() {
        let finished = |start, cost| StartOutcome::Finished {
            start,
            cost,
            iterations: 10,
            termination: TerminationReason::GradientBelowTolerance,
        };
        // Residual variance 1e-8: SSR 2 * 1e-6 above the best is 200 variances.
        let agree = start_agreement(&[finished(0, 1.0), finished(1, 1.0 + 1e-9)], 1.0, 1e-8);
        assert_eq!(agree.unwrap().status, Status::Pass);
        let worse = start_agreement(&[finished(0, 1.0), finished(1, 1.0 + 1e-6)], 1.0, 1e-8);
        assert_eq!(worse.unwrap().status, Status::Warn);
        assert!(start_agreement(&[finished(0, 1.0)], 1.0, 1e-8).is_none());
    }

    #[test]
    fn non_convergence_fails() {
        let f = convergence(&TerminationReason::IterationLimit { limit: 3 }, &[]);
        assert_eq!(f.status, Status::Fail);
        assert!(f.message.contains("iteration limit (3) reached"));
        assert_eq!(
            convergence(&TerminationReason::StepBelowTolerance, &[]).status,
            Status::Pass
        );
    }

    /// Converged with unbounded parameters held: a pass while a model parameter settled, a
    /// warning naming them when none did.
    #[test]
    fn convergence_with_no_model_parameter_settled_is_a_warning() {
        let model: Vec<String> = ["sigma0", "mu_c"].map(String::from).to_vec();
        let held = |names: &[&str]| TerminationReason::ConvergedExceptUnbounded {
            parameters: names.iter().map(|n| n.to_string()).collect(),
        };
        assert_eq!(convergence(&held(&["sigma0"]), &model).status, Status::Pass);
        let none = convergence(&held(&["sigma0", "mu_c"]), &model);
        assert_eq!(none.status, Status::Warn);
        assert!(
            none.message
                .starts_with("no model parameter settled: every one (`sigma0`, `mu_c`)"),
            "{}",
            none.message
        );
    }

    #[test]
    fn starts_count_at_the_best_within_chi_square_over_two_variances() {
        let done = |start, cost| StartOutcome::Finished {
            start,
            cost,
            iterations: 1,
            termination: TerminationReason::GradientBelowTolerance,
        };
        // variance 1e-8: tolerance 1.92e-8.
        let outcomes = [done(0, 1.0), done(1, 1.0 + 1.9e-8), done(2, 1.0 + 2.0e-8)];
        assert_eq!(starts_at_best(&outcomes, 1.0, 1e-8), 2);
    }
}
