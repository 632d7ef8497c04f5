//! Multi-start strategy: where the starts begin, one Levenberg-Marquardt run per start, a short
//! screening of every start and the continuation of the most promising one.

use super::lm::{termination_reason, LevenbergMarquardt, LmState, NonFiniteStart, Pace};
use crate::error::EngineError;
use crate::identify::problem::least_squares::{FitProblem, Realised};
use crate::identify::problem::residuals::{RecordCase, Residuals};
use crate::identify::values::fit_options::Hooks;
use crate::identify::values::layout::{FreeParam, ParamKind};
use crate::identify::values::nuisance::NuisanceKind;
use crate::identify::values::options::{Progress, ProgressFn};
use crate::identify::values::outcome::{StartOutcome, TerminationReason};
use crate::identify::values::param_options::ParamOptions;
use crate::identify::values::search::SearchOptions;
use crate::record::Record;
use argmin::core::observers::{Observe, ObserverMode};
use argmin::core::{Error, Executor, Jacobian, Operator, State, KV};
use frictionid_models::FrictionModel;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::sync::{Arc, Mutex};

/// A fit's run stops when the Gauss-Newton step would move its parameters by less than this
/// many standard errors: further iterations would not change the estimates within their
/// precision (on the damper sweep a tenth of the iterations, mostly Coulomb's, with every
/// estimate within 0.009 standard errors of where the other tolerances stopped it).
pub const STANDARD_ERROR_RESOLUTION: f64 = 0.01;

/// Starts of a multi-start fit when more than two model parameters are free.
pub const DEFAULT_STARTS: usize = 4;

/// Most starts of a multi-start fit (each is a full Levenberg-Marquardt run).
pub const MAX_STARTS: usize = 1000;

/// Iterations every start of a multi-start fit runs before the most promising is continued.
pub const SCREEN_ITERATIONS: u64 = 15;

/// Iterations a screened start runs before it is held to a cost the model is known to reach
/// (the fit of the nested law it contains): one still [`super::lm::OUTPACE_FACTOR`] times
/// above it is abandoned.
pub const SCREEN_GRACE: u64 = 5;

/// One start's run: where it ended and how.
pub struct StartRun {
    /// Internal coordinates of its best point.
    pub u: DVector<f64>,
    /// Its best cost.
    pub cost: f64,
    /// Solver iterations.
    pub iterations: u64,
    /// Simulations run.
    pub simulations: u64,
    /// Why it stopped.
    pub termination: TerminationReason,
    /// The Jacobian (internal coordinates) and residuals at `u`, when the solver has them.
    pub linearisation: Option<(DMatrix<f64>, DVector<f64>)>,
}

impl StartRun {
    /// Whether it converged.
    pub fn converged(&self) -> bool {
        self.termination.is_converged()
    }
}

/// The number of starts: as asked, else one when at most two model parameters are free or
/// the fit is `direct` (a static law along the measured motion, see
/// [`crate::identify::values::fits_directly`]).
pub fn start_count(
    search: &SearchOptions,
    n_model_free: usize,
    direct: bool,
) -> Result<usize, EngineError> {
    let n = search
        .multistart
        .unwrap_or(if n_model_free > 2 && !direct {
            DEFAULT_STARTS
        } else {
            1
        })
        .max(1);
    if n > MAX_STARTS {
        return Err(EngineError::InvalidInput(format!(
            "multistart = {n}: at most {MAX_STARTS} starts"
        )));
    }
    Ok(n)
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
pub fn starting_points(layout: &[FreeParam], start: &[f64], n: usize) -> Vec<Vec<f64>> {
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
                f.clip(x)
            })
            .collect();
        out.push(p);
    }
    out
}

