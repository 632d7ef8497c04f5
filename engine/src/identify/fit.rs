//! Fitting a friction model (and optionally the oscillator) to records: checks the inputs,
//! lays out the free parameters, runs the starts and turns the best one into a [`FitResult`]
//! (statistics, per-record fits, the energy-balance check and the findings).

use super::budget::{apply_budget, Refit};
use super::diagnostics;
use super::energy_check::{energy_force_check, EnergyForce, ForceReference};
use super::force::{fit_force, require_mechanics};
use super::identifiability::{self, covariance_of_determined, Standing};
use super::layout::{FreeParam, ParamKind};
use super::options::FitDomain;
use super::options::{FitOptions, OscillatorParam};
use super::outcome::{Check, Finding, StartOutcome, Status, TerminationReason};
use super::prefit::{prefit, prefit_finding, Prefit, PREFIT_ORIGIN};
use super::problem::{FitProblem, ProblemParts, Realised, STEPS_PER_SAMPLE};
use super::residuals::{NuisanceValues, Residuals, Segment, VelocityResponse};
use super::setup::{build_layout, Layout};
use super::starts::{run_starts, start_count, MultiStart, StartRun};
use super::stats::{self, aic, bic, t_quantile_975, Covariance};
use super::strategy::{self, plan_starts, Planned, Search, Seeded, StartPlan};
use crate::energy::{analyze_record, forces_from_states, states_along};
use crate::error::EngineError;
use crate::oscillator::Oscillator;
use crate::record::{NormalForce, Record};
use frictionid_models::FrictionModel;
use nalgebra::{DMatrix, DVector};
use std::sync::Arc;
use std::time::Instant;

pub use super::result::{ChannelFit, Derived, FitResult, FitSeries, FittedParam, Rank, RecordFit};
pub use super::setup::guess_hint;
pub use super::starts::{DEFAULT_STARTS, MAX_STARTS, PROMOTED_STARTS, SCREEN_ITERATIONS};

/// Correlations above this magnitude are reported as warnings.
pub const CORRELATION_WARNING: f64 = 0.95;

