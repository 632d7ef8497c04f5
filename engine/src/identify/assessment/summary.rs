//! The fit at its best start, as a [`FitResult`]: the statistics at the optimum (the
//! covariance of the determined parameters, widened for autocorrelated residuals), every
//! parameter's entry, the per-record fits and the findings, in report order.

use super::diagnostics::{self, starts_at_best};
use super::energy_check::FittedDamping;
use super::goodness;
use super::identifiability::{self, covariance_of_determined, Standing};
use super::record_fits::{record_fits, RecordFits};
use super::stats::{self, aic, bic, t_quantile_975, Covariance};
use crate::energy::EnergyOptions;
use crate::error::EngineError;
use crate::identify::problem::{FitProblem, Realised, Residuals};
use crate::identify::search::starts::{MultiStart, StartRun};
use crate::identify::search::Layout;
use crate::identify::values::ParamOptions;
use crate::identify::values::{
    Check, Derived, Finding, FitResult, FittedParam, FreeParam, FrictionLevels, OscillatorParam,
    ParamKind, Search, StartOutcome, Status,
};
use crate::oscillator::{Oscillator, OscillatorProperty};
use crate::record::Channel;
use nalgebra::DMatrix;
use std::time::Instant;

/// Correlations above this magnitude are reported as warnings.
pub(crate) const CORRELATION_WARNING: f64 = 0.95;

/// What the final phase needs besides the runs.
pub(crate) struct FinishContext<'a, R: Residuals> {
    /// Which parameters are free (the oscillator's among them).
    pub params: &'a ParamOptions,
    /// The energy-analysis options (the energy checks).
    pub energy: &'a EnergyOptions,
    /// Its free parameters.
    pub layout: &'a Layout,
    /// The problem at the fit's start, which evaluates the optimum.
    pub reference: &'a FitProblem<R>,
    /// Starts run.
    pub n_starts: usize,
    /// The search that ran them.
    pub search: Search,
    /// Where each start came from.
    pub origins: &'a [String],
    /// What the records say about each free parameter.
    pub standings: &'a [Standing],
    /// The slots found redundant before profiling (not identifiable in `standings`).
    pub redundant: &'a [usize],
}

/// The statistics at the best parameters.
struct Statistics {
    p_best: Vec<f64>,
    world: Realised,
    cov: Covariance,
    ssr: f64,
    t_quantile: f64,
    /// Says how the standard errors were widened for autocorrelated residuals.
    widening: Option<Finding>,
    /// Names the free parameters that change no residual.
    without_effect: Option<Finding>,
    /// What the records say about each free parameter, with the parameters that share an
    /// undetermined one's column not identifiable too.
    standings: Vec<Standing>,
    /// The parameters that share an undetermined one's column.
    shared: Vec<identifiability::SharedColumn>,
    /// The slots whose column is a combination of the other determined ones'.
    redundant: Vec<usize>,
}

fn statistics<R: Residuals>(
    reference: &FitProblem<R>,
    best: &StartRun,
    (standings, redundant_before): (&[Standing], &[usize]),
) -> Result<Statistics, EngineError> {
    // Statistics in physical coordinates at the optimum, of the determined parameters.
    let p_best = reference.physical(&best.u);
    // The statistics are the Jacobian's last reader.
    let (jac, r) = reference.take_jacobian_physical(&p_best)?;
    let ssr = r.norm_squared();
    let without_effect = diagnostics::parameters_without_effect(&reference.layout, &p_best, &jac);
    // Model parameters are profiled; the others take the verdict of a column they share.
    let unprofiled: Vec<bool> = (0..reference.layout.len())
        .map(|j| !matches!(reference.layout[j].kind, ParamKind::Model(_)))
        .collect();
    let shared = identifiability::shared_columns(&jac, standings, &unprofiled);
    let standings = identifiability::with_shared(standings, &shared);
    let mut redundant = identifiability::redundant_columns(&jac, &standings);
    redundant.extend(redundant_before);
    redundant.sort_unstable();
    redundant.dedup();
    let standings = identifiability::not_identifiable(&standings, &redundant);
    let mut cov = covariance_of_determined(&jac, ssr, &standings);
    let segments = reference.residual_counts();
    let widening = widen_for_autocorrelation(&mut cov, &jac, r.as_slice(), &segments);
    let t_quantile = t_quantile_975(cov.dof);
    let world = reference.realise(&p_best)?;
    Ok(Statistics {
        p_best,
        world,
        cov,
        ssr,
        t_quantile,
        widening,
        without_effect,
        standings,
        shared,
        redundant,
    })
}