/// The starting points of a fit: [`starting_points`], with the configured model values as a
/// start of their own (second) when they differ from the data-driven guess (for the built-in
/// models they are typical literature values).
pub fn fit_starting_points(
    layout: &[FreeParam],
    start: &[f64],
    configured_model: &dyn FrictionModel,
    params: &ParamOptions,
    n_starts: usize,
) -> Vec<Vec<f64>> {
    let mut points = starting_points(layout, start, n_starts);
    if n_starts > 1 && params.guess {
        let given = configured_model.params();
        let configured: Vec<f64> = layout
            .iter()
            .zip(start)
            .map(|(f, &x)| match f.kind {
                ParamKind::Model(i) => given[i].clamp(f.lower, f.upper),
                _ => x,
            })
            .collect();
        if configured != start {
            points.insert(1, configured);
            points.truncate(n_starts);
        }
    }
    points
}

struct ProgressObserver {
    model: String,
    start: usize,
    starts: usize,
    max_iterations: u64,
    callback: ProgressFn,
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

/// The solver for `problem`'s bounds with the fit's step cap and tolerance.
fn solver_for<R: Residuals>(problem: &FitProblem<R>, search: &SearchOptions) -> LevenbergMarquardt {
    let bounds: Vec<(f64, f64)> = problem
        .layout
        .iter()
        .map(FreeParam::internal_bounds)
        .collect();
    let lower = DVector::from_iterator(bounds.len(), bounds.iter().map(|b| b.0));
    let upper = DVector::from_iterator(bounds.len(), bounds.iter().map(|b| b.1));
    let mut solver = LevenbergMarquardt::new(lower, upper);
    // One step changes a log-scaled parameter by at most a factor e^2 and a linear one by at
    // most twice its scale or its magnitude, whichever is larger, so a poor linearisation
    // cannot throw a trial point into a region where the simulation is stiff or degenerate.
    solver.max_step = 2.0;
    solver.relative_step = problem.layout.iter().map(|f| !f.log).collect();
    solver.standard_error_resolution = Some(STANDARD_ERROR_RESOLUTION);
    if let Some(t) = search.tolerance {
        solver.ftol = t;
    }
    solver
}

/// Which start of how many a run is, its iteration budget and the runs it races.
#[derive(Debug, Clone)]
pub struct RunSlot {
    /// Index of the start.
    pub start: usize,
    /// Number of starts.
    pub starts: usize,
    /// Iteration limit of this run.
    pub max_iterations: u64,
    /// The costs the concurrent runs of the fit converged to (the run is abandoned when it
    /// falls behind them, and reports its own when it converges); `None`: a run on its own.
    pub pace: Option<Arc<Pace>>,
    /// The precision its cost is wanted to (absolute; a profile step's, a fraction of the
    /// profile's rise): it stops when the Gauss-Newton step promises less. `None`: the
    /// solver's own convergence tests only.
    pub cost_resolution: Option<f64>,
    /// Whether a start that cannot be evaluated is explained ([`non_finite_start`] evaluates
    /// it again, record by record): the fit's starts, whose failures are reported; not the
    /// identifiability's re-optimisations, whose failures only end a profile or a restart.
    pub explain: bool,
}

/// Runs the solver on `problem` from `u0` (with `search`'s tolerance, reporting to `hooks`'
/// progress). A start whose residuals are not finite is dropped at once, with the error
/// [`non_finite_start`] writes.
pub fn run_start<R: Residuals + 'static>(
    problem: FitProblem<R>,
    u0: DVector<f64>,
    search: &SearchOptions,
    hooks: &Hooks,
    slot: RunSlot,
) -> Result<StartRun, EngineError> {
    let mut solver = solver_for(&problem, search);
    solver.pace = slot.pace.clone();
    solver.cost_resolution = slot.cost_resolution;
    let model_name = problem.model.name().to_string();
    let mut exec = Executor::new(&problem, solver)
        .configure(|s| s.param(u0.clone()).max_iters(slot.max_iterations))
        .ctrlc(false)
        .timer(false);
    if let Some(cb) = &hooks.progress {
        exec = exec.add_observer(
            ProgressObserver {
                model: model_name,
                start: slot.start,
                starts: slot.starts,
                max_iterations: slot.max_iterations,
                callback: cb.clone(),
            },
            ObserverMode::Always,
        );
    }
    let res = exec
        .run()
        .map_err(|e| match e.downcast_ref::<NonFiniteStart>() {
            Some(_) if slot.explain => non_finite_start(&problem, &u0),
            _ => EngineError::Fit(e.to_string()),
        })?;
    let state = res.state();
    let u = state
        .get_best_param()
        .cloned()
        .ok_or_else(|| EngineError::Fit("the solver returned no parameters".into()))?;
    let cost = state.get_best_cost();
    let iterations = state.get_iter();
    let termination =
        termination_reason(&res.solver, &state.termination_status, slot.max_iterations);
    let (jac, r) = res.solver.into_linearisation();
    let linearisation = (jac.ncols() == u.len() && r.len() == jac.nrows()).then_some((jac, r));
    let run = StartRun {
        u,
        linearisation,
        cost,
        iterations,
        simulations: problem.simulations(),
        termination,
    };
    if let (Some(pace), true) = (&slot.pace, run.converged()) {
        pace.converged_at(run.cost);
    }
    Ok(run)
}

