//! The one place a fit runs: [`fit`] picks the residuals (the simulated response, or the
//! force along the measured motion: [`fit_force`]), runs the force-domain prefit that seeds a
//! velocity fit of a dynamic model, lays out the free parameters, searches for the optimum
//! from the starts the strategy plans, settles what the records determine, sums the result
//! up and, when the oscillator's properties are uncertain, runs the refits that propagate
//! them. Read top-down, one fit is: [`fit`] -> (velocity: [`fit_force`] for the prefit) ->
//! `fit_seeded` -> `search_optimum` -> settle and summarise -> property refits (each a
//! [`fit_with`]). The floors below only compute: the prefit ([`search::prefit`]) says with
//! which options to fit and reads the fit it is handed; the strategy
//! ([`search::strategy::plan_fit_starts`]) plans every start, the prefit's among them; the
//! property refits ([`assessment::property_refits`]) say where to refit and are handed a
//! closure that fits (the assessment floor cannot call up into this module); the staged
//! starts fit their simpler laws with the search's own runs, not through this module.

use super::assessment::identifiability;
use super::assessment::property_refits::add_property_uncertainty;
use super::assessment::summary::{summarise, FinishContext};
use super::problem::{check_force_domain, check_moves, require_mechanics, ForceAlongMotion};
use super::problem::{
    simulated_levels, FitProblem, ProblemParts, Realised, Residuals, SimulatedResponse,
};
use super::search::further::{search_further, Searched};
use super::search::prefit::{prefit_finding, prefit_options, Prefit};
use super::search::starts::{run_starts, start_count, MultiStart, StartRun};
use super::search::strategy::{plan_fit_starts, Planned, SimplerFit, StartPlan};
use super::search::{build_layout, Layout};
use super::values::search::check_f_scale;
use super::values::{
    check_min_speed, fits_directly, Finding, FitDomain, FitOptions, FitResult, Search,
    TerminationReason,
};
use crate::error::EngineError;
use crate::oscillator::{Oscillator, OscillatorProperty};
use crate::record::Record;
use crate::simulate::require_simulable_conditions;
use frictionid_models::FrictionModel;
use nalgebra::DVector;
use std::sync::Arc;
use std::time::Instant;

