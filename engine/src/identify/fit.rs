//! Fitting a friction model (and optionally the oscillator) to velocity records.

use super::layout::{FreeParam, ParamKind};
use super::lm::{is_converged, LevenbergMarquardt, LmState};
use super::options::{FitOptions, OscillatorParam, Progress};
use super::problem::FitProblem;
use super::stats::{aic, bic, covariance, t_quantile_975};
use crate::energy::{analyze_record, force_residuals, mean_abs_where_defined, percent_difference};
use crate::error::EngineError;
use crate::oscillator::Oscillator;
use crate::record::Record;
use argmin::core::observers::{Observe, ObserverMode};
use argmin::core::{Executor, State, KV};
use frictionid_models::{FrictionModel, GuessHint};
use nalgebra::DVector;
use rayon::prelude::*;
use serde::Serialize;
use std::time::Instant;

/// Starts of a multi-start fit when more than two model parameters are free.
pub const DEFAULT_STARTS: usize = 4;

/// Most starts of a multi-start fit (each is a full Levenberg-Marquardt run).
pub const MAX_STARTS: usize = 1000;

/// Iterations every start of a multi-start fit runs before the most promising is continued.
pub const SCREEN_ITERATIONS: u64 = 15;

/// Starts continued to convergence after the screening phase (the best one).
pub const PROMOTED_STARTS: usize = 1;

/// Correlations above this magnitude are reported as warnings.
pub const CORRELATION_WARNING: f64 = 0.95;

/// One parameter of a fit result.
#[derive(Debug, Clone, Serialize)]
pub struct FittedParam {
    /// Name.
    pub name: String,
    /// Value (fitted, or fixed).
    pub value: f64,
    /// Standard error (`None` for fixed or unidentifiable parameters).
    pub std_error: Option<f64>,
    /// 95 % confidence interval.
    pub ci95: Option<[f64; 2]>,
    /// Unit.
    pub unit: String,
    /// Whether it was fitted.
    pub free: bool,
}

/// The energy-based force check of one record.
#[derive(Debug, Clone, Serialize)]
pub struct EnergyForce {
    /// Mean |F_f| from Eq. 7 over the unmasked oscillating samples [N].
    pub mean_abs: f64,
    /// Mean |F| of the fitted model along the measured motion over the same samples [N]
    /// (mu N for Coulomb).
    pub reference: f64,
    /// 100 (mean_abs - reference) / reference.
    pub percent_difference: f64,
    /// RMS of the energy-based minus model force [N].
    pub residual_rms: f64,
    /// Samples compared.
    pub samples: usize,
    /// Mean friction force of the half-cycles (energy balance, no differentiation) [N].
    pub half_cycle_mean: f64,
}

/// The fit of one record.
#[derive(Debug, Clone, Serialize)]
pub struct RecordFit {
    /// Record name (file).
    pub file: String,
    /// Release displacement [m].
    pub x0: f64,
    /// Samples.
    pub samples: usize,
    /// RMS of v_sim - v_measured [m/s].
    pub rms_residual: f64,
    /// Energy-based force check (absent when the record cannot be analysed).
    pub energy_force: Option<EnergyForce>,
    /// Time stamps (for plots).
    #[serde(skip)]
    pub time: Vec<f64>,
    /// Measured velocity.
    #[serde(skip)]
    pub measured: Vec<f64>,
    /// Fitted velocity (simulated, plus offset).
    #[serde(skip)]
    pub fitted: Vec<f64>,
    /// Energy-based friction force (NaN where masked).
    #[serde(skip)]
    pub energy_based_force: Vec<f64>,
    /// The model's force along the measured motion.
    #[serde(skip)]
    pub model_force: Vec<f64>,
}