/// A run borrows its problem (argmin's solvers take the problem by value), which then
/// explains a start that cannot be evaluated.
impl<R: Residuals> Operator for &FitProblem<R> {
    type Param = DVector<f64>;
    type Output = DVector<f64>;
    fn apply(&self, u: &DVector<f64>) -> Result<DVector<f64>, Error> {
        <FitProblem<R> as Operator>::apply(self, u)
    }
}

impl<R: Residuals> Jacobian for &FitProblem<R> {
    type Param = DVector<f64>;
    type Jacobian = DMatrix<f64>;
    fn jacobian(&self, u: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
        <FitProblem<R> as Jacobian>::jacobian(self, u)
    }
}

/// The error of a start at `u0` whose residuals are not finite: the parameter values, and
/// the first record whose residuals cannot be evaluated (with the evaluation's error) or are
/// not finite (with the channel and sample of the first such residual).
pub fn non_finite_start<R: Residuals>(problem: &FitProblem<R>, u0: &DVector<f64>) -> EngineError {
    let p = problem.physical(u0);
    let values: Vec<String> = problem
        .layout
        .iter()
        .zip(&p)
        .map(|(f, x)| match f.unit.as_str() {
            "1" | "" => format!("{} = {x:.4e}", f.name),
            unit => format!("{} = {x:.4e} {unit}", f.name),
        })
        .collect();
    let reason = match problem.realise(&p) {
        Err(e) => format!("cannot be evaluated: {e}"),
        Ok(world) => first_failing_record(problem, &world),
    };
    EngineError::Fit(format!(
        "the residuals at the start ({}) {reason}; the start is dropped",
        values.join(", ")
    ))
}

/// Why the residuals at `world` are not finite: the first record whose residuals cannot be
/// evaluated or are not finite, and where.
fn first_failing_record<R: Residuals>(problem: &FitProblem<R>, world: &Realised) -> String {
    let at = problem.evaluation(world);
    for (index, record) in problem.records.iter().enumerate() {
        let case = RecordCase {
            index,
            record,
            nuisance: &world.nuisance[index],
        };
        match problem.residuals.residuals(&at, case) {
            Err(e) => return format!("cannot be evaluated: record `{}`: {e}", record.name),
            Ok(r) => {
                if let Some(place) = first_non_finite(problem, index, record, &r) {
                    return format!("are not finite: record `{}`: {place}", record.name);
                }
            }
        }
    }
    "are not finite".into()
}

/// Where the first non-finite residual of record `index` (`r`) lies: its channel's residual
/// index and, where the channel's samples have times, its time.
fn first_non_finite<R: Residuals>(
    problem: &FitProblem<R>,
    index: usize,
    record: &Record,
    r: &[f64],
) -> Option<String> {
    let first = r.iter().position(|x| !x.is_finite())?;
    let mut k = first;
    for segment in problem.residuals.segments(index, record) {
        if k >= segment.len {
            k -= segment.len;
            continue;
        }
        let times = problem.residuals.sample_axes(index, record).time;
        let time = match times.get(k) {
            Some(t) if times.len() == segment.len => format!(" (t = {t} s)"),
            _ => String::new(),
        };
        return Some(format!(
            "{} residual {k} of {}{time} is {}",
            segment.channel, segment.len, r[first]
        ));
    }
    None
}