/// The smallest widening of a standard error that is applied and reported: below, the
/// HAC estimate's own scatter on white noise (a few per cent) would move the errors of
/// every well-fitted record.
pub(crate) const MIN_WIDENING: f64 = 1.1;

pub(crate) use super::diagnostics::SMOOTH_RESIDUALS;

/// Widens the covariance for autocorrelated residuals: each standard error becomes the
/// larger of the classical and the HAC one ([`stats::hac_covariance`]: Newey-West on each
/// estimate's influence series prewhitened by its own AR(2) filter, Bartlett lags by Andrews'
/// plug-in rule, at most a quarter of the shortest record), keeping the correlations, when
/// some error grows by [`MIN_WIDENING`] or more. Nothing here hangs on a noise estimate
/// that a ringing can turn negative: the filters' gains at zero frequency are positive by
/// construction. Residuals smoother than measurement noise at the sample scale (a ringing,
/// low-pass filtered data, or a misfit the law cannot follow) are widened alike and warned
/// about. Returns the finding.
fn widen_for_autocorrelation(
    cov: &mut Covariance,
    jac: &DMatrix<f64>,
    r: &[f64],
    segments: &[usize],
) -> Option<Finding> {
    let parts = split(r, segments);
    let smoothness = diagnostics::residual_smoothness(&parts);
    let smooth = smoothness >= SMOOTH_RESIDUALS;
    let usable = !cov.singular && cov.residual_variance.is_finite() && cov.residual_variance > 0.0;
    if !usable {
        return smooth.then(|| smooth_residuals_finding(smoothness, None));
    }
    let shortest = segments.iter().copied().min().unwrap_or(0);
    // Undetermined parameters' rows are NaN: they take no part in the sandwich.
    let bread = (&cov.matrix / cov.residual_variance).map(|b| if b.is_finite() { b } else { 0.0 });
    let hac = stats::hac_covariance(jac, r, segments, &bread, shortest / 4 + 1);
    let p = cov.std_errors.len();
    let factors: Vec<f64> = (0..p)
        .map(|i| (hac.variances[i] / cov.matrix[(i, i)]).sqrt())
        .map(|f| if f.is_finite() { f.max(1.0) } else { 1.0 })
        .collect();
    let widest = factors.iter().copied().fold(1.0, f64::max);
    let widening = (widest >= MIN_WIDENING).then(|| {
        for a in 0..p {
            for b in 0..p {
                cov.matrix[(a, b)] *= factors[a] * factors[b];
            }
            cov.std_errors[a] *= factors[a];
        }
        Widening {
            widest,
            lags: hac.lags,
            rho: diagnostics::lag_one_correlation(&parts),
        }
    });
    if smooth {
        return Some(smooth_residuals_finding(smoothness, widening));
    }
    widening.map(|w| {
        Finding::new(
            Check::NoiseCorrelation,
            Status::Pass,
            Some(w.widest),
            format!(
                "residuals are autocorrelated (lag-1 correlation {:.2}): standard errors widened by up to {:.2}x ({})",
                w.rho,
                w.widest,
                w.method()
            ),
        )
    })
}

/// How far the standard errors were widened, and how.
#[derive(Debug, Clone, Copy)]
struct Widening {
    widest: f64,
    lags: usize,
    rho: f64,
}

impl Widening {
    fn method(&self) -> String {
        format!(
            "Newey-West on each estimate's influence prewhitened by an AR(2) filter of its own, {} Bartlett lags by Andrews' plug-in rule",
            self.lags
        )
    }
}