/// Fits `model` (its free parameters, and the oscillator properties and nuisance parameters
/// named in `opts.params`) to `records`: one parameter set shared by all records, minimising
/// the weighted sum of squared velocity residuals with the bounded Levenberg-Marquardt
/// solver.
///
/// With `opts.target.domain` = force, the model's force along the measured motion is fitted
/// instead ([`fit_force`]). A velocity fit of a model with internal states starts also from
/// the optimum of the force-domain prefit ([`super::search::prefit`]).
pub fn fit(
    osc: &Oscillator,
    model: &(dyn FrictionModel + 'static),
    records: &[Record],
    opts: &FitOptions,
) -> Result<FitResult, EngineError> {
    let target = &opts.target;
    check_min_speed(target.min_speed, target.domain).map_err(EngineError::InvalidInput)?;
    check_f_scale(opts.search.f_scale).map_err(EngineError::InvalidInput)?;
    if target.domain == FitDomain::Force {
        return fit_force(osc, model, records, opts);
    }
    require_simulable_conditions(model, records)?;
    let clock = Instant::now();
    let (residuals, simulated) = simulated_response(osc, records, opts)?;
    let seed = prefit_options(model, opts)
        .map(|force_opts| fit_force(osc, model, records, &force_opts).map(Prefit::of));
    let mut result = fit_seeded(residuals, &simulated, model, records, opts, seed.as_ref())?;
    if let Some(seed) = &seed {
        result.diagnostics.push(prefit_finding(seed, &result));
        result.wall_time_s = clock.elapsed().as_secs_f64();
    }
    Ok(result)
}

/// The residuals of a velocity fit (the simulated response of every record, with the
/// nuisance parameters `opts.params` names) and the oscillator it simulates (the levels'
/// normal force where the records carry none).
fn simulated_response(
    osc: &Oscillator,
    records: &[Record],
    opts: &FitOptions,
) -> Result<(Arc<SimulatedResponse>, Oscillator), EngineError> {
    let unknown = &opts.target.unknown_oscillator;
    require_mechanics(unknown, osc.axis, "a velocity-domain fit")?;
    let (levels, simulated) = simulated_levels(records, osc, unknown)?;
    let p = &opts.params;
    let residuals = SimulatedResponse::for_records(records, p.velocity_offset, p.time_shift, p.x0)?
        .with_levels(levels);
    Ok((Arc::new(residuals), simulated))
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

/// Fits `model`'s force along the measured motion of `records` to their target forces (see
/// [`ForceAlongMotion`]; for inverse dynamics with the oscillator properties in
/// `opts.params.oscillator`, started at the linear estimate). The result's residuals are in N.
pub fn fit_force(
    osc: &Oscillator,
    model: &(dyn FrictionModel + 'static),
    records: &[Record],
    opts: &FitOptions,
) -> Result<FitResult, EngineError> {
    check_force_domain(opts)?;
    let producer = ForceAlongMotion::new(records, osc, opts)?;
    producer.check_conditions(model)?;
    let mean_normal = producer.mean_normal_force();
    // Inverse dynamics starts its oscillator properties at the linear estimate.
    let start = producer.starting_oscillator(osc, &opts.params.oscillator);
    let mut result = fit_with(Arc::new(producer), &start, model, records, opts)?;
    if opts.target.is_unknown(OscillatorProperty::NormalForce) {
        // The records carry the normal force; the result's oscillator shows their mean.
        result.oscillator.normal_force = mean_normal;
    }
    Ok(result)
}

/// [`fit_with`], with one more start at the prefit's optimum when `seed` holds one: the
/// layout, the search for the optimum, what the records determine, the result, and the
/// property refits.
fn fit_seeded<R: Residuals + 'static>(
    residuals: Arc<R>,
    osc: &Oscillator,
    model: &(dyn FrictionModel + 'static),
    records: &[Record],
    opts: &FitOptions,
    seed: Option<&Result<Prefit, EngineError>>,
) -> Result<FitResult, EngineError> {
    let clock = Instant::now();
    let seed_model = seed.and_then(|s| s.as_ref().ok()).map(|p| p.model.as_ref());
    let (layout, found) = laid_out_optimum(&residuals, osc, model, records, opts, seed_model)?;
    let settled = identifiability::settle(
        &found.reference,
        found.runs,
        opts,
        found.limit_stage.as_ref(),
    )?;
    let context = FinishContext {
        params: &opts.params,
        energy: &opts.energy,
        layout: &layout,
        reference: &found.reference,
        n_starts: found.origins.len(),
        search: found.search,
        origins: &found.origins,
        standings: &settled.standings,
        redundant: &settled.redundant,
    };
    let mut result = summarise(&context, settled.runs, clock)?;
    result.diagnostics.extend(found.further);
    if opts.uncertainty.any() {
        add_property_uncertainty(&mut result, osc, opts, |shifted, fitted, refit_opts| {
            fit_with(residuals.clone(), shifted, fitted, records, refit_opts)
        })?;
        result.wall_time_s = clock.elapsed().as_secs_f64();
    }
    Ok(result)
}

/// The checked inputs, the layout of the free parameters (the law's fixed ones checked) and
/// the optimum over it ([`search_optimum`], with the prefit's optimum `seed` as one more
/// start): the part of a fit that [`fit_seeded`] and [`lean_fit`] share.
fn laid_out_optimum<R: Residuals + 'static>(
    residuals: &Arc<R>,
    osc: &Oscillator,
    model: &(dyn FrictionModel + 'static),
    records: &[Record],
    opts: &FitOptions,
    seed: Option<&dyn FrictionModel>,
) -> Result<(Layout, Found<R>), EngineError> {
    check_inputs(osc, records, residuals.as_ref())?;
    let layout = build_layout(
        osc,
        model,
        records,
        residuals.as_ref(),
        &opts.params,
        &opts.energy,
    )?;
    layout.validate_fixed(model)?;
    let plan = StartPlan {
        residuals,
        osc,
        model,
        records,
        layout: &layout,
        opts,
    };
    let found = search_optimum(&plan, seed)?;
    Ok((layout, found))
}

/// A fit without its assessment (no identifiability, no diagnostics, no property refits):
/// the realised optimum and each record's residuals at its compared samples, for the
/// held-out validation of a comparison, where only these count.
pub(crate) struct LeanFit {
    /// The oscillator, model and nuisance values at the optimum.
    pub world: Realised,
    /// Each record's residuals (measured minus predicted, its first channel) and their times.
    pub records: Vec<(Vec<f64>, Vec<f64>)>,
}

/// [`fit`] without the prefit and the assessment: the optimum of `model` on `records` from
/// the starts `opts` plan (see [`LeanFit`]).
pub(crate) fn lean_fit(
    osc: &Oscillator,
    model: &(dyn FrictionModel + 'static),
    records: &[Record],
    opts: &FitOptions,
) -> Result<LeanFit, EngineError> {
    check_min_speed(opts.target.min_speed, opts.target.domain)
        .map_err(EngineError::InvalidInput)?;
    if opts.target.domain == FitDomain::Force {
        check_force_domain(opts)?;
        let producer = ForceAlongMotion::new(records, osc, opts)?;
        producer.check_conditions(model)?;
        let start = producer.starting_oscillator(osc, &opts.params.oscillator);
        return lean_with(Arc::new(producer), &start, model, records, opts);
    }
    require_simulable_conditions(model, records)?;
    let (residuals, simulated) = simulated_response(osc, records, opts)?;
    lean_with(residuals, &simulated, model, records, opts)
}

fn lean_with<R: Residuals + 'static>(
    residuals: Arc<R>,
    osc: &Oscillator,
    model: &(dyn FrictionModel + 'static),
    records: &[Record],
    opts: &FitOptions,
) -> Result<LeanFit, EngineError> {
    let (_, found) = laid_out_optimum(&residuals, osc, model, records, opts, None)?;
    let reference = &found.reference;
    let world = reference.realise(&reference.physical(&found.runs.best.u))?;
    let per_record = records
        .iter()
        .enumerate()
        .map(|(ri, rec)| {
            let predicted = reference.predict_record(&world, ri)?;
            let measured = residuals.measured(ri, rec);
            let time = residuals.sample_axes(ri, rec).time;
            let first = match time.len() {
                0 => measured.len(),
                n => n,
            }
            .min(measured.len())
            .min(predicted.len());
            let r = measured[..first]
                .iter()
                .zip(&predicted[..first])
                .map(|(m, p)| m - p)
                .collect();
            Ok((r, time))
        })
        .collect::<Result<Vec<_>, EngineError>>()?;
    Ok(LeanFit {
        world,
        records: per_record,
    })
}

/// The optimum a search found: its runs (the best with its Jacobian adopted by
/// `reference`), where each start came from and the strategy that planned them.
struct Found<R: Residuals> {
    runs: MultiStart,
    reference: FitProblem<R>,
    origins: Vec<String>,
    search: Search,
    /// What the further starts of a record that sticks found, when they ran.
    further: Option<Finding>,
    /// The staged search's fit of the model's rigid-limit law, when it ran one.
    limit_stage: Option<SimplerFit>,
}

/// Searches for the optimum over `plan`'s layout: the number of starts and the strategy
/// the options resolve to, the starts it plans (the prefit's optimum `seed` last), each
/// projected into the domain and run ([`run_starts`]); with nothing free, the model as it
/// is.
fn search_optimum<R: Residuals + 'static>(
    plan: &StartPlan<'_, R>,
    seed: Option<&dyn FrictionModel>,
) -> Result<Found<R>, EngineError> {
    let (layout, opts) = (plan.layout, plan.opts);
    let simulated = plan.residuals.simulates_response();
    let n_model_free = layout.n_model_free();
    let direct = fits_directly(plan.model, simulated);
    let n_starts = start_count(&opts.search, n_model_free, direct)?;
    let shared: Arc<[Record]> = plan.records.into();
    let make_problem = || {
        FitProblem::new(
            plan.residuals.clone(),
            ProblemParts {
                oscillator: *plan.osc,
                model: layout.start_model.clone(),
                records: shared.clone(),
                layout: layout.params.clone(),
                sim: opts.sim,
                parallel: opts.hooks.parallel,
            },
        )
        .with_loss(opts.search.robust_loss())
    };
    let reference = make_problem();
    let search = Search::resolve(opts.search.strategy, plan.model, n_model_free, simulated);
    let (mut runs, origins, further, limit_stage) = if layout.params.is_empty() {
        (
            evaluate_as_is(&reference)?,
            vec!["as given".to_string()],
            None,
            None,
        )
    } else {
        let Planned {
            seeded,
            reachable,
            limit_stage,
        } = plan_fit_starts(plan, search, n_starts, seed);
        let points: Vec<Vec<f64>> = seeded.iter().map(|s| layout.projected(&s.point)).collect();
        let runs = run_starts(
            make_problem,
            &reference,
            &points,
            &opts.search,
            &opts.hooks,
            search.promoted(),
            reachable,
        )?;
        let origins = seeded.into_iter().map(|s| s.origin).collect();
        let Searched {
            runs,
            origins,
            finding,
        } = search_further(plan, &make_problem, &reference, runs, origins);
        (runs, origins, finding, limit_stage)
    };
    if let Some((jac, r)) = runs.best.linearisation.take() {
        reference.adopt_linearisation(&runs.best.u, jac, r);
    }
    Ok(Found {
        runs,
        reference,
        origins,
        search,
        further,
        limit_stage,
    })
}

/// The oscillator and every record are valid (as `residuals` needs them), every record moves
/// ([`check_moves`]), and there is a record. (The model's fixed parameters are checked once
/// the layout says which are free: [`super::search::Layout::validate_fixed`].)
fn check_inputs<R: Residuals + ?Sized>(
    osc: &Oscillator,
    records: &[Record],
    residuals: &R,
) -> Result<(), EngineError> {
    osc.validate()?;
    if records.is_empty() {
        return Err(EngineError::InvalidInput(
            "a fit needs at least one record".into(),
        ));
    }
    records.iter().try_for_each(|rec| {
        residuals.check_record(rec)?;
        check_moves(rec)
    })
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