/// A run's Jacobian (internal coordinates) and residuals at its best point.
type Linearisation = (DMatrix<f64>, DVector<f64>);

/// The linearisation of the lowest-cost run among those handed in: the fit adopts the best
/// run's only, and each is as large as the records times the free parameters, so the others
/// are dropped as they finish (a global search screens a dozen starts).
#[derive(Default)]
struct BestLinearisation(Mutex<Option<(f64, usize, Linearisation)>>);

impl BestLinearisation {
    /// Takes the linearisation of start `start`'s `run`, keeping it if the run is the best so
    /// far.
    fn offer(&self, start: usize, run: &mut StartRun) {
        let Some(linearisation) = run.linearisation.take() else {
            return;
        };
        if let Ok(mut best) = self.0.lock() {
            let better = best
                .as_ref()
                .is_none_or(|(cost, _, _)| run.cost.total_cmp(cost).is_lt());
            if better && run.cost.is_finite() {
                *best = Some((run.cost, start, linearisation));
            }
        }
    }

    /// Gives the kept linearisation back to its run among `runs` (the same start, still at
    /// the same cost).
    fn restore(self, runs: &mut [(usize, StartRun)]) {
        let Some((cost, start, linearisation)) = self.0.into_inner().ok().flatten() else {
            return;
        };
        let owner = runs.iter_mut().find(|(s, r)| *s == start && r.cost == cost);
        if let Some((_, run)) = owner {
            run.linearisation = Some(linearisation);
        }
    }
}

/// The result of every start: the best run and what became of each start.
pub struct MultiStart {
    /// The run with the lowest cost.
    pub best: StartRun,
    /// Its start's index.
    pub best_start: usize,
    /// Solver iterations over all starts.
    pub iterations: u64,
    /// Simulations over all starts.
    pub simulations: u64,
    /// Starts that reached the best cost (within 1e-6 relative).
    pub starts_at_best: usize,
    /// One outcome per start, in start order.
    pub outcomes: Vec<StartOutcome>,
}

/// Screened runs that produced a finite cost, by start index, and the outcomes of the others.
struct Screened {
    ok: Vec<(usize, StartRun)>,
    outcomes: Vec<(usize, StartOutcome)>,
    first_error: Option<EngineError>,
}

fn classify(runs: Vec<Result<StartRun, EngineError>>) -> Screened {
    let mut screened = Screened {
        ok: Vec::new(),
        outcomes: Vec::new(),
        first_error: None,
    };
    for (start, run) in runs.into_iter().enumerate() {
        match run {
            Ok(o) if o.cost.is_finite() => screened.ok.push((start, o)),
            Ok(_) => screened
                .outcomes
                .push((start, StartOutcome::NonFiniteCost { start })),
            Err(error) => {
                screened.first_error.get_or_insert(error.clone());
                screened
                    .outcomes
                    .push((start, StartOutcome::Failed { start, error }));
            }
        }
    }
    screened
}