/// A ratio the data fix even when its parts are not separately identifiable.
#[derive(Debug, Clone, Serialize)]
pub struct Derived {
    /// Name (e.g. `k/m`).
    pub name: String,
    /// Value.
    pub value: f64,
    /// Standard error by the delta method (when the covariance exists).
    pub std_error: Option<f64>,
    /// Unit.
    pub unit: String,
}

/// The result of a fit.
#[derive(Debug, Clone, Serialize)]
pub struct FitResult {
    /// Registry name of the model.
    pub model: String,
    /// The fitted model (all parameters).
    pub fitted_model: Box<dyn FrictionModel>,
    /// The oscillator (fitted where requested).
    pub oscillator: Oscillator,
    /// Every model parameter, then fitted oscillator and nuisance parameters.
    pub parameters: Vec<FittedParam>,
    /// Names of the free parameters, in the order of `correlation`.
    pub correlation_names: Vec<String>,
    /// Correlation matrix of the free parameters (rows).
    pub correlation: Vec<Vec<f64>>,
    /// Ratios the data fix (k/m, c/m) when the oscillator is fitted.
    pub derived: Vec<Derived>,
    /// Per record.
    pub records: Vec<RecordFit>,
    /// RMS residual over all records [m/s].
    pub rms_residual: f64,
    /// Half the weighted sum of squared residuals.
    pub cost: f64,
    /// Akaike information criterion.
    pub aic: f64,
    /// Bayesian information criterion.
    pub bic: f64,
    /// Samples over all records.
    pub samples: usize,
    /// Free parameters (including nuisance parameters).
    pub free_parameters: usize,
    /// Whether the best start converged.
    pub converged: bool,
    /// Why the solver stopped.
    pub termination: String,
    /// Solver iterations over all starts.
    pub iterations: u64,
    /// Simulations over all starts and the statistics.
    pub simulations: u64,
    /// Number of starts.
    pub starts: usize,
    /// Starts that reached the best cost (within 1e-6 relative).
    pub starts_at_best: usize,
    /// Warnings (strong correlations, unidentifiable combinations, failed starts, ...).
    pub warnings: Vec<String>,
    /// Wall time of the fit [s].
    pub wall_time_s: f64,
}

struct StartOutcome {
    u: DVector<f64>,
    cost: f64,
    iterations: u64,
    simulations: u64,
    termination: String,
    converged: bool,
}

struct ProgressObserver {
    model: String,
    start: usize,
    starts: usize,
    max_iterations: u64,
    callback: super::options::ProgressFn,
}

impl Observe<LmState> for ProgressObserver {
    fn observe_iter(&mut self, state: &LmState, _kv: &KV) -> Result<(), argmin::core::Error> {
        (self.callback)(&Progress {
            model: self.model.clone(),
            start: self.start,
            starts: self.starts,
            iteration: state.get_iter(),
            max_iterations: self.max_iterations,
            cost: state.get_best_cost(),
        });
        Ok(())
    }
}