/// `r` cut into its records' parts.
fn split(r: &[f64], segments: &[usize]) -> Vec<Vec<f64>> {
    let mut start = 0;
    segments
        .iter()
        .map(|&len| {
            let part = r[start.min(r.len())..(start + len).min(r.len())].to_vec();
            start += len;
            part
        })
        .collect()
}

/// The warning for residuals smoother than measurement noise at the sample scale, saying
/// how far the standard errors were widened (`widening`).
fn smooth_residuals_finding(smoothness: f64, widening: Option<Widening>) -> Finding {
    let errors = match widening {
        Some(w) => format!(
            "the standard errors are widened by up to {:.2}x as for coloured noise ({}), which understates the uncertainty of a misfit",
            w.widest,
            w.method()
        ),
        None => "the standard errors are not widened and may understate the uncertainty".into(),
    };
    Finding::warn(
        Check::NoiseCorrelation,
        Some(smoothness),
        format!(
            "the residuals correlate {:.3} at lag 1 (from their differences): smoother than measurement noise at the sample scale, so a ringing, low-pass filtered data or a misfit the law cannot follow; {errors} (look at the residual plot, try another model)",
            smoothness.min(1.0)
        ),
    )
}

/// Statistics, per-record fits, the energy check and the findings at the best start.
pub(crate) fn summarise<R: Residuals>(
    ctx: &FinishContext<'_, R>,
    runs: MultiStart,
    clock: Instant,
) -> Result<FitResult, EngineError> {
    let params = &ctx.layout.params;
    let stats = statistics(ctx.reference, &runs.best, (ctx.standings, ctx.redundant))?;
    let mut simulations = runs.simulations + ctx.reference.simulations();
    let fits = record_fits(
        ctx.reference,
        &stats.world,
        ctx.energy,
        fitted_damping(params, &stats),
    )?;
    simulations += ctx.reference.records.len() as u64;
    let levels = ctx.reference.residuals.friction_levels();
    let parameters = parameter_entries(&stats, params, &stats.standings, levels);
    let axis = stats.world.oscillator.axis;
    let findings = diagnose(ctx, &runs, &stats, &parameters, &fits);
    let n_free = params.len();
    let samples = ctx.reference.n_residuals();
    let k = params.len();
    let warnings = findings
        .iter()
        .filter(|f| f.status != Status::Pass)
        .map(|f| f.message.clone())
        .collect();
    Ok(FitResult {
        model: stats.world.model.name().to_string(),
        parameters,
        correlation_names: params.iter().map(|f| f.name.clone()).collect(),
        correlation: (0..k)
            .map(|a| (0..k).map(|b| stats.cov.correlation[(a, b)]).collect())
            .collect(),
        derived: if ctx.reference.residuals.simulates_response() {
            derived_ratios(
                &stats.world.oscillator,
                params,
                &stats.cov.matrix,
                ctx.params,
            )
        } else {
            // The ratios a free response fixes; a force balance fixes the properties.
            Vec::new()
        },
        records: fits.records,
        rms_residual: (fits.sum_sq / fits.n_total.max(1) as f64).sqrt(),
        compared: ctx.reference.residuals.channel().to_string(),
        residual_unit: axis.unit(ctx.reference.residuals.unit()),
        cost: 0.5 * stats.ssr,
        aic: aic(samples, stats.ssr, n_free),
        bic: bic(samples, stats.ssr, n_free),
        samples,
        free_parameters: n_free,
        converged: runs.best.converged(),
        termination: runs.best.termination,
        iterations: runs.iterations,
        simulations,
        starts: ctx.n_starts,
        starts_at_best: starts_at_best(&runs.outcomes, runs.best.cost, stats.cov.residual_variance),
        search: ctx.search,
        best_start: runs.best_start,
        best_start_origin: ctx
            .origins
            .get(runs.best_start)
            .cloned()
            .unwrap_or_default(),
        start_outcomes: runs.outcomes,
        diagnostics: findings,
        warnings,
        wall_time_s: clock.elapsed().as_secs_f64(),
        rank: None,
        fitted_model: stats.world.model,
        oscillator: stats.world.oscillator,
    })
}