/// Fits `model` (its free parameters, and the oscillator properties and nuisance parameters
/// named in `opts`) to `records`: one parameter set shared by all records, minimising the
/// weighted sum of squared velocity residuals with the bounded Levenberg-Marquardt solver.
///
/// With `opts.domain` = force, the model's force along the measured motion is fitted instead
/// ([`super::force::fit_force`]). A velocity fit of a model with internal states starts also
/// from the optimum of the force-domain prefit ([`super::prefit`]).
pub fn fit(
    osc: &Oscillator,
    model: &(dyn FrictionModel + 'static),
    records: &[Record],
    opts: &FitOptions,
) -> Result<FitResult, EngineError> {
    if opts.domain == FitDomain::Force {
        return fit_force(osc, model, records, opts);
    }
    require_mechanics(&opts.unknown_oscillator, "a velocity-domain fit")?;
    let clock = Instant::now();
    let residuals = Arc::new(VelocityResponse::for_records(
        records,
        opts.velocity_offset,
        opts.time_shift,
        opts.x0,
    )?);
    let seed = prefit(osc, model, records, opts);
    let mut result = fit_seeded(residuals, osc, model, records, opts, seed.as_ref())?;
    if let Some(seed) = &seed {
        result.diagnostics.push(prefit_finding(seed, &result));
        result.wall_time_s = clock.elapsed().as_secs_f64();
    }
    Ok(result)
}

/// Fits `model` with the residuals of `residuals` (see [`fit`]; the nuisance parameters are
/// those `residuals` declares).
pub fn fit_with<R: Residuals + 'static>(
    residuals: Arc<R>,
    osc: &Oscillator,
    model: &(dyn FrictionModel + 'static),
    records: &[Record],
    opts: &FitOptions,
) -> Result<FitResult, EngineError> {
    fit_seeded(residuals, osc, model, records, opts, None)
}

/// [`fit_with`], with one more start at the prefit's optimum when `seed` holds one.
fn fit_seeded<R: Residuals + 'static>(
    residuals: Arc<R>,
    osc: &Oscillator,
    model: &(dyn FrictionModel + 'static),
    records: &[Record],
    opts: &FitOptions,
    seed: Option<&Result<Prefit, EngineError>>,
) -> Result<FitResult, EngineError> {
    let clock = Instant::now();
    check_inputs(osc, model, records, residuals.as_ref())?;
    let layout = build_layout(osc, model, records, residuals.as_ref(), opts)?;
    let seed_model = seed.and_then(|s| s.as_ref().ok()).map(|p| p.model.as_ref());
    let simulated = residuals.simulates_response();
    let direct = strategy::fits_directly(model, simulated);
    let n_starts = start_count(opts, layout.n_model_free(), direct)?;
    let shared: Arc<[Record]> = records.into();
    let make_problem = || {
        FitProblem::new(
            residuals.clone(),
            ProblemParts {
                oscillator: *osc,
                model: layout.start_model.clone(),
                records: shared.clone(),
                layout: layout.params.clone(),
                sim: opts.sim,
                parallel: opts.parallel,
            },
        )
    };
    let reference = make_problem();
    let search = Search::resolve(opts.search, model, layout.n_model_free(), simulated);
    let (runs, origins) = if layout.params.is_empty() {
        (evaluate_as_is(&reference)?, vec!["as given".to_string()])
    } else {
        let plan = StartPlan {
            residuals: &residuals,
            osc,
            model,
            records,
            layout: &layout,
            opts,
        };
        let Planned { seeded, reachable } = starts_with_prefit(&plan, search, n_starts, seed_model);
        let points: Vec<Vec<f64>> = seeded.iter().map(|s| s.point.clone()).collect();
        let runs = run_starts(
            make_problem,
            &reference,
            &points,
            opts,
            search.promoted(),
            reachable,
        )?;
        (runs, seeded.into_iter().map(|s: Seeded| s.origin).collect())
    };
    if let Some((jac, r)) = &runs.best.linearisation {
        reference.adopt_linearisation(&runs.best.u, jac, r);
    }
    let (runs, standings) = identifiability::settle(&reference, runs, opts)?;
    let context = FinishContext {
        opts,
        layout: &layout,
        reference: &reference,
        n_starts: origins.len(),
        search,
        origins: &origins,
        standings: &standings,
    };
    let mut result = finish(&context, runs, clock)?;
    if opts.uncertainty.any() {
        let refit = Refit {
            residuals: residuals.clone(),
            osc,
            opts,
        };
        apply_budget(&mut result, &refit, |r, o, m, op| {
            fit_with(r, o, m, records, op)
        })?;
        result.wall_time_s = clock.elapsed().as_secs_f64();
    }
    Ok(result)
}

/// The starts of `search` (see [`plan_starts`]) and, last (where the prefit finding looks
/// for it), the prefit's optimum when there is one.
fn starts_with_prefit<R: Residuals + 'static>(
    plan: &StartPlan<'_, R>,
    search: Search,
    n_starts: usize,
    prefit: Option<&dyn FrictionModel>,
) -> Planned {
    let mut planned = plan_starts(plan, search, n_starts);
    if let Some(prefit) = prefit {
        planned.seeded.push(Seeded {
            point: seeded_point(plan.layout, prefit),
            origin: PREFIT_ORIGIN.into(),
        });
    }
    planned
}

/// The layout's starting point with the free model parameters at `seeded`'s values (clipped
/// to their bounds).
fn seeded_point(layout: &Layout, seeded: &dyn FrictionModel) -> Vec<f64> {
    let values = seeded.params();
    layout
        .params
        .iter()
        .zip(&layout.start)
        .map(|(f, &x)| match f.kind {
            ParamKind::Model(i) => values.get(i).copied().unwrap_or(x).clamp(f.lower, f.upper),
            _ => x,
        })
        .collect()
}

/// The model, the oscillator and every record are valid (as `residuals` needs them), and
/// there is a record.
fn check_inputs<R: Residuals + ?Sized>(
    osc: &Oscillator,
    model: &dyn FrictionModel,
    records: &[Record],
    residuals: &R,
) -> Result<(), EngineError> {
    osc.validate()?;
    model.validate()?;
    if records.is_empty() {
        return Err(EngineError::InvalidInput(
            "a fit needs at least one record".into(),
        ));
    }
    records
        .iter()
        .try_for_each(|rec| residuals.check_record(rec))
}