/// Data-driven hints: the friction level from the half-cycle energy estimate, a typical speed.
pub fn guess_hint(osc: &Oscillator, records: &[Record], opts: &FitOptions) -> GuessHint {
    let mut levels = Vec::new();
    let mut speeds = Vec::new();
    for rec in records {
        if let Ok(a) = analyze_record(rec, osc, &opts.energy) {
            if a.half_cycle_mean.is_finite() && a.half_cycle_mean > 0.0 {
                levels.push(a.half_cycle_mean);
            } else if a.mean_abs_force.is_finite() && a.mean_abs_force > 0.0 {
                levels.push(a.mean_abs_force);
            }
        }
        let peak = rec.velocity().iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if peak > 0.0 {
            speeds.push(peak / 2.0);
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let n = osc.normal_force;
    let mu = if levels.is_empty() || n <= 0.0 {
        0.2
    } else {
        (mean(&levels) / n).clamp(1e-4, 5.0)
    };
    GuessHint {
        mu,
        typical_velocity: if speeds.is_empty() {
            0.05
        } else {
            mean(&speeds)
        },
        normal_force: n,
        stiffness: osc.stiffness,
        mass: osc.mass,
    }
}

fn unknown_name(kind: &str, name: &str, valid: &[String]) -> EngineError {
    let hint = frictionid_models::suggest::did_you_mean(name, valid.iter().map(String::as_str));
    EngineError::InvalidInput(format!(
        "{kind} `{name}` is not a parameter{hint}; valid: {}",
        valid.join(", ")
    ))
}

/// The initial model, the layout of free parameters and the initial physical values.
type Layout = (Box<dyn FrictionModel>, Vec<FreeParam>, Vec<f64>);

/// Builds the starting model and the free-parameter layout from the options.
fn build_layout(
    osc: &Oscillator,
    model: &(dyn FrictionModel + 'static),
    records: &[Record],
    opts: &FitOptions,
) -> Result<Layout, EngineError> {
    let info = model.param_info();
    let names: Vec<String> = info.iter().map(|p| p.name.clone()).collect();
    let mut valid = names.clone();
    valid.extend(["mass", "damping", "stiffness", "offset", "shift"].map(String::from));
    for b in opts.bounds.keys() {
        if !valid.contains(b) {
            return Err(unknown_name("bound", b, &valid));
        }
    }
    for (k, &(lo, hi)) in &opts.bounds {
        if lo.is_nan() || hi.is_nan() || lo >= hi {
            return Err(EngineError::InvalidInput(format!(
                "bounds of `{k}` must satisfy lower < upper, got [{lo}, {hi}]"
            )));
        }
    }
    let free: Vec<usize> = match &opts.free {
        Some(list) => {
            let mut idx = Vec::new();
            for name in list {
                match names.iter().position(|n| n == name) {
                    Some(i) if !idx.contains(&i) => idx.push(i),
                    Some(_) => {}
                    None if OscillatorParam::parse(name).is_some() => {}
                    None => return Err(unknown_name("free parameter", name, &names)),
                }
            }
            idx.sort_unstable();
            idx
        }
        None => (0..info.len())
            .filter(|&i| !info[i].fixed_by_default)
            .collect(),
    };
    for k in &opts.keep_initial {
        if !names.contains(k) {
            return Err(unknown_name("initial value", k, &names));
        }
    }

    let mut start_model = frictionid_models::clone_model(model);
    if opts.guess && !free.is_empty() {
        let given = model.params();
        start_model.apply_guess(&guess_hint(osc, records, opts));
        let mut values = start_model.params();
        for (i, name) in names.iter().enumerate() {
            if !free.contains(&i) || opts.keep_initial.contains(name) {
                values[i] = given[i];
            }
        }
        start_model.set_params(&values)?;
    }
    let values = start_model.params();

    let mut layout = Vec::new();
    let mut start = Vec::new();
    for &i in &free {
        let p = &info[i];
        let (lo, hi) = opts
            .bounds
            .get(&p.name)
            .copied()
            .unwrap_or((p.lower, p.upper));
        let log = p.lower_exclusive && p.lower == 0.0 && lo >= 0.0;
        let (lo_eff, hi_eff) = if log { (lo.max(0.0), hi) } else { (lo, hi) };
        let mut x = values[i];
        if log {
            x = x.max(lo_eff).max(f64::MIN_POSITIVE);
        }
        x = x.clamp(lo_eff, hi_eff);
        let mut f = FreeParam::linear(
            p.name.clone(),
            &p.unit,
            ParamKind::Model(i),
            (lo_eff, hi_eff),
            x,
            1.0,
        );
        f.log = log;
        layout.push(f);
        start.push(x);
    }
    for q in &opts.oscillator {
        let name = q.name();
        let current = match q {
            OscillatorParam::Mass => osc.mass,
            OscillatorParam::Damping => osc.damping,
            OscillatorParam::Stiffness => osc.stiffness,
        };
        let log = !matches!(q, OscillatorParam::Damping);
        let default_bounds = (0.0, f64::INFINITY);
        let (lo, hi) = opts.bounds.get(name).copied().unwrap_or(default_bounds);
        let typical = 2e-3 * (osc.mass * osc.stiffness).sqrt();
        let mut f = FreeParam::linear(
            name.to_string(),
            q.unit(),
            match q {
                OscillatorParam::Mass => ParamKind::Mass,
                OscillatorParam::Damping => ParamKind::Damping,
                OscillatorParam::Stiffness => ParamKind::Stiffness,
            },
            (lo, hi),
            current,
            typical,
        );
        f.log = log;
        layout.push(f);
        start.push(current.clamp(lo.max(if log { f64::MIN_POSITIVE } else { lo }), hi));
    }
    for (r, rec) in records.iter().enumerate() {
        if opts.velocity_offset {
            let b = opts
                .bounds
                .get("offset")
                .copied()
                .unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
            layout.push(FreeParam::linear(
                format!("offset[{}]", rec.name),
                "m/s",
                ParamKind::Offset(r),
                b,
                0.0,
                1e-4,
            ));
            start.push(0.0f64.clamp(b.0, b.1));
        }
        if opts.time_shift {
            let b = opts.bounds.get("shift").copied().unwrap_or((-0.1, 0.1));
            layout.push(FreeParam::linear(
                format!("shift[{}]", rec.name),
                "s",
                ParamKind::Shift(r),
                b,
                0.0,
                1e-3,
            ));
            start.push(0.0f64.clamp(b.0, b.1));
        }
    }
    Ok((start_model, layout, start))
}

/// Radical inverse in base `b` (the Halton sequence), in [0, 1).
fn halton(mut i: usize, b: usize) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= b as f64;
        r += f * (i % b) as f64;
        i /= b;
    }
    r
}

const PRIMES: [usize; 12] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37];