/// Runs every start from `points`, each with its force offsets centred
/// ([`centred_offsets`]; phase 1: each for a few iterations when there are several,
/// abandoning those left far behind a `reachable` cost after [`SCREEN_GRACE`] iterations;
/// phase 2: the `promote` most promising to the iteration limit) and picks the best.
/// `make_problem` builds a fresh problem per run; `reference` explains a total failure.
pub fn run_starts<R, F>(
    make_problem: F,
    reference: &FitProblem<R>,
    points: &[Vec<f64>],
    search: &SearchOptions,
    hooks: &Hooks,
    promote: usize,
    reachable: Option<f64>,
) -> Result<MultiStart, EngineError>
where
    R: Residuals + 'static,
    F: Fn() -> FitProblem<R> + Sync,
{
    let centring = make_problem();
    let centred: Vec<Vec<f64>> = points
        .iter()
        .map(|p| centred_offsets(&centring, p))
        .collect();
    let points = &centred[..];
    let n_starts = points.len();
    let screen = if n_starts > 1 {
        SCREEN_ITERATIONS.min(search.max_iterations)
    } else {
        search.max_iterations
    };
    let screen_pace = reachable.filter(|_| n_starts > 1).map(|cost| {
        let pace = Pace::with_grace(SCREEN_GRACE);
        pace.converged_at(cost);
        Arc::new(pace)
    });
    let best = BestLinearisation::default();
    let run = |(s, p): (usize, &Vec<f64>)| {
        let problem = make_problem();
        let u0 = problem.internal(p);
        let slot = RunSlot {
            start: s,
            starts: n_starts,
            max_iterations: screen,
            pace: screen_pace.clone(),
            cost_resolution: None,
            explain: true,
        };
        let mut run = run_start(problem, u0, search, hooks, slot)?;
        best.offer(s, &mut run);
        Ok(run)
    };
    let runs: Vec<Result<StartRun, EngineError>> = if hooks.parallel && n_starts > 1 {
        points.par_iter().enumerate().map(run).collect()
    } else {
        points.iter().enumerate().map(run).collect()
    };
    let mut screened = classify(runs);
    best.restore(&mut screened.ok);
    if n_starts > 1 && screen < search.max_iterations {
        let phase = Phase {
            screen,
            n_starts,
            promote,
        };
        continue_best(
            &make_problem,
            &mut screened,
            search,
            hooks,
            phase,
            reachable,
        );
    }
    let first_error = screened.first_error.take();
    let mut runs =
        pick_best(screened).ok_or_else(|| total_failure(first_error, reference, points))?;
    runs.simulations += centring.simulations();
    Ok(runs)
}

/// `point` with each record's force offset (a load cell's zero,
/// [`crate::identify::values::nuisance::NuisanceKind::ForceOffset`]) at its least-squares
/// value given every other parameter: the offset adds to the predicted force, so the
/// residuals are affine in it and one Gauss-Newton step on the offsets alone, its slope
/// taken from a second evaluation with every offset moved by its scale, lands at that value
/// exactly. Left at a blind start (0), an offset of a few newtons takes the solver's first
/// iterations: its step cap, scaled to the offset's typical size, lets it grow threefold per
/// iteration. `point` as it is when there is no force offset or an evaluation fails.
fn centred_offsets<R: Residuals>(problem: &FitProblem<R>, point: &[f64]) -> Vec<f64> {
    let slots: Vec<(usize, usize)> = problem
        .layout
        .iter()
        .enumerate()
        .filter_map(|(j, f)| match f.kind {
            ParamKind::Nuisance {
                kind: NuisanceKind::ForceOffset,
                record,
            } => Some((j, record)),
            _ => None,
        })
        .collect();
    if slots.is_empty() {
        return point.to_vec();
    }
    let mut moved = point.to_vec();
    for &(j, _) in &slots {
        moved[j] += problem.layout[j].scale;
    }
    let (Ok(r0), Ok(r1)) = (problem.residuals_at(point), problem.residuals_at(&moved)) else {
        return point.to_vec();
    };
    let ranges = problem.record_ranges();
    let mut out = point.to_vec();
    for (j, record) in slots {
        let Some(range) = ranges.get(record).cloned() else {
            continue;
        };
        let step = offset_step(&r0.as_slice()[range.clone()], &r1.as_slice()[range]);
        let f = &problem.layout[j];
        if let Some(step) = step {
            out[j] = f.clip(point[j] + step * f.scale);
        }
    }
    out
}

/// The move t (in units of the trial move) of a parameter the residuals are affine in that
/// minimises |r0 + t (r1 - r0)|^2, given the residuals `r0` at the point and `r1` after the
/// trial move: t = -(r0 . d) / (d . d) with d = r1 - r0. `None` when the move does not
/// change the residuals or the result is not finite.
fn offset_step(r0: &[f64], r1: &[f64]) -> Option<f64> {
    let (mut rd, mut dd) = (0.0, 0.0);
    for (a, b) in r0.iter().zip(r1) {
        let d = b - a;
        rd += a * d;
        dd += d * d;
    }
    let t = -rd / dd;
    (dd > 0.0 && t.is_finite()).then_some(t)
}