/// The damping and its standard error when it is fitted as an oscillator property.
fn fitted_damping(params: &[FreeParam], stats: &Statistics) -> Option<FittedDamping> {
    let slot = params
        .iter()
        .position(|f| f.kind == ParamKind::Property(OscillatorProperty::Damping))?;
    Some(FittedDamping {
        value: stats.p_best[slot],
        std_error: stats.cov.std_errors[slot],
    })
}

/// Every check of the fit, in report order.
fn diagnose<R: Residuals>(
    ctx: &FinishContext<'_, R>,
    runs: &MultiStart,
    stats: &Statistics,
    parameters: &[FittedParam],
    fits: &RecordFits,
) -> Vec<Finding> {
    let params = &ctx.layout.params;
    let model_params: Vec<String> = params
        .iter()
        .filter(|f| matches!(f.kind, ParamKind::Model(_)))
        .map(|f| f.name.clone())
        .collect();
    let mut findings = vec![diagnostics::convergence(
        &runs.best.termination,
        &model_params,
    )];
    findings.extend(start_findings(&runs.outcomes));
    findings.extend(diagnostics::start_agreement(
        &runs.outcomes,
        runs.best.cost,
        stats.cov.residual_variance,
    ));
    findings.extend(correlation_findings(params, &stats.cov));
    findings.push(diagnostics::standard_errors(parameters, stats.cov.singular));
    let judged = judged_records(ctx, fits);
    findings.extend(
        stats
            .widening
            .clone()
            .map(|w| at_numerical_floor(w, &judged)),
    );
    if ctx.reference.residuals.simulates_response() {
        let driven = ctx
            .reference
            .records
            .iter()
            .any(|r| r.channel(Channel::InputForce).is_some());
        findings.extend(identifiability_findings(
            ctx.params,
            ctx.layout.n_model_free(),
            driven,
        ));
    }
    let names: Vec<(String, String)> = params
        .iter()
        .map(|f| (f.name.clone(), f.unit.clone()))
        .collect();
    // A redundant parameter's profile verdict is overruled; the redundancy's finding names it.
    let (profiled_names, profiled): (Vec<(String, String)>, Vec<Standing>) = names
        .iter()
        .zip(ctx.standings)
        .enumerate()
        .filter(|(j, _)| !stats.redundant.contains(j))
        .map(|(_, (name, standing))| (name.clone(), *standing))
        .unzip();
    findings.extend(identifiability::findings(&profiled_names, &profiled));
    let slot_names: Vec<String> = names.iter().map(|(n, _)| n.clone()).collect();
    findings.extend(identifiability::shared_findings(&slot_names, &stats.shared));
    findings.extend(identifiability::redundant_findings(
        &slot_names,
        &stats.redundant,
    ));
    findings.extend(identifiability::consistency_findings(
        stats.world.model.as_ref(),
        ctx.reference.residuals.friction_levels(),
    ));
    findings.extend(diagnostics::parameters_at_bounds(params, &stats.p_best));
    findings.extend(stats.without_effect.clone());
    findings.extend(fits.findings.iter().cloned());
    findings.push(goodness::goodness_of_fit(&judged));
    findings.push(diagnostics::residual_structure(
        &fits.records,
        &stats.world.oscillator,
        ctx.energy.velocity_threshold,
    ));
    findings
}

/// Each record's goodness of fit against its noise floor (raised to the noise level the
/// record gives for its compared channel).
fn judged_records<R: Residuals>(
    ctx: &FinishContext<'_, R>,
    fits: &RecordFits,
) -> Vec<goodness::JudgedRecord> {
    fits.records
        .iter()
        .zip(ctx.reference.records.iter())
        .map(|(fit, rec)| {
            let given = Channel::from_name(&fit.channel).and_then(|c| rec.given_noise(c));
            goodness::judged_record(fit, given)
        })
        .collect()
}