/// Starting points: the initial values, then points spread by factors 3^(±1) around them
/// along a Halton sequence (clipped to the bounds); nuisance parameters start at 0.
fn starting_points(layout: &[FreeParam], start: &[f64], n: usize) -> Vec<Vec<f64>> {
    let mut out = vec![start.to_vec()];
    for s in 1..n {
        let p = layout
            .iter()
            .zip(start)
            .enumerate()
            .map(|(j, (f, &x0))| {
                if !matches!(f.kind, ParamKind::Model(_)) {
                    return x0;
                }
                let q = 2.0 * halton(s, PRIMES[j % PRIMES.len()]) - 1.0;
                let x = if x0 != 0.0 {
                    x0 * 3f64.powf(q)
                } else {
                    f.scale * (q + 1.0)
                };
                let lo = if f.log {
                    f.lower.max(f64::MIN_POSITIVE)
                } else {
                    f.lower
                };
                x.clamp(lo, f.upper)
            })
            .collect();
        out.push(p);
    }
    out
}

fn run_start(
    problem: FitProblem,
    u0: DVector<f64>,
    opts: &FitOptions,
    max_iterations: u64,
    start: usize,
    starts: usize,
) -> Result<StartOutcome, EngineError> {
    let bounds: Vec<(f64, f64)> = problem
        .layout
        .iter()
        .map(FreeParam::internal_bounds)
        .collect();
    let lower = DVector::from_iterator(bounds.len(), bounds.iter().map(|b| b.0));
    let upper = DVector::from_iterator(bounds.len(), bounds.iter().map(|b| b.1));
    let mut solver = LevenbergMarquardt::new(lower, upper);
    // One step changes a log-scaled parameter by at most a factor e^2 and a linear one by at
    // most twice its scale, so a poor linearisation cannot throw a trial point into a region
    // where the simulation is stiff or degenerate.
    solver.max_step = 2.0;
    if let Some(t) = opts.tolerance {
        solver.ftol = t;
    }
    let model_name = problem.model.name().to_string();
    let mut exec = Executor::new(problem, solver)
        .configure(|s| s.param(u0).max_iters(max_iterations))
        .ctrlc(false)
        .timer(false);
    if let Some(cb) = &opts.progress {
        exec = exec.add_observer(
            ProgressObserver {
                model: model_name,
                start,
                starts,
                max_iterations,
                callback: cb.clone(),
            },
            ObserverMode::Always,
        );
    }
    let res = exec.run().map_err(|e| EngineError::Fit(e.to_string()))?;
    let state = res.state();
    let simulations = res
        .problem()
        .problem
        .as_ref()
        .map(FitProblem::simulations)
        .unwrap_or(0);
    let u = state
        .get_best_param()
        .cloned()
        .ok_or_else(|| EngineError::Fit("the solver returned no parameters".into()))?;
    let converged = is_converged(&state.termination_status);
    let termination = match &state.termination_status {
        argmin::core::TerminationStatus::Terminated(
            argmin::core::TerminationReason::MaxItersReached,
        ) => format!("iteration limit ({max_iterations}) reached"),
        s => s.to_string(),
    };
    Ok(StartOutcome {
        u,
        cost: state.get_best_cost(),
        iterations: state.get_iter(),
        simulations,
        termination,
        converged,
    })
}