/// The screening's iterations, the number of starts and how many are continued.
#[derive(Clone, Copy)]
struct Phase {
    screen: u64,
    n_starts: usize,
    promote: usize,
}

/// Phase 2: continues the best screened starts (unless converged) to the iteration limit, in
/// the order of their screened costs; a continued start still [`super::lm::OUTPACE_FACTOR`]
/// times above the cost an earlier start converged to is abandoned.
fn continue_best<R, F>(
    make_problem: &F,
    screened: &mut Screened,
    search: &SearchOptions,
    hooks: &Hooks,
    phase: Phase,
    reachable: Option<f64>,
) where
    R: Residuals + 'static,
    F: Fn() -> FitProblem<R> + Sync,
{
    screened.ok.sort_by(|a, b| a.1.cost.total_cmp(&b.1.cost));
    let Phase {
        screen,
        n_starts,
        promote,
    } = phase;
    let keep = promote.max(1).min(screened.ok.len());
    let promoted: Vec<(usize, DVector<f64>)> = screened.ok[..keep]
        .iter()
        .filter(|(_, o)| !o.converged())
        .map(|(s, o)| (*s, o.u.clone()))
        .collect();
    // The promoted runs race each other and any start that converged while screening.
    let pace = Arc::new(Pace::default());
    for (_, o) in screened.ok.iter().filter(|(_, o)| o.converged()) {
        pace.converged_at(o.cost);
    }
    if let Some(cost) = reachable {
        pace.converged_at(cost);
    }
    let slot = |start| RunSlot {
        start,
        starts: n_starts,
        max_iterations: search.max_iterations - screen,
        pace: Some(pace.clone()),
        cost_resolution: None,
        explain: true,
    };
    let finish = |(s, u): &(usize, DVector<f64>)| {
        (
            *s,
            run_start(make_problem(), u.clone(), search, hooks, slot(*s)),
        )
    };
    // One after the other, best screened first: which start is abandoned then depends on the
    // costs alone, never on which thread ran faster (each run still simulates its records
    // and Jacobian columns in parallel).
    let finished: Vec<(usize, Result<StartRun, EngineError>)> =
        promoted.iter().map(finish).collect();
    let best = BestLinearisation::default();
    for (start, run) in &mut screened.ok {
        best.offer(*start, run);
    }
    for (start, run) in finished {
        match run {
            Ok(mut o) if o.cost.is_finite() => {
                best.offer(start, &mut o);
                if let Some(slot) = screened.ok.iter_mut().find(|(t, _)| *t == start) {
                    merge_continuation(&mut slot.1, o, search.max_iterations);
                }
            }
            Ok(_) => {}
            Err(error) => screened
                .outcomes
                .push((start, StartOutcome::ContinuationFailed { start, error })),
        }
    }
    best.restore(&mut screened.ok);
}

/// Replaces a screened run by its continuation, adding up the work of both; an iteration
/// limit is reported as the fit's limit.
fn merge_continuation(screened: &mut StartRun, continued: StartRun, max_iterations: u64) {
    let before = std::mem::replace(screened, continued);
    screened.iterations += before.iterations;
    screened.simulations += before.simulations;
    if let TerminationReason::IterationLimit { limit } = &mut screened.termination {
        *limit = max_iterations;
    }
}

/// The error when no start produced a finite cost: the first start's error, with what the
/// residuals at the first starting point say.
fn total_failure<R: Residuals>(
    first_error: Option<EngineError>,
    reference: &FitProblem<R>,
    points: &[Vec<f64>],
) -> EngineError {
    let why = first_error
        .map(|e| e.to_string())
        .unwrap_or_else(|| "no start produced a finite cost".into());
    let detail = points
        .first()
        .and_then(|p| reference.residuals_at(p).err())
        .map(|d| format!(" ({d})"))
        .unwrap_or_default();
    EngineError::Fit(format!("{why}{detail}"))
}