/// Nothing to vary: the model evaluated as it is, as a converged run.
fn evaluate_as_is<R: Residuals>(reference: &FitProblem<R>) -> Result<MultiStart, EngineError> {
    let r = reference.residuals_at(&[])?;
    Ok(MultiStart {
        best: StartRun {
            u: DVector::zeros(0),
            cost: 0.5 * r.norm_squared(),
            iterations: 0,
            simulations: reference.simulations(),
            termination: TerminationReason::NoFreeParameters,
            linearisation: None,
        },
        iterations: 0,
        simulations: 0,
        starts_at_best: 1,
        best_start: 0,
        outcomes: Vec::new(),
    })
}

/// What the final phase needs besides the runs.
struct FinishContext<'a, R: Residuals> {
    opts: &'a FitOptions,
    layout: &'a Layout,
    reference: &'a FitProblem<R>,
    n_starts: usize,
    search: Search,
    /// Where each start came from.
    origins: &'a [String],
    /// What the records say about each free parameter.
    standings: &'a [Standing],
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
}

fn statistics<R: Residuals>(
    reference: &FitProblem<R>,
    best: &StartRun,
    standings: &[Standing],
) -> Result<Statistics, EngineError> {
    // Statistics in physical coordinates at the optimum, of the determined parameters.
    let p_best = reference.physical(&best.u);
    let (jac, r) = reference.jacobian_physical(&p_best)?;
    let ssr = r.norm_squared();
    let mut cov = covariance_of_determined(&jac, ssr, standings);
    let segments: Vec<usize> = reference
        .records
        .iter()
        .enumerate()
        .map(|(i, rec)| reference.residuals.residual_count(i, rec))
        .collect();
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
    })
}

/// Noise lag-1 correlation above which standard errors are checked for widening (white
/// noise gives about 1/sqrt(n), far below).
pub const AUTOCORRELATION_THRESHOLD: f64 = 0.1;

/// Widens the covariance when the residuals are autocorrelated: each standard error becomes
/// the larger of the classical and the Newey-West one (Bartlett lags covering the noise's
/// correlation time), keeping the correlations. Returns the finding that says so.
fn widen_for_autocorrelation(
    cov: &mut Covariance,
    jac: &DMatrix<f64>,
    r: &[f64],
    segments: &[usize],
) -> Option<Finding> {
    let mut start = 0;
    let parts: Vec<Vec<f64>> = segments
        .iter()
        .map(|&len| {
            let part = r[start..(start + len).min(r.len())].to_vec();
            start += len;
            part
        })
        .collect();
    let phi = diagnostics::noise_correlation(&parts);
    if phi <= AUTOCORRELATION_THRESHOLD
        || cov.singular
        || cov.residual_variance.is_nan()
        || cov.residual_variance <= 0.0
    {
        return None;
    }
    let shortest = segments.iter().copied().min().unwrap_or(0);
    let lags = ((5.0 * (1.0 + phi) / (1.0 - phi)).ceil() as usize).clamp(1, shortest / 4 + 1);
    let bread = &cov.matrix / cov.residual_variance;
    let hac = stats::newey_west(jac, r, segments, lags, &bread);
    let p = cov.std_errors.len();
    let factors: Vec<f64> = (0..p)
        .map(|i| (hac[(i, i)] / cov.matrix[(i, i)]).sqrt())
        .map(|f| if f.is_finite() { f.max(1.0) } else { 1.0 })
        .collect();
    for a in 0..p {
        for b in 0..p {
            cov.matrix[(a, b)] *= factors[a] * factors[b];
        }
        cov.std_errors[a] *= factors[a];
    }
    let widest = factors.iter().copied().fold(1.0, f64::max);
    Some(Finding::new(
        Check::NoiseCorrelation,
        Status::Pass,
        Some(widest),
        format!(
            "residuals are autocorrelated (noise lag-1 correlation {phi:.2}): standard errors widened by up to {widest:.2}x (Newey-West, {lags} lags)"
        ),
    ))
}