/// Fits `model` (its free parameters, and the oscillator properties and nuisance parameters
/// named in `opts`) to `records`: one parameter set shared by all records, minimising the
/// weighted sum of squared velocity residuals with the bounded Levenberg-Marquardt solver.
pub fn fit(
    osc: &Oscillator,
    model: &(dyn FrictionModel + 'static),
    records: &[Record],
    opts: &FitOptions,
) -> Result<FitResult, EngineError> {
    let clock = Instant::now();
    osc.validate()?;
    model.validate()?;
    if records.is_empty() {
        return Err(EngineError::InvalidInput(
            "a fit needs at least one record".into(),
        ));
    }
    for rec in records {
        rec.validate(3)?;
    }
    let (start_model, layout, start) = build_layout(osc, model, records, opts)?;
    let n_model_free = layout
        .iter()
        .filter(|f| matches!(f.kind, ParamKind::Model(_)))
        .count();
    let n_starts = opts
        .multistart
        .unwrap_or(if n_model_free > 2 { DEFAULT_STARTS } else { 1 })
        .max(1);
    if n_starts > MAX_STARTS {
        return Err(EngineError::InvalidInput(format!(
            "multistart = {n_starts}: at most {MAX_STARTS} starts"
        )));
    }
    let make_problem = || {
        FitProblem::new(
            *osc,
            start_model.clone(),
            records.to_vec(),
            layout.clone(),
            opts.sim,
            opts.parallel,
        )
    };
    let reference = make_problem();
    let mut points = starting_points(&layout, &start, n_starts);
    // The configured values are a start of their own when they differ from the data-driven
    // guess (for the built-in models they are typical literature values).
    if n_starts > 1 && opts.guess {
        let configured: Vec<f64> = layout
            .iter()
            .zip(&start)
            .map(|(f, &x)| match f.kind {
                ParamKind::Model(i) => model.params()[i].clamp(f.lower, f.upper),
                _ => x,
            })
            .collect();
        if configured != start {
            points.insert(1, configured);
            points.truncate(n_starts);
        }
    }
    // Phase 1: every start for a few iterations; phase 2: the most promising ones to the end.
    let screen = if n_starts > 1 {
        SCREEN_ITERATIONS.min(opts.max_iterations)
    } else {
        opts.max_iterations
    };
    let run = |(s, p): (usize, &Vec<f64>), iters: u64| {
        let problem = make_problem();
        let u0 = problem.internal(p);
        run_start(problem, u0, opts, iters, s, n_starts)
    };
    if layout.is_empty() {
        // Nothing to vary: evaluate the model as it is.
        let r = reference.residuals_at(&[])?;
        let cost = half_sq_norm(&r);
        return finish(
            FinishInput {
                records,
                opts,
                layout: &layout,
                reference: &reference,
                best: StartOutcome {
                    u: DVector::zeros(0),
                    cost,
                    iterations: 0,
                    simulations: reference.simulations(),
                    termination: "converged: no free parameters".into(),
                    converged: true,
                },
                iterations: 0,
                simulations: 0,
                n_starts: 1,
                starts_at_best: 1,
                n_model_free,
                warnings: Vec::new(),
            },
            clock,
        );
    }
    let screened: Vec<Result<StartOutcome, EngineError>> = if opts.parallel && n_starts > 1 {
        points
            .par_iter()
            .enumerate()
            .map(|x| run(x, screen))
            .collect()
    } else {
        points.iter().enumerate().map(|x| run(x, screen)).collect()
    };
    let mut warnings = Vec::new();
    let mut ok = Vec::new();
    let mut first_error = None;
    for (s, o) in screened.into_iter().enumerate() {
        match o {
            Ok(o) if o.cost.is_finite() => ok.push((s, o)),
            Ok(_) => warnings.push(format!("start {s} ended with a non-finite cost")),
            Err(e) => {
                warnings.push(format!("start {s} failed: {e}"));
                first_error.get_or_insert(e);
            }
        }
    }
    if n_starts > 1 && screen < opts.max_iterations {
        ok.sort_by(|a, b| a.1.cost.total_cmp(&b.1.cost));
        let keep = PROMOTED_STARTS.min(ok.len());
        let promoted: Vec<(usize, DVector<f64>)> = ok[..keep]
            .iter()
            .filter(|(_, o)| !o.converged)
            .map(|(s, o)| (*s, o.u.clone()))
            .collect();
        let remaining = opts.max_iterations - screen;
        let finish = |(s, u): &(usize, DVector<f64>)| {
            run_start(make_problem(), u.clone(), opts, remaining, *s, n_starts).map(|o| (*s, o))
        };
        let finished: Vec<Result<(usize, StartOutcome), EngineError>> = if opts.parallel {
            promoted.par_iter().map(finish).collect()
        } else {
            promoted.iter().map(finish).collect()
        };
        for f in finished {
            match f {
                Ok((s, o)) if o.cost.is_finite() => {
                    if let Some(slot) = ok.iter_mut().find(|(t, _)| *t == s) {
                        let before = std::mem::replace(&mut slot.1, o);
                        slot.1.iterations += before.iterations;
                        slot.1.simulations += before.simulations;
                        if !slot.1.converged && slot.1.termination.starts_with("iteration limit") {
                            slot.1.termination =
                                format!("iteration limit ({}) reached", opts.max_iterations);
                        }
                    }
                }
                Ok(_) => {}
                Err(e) => warnings.push(format!("a promoted start failed: {e}")),
            }
        }
    }
    let mut ok: Vec<StartOutcome> = ok.into_iter().map(|(_, o)| o).collect();
    if ok.is_empty() {
        let why = first_error
            .map(|e| e.to_string())
            .unwrap_or_else(|| "no start produced a finite cost".into());
        let detail = reference
            .residuals_at(&points[0])
            .err()
            .map(|d| format!(" ({d})"))
            .unwrap_or_default();
        return Err(EngineError::Fit(format!("{why}{detail}")));
    }
    let iterations: u64 = ok.iter().map(|o| o.iterations).sum();
    let simulations: u64 = ok.iter().map(|o| o.simulations).sum();
    let best_idx = ok
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.cost.total_cmp(&b.1.cost))
        .map(|(i, _)| i)
        .unwrap_or(0);
    let best_cost = ok[best_idx].cost;
    let starts_at_best = ok
        .iter()
        .filter(|o| o.cost <= best_cost * (1.0 + 1e-6) + 1e-300)
        .count();

    let best = ok.swap_remove(best_idx);
    finish(
        FinishInput {
            records,
            opts,
            layout: &layout,
            reference: &reference,
            best,
            iterations,
            simulations,
            n_starts,
            starts_at_best,
            n_model_free,
            warnings,
        },
        clock,
    )
}