/// The autocorrelation finding `widening`, but a pass where every record's residuals are
/// at the simulations' numerical floor: round-off is smooth, not a misfit to warn about.
fn at_numerical_floor(widening: Finding, judged: &[goodness::JudgedRecord]) -> Finding {
    let floor = !judged.is_empty()
        && judged
            .iter()
            .all(|j| matches!(j.3, goodness::RecordGoodness::Numerical(_)));
    if !floor || widening.status != Status::Warn {
        return widening;
    }
    Finding::new(
        Check::NoiseCorrelation,
        Status::Pass,
        widening.value,
        "the residuals are at the simulations' numerical floor (a noise-free record): their correlation is round-off's, neither noise to correct for nor a misfit".into(),
    )
}

/// A warning per failed start: screening failures first, then failed continuations.
fn start_findings(outcomes: &[StartOutcome]) -> Vec<Finding> {
    let continued = |o: &&StartOutcome| matches!(o, StartOutcome::ContinuationFailed { .. });
    let screening = outcomes.iter().filter(|o| !continued(o));
    screening
        .chain(outcomes.iter().filter(continued))
        .filter_map(StartOutcome::warning)
        .map(|w| Finding::warn(Check::StartFailure, None, w))
        .collect()
}

/// Every model parameter (fitted or fixed), then the free oscillator and nuisance parameters.
fn parameter_entries(
    stats: &Statistics,
    params: &[FreeParam],
    standings: &[Standing],
    levels: FrictionLevels,
) -> Vec<FittedParam> {
    let se = &stats.cov.std_errors;
    let tq = stats.t_quantile;
    let stand = |mut p: FittedParam, slot: Option<usize>| {
        if let Some(s) = slot.and_then(|s| standings.get(s)) {
            p.identifiability = Some(s.class);
            p.bound = s.bound;
        }
        p
    };
    let model = &stats.world.model;
    let mut out: Vec<FittedParam> = model
        .param_info()
        .iter()
        .zip(model.params())
        .enumerate()
        .map(|(i, (p, v))| {
            let slot = params.iter().position(|f| f.kind == ParamKind::Model(i));
            let unit = levels.unit(p, stats.world.oscillator.axis);
            // A value collapsed onto its open lower bound is reported as that bound.
            let v = slot.map_or(v, |s| params[s].reported(v));
            stand(param_entry(&p.name, &unit, v, slot, se, tq), slot)
        })
        .collect();
    for (slot, f) in params.iter().enumerate() {
        if !matches!(f.kind, ParamKind::Model(_)) {
            let value = stats.p_best[slot];
            let entry = param_entry(&f.name, &f.unit, value, Some(slot), se, tq);
            out.push(stand(entry, Some(slot)));
        }
    }
    out
}

fn param_entry(
    name: &str,
    unit: &str,
    value: f64,
    slot: Option<usize>,
    se: &[f64],
    tq: f64,
) -> FittedParam {
    let std_error = slot
        .and_then(|s| se.get(s).copied())
        .filter(|s| s.is_finite() && *s > 0.0);
    FittedParam {
        name: name.to_string(),
        value,
        std_error,
        ci95: std_error.map(|s| [value - tq * s, value + tq * s]),
        unit: unit.to_string(),
        free: slot.is_some(),
        identifiability: None,
        bound: None,
        std_error_components: None,
    }
}

/// A warning for every pair of free parameters correlated above [`CORRELATION_WARNING`].
fn correlation_findings(params: &[FreeParam], cov: &Covariance) -> Vec<Finding> {
    let mut out = Vec::new();
    for a in 0..params.len() {
        for b in (a + 1)..params.len() {
            let rho = cov.correlation[(a, b)];
            if rho.abs() > CORRELATION_WARNING {
                out.push(Finding::warn(
                    Check::Correlation,
                    Some(rho),
                    format!(
                        "`{}` and `{}` are strongly correlated (rho = {rho:.3}): the data barely separate them",
                        params[a].name, params[b].name
                    ),
                ));
            }
        }
    }
    out
}

