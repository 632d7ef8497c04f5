//! The one place a fit runs: [`fit`] picks the residuals (the simulated response, or the
//! force along the measured motion: [`fit_force`]), runs the force-domain prefit that seeds a
//! velocity fit of a dynamic model, lays out the free parameters, runs the starts, settles
//! what the records determine, sums the result up and, when the oscillator's properties are
//! uncertain, runs the refits that propagate them. The floors below only compute: the
//! prefit ([`search::prefit`]) says with which options to fit and reads the fit it is handed;
//! the property refits ([`assessment::property_refits`]) say where to refit and are handed a
//! closure that fits; the staged starts fit their simpler laws with the search's own runs,
//! not through this module.

use super::assessment::identifiability;
use super::assessment::property_refits::add_property_uncertainty;
use super::assessment::summary::{summarise, FinishContext};
use super::problem::{check_force_domain, check_moves, require_mechanics, ForceAlongMotion};
use super::problem::{simulated_levels, FitProblem, ProblemParts, Residuals, SimulatedResponse};
use super::search::prefit::{prefit_finding, prefit_options, Prefit, PREFIT_ORIGIN};
use super::search::starts::{run_starts, start_count, MultiStart, StartRun};
use super::search::strategy::{plan_starts, Planned, Seeded, StartPlan};
use super::search::{build_layout, Layout};
use super::values::{
    check_min_speed, fits_directly, FitDomain, FitOptions, FitResult, ParamKind, Search,
    TerminationReason,
};
use crate::error::EngineError;
use crate::oscillator::{Oscillator, OscillatorProperty};
use crate::record::Record;
use frictionid_models::FrictionModel;
use nalgebra::DVector;
use std::sync::Arc;
use std::time::Instant;

/// Fits `model` (its free parameters, and the oscillator properties and nuisance parameters
/// named in `opts`) to `records`: one parameter set shared by all records, minimising the
/// weighted sum of squared velocity residuals with the bounded Levenberg-Marquardt solver.
///
/// With `opts.domain` = force, the model's force along the measured motion is fitted instead
/// ([`fit_force`]). A velocity fit of a model with internal states starts also from the
/// optimum of the force-domain prefit ([`super::search::prefit`]).
pub fn fit(
    osc: &Oscillator,
    model: &(dyn FrictionModel + 'static),
    records: &[Record],
    opts: &FitOptions,
) -> Result<FitResult, EngineError> {
    check_min_speed(opts.min_speed, opts.domain).map_err(EngineError::InvalidInput)?;
    if opts.domain == FitDomain::Force {
        return fit_force(osc, model, records, opts);
    }
    require_mechanics(&opts.unknown_oscillator, osc.axis, "a velocity-domain fit")?;
    let clock = Instant::now();
    let (levels, simulated) = simulated_levels(records, osc, &opts.unknown_oscillator)?;
    let residuals = Arc::new(
        SimulatedResponse::for_records(records, opts.velocity_offset, opts.time_shift, opts.x0)?
            .with_levels(levels),
    );
    let seed = prefit_options(model, opts)
        .map(|force_opts| fit_force(osc, model, records, &force_opts).map(Prefit::of));
    let mut result = fit_seeded(residuals, &simulated, model, records, opts, seed.as_ref())?;
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

/// Fits `model`'s force along the measured motion of `records` to their target forces (see
/// [`ForceAlongMotion`]; for inverse dynamics with the oscillator properties in
/// `opts.oscillator`, started at the linear estimate). The result's residuals are in N.
pub fn fit_force(
    osc: &Oscillator,
    model: &(dyn FrictionModel + 'static),
    records: &[Record],
    opts: &FitOptions,
) -> Result<FitResult, EngineError> {
    check_force_domain(opts)?;
    let producer = ForceAlongMotion::new(records, osc, opts)?;
    let mean_normal = producer.mean_normal_force();
    // Inverse dynamics starts its oscillator properties at the linear estimate.
    let start = producer.starting_oscillator(osc, &opts.oscillator);
    let mut result = fit_with(Arc::new(producer), &start, model, records, opts)?;
    if opts
        .unknown_oscillator
        .contains(&OscillatorProperty::NormalForce)
    {
        // The records carry the normal force; the result's oscillator shows their mean.
        result.oscillator.normal_force = mean_normal;
    }
    Ok(result)
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
    check_inputs(osc, records, residuals.as_ref())?;
    let layout = build_layout(osc, model, records, residuals.as_ref(), opts)?;
    layout.validate_fixed(model)?;
    let seed_model = seed.and_then(|s| s.as_ref().ok()).map(|p| p.model.as_ref());
    let simulated = residuals.simulates_response();
    let direct = fits_directly(model, simulated);
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
        let points: Vec<Vec<f64>> = seeded.iter().map(|s| layout.projected(&s.point)).collect();
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
    let mut runs = runs;
    if let Some((jac, r)) = runs.best.linearisation.take() {
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
    let mut result = summarise(&context, runs, clock)?;
    if opts.uncertainty.any() {
        add_property_uncertainty(&mut result, osc, opts, |shifted, fitted, refit_opts| {
            fit_with(residuals.clone(), shifted, fitted, records, refit_opts)
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

/// The oscillator and every record are valid (as `residuals` needs them), every record moves
/// ([`check_moves`]), and there is a record. (The model's fixed parameters are checked once
/// the layout says which are free: [`Layout::validate_fixed`].)
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