fn half_sq_norm(r: &DVector<f64>) -> f64 {
    0.5 * r.norm_squared()
}

struct FinishInput<'a> {
    records: &'a [Record],
    opts: &'a FitOptions,
    layout: &'a [FreeParam],
    reference: &'a FitProblem,
    best: StartOutcome,
    iterations: u64,
    simulations: u64,
    n_starts: usize,
    starts_at_best: usize,
    n_model_free: usize,
    warnings: Vec<String>,
}

/// Statistics, per-record residuals and the energy check at the best parameters.
fn finish(input: FinishInput<'_>, clock: Instant) -> Result<FitResult, EngineError> {
    let FinishInput {
        records,
        opts,
        layout,
        reference,
        best,
        iterations,
        mut simulations,
        n_starts,
        starts_at_best,
        n_model_free,
        mut warnings,
    } = input;
    // Statistics in physical coordinates at the optimum.
    let p_best = reference.physical(&best.u);
    let (jac, r) = reference.jacobian_physical(&p_best)?;
    simulations += reference.simulations();
    let ssr = r.norm_squared();
    let cov = covariance(&jac, ssr);
    let tq = t_quantile_975(cov.dof);
    let world = reference.realise(&p_best)?;

    let mut parameters = Vec::new();
    let info = world.model.param_info();
    let values = world.model.params();
    for (i, (p, &v)) in info.iter().zip(&values).enumerate() {
        let slot = layout.iter().position(|f| f.kind == ParamKind::Model(i));
        parameters.push(param_entry(&p.name, &p.unit, v, slot, &cov.std_errors, tq));
    }
    for (slot, f) in layout.iter().enumerate() {
        if !matches!(f.kind, ParamKind::Model(_)) {
            parameters.push(param_entry(
                &f.name,
                &f.unit,
                p_best[slot],
                Some(slot),
                &cov.std_errors,
                tq,
            ));
        }
    }
    let names: Vec<String> = layout.iter().map(|f| f.name.clone()).collect();
    let k = layout.len();
    let correlation: Vec<Vec<f64>> = (0..k)
        .map(|a| (0..k).map(|b| cov.correlation[(a, b)]).collect())
        .collect();
    for a in 0..k {
        for b in (a + 1)..k {
            let rho = cov.correlation[(a, b)];
            if rho.abs() > CORRELATION_WARNING {
                warnings.push(format!(
                    "`{}` and `{}` are strongly correlated (rho = {rho:.3}): the data barely separate them",
                    names[a], names[b]
                ));
            }
        }
    }
    if cov.singular {
        warnings.push(
            "the Jacobian is rank-deficient: some free parameters are not separately identifiable from these records (no standard errors)".into(),
        );
    }
    let osc_free = |q: OscillatorParam| opts.oscillator.contains(&q);
    if osc_free(OscillatorParam::Mass)
        && (osc_free(OscillatorParam::Stiffness)
            || osc_free(OscillatorParam::Damping)
            || n_model_free > 0)
    {
        warnings.push(
            "velocity alone fixes k/m, c/m and friction/m, not m: with the mass free, scaling m, c, k and the friction level together leaves the motion unchanged; fix the mass (or another of them) to identify the rest".into(),
        );
    }
    let derived = derived_ratios(&world.oscillator, layout, &cov.matrix, opts);

    // Per-record residuals, fitted series and the energy-based force check.
    let mut record_fits = Vec::new();
    let mut sum_sq = 0.0;
    let mut n_total = 0usize;
    for (ri, rec) in records.iter().enumerate() {
        let sim = reference.simulate_record(&world, ri)?;
        let fitted: Vec<f64> = sim.iter().map(|v| v + world.offsets[ri]).collect();
        let ss: f64 = fitted
            .iter()
            .zip(rec.velocity())
            .map(|(f, m)| (f - m).powi(2))
            .sum();
        sum_sq += ss;
        n_total += rec.len();
        let (energy_force, ebf, mf) = match energy_check(rec, &world, ri, opts) {
            Ok(x) => x,
            Err(e) => {
                warnings.push(format!(
                    "record `{}`: no energy-based force check: {e}",
                    rec.name
                ));
                (None, Vec::new(), Vec::new())
            }
        };
        record_fits.push(RecordFit {
            file: rec.name.clone(),
            x0: rec.x0,
            samples: rec.len(),
            rms_residual: (ss / rec.len() as f64).sqrt(),
            energy_force,
            time: rec.time().to_vec(),
            measured: rec.velocity().to_vec(),
            fitted,
            energy_based_force: ebf,
            model_force: mf,
        });
    }
    simulations += records.len() as u64;
    let n_free = layout.len();
    let samples = reference.n_residuals();
    Ok(FitResult {
        model: world.model.name().to_string(),
        fitted_model: world.model,
        oscillator: world.oscillator,
        parameters,
        correlation_names: names,
        correlation,
        derived,
        records: record_fits,
        rms_residual: (sum_sq / n_total.max(1) as f64).sqrt(),
        cost: 0.5 * ssr,
        aic: aic(samples, ssr, n_free),
        bic: bic(samples, ssr, n_free),
        samples,
        free_parameters: n_free,
        converged: best.converged,
        termination: best.termination.clone(),
        iterations,
        simulations,
        starts: n_starts,
        starts_at_best,
        warnings,
        wall_time_s: clock.elapsed().as_secs_f64(),
    })
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
        .filter(|s| s.is_finite());
    FittedParam {
        name: name.to_string(),
        value,
        std_error,
        ci95: std_error.map(|s| [value - tq * s, value + tq * s]),
        unit: unit.to_string(),
        free: slot.is_some(),
    }
}