/// Statistics, per-record fits, the energy check and the findings at the best start.
fn finish<R: Residuals>(
    ctx: &FinishContext<'_, R>,
    runs: MultiStart,
    clock: Instant,
) -> Result<FitResult, EngineError> {
    let params = &ctx.layout.params;
    let stats = statistics(ctx.reference, &runs.best, ctx.standings)?;
    let mut simulations = runs.simulations + ctx.reference.simulations();
    let fits = record_fits(ctx.reference, &stats.world, ctx.opts)?;
    simulations += ctx.reference.records.len() as u64;
    let parameters = parameter_entries(&stats, params, ctx.standings);
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
        derived: derived_ratios(&stats.world.oscillator, params, &stats.cov.matrix, ctx.opts),
        records: fits.records,
        rms_residual: (fits.sum_sq / fits.n_total.max(1) as f64).sqrt(),
        compared: ctx.reference.residuals.channel().to_string(),
        residual_unit: ctx.reference.residuals.unit().to_string(),
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
        starts_at_best: strategy::starts_at_best(
            &runs.outcomes,
            runs.best.cost,
            stats.cov.residual_variance,
        ),
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
    findings.extend(stats.widening.clone());
    findings.extend(identifiability_findings(
        ctx.opts,
        ctx.layout.n_model_free(),
    ));
    let names: Vec<(String, String)> = params
        .iter()
        .map(|f| (f.name.clone(), f.unit.clone()))
        .collect();
    findings.extend(identifiability::findings(&names, ctx.standings));
    findings.extend(identifiability::consistency_findings(
        stats.world.model.as_ref(),
    ));
    findings.extend(diagnostics::parameters_at_bounds(params, &stats.p_best));
    findings.extend(fits.findings.iter().cloned());
    if ctx.reference.residuals.simulates_response() {
        findings.push(diagnostics::residual_structure(
            &fits.records,
            &stats.world.oscillator,
            ctx.opts.energy.velocity_threshold,
        ));
    }
    findings
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
            stand(param_entry(&p.name, &p.unit, v, slot, se, tq), slot)
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

/// A warning for a free mass with anything that scales with it.
fn identifiability_findings(opts: &FitOptions, n_model_free: usize) -> Vec<Finding> {
    let mut out = Vec::new();
    let osc_free = |q: OscillatorParam| opts.oscillator.contains(&q);
    if osc_free(OscillatorParam::Mass)
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

/// The per-record fits and what they add up to.
struct RecordFits {
    records: Vec<RecordFit>,
    sum_sq: f64,
    n_total: usize,
    findings: Vec<Finding>,
}

/// Per-record residuals, fitted series and the energy-based force check (one record after
/// the other: on rayon's pool the Coulomb fit on three records took 15-30 % longer).
fn record_fits<R: Residuals>(
    problem: &FitProblem<R>,
    world: &Realised,
    opts: &FitOptions,
) -> Result<RecordFits, EngineError> {
    let mut out = RecordFits {
        records: Vec::new(),
        sum_sq: 0.0,
        n_total: 0,
        findings: Vec::new(),
    };
    for (ri, rec) in problem.records.iter().enumerate() {
        let (record, sum_sq, finding) = record_fit(problem, world, opts, ri, rec)?;
        out.sum_sq += sum_sq;
        out.n_total += record.series.measured.len();
        out.findings.extend(finding);
        out.records.push(record);
    }
    Ok(out)
}

/// The fit of record `ri`: residuals, fitted series and the energy-based force check (with
/// its finding), and the sum of squared residuals of its first channel.
fn record_fit<R: Residuals>(
    problem: &FitProblem<R>,
    world: &Realised,
    opts: &FitOptions,
    ri: usize,
    rec: &Record,
) -> Result<(RecordFit, f64, Option<Finding>), EngineError> {
    let predicted = problem.predict_record(world, ri)?;
    let stacked = problem.residuals.measured(ri, rec);
    let channels = channel_fits(&problem.residuals.segments(ri, rec), &predicted, stacked);
    // The record's first channel is what its `measured` and `fitted` series hold.
    let first = channels.first().map_or(0, |c| c.samples);
    let (fitted, measured) = (predicted[..first].to_vec(), &stacked[..first]);
    let sum_sq = channels.first().map_or(0.0, |c| c.rms_residual.powi(2)) * first as f64;
    let nuisance = &world.nuisance[ri];
    let (energy_force, ebf, mf, finding) = if problem.residuals.simulates_response() {
        match energy_check(problem.residuals.as_ref(), ri, rec, nuisance, world, opts) {
            Ok((ef, ebf, mf)) => {
                let finding = diagnostics::energy_balance(&rec.name, &ef);
                (Some(ef), ebf, mf, Some(finding))
            }
            Err(e) => {
                let finding = Finding::warn(
                    Check::EnergyBalance,
                    None,
                    format!("record `{}`: no energy-based force check: {e}", rec.name),
                );
                (None, Vec::new(), Vec::new(), Some(finding))
            }
        }
    } else {
        (None, Vec::new(), Vec::new(), None)
    };
    let axes = problem.residuals.sample_axes(ri, rec);
    let record = RecordFit {
        file: rec.name.clone(),
        x0: nuisance.x0_of(rec),
        release_time: rec.release_time,
        samples: rec.len(),
        channel: problem.residuals.record_channel(ri).to_string(),
        rms_residual: (sum_sq / measured.len() as f64).sqrt(),
        channels,
        energy_force,
        axes,
        series: FitSeries {
            measured: measured.to_vec(),
            fitted,
            energy_based_force: ebf,
            model_force: mf,
        },
    };
    Ok((record, sum_sq, finding))
}

/// The fit of each compared channel of a record: its RMS residual and noise level, from the
/// record's stacked `predicted` and `measured` series cut at `segments`.
fn channel_fits(segments: &[Segment], predicted: &[f64], measured: &[f64]) -> Vec<ChannelFit> {
    let mut start = 0;
    segments
        .iter()
        .map(|s| {
            let end = (start + s.len).min(predicted.len()).min(measured.len());
            let ss: f64 = predicted[start..end]
                .iter()
                .zip(&measured[start..end])
                .map(|(p, m)| (p - m).powi(2))
                .sum();
            let samples = end - start;
            start = end;
            ChannelFit {
                channel: s.channel.to_string(),
                unit: s.unit.to_string(),
                samples,
                rms_residual: (ss / samples.max(1) as f64).sqrt(),
                noise: s.noise,
            }
        })
        .collect()
}

/// The energy check of record `index` (`rec`), its energy-based force and the model force
/// along it.
fn energy_check<R: Residuals + ?Sized>(
    residuals: &R,
    index: usize,
    rec: &Record,
    nuisance: &NuisanceValues,
    world: &Realised,
    opts: &FitOptions,
) -> Result<(EnergyForce, Vec<f64>, Vec<f64>), EngineError> {
    // The energy analysis sees the measured velocity corrected by the fitted offset, from the
    // fitted release displacement.
    let osc = &world.oscillator;
    let x0 = nuisance.x0_of(rec);
    let analysis = if nuisance.offset == 0.0 && x0 == rec.x0 {
        // The record as measured: the analysis the guess made, when m, c and k are those it
        // was made with.
        residuals.energy_analysis(index, rec, osc, &opts.energy)?
    } else {
        let mut corrected = rec.clone();
        corrected.x0 = x0;
        for v in corrected.velocity_mut() {
            *v -= nuisance.offset;
        }
        Arc::new(analyze_record(&corrected, osc, &opts.energy)?)
    };
    // The fit's step budget: bristles too stiff to replay cheaply (sigma0 far inside a
    // one-sided bound) leave the check out, with a warning, instead of taking seconds.
    let budget = STEPS_PER_SAMPLE * (analysis.time.len() as u64).max(100);
    let model = world.model.as_ref();
    let normal = NormalForce::Constant(osc.normal_force);
    let states = states_along(model, &analysis.time, &analysis.v, &normal, budget)?;
    let model_force = forces_from_states(model, &analysis.v, &normal, &states);
    let ef = energy_force_check(&analysis, ForceReference::ModelForce(&model_force))?;
    Ok((ef, analysis.friction.clone(), model_force))
}

/// k/m and c/m (the combinations velocity data fix) with delta-method standard errors.
fn derived_ratios(
    osc: &Oscillator,
    layout: &[FreeParam],
    cov: &DMatrix<f64>,
    opts: &FitOptions,
) -> Vec<Derived> {
    if opts.oscillator.is_empty() {
        return Vec::new();
    }
    let slot = |kind: ParamKind| layout.iter().position(|f| f.kind == kind);
    let (m, c, k) = (osc.mass, osc.damping, osc.stiffness);
    let sm = slot(ParamKind::Mass);
    let mut out = Vec::new();
    for (name, unit, num, kind) in [
        ("k/m", "1/s^2", k, ParamKind::Stiffness),
        ("c/m", "1/s", c, ParamKind::Damping),
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