/// A warning for a free mass with anything that scales with it in a fit of the free
/// response; none when a record is `driven` (its measured input force fixes the scale).
fn identifiability_findings(
    opts: &ParamOptions,
    n_model_free: usize,
    driven: bool,
) -> Vec<Finding> {
    let mut out = Vec::new();
    let osc_free = |q: OscillatorParam| opts.oscillator.contains(&q);
    if !driven
        && osc_free(OscillatorParam::Mass)
        && (osc_free(OscillatorParam::Stiffness)
            || osc_free(OscillatorParam::Damping)
            || n_model_free > 0)
    {
        out.push(Finding::warn(
            Check::Identifiability,
            None,
            "velocity alone fixes k/m, c/m and friction/m, not m: with the mass free, scaling m, c, k and the friction level together leaves the motion unchanged; fix the mass (or another of them) to identify the rest".into(),
        ));
    }
    out
}

/// k/m and c/m (the combinations velocity data fix) with delta-method standard errors.
fn derived_ratios(
    osc: &Oscillator,
    layout: &[FreeParam],
    cov: &DMatrix<f64>,
    opts: &ParamOptions,
) -> Vec<Derived> {
    if opts.oscillator.is_empty() {
        return Vec::new();
    }
    let slot = |kind: ParamKind| layout.iter().position(|f| f.kind == kind);
    let (m, c, k) = (osc.mass, osc.damping, osc.stiffness);
    let sm = slot(ParamKind::Property(OscillatorParam::Mass));
    let mut out = Vec::new();
    for (name, unit, num, kind) in [
        (
            "k/m",
            "1/s^2",
            k,
            ParamKind::Property(OscillatorParam::Stiffness),
        ),
        (
            "c/m",
            "1/s",
            c,
            ParamKind::Property(OscillatorParam::Damping),
        ),
    ] {
        let sn = slot(kind);
        // gradient of num/m with respect to (num, m)
        let g = [(sn, 1.0 / m), (sm, -num / (m * m))];
        let mut var = 0.0;
        for (a, ga) in g {
            for (b, gb) in g {
                if let (Some(a), Some(b)) = (a, b) {
                    var += ga * gb * cov[(a, b)];
                }
            }
        }
        out.push(Derived {
            name: name.into(),
            value: num / m,
            std_error: (var.is_finite() && var >= 0.0).then(|| var.sqrt()),
            unit: unit.into(),
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A free mass beside a free damping warns on a free response, where velocity fixes only
    /// the ratios, and not on a driven record, whose measured input force fixes the mass.
    #[test]
    fn the_mass_warning_is_for_free_responses_only() {
        let opts = ParamOptions {
            oscillator: vec![OscillatorParam::Mass, OscillatorParam::Damping],
            ..ParamOptions::default()
        };
        let free = identifiability_findings(&opts, 1, false);
        assert_eq!(free.len(), 1);
        assert!(free[0].message.contains("not m"), "{}", free[0].message);
        assert!(identifiability_findings(&opts, 1, true).is_empty());
        let mass_only = ParamOptions {
            oscillator: vec![OscillatorParam::Mass],
            ..ParamOptions::default()
        };
        assert!(identifiability_findings(&mass_only, 0, false).is_empty());
    }

    fn judged(goodness: goodness::RecordGoodness) -> goodness::JudgedRecord {
        ("r".into(), "velocity".into(), "m/s".into(), goodness)
    }

    /// Smooth residuals warn, unless every record's residuals are at the numerical floor.
    #[test]
    fn smooth_residuals_at_the_numerical_floor_do_not_warn() {
        let warning = smooth_residuals_finding(0.999, None);
        let floor = [judged(goodness::RecordGoodness::Numerical(3e-11))];
        let f = at_numerical_floor(warning.clone(), &floor);
        assert_eq!(f.status, Status::Pass, "{}", f.message);
        assert!(f.message.contains("numerical floor"), "{}", f.message);
        let noisy = goodness::RecordGoodness::Ratio {
            rms: 6.0,
            floor: 1.0,
            phi: 0.0,
            smooth: false,
        };
        let mixed = [floor[0].clone(), judged(noisy)];
        assert_eq!(
            at_numerical_floor(warning.clone(), &mixed).status,
            Status::Warn
        );
        assert_eq!(at_numerical_floor(warning, &[]).status, Status::Warn);
    }
}