type EnergyCheck = (Option<EnergyForce>, Vec<f64>, Vec<f64>);

fn energy_check(
    rec: &Record,
    world: &super::problem::Realised,
    ri: usize,
    opts: &FitOptions,
) -> Result<EnergyCheck, EngineError> {
    // The energy analysis sees the measured velocity corrected by the fitted offset.
    let mut corrected = rec.clone();
    for v in corrected.velocity_mut() {
        *v -= world.offsets[ri];
    }
    let analysis = analyze_record(&corrected, &world.oscillator, &opts.energy)?;
    let fr = force_residuals(&analysis, world.model.as_ref(), &world.oscillator)?;
    let reference = mean_abs_where_defined(&fr.model_force, &analysis.friction);
    let ef = EnergyForce {
        mean_abs: analysis.mean_abs_force,
        reference,
        percent_difference: percent_difference(analysis.mean_abs_force, reference),
        residual_rms: fr.rms,
        samples: fr.used,
        half_cycle_mean: analysis.half_cycle_mean,
    };
    Ok((Some(ef), analysis.friction.clone(), fr.model_force))
}

/// k/m and c/m (the combinations velocity data fix) with delta-method standard errors.
fn derived_ratios(
    osc: &Oscillator,
    layout: &[FreeParam],
    cov: &nalgebra::DMatrix<f64>,
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

/// A fit's parameter value by name (model or oscillator), for callers and tests.
impl FitResult {
    /// The value of the parameter `name`.
    pub fn value(&self, name: &str) -> Option<f64> {
        self.parameters
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.value)
    }

    /// The parameter entry `name`.
    pub fn param(&self, name: &str) -> Option<&FittedParam> {
        self.parameters.iter().find(|p| p.name == name)
    }
}