/// The best run, the totals and one outcome per start (a start whose continuation failed
/// keeps its screened run among the candidates); `None` when no start has a finite cost.
fn pick_best(screened: Screened) -> Option<MultiStart> {
    let Screened {
        ok, mut outcomes, ..
    } = screened;
    let iterations: u64 = ok.iter().map(|(_, o)| o.iterations).sum();
    let simulations: u64 = ok.iter().map(|(_, o)| o.simulations).sum();
    let best_cost = ok
        .iter()
        .map(|(_, o)| o.cost)
        .min_by(f64::total_cmp)
        .unwrap_or(f64::INFINITY);
    let starts_at_best = ok
        .iter()
        .filter(|(_, o)| o.cost <= best_cost * (1.0 + 1e-6) + 1e-300)
        .count();
    let mut best: Option<(usize, StartRun)> = None;
    for (start, run) in ok {
        if !outcomes.iter().any(|(s, _)| *s == start) {
            outcomes.push((
                start,
                StartOutcome::Finished {
                    start,
                    cost: run.cost,
                    iterations: run.iterations,
                    termination: run.termination.clone(),
                },
            ));
        }
        let better = best
            .as_ref()
            .is_none_or(|(_, b)| run.cost.total_cmp(&b.cost).is_lt());
        if better {
            best = Some((start, run));
        }
    }
    outcomes.sort_by_key(|(s, _)| *s);
    let (best_start, best) = best?;
    Some(MultiStart {
        best,
        best_start,
        iterations,
        simulations,
        starts_at_best,
        outcomes: outcomes.into_iter().map(|(_, o)| o).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::search::strategy::{law_force_problem, offset_stroke};
    use crate::record::Channel;

    /// The least-squares offset of a residual affine in it: minus the mean residual per unit
    /// move, whatever the weight, and nothing when the move changes nothing.
    #[test]
    fn the_offset_step_is_the_mean_residual_over_the_slope() {
        let r0 = [1.0, -2.0, 4.0, 5.0];
        let r1: Vec<f64> = r0.iter().map(|r| r + 0.5).collect();
        let t = offset_step(&r0, &r1).unwrap();
        assert!((t - (-2.0 / 0.5)).abs() < 1e-12, "{t}");
        assert!(offset_step(&r0, &r0).is_none());
    }

    /// Dahl at its true values along a stroke whose load cell reads 3 N high, the offset
    /// started at 0: the centred start takes the offset the record gives against Dahl's
    /// closed-form force, the mean of the measured force less the law's; from there it does
    /// not move, and a point without a force offset is left as it is.
    #[test]
    fn a_start_takes_the_offset_the_record_gives_at_its_other_values() {
        let (record, osc, opts) = offset_stroke(3.0);
        let records: Arc<[Record]> = vec![record].into();
        let truth = frictionid_models::Dahl {
            sigma0: 4e5,
            mu_c: 50.0,
            alpha: 1.0,
        };
        let (problem, _) = law_force_problem(&records, osc, &opts, &truth);
        let names: Vec<&str> = problem.layout.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, ["sigma0", "mu_c", "force_offset[stroke]"]);
        let start = [4e5, 50.0, 0.0];
        let centred = centred_offsets(&problem, &start);
        let x = records[0].channel(Channel::Displacement).unwrap();
        let measured = records[0].channel(Channel::Force).unwrap();
        let law = crate::testing::dahl_force_along(x, 4e5, 50.0);
        let n = measured.len() as f64;
        let oracle = measured.iter().zip(&law).map(|(m, f)| m - f).sum::<f64>() / n;
        assert_eq!(centred[..2], start[..2]);
        assert!(
            (centred[2] - oracle).abs() < 1e-6,
            "{} {oracle}",
            centred[2]
        );
        assert!((centred[2] - 3.0).abs() < 0.02, "{}", centred[2]);
        let again = centred_offsets(&problem, &centred);
        assert!((again[2] - centred[2]).abs() < 1e-9, "{again:?}");
    }
}
