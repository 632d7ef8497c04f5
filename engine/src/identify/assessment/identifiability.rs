//! Identifiability, stated: which fitted parameters the records determine, and which they
//! only bound from one side.
//!
//! A free model parameter whose standard error in the solver's coordinates exceeds
//! [`FLAT_INTERNAL_SE`] (a factor e for a log parameter) or has none is profiled: stepped
//! outward on each side (a decade per step for log parameters) with the other parameters
//! re-optimised at each step, until the cost rises by more than [`PROFILE_DELTA`] residual
//! variances (chi²(1 dof) at 95 %, halved because the cost is half the sum of squares). A side
//! where it rises is bounded there; the parameter is `determined` (both sides), a
//! `lower_bound` (only values below are excluded, e.g. sigma0 on Coulomb-like records), an
//! `upper_bound`, or `not_identifiable`. Each step's re-optimisation is wanted only to a
//! twentieth of that rise ([`PROFILE_RESOLUTION`]): it stops when the Gauss-Newton step
//! promises less.
//!
//! A fit that hit the iteration limit only because such a parameter kept running on is
//! settled: the unbounded parameters are pinned where they are and the others re-optimised;
//! when that converges the fit counts as converged for them.

use super::stats::{chi_square_95, covariance, Covariance};
use crate::error::EngineError;
use crate::identify::problem::least_squares::{FitProblem, ProblemParts};
use crate::identify::problem::residuals::Residuals;
use crate::identify::search::starts::{run_start, MultiStart, RunSlot, StartRun};
use crate::identify::search::strategy::{fit_simpler, stage_options, FitTarget, Onto};
use crate::identify::values::fit_options::FitOptions;
use crate::identify::values::layout::ParamKind;
use crate::identify::values::levels::FrictionLevels;
use crate::identify::values::outcome::{Check, Finding, TerminationReason};
use crate::identify::values::result::Identifiability;
use frictionid_models::start::TYPICAL_PRESLIDING_DISPLACEMENT;
use frictionid_models::{FrictionModel, ModelError, StartContext, StribeckLevels};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// chi²(1 dof, 95 %) / 2 = 3.8415 / 2: the rise of the cost (half the sum of squares), in
/// residual variances, that excludes a parameter value at 95 %.
pub const PROFILE_DELTA: f64 = 1.920_729_410_347_062;

/// Standard error in the solver's coordinates above which a parameter is profiled.
pub const FLAT_INTERNAL_SE: f64 = 1.0;

/// Profile steps on each side.
pub const PROFILE_STEPS: usize = 4;

/// Halvings of a first profile step that fails (a simulation too stiff or degenerate).
pub const PROFILE_HALVINGS: usize = 3;

/// Iterations of the re-optimisation of the other parameters at each profile step.
pub const PROFILE_ITERATIONS: u64 = 12;

/// The precision a profile step's re-optimisation needs, as a fraction of the profile's
/// cost rise: it stops when the Gauss-Newton step promises less decrease (a standing turns
/// on the cost against the rise; the solver's own tests ask about a thousandth of it).
pub const PROFILE_RESOLUTION: f64 = 0.05;

/// Iterations of the re-optimisation at each step of the profile of a rigid limit's
/// stiffness: the other parameters move far along it (LuGre's Stribeck levels and bristle
/// damping change by factors between decades of sigma0), and a profile that stops short of
/// their optimum overstates the lower bound.
pub const LIMIT_PROFILE_ITERATIONS: u64 = 40;

/// One free parameter's standing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Standing {
    /// What the records say.
    pub class: Identifiability,
    /// The 95 % bound (physical) of a one-sided parameter.
    pub bound: Option<f64>,
}

impl Standing {
    const DETERMINED: Self = Self {
        class: Identifiability::Determined,
        bound: None,
    };

    /// Whether the value and its standard error stand.
    pub fn determined(&self) -> bool {
        self.class == Identifiability::Determined
    }
}

/// Times a profile that found a clearly lower cost restarts the fit from there.
pub const PROFILE_RESTARTS: usize = 2;

/// Profiles the flat parameters at the best run, settles an iteration limit caused only by
/// unbounded ones, and returns the runs with one standing per free parameter. A profile
/// point whose cost lies a [`PROFILE_DELTA`] rise below the best (the fit stopped in a local
/// minimum or on a plateau the profile stepped off) restarts the solver there, and the
/// profiles are taken again at the better optimum.
pub fn settle<R: Residuals + 'static>(
    reference: &FitProblem<R>,
    mut runs: MultiStart,
    opts: &FitOptions,
) -> Result<(MultiStart, Vec<Standing>), EngineError> {
    let quiet = FitOptions {
        hooks: opts.hooks.quiet(),
        ..opts.clone()
    };
    let limit = rigid_limit(reference, &runs.best, &quiet);
    let mut restarts = PROFILE_RESTARTS;
    loop {
        match profile_all(reference, &runs.best, &quiet, limit.as_ref(), restarts > 0)? {
            Profiled::Standings(standings) => {
                return Ok(finish(reference, runs, standings, &quiet))
            }
            Profiled::Lower(u) => {
                restarts = if restart_from(reference, &mut runs, u, &quiet) {
                    restarts - 1
                } else {
                    0
                };
            }
        }
    }
}

fn finish<R: Residuals + 'static>(
    reference: &FitProblem<R>,
    mut runs: MultiStart,
    standings: Vec<Standing>,
    opts: &FitOptions,
) -> (MultiStart, Vec<Standing>) {
    settle_convergence(reference, &mut runs, &standings, opts);
    (runs, standings)
}

/// What the profiles of a best run found.
enum Profiled {
    /// One standing per free parameter.
    Standings(Vec<Standing>),
    /// A point (internal coordinates) clearly below the best cost.
    Lower(DVector<f64>),
}

/// The flat slots at `best` and the profile's cost rise; `None` without a residual variance.
fn flat_and_delta<R: Residuals>(
    reference: &FitProblem<R>,
    best: &StartRun,
) -> Result<Option<(Vec<usize>, f64)>, EngineError> {
    if reference.layout.is_empty() {
        return Ok(None);
    }
    let p = reference.physical(&best.u);
    let (jac, r) = reference.jacobian_physical(&p)?;
    let ssr = r.norm_squared();
    let variance = covariance(&jac, ssr).residual_variance;
    if !(variance.is_finite() && variance > 0.0) {
        return Ok(None);
    }
    let slots = flat_slots(reference, &jac, ssr, &p, &r);
    Ok(Some((slots, PROFILE_DELTA * variance)))
}

/// Profiles every flat parameter at `best`, and the stiffness of a rigid `limit` the records
/// do not exclude (its upper side open, only the lower side profiled); with `restart`, stops
/// at the first profile point a `delta` below the best cost, or at the limit when it lies
/// that far below.
fn profile_all<R: Residuals + 'static>(
    reference: &FitProblem<R>,
    best: &StartRun,
    opts: &FitOptions,
    limit: Option<&Limit>,
    restart: bool,
) -> Result<Profiled, EngineError> {
    let mut standings = vec![Standing::DETERMINED; reference.layout.len()];
    let Some((mut slots, delta)) = flat_and_delta(reference, best)? else {
        return Ok(Profiled::Standings(standings));
    };
    let open_limit = limit.filter(|l| l.cost <= best.cost + delta * l.rise_factor());
    if let Some(l) = open_limit {
        if l.cost < best.cost - delta && restart {
            if let Some(u) = l.approach(reference, best, delta) {
                return Ok(Profiled::Lower(u));
            }
        }
        l.plan_profiles(best.cost + delta, &mut slots, &mut standings);
    }
    let profile = Profile {
        reference,
        best,
        opts,
        limit: open_limit,
        resolution: PROFILE_RESOLUTION * delta,
    };
    let profile_of = |j: usize| {
        let open_above = open_limit.filter(|l| l.is_stiffness(j)).map(|l| l.cost);
        (j, profile.standing(j, delta, open_above))
    };
    // The profiles are independent: in parallel, read in slot order (the first lower point
    // restarts the fit, whichever thread found it first).
    let profiled: Vec<_> = if opts.hooks.parallel {
        slots.par_iter().map(|&j| profile_of(j)).collect()
    } else {
        slots.iter().map(|&j| profile_of(j)).collect()
    };
    for (j, (standing, lower)) in profiled {
        if let Some(u) = lower.filter(|_| restart) {
            return Ok(Profiled::Lower(u));
        }
        standings[j] = standing;
    }
    Ok(Profiled::Standings(standings))
}

/// The rigid-contact limit of the fitted model (`InternalStates::rigid_limit`) fitted to the
/// same records. The records resolve the contact's stiffness only when they reject the limit:
/// a likelihood-ratio test of the nested limit law, whose cost must lie more than
/// chi²(d, 95 %) / 2 residual variances above the best, d the parameters the limit removes.
/// Otherwise the stiffness's upper side is open (it is at most a lower bound).
struct Limit {
    /// The slots of the stiffnesses in the layout (the first drives the approach).
    slots: Vec<usize>,
    /// The slots of the parameters that act only through presliding.
    presliding: Vec<usize>,
    /// The limit law's best cost.
    cost: f64,
    /// The free parameters the limit removes (at least 1).
    removed: usize,
    /// The fitted limit law.
    law: Box<dyn FrictionModel>,
}

/// Decades of contact stiffness the target steps through on its way to a rigid limit that
/// fits clearly better than the fit's optimum (from a tenth of the typical presliding
/// displacement down; a step clipped at the stiffness's bound ends it).
pub const LIMIT_APPROACH_DECADES: i32 = 10;

impl Limit {
    /// The profiles of a limit the records do not reject: every stiffness (its lower side);
    /// and, when the limit's cost is within `within` (the best cost plus one parameter's 95 %
    /// rise), none of the presliding-only parameters, which are not identifiable: every value
    /// of one reaches the limit's cost as the stiffnesses grow.
    fn plan_profiles(&self, within: f64, slots: &mut Vec<usize>, standings: &mut [Standing]) {
        for &j in &self.slots {
            if !slots.contains(&j) {
                slots.push(j);
            }
        }
        if self.cost <= within {
            for &j in &self.presliding {
                standings[j] = Standing {
                    class: Identifiability::NotIdentifiable,
                    bound: None,
                };
            }
            slots.retain(|j| !self.presliding.contains(j));
        }
    }

    /// Whether slot `j` is one of the limit's stiffnesses.
    fn is_stiffness(&self, j: usize) -> bool {
        self.slots.contains(&j)
    }

    /// Whether slot `j` is the limit's first stiffness, whose profile steps are re-optimised
    /// from two starts with more iterations (the others, e.g. GMS's further elements, are
    /// profiled as ordinary parameters with their upper side open).
    fn is_first_stiffness(&self, j: usize) -> bool {
        self.slots.first() == Some(&j)
    }

    /// The cost rise that rejects the limit, in units of the one-parameter rise
    /// [`PROFILE_DELTA`]: chi²(d) / chi²(1).
    fn rise_factor(&self) -> f64 {
        chi_square_95(self.removed) / chi_square_95(1)
    }

    /// The target started from the fitted limit law at the presliding displacement of `ctx`
    /// (internal coordinates; the parameters that are not the model's where `best` has them).
    fn start_of_target<R: Residuals>(
        &self,
        reference: &FitProblem<R>,
        best: &StartRun,
        ctx: &StartContext,
    ) -> Option<DVector<f64>> {
        let at_best = reference.physical(&best.u);
        let onto = Onto {
            model: reference.model.as_ref(),
            params: &reference.layout,
            base: &at_best,
            keep: &[],
        };
        let p = onto.started_from(self.law.as_ref(), ctx)?;
        Some(reference.internal(&p))
    }

    /// The target mapped from the limit law with the stiffness in `slot` at the internal
    /// value `u` (the others at the same physical stiffness; internal coordinates); `None`
    /// when the law has no Coulomb level or the mapping fails.
    fn target_at_stiffness<R: Residuals>(
        &self,
        reference: &FitProblem<R>,
        best: &StartRun,
        (slot, u): (usize, f64),
    ) -> Option<DVector<f64>> {
        let osc = &reference.oscillator;
        let level = StribeckLevels::from_model(self.law.as_ref())?.mu_c * osc.normal_force;
        let stiffness = reference.layout[slot].to_physical(u);
        let ctx = StartContext {
            presliding_displacement: level / stiffness,
            ..StartContext::new(osc.normal_force, osc.mass)
        };
        let mut at = self.start_of_target(reference, best, &ctx)?;
        at[slot] = u;
        Some(at)
    }

    /// The way from the fit's optimum to a limit that fits better by more than `delta`: the
    /// target mapped from the limit law at stiffnesses a decade apart; the first point whose
    /// cost is within `delta` of the limit's, else the lowest one.
    fn approach<R: Residuals>(
        &self,
        reference: &FitProblem<R>,
        best: &StartRun,
        delta: f64,
    ) -> Option<DVector<f64>> {
        let osc = &reference.oscillator;
        let mut lowest: Option<(f64, DVector<f64>)> = None;
        let mut previous: Option<DVector<f64>> = None;
        for k in 1..=LIMIT_APPROACH_DECADES {
            let ctx = StartContext {
                presliding_displacement: TYPICAL_PRESLIDING_DISPLACEMENT * 10f64.powi(-k),
                ..StartContext::new(osc.normal_force, osc.mass)
            };
            let u = self.start_of_target(reference, best, &ctx)?;
            if previous.as_ref() == Some(&u) {
                break;
            }
            let cost = reference
                .residuals_at(&reference.physical(&u))
                .ok()
                .map(|r| 0.5 * r.norm_squared())
                .filter(|c| c.is_finite());
            if let Some(c) = cost {
                if c <= self.cost + delta {
                    return Some(u);
                }
                if lowest.as_ref().is_none_or(|(l, _)| c < *l) {
                    lowest = Some((c, u.clone()));
                }
            }
            previous = Some(u);
        }
        lowest.map(|(_, u)| u)
    }
}

/// The model's rigid limit fitted to the records (from its own guess and from the fit's best
/// mapped onto it), when the model declares one and a stiffness of it is free; `None`
/// otherwise or when the limit cannot be fitted.
fn rigid_limit<R: Residuals + 'static>(
    reference: &FitProblem<R>,
    best: &StartRun,
    opts: &FitOptions,
) -> Option<Limit> {
    let declared = reference.model.states()?.rigid_limit()?;
    let slots_of = |indices: &[usize]| -> Vec<usize> {
        (0..reference.layout.len())
            .filter(|&j| matches!(reference.layout[j].kind, ParamKind::Model(i) if indices.contains(&i)))
            .collect()
    };
    let slots = slots_of(&declared.stiffnesses);
    if slots.is_empty() {
        return None;
    }
    let fitted = reference.realise(&reference.physical(&best.u)).ok()?.model;
    let osc = &reference.oscillator;
    let ctx = StartContext::new(osc.normal_force, osc.mass);
    let on = FitTarget {
        residuals: &reference.residuals,
        osc,
        records: &reference.records,
    };
    let mut limit_opts = stage_options(opts);
    limit_opts.params.oscillator = opts.params.oscillator.clone();
    limit_opts.params.free = limit_free(declared.law.as_ref(), &declared.also_free);
    let fit = fit_simpler(
        &on,
        declared.law.as_ref(),
        &limit_opts,
        &[(fitted.as_ref(), ctx)],
    )?;
    Some(Limit {
        slots,
        presliding: slots_of(&declared.presliding),
        cost: fit.cost,
        removed: reference.layout.len().saturating_sub(fit.free).max(1),
        law: fit.model,
    })
}

/// The free parameters of a limit law: its defaults and `also_free`; `None` (the defaults)
/// when there is nothing to add.
fn limit_free(law: &dyn FrictionModel, also_free: &[&str]) -> Option<Vec<String>> {
    if also_free.is_empty() {
        return None;
    }
    let free = law
        .param_info()
        .into_iter()
        .filter(|p| !p.fixed_by_default || also_free.contains(&p.name.as_str()))
        .map(|p| p.name)
        .collect();
    Some(free)
}

/// Runs the solver from `u` and makes it the best run when it ends lower; whether it did.
fn restart_from<R: Residuals + 'static>(
    reference: &FitProblem<R>,
    runs: &mut MultiStart,
    u: DVector<f64>,
    opts: &FitOptions,
) -> bool {
    let Some(problem) = pinned_problem(reference, &[]) else {
        return false;
    };
    let slot = RunSlot {
        start: runs.best_start,
        starts: 1,
        max_iterations: opts.search.max_iterations,
        pace: None,
        cost_resolution: None,
        explain: false,
    };
    let Ok(run) = run_start(problem, u, &opts.search, &opts.hooks, slot) else {
        return false;
    };
    runs.iterations += run.iterations;
    runs.simulations += run.simulations;
    if run.cost.is_nan() || run.cost >= runs.best.cost {
        return false;
    }
    let before = std::mem::replace(&mut runs.best, run);
    runs.best.iterations += before.iterations;
    runs.best.simulations += before.simulations;
    if let Some((jac, r)) = runs.best.linearisation.take() {
        reference.adopt_linearisation(&runs.best.u, jac, r);
    }
    true
}

/// Free model parameters the records may not determine: every one when the Jacobian is
/// rank-deficient, else those whose standard error in the solver's coordinates is missing
/// or above [`FLAT_INTERNAL_SE`], those held at a bound (where the curvature says nothing of
/// the side beyond it), or (a model with internal states) those whose Jacobian column is
/// integration noise ([`noise_dominated`]).
fn flat_slots<R: Residuals>(
    reference: &FitProblem<R>,
    jac: &DMatrix<f64>,
    ssr: f64,
    p: &[f64],
    r: &DVector<f64>,
) -> Vec<usize> {
    let layout = &reference.layout;
    let cov = covariance(jac, ssr);
    let dynamic = reference.model.n_states() > 0;
    (0..layout.len())
        .filter(|&j| matches!(layout[j].kind, ParamKind::Model(_)))
        .filter(|&j| {
            let se = cov.std_errors[j] * layout[j].internal_derivative(p[j]).abs();
            let fine = !cov.singular && se.is_finite() && se > 0.0 && se <= FLAT_INTERNAL_SE;
            let at_bound = layout[j].bound_side(p[j]).is_some();
            !fine || at_bound || (dynamic && noise_dominated(reference, jac, p, r, j))
        })
        .collect()
}

/// Relative disagreement of the forward and backward difference columns above which a
/// column is taken for integration noise (a smooth column's two one-sided quotients differ
/// by the step times its curvature: about 1e-5 relative).
pub const NOISY_COLUMN: f64 = 0.1;

/// Whether column `j` of the physical Jacobian `jac` at `p` (residuals `r`; a forward
/// difference away from the bounds) is the adaptive integrator's noise rather than the
/// residuals' slope: the forward and backward difference quotients disagree by more than
/// [`NOISY_COLUMN`]. A parameter far inside a flat region (sigma0 of stiff bristles on
/// Coulomb-like records) can then show a small, false standard error.
fn noise_dominated<R: Residuals>(
    reference: &FitProblem<R>,
    jac: &DMatrix<f64>,
    p: &[f64],
    r: &DVector<f64>,
    j: usize,
) -> bool {
    let u = reference.internal(p);
    let h = reference.fd_step(&u, j);
    let f = &reference.layout[j];
    let (lo, hi) = f.internal_bounds();
    if u[j] - h < lo || u[j] + h > hi {
        return false;
    }
    let forward = jac.column(j) / f.internal_derivative(p[j]);
    let backward = reference.difference_column(&u, r, j, -h);
    let scale = forward.norm().max(backward.norm());
    (forward - backward).norm() > NOISY_COLUMN * scale || !scale.is_finite()
}

/// The problem with the free parameters `pins` (slot, internal value) fixed at those values.
fn pinned_problem<R: Residuals>(
    reference: &FitProblem<R>,
    pins: &[(usize, f64)],
) -> Option<FitProblem<R>> {
    let mut model: Box<dyn FrictionModel> = reference.model.clone();
    let mut values = model.params();
    for &(j, u) in pins {
        let f = &reference.layout[j];
        let ParamKind::Model(i) = f.kind else {
            return None;
        };
        *values.get_mut(i)? = f.to_physical(u);
    }
    model.set_params(&values).ok()?;
    let layout = (0..reference.layout.len())
        .filter(|j| !pins.iter().any(|(p, _)| p == j))
        .map(|j| reference.layout[j].clone())
        .collect();
    Some(FitProblem::new(
        reference.residuals.clone(),
        ProblemParts {
            oscillator: reference.oscillator,
            model,
            records: reference.records.clone(),
            layout,
            sim: reference.sim,
            parallel: reference.parallel,
        },
    ))
}

/// `u` without the pinned slots.
fn without(u: &DVector<f64>, pins: &[(usize, f64)]) -> DVector<f64> {
    let kept: Vec<f64> = (0..u.len())
        .filter(|j| !pins.iter().any(|(p, _)| p == j))
        .map(|j| u[j])
        .collect();
    DVector::from_vec(kept)
}

/// The full internal point from the others' values and the pins.
fn merged(others: &DVector<f64>, pins: &[(usize, f64)], n: usize) -> DVector<f64> {
    let mut rest = others.iter();
    DVector::from_iterator(
        n,
        (0..n).map(|j| match pins.iter().find(|(p, _)| *p == j) {
            Some(&(_, u)) => u,
            None => rest.next().copied().unwrap_or(f64::NAN),
        }),
    )
}

/// The others re-optimised (at most `iterations`) with `pins` fixed, from `others`; `None`
/// when the problem cannot be built, the run fails or its cost is not finite.
fn pinned_fit<R: Residuals + 'static>(
    reference: &FitProblem<R>,
    pins: &[(usize, f64)],
    others: &DVector<f64>,
    opts: &FitOptions,
    (iterations, cost_resolution): (u64, Option<f64>),
) -> Option<StartRun> {
    let sub = pinned_problem(reference, pins)?;
    let run = if sub.layout.is_empty() {
        let r = sub.residuals_at(&[]).ok()?;
        StartRun {
            u: DVector::zeros(0),
            cost: 0.5 * r.norm_squared(),
            iterations: 0,
            simulations: sub.simulations(),
            termination: TerminationReason::NoFreeParameters,
            linearisation: None,
        }
    } else {
        let slot = RunSlot {
            start: 0,
            starts: 1,
            max_iterations: iterations,
            pace: None,
            cost_resolution,
            explain: false,
        };
        run_start(sub, others.clone(), &opts.search, &opts.hooks, slot).ok()?
    };
    run.cost.is_finite().then_some(run)
}

/// One profile step: the parameter's internal value, the re-optimised cost, and the whole
/// point (internal coordinates).
struct ProfilePoint {
    u: f64,
    cost: f64,
    at: DVector<f64>,
}

/// A profile of the cost along one parameter at the best run.
struct Profile<'a, R: Residuals> {
    reference: &'a FitProblem<R>,
    best: &'a StartRun,
    opts: &'a FitOptions,
    /// The model's rigid limit when the records do not reject it: the profile of its
    /// stiffness (the lower side) also tries the others mapped from the limit law at each
    /// stiffness (levels and a critically damped contact). A rejected limit leaves the
    /// stiffness an ordinary parameter.
    limit: Option<&'a Limit>,
    /// The precision of a step's cost ([`PROFILE_RESOLUTION`] of the rise).
    resolution: f64,
}

impl<R: Residuals + 'static> Profile<'_, R> {
    /// Profile points (internal value, cost) on one side (`side` = ±1), stepping outward
    /// until the cost exceeds `limit` (for the rigid limit's stiffness: at two steps in a
    /// row, since a re-optimisation near the limit can end in a poorer local minimum), a
    /// bound is reached or a step fails; a first step that fails is retried at half the
    /// distance (at most [`PROFILE_HALVINGS`] times).
    fn side(&self, j: usize, side: f64, limit: f64) -> Vec<ProfilePoint> {
        let confirmations = if self.limit.is_some_and(|l| l.is_first_stiffness(j)) {
            2
        } else {
            1
        };
        let f = &self.reference.layout[j];
        let (lo, hi) = f.internal_bounds();
        let centre = self.best.u[j];
        let mut step = if f.log {
            std::f64::consts::LN_10
        } else {
            centre.abs().max(1.0)
        };
        let mut others = without(&self.best.u, &[(j, centre)]);
        let mut out: Vec<ProfilePoint> = Vec::new();
        let mut halvings = 0;
        while out.len() < PROFILE_STEPS {
            let previous = out.last().map_or(centre, |p| p.u);
            let u = (previous + side * step).clamp(lo, hi);
            if u == previous {
                break;
            }
            let pins = [(j, u)];
            match self.step_fit(&pins, &others) {
                None if out.is_empty() && halvings < PROFILE_HALVINGS => {
                    step /= 2.0;
                    halvings += 1;
                }
                None => break,
                Some(run) => {
                    others = run.u;
                    out.push(ProfilePoint {
                        u,
                        cost: run.cost,
                        at: merged(&others, &pins, self.best.u.len()),
                    });
                    let above = out.iter().rev().take_while(|p| p.cost > limit).count();
                    if above >= confirmations {
                        break;
                    }
                }
            }
        }
        out
    }

    /// The others re-optimised at a profile step `pins` from where the previous step left
    /// them (`previous`); a step of the rigid limit's stiffness also from the others mapped
    /// from the limit law at that stiffness (with more iterations), keeping the lower end: the
    /// cost near a rigid limit has several minima in the levels.
    fn step_fit(&self, pins: &[(usize, f64)], previous: &DVector<f64>) -> Option<StartRun> {
        let &[(j, u)] = pins else {
            return None;
        };
        let Some(limit) = self.limit.filter(|l| l.is_first_stiffness(j)) else {
            return pinned_fit(
                self.reference,
                pins,
                previous,
                self.opts,
                (PROFILE_ITERATIONS, Some(self.resolution)),
            );
        };
        let run = |start: &DVector<f64>| {
            pinned_fit(
                self.reference,
                pins,
                start,
                self.opts,
                (LIMIT_PROFILE_ITERATIONS, Some(self.resolution)),
            )
        };
        let Some(mapped) = limit.target_at_stiffness(self.reference, self.best, (j, u)) else {
            return run(previous);
        };
        let mapped = without(&mapped, pins);
        let (a, b) = if self.opts.hooks.parallel {
            rayon::join(|| run(previous), || run(&mapped))
        } else {
            (run(previous), run(&mapped))
        };
        [a, b]
            .into_iter()
            .flatten()
            .min_by(|x, y| x.cost.total_cmp(&y.cost))
    }

    /// The standing of slot `j` for a cost rise `delta` (absolute), and the lowest profile
    /// point (internal coordinates) when its cost lies more than `delta` below the best.
    /// `open_above`: the cost the parameter's upper side runs to (a rigid limit the records
    /// do not exclude): that side is open and not profiled.
    fn standing(
        &self,
        j: usize,
        delta: f64,
        open_above: Option<f64>,
    ) -> (Standing, Option<DVector<f64>>) {
        let best = self.best.cost;
        // The two sides are independent refits: side by side on two threads.
        let (below, above) = if open_above.is_some() {
            (self.side(j, -1.0, best + delta), Vec::new())
        } else if self.opts.hooks.parallel {
            rayon::join(
                || self.side(j, -1.0, best + delta),
                || self.side(j, 1.0, best + delta),
            )
        } else {
            (
                self.side(j, -1.0, best + delta),
                self.side(j, 1.0, best + delta),
            )
        };
        let lowest = below
            .iter()
            .chain(&above)
            .min_by(|a, b| a.cost.total_cmp(&b.cost))
            .filter(|p| p.cost < best - delta)
            .map(|p| p.at.clone());
        // A profile that found a lower cost (a parameter still running on) measures from it.
        let floor = below
            .iter()
            .chain(&above)
            .map(|p| p.cost)
            .chain(open_above)
            .fold(best, f64::min);
        let pairs = |side: &[ProfilePoint]| -> Vec<(f64, f64)> {
            side.iter().map(|p| (p.u, p.cost)).collect()
        };
        let (below, above) = (pairs(&below), pairs(&above));
        let centre = (self.best.u[j], best);
        let f = &self.reference.layout[j];
        // A side that cannot be evaluated at all (too stiff to simulate) counts as open.
        let low = outer_crossing(centre, &below, floor + delta).map(|u| f.to_physical(u));
        let high = outer_crossing(centre, &above, floor + delta).map(|u| f.to_physical(u));
        let (class, bound) = match (low, high) {
            (Some(_), Some(_)) => (Identifiability::Determined, None),
            (Some(b), None) => (Identifiability::LowerBound, Some(b)),
            (None, Some(b)) => (Identifiability::UpperBound, Some(b)),
            (None, None) => (Identifiability::NotIdentifiable, None),
        };
        (Standing { class, bound }, lowest)
    }
}

/// Where the profile rises above `limit` for good: [`crossing`] from its last point within
/// the limit (a point above it followed by one within is a re-optimisation that stopped in a
/// poorer local minimum, not the edge of the interval).
fn outer_crossing(centre: (f64, f64), points: &[(f64, f64)], limit: f64) -> Option<f64> {
    match points.iter().rposition(|&(_, c)| c <= limit) {
        Some(k) => crossing(points[k], &points[k + 1..], limit),
        None => crossing(centre, points, limit),
    }
}

/// Where the profile first rises above `limit` (linear between its points), from `centre`.
fn crossing(centre: (f64, f64), points: &[(f64, f64)], limit: f64) -> Option<f64> {
    let mut previous = centre;
    for &(u, c) in points {
        if c > limit {
            let t = if c > previous.1 {
                ((limit - previous.1) / (c - previous.1)).clamp(0.0, 1.0)
            } else {
                1.0
            };
            return Some(previous.0 + t * (u - previous.0));
        }
        previous = (u, c);
    }
    None
}

/// An iteration limit with unbounded parameters: pins them, re-optimises the others and,
/// when that converges, counts the fit as converged for them.
fn settle_convergence<R: Residuals + 'static>(
    reference: &FitProblem<R>,
    runs: &mut MultiStart,
    standings: &[Standing],
    opts: &FitOptions,
) {
    if runs.best.converged() {
        return;
    }
    let pins: Vec<(usize, f64)> = (0..standings.len())
        .filter(|&j| !standings[j].determined())
        .map(|j| (j, runs.best.u[j]))
        .collect();
    if pins.is_empty() {
        return;
    }
    let others = without(&runs.best.u, &pins);
    let Some(run) = pinned_fit(
        reference,
        &pins,
        &others,
        opts,
        (opts.search.max_iterations, None),
    ) else {
        return;
    };
    if !run.converged() || run.cost > runs.best.cost {
        return;
    }
    let names = pins
        .iter()
        .map(|&(j, _)| reference.layout[j].name.clone())
        .collect();
    runs.iterations += run.iterations;
    runs.simulations += run.simulations;
    runs.best = StartRun {
        u: merged(&run.u, &pins, standings.len()),
        cost: run.cost,
        iterations: runs.best.iterations + run.iterations,
        simulations: runs.best.simulations + run.simulations,
        termination: TerminationReason::ConvergedExceptUnbounded { parameters: names },
        linearisation: None,
    };
}

/// The covariance of the determined parameters, marginal over every undetermined parameter
/// whose column keeps JᵀJ invertible (a Stribeck velocity the records leave flat trades with
/// the levels: holding it fixed would understate their errors) and conditional on the rest
/// (a stiffness run to its rigid limit has a vanishing column). The undetermined parameters'
/// rows and columns come back as NaN.
pub fn covariance_of_determined(
    jac: &DMatrix<f64>,
    ssr: f64,
    standings: &[Standing],
) -> Covariance {
    let determined = |j: usize| standings.get(j).is_none_or(Standing::determined);
    let mut keep: Vec<usize> = (0..jac.ncols()).filter(|&j| determined(j)).collect();
    if keep.len() == jac.ncols() {
        return covariance(jac, ssr);
    }
    for j in (0..jac.ncols()).filter(|&j| !determined(j)) {
        let mut with = keep.clone();
        with.push(j);
        with.sort_unstable();
        let cov = covariance(&jac.select_columns(&with), ssr);
        if !cov.singular && cov.std_errors.iter().all(|s| s.is_finite()) {
            keep = with;
        }
    }
    let reduced = covariance(&jac.select_columns(&keep), ssr);
    let p = jac.ncols();
    let mut matrix = DMatrix::from_element(p, p, f64::NAN);
    let mut correlation = DMatrix::from_element(p, p, f64::NAN);
    let mut std_errors = vec![f64::NAN; p];
    let shown: Vec<(usize, usize)> = keep
        .iter()
        .enumerate()
        .filter(|(_, &j)| determined(j))
        .map(|(a, &j)| (a, j))
        .collect();
    for &(a, ja) in &shown {
        std_errors[ja] = reduced.std_errors[a];
        for &(b, jb) in &shown {
            matrix[(ja, jb)] = reduced.matrix[(a, b)];
            correlation[(ja, jb)] = reduced.correlation[(a, b)];
        }
    }
    Covariance {
        matrix,
        std_errors,
        correlation,
        ..reduced
    }
}

/// A warning per parameter the records do not determine, with its 95 % bound.
pub fn findings(names: &[(String, String)], standings: &[Standing]) -> Vec<Finding> {
    names
        .iter()
        .zip(standings)
        .filter(|(_, s)| !s.determined())
        .map(|((name, unit), s)| {
            let message = match (s.class, s.bound) {
                (Identifiability::LowerBound, Some(b)) => format!(
                    "{name} > {b:.2e} {unit} at 95 %: the records bound it only from below (a larger value fits as well, e.g. presliding the records do not resolve); no standard error"
                ),
                (Identifiability::UpperBound, Some(b)) => format!(
                    "{name} < {b:.2e} {unit} at 95 %: the records bound it only from above; no standard error"
                ),
                _ => format!(
                    "`{name}` is not identifiable from these records: the cost stays within chi²/2 of its minimum on both sides; no standard error"
                ),
            };
            Finding::warn(Check::Identifiability, s.bound, message)
        })
        .collect()
}

/// A warning for each physical inconsistency the fitted model reports (e.g. mu_s < mu_c).
/// A level read as a force (`levels`) beyond the declared bound of its coefficient is no
/// inconsistency: its bounds are the data's.
pub fn consistency_findings(model: &dyn FrictionModel, levels: FrictionLevels) -> Vec<Finding> {
    match model.validate() {
        Ok(warnings) => warnings
            .into_iter()
            .map(|w| Finding::warn(Check::PhysicalConsistency, None, w))
            .collect(),
        Err(ModelError::OutOfBounds { param, .. })
            if levels.are_forces()
                && model
                    .param_info()
                    .iter()
                    .any(|p| p.name == param && FrictionLevels::is_level(p)) =>
        {
            Vec::new()
        }
        Err(e) => vec![Finding::warn(
            Check::PhysicalConsistency,
            None,
            e.to_string(),
        )],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_crossing_interpolates_between_profile_points() {
        // From cost 0 at u = 0 to 4 at u = 2: the limit 1.92 is crossed at u = 0.96.
        let u = crossing((0.0, 0.0), &[(2.0, 4.0)], 1.92).unwrap();
        assert!((u - 0.96).abs() < 1e-12);
        assert_eq!(crossing((0.0, 0.0), &[(1.0, 0.5), (2.0, 1.0)], 1.92), None);
    }

    #[test]
    fn the_outer_crossing_skips_a_point_above_the_limit_that_a_later_one_undercuts() {
        // -1 rose to 3 (a poor local minimum), -2 fits again at 1, -3 rises to 5: the
        // interval ends between -2 and -3, at -2.25.
        let points = [(-1.0, 3.0), (-2.0, 1.0), (-3.0, 5.0)];
        let u = outer_crossing((0.0, 0.0), &points, 2.0).unwrap();
        assert!((u + 2.25).abs() < 1e-12);
        assert_eq!(outer_crossing((0.0, 0.0), &points[..2], 2.0), None);
        assert_eq!(
            outer_crossing((0.0, 0.0), &points[..1], 2.0),
            crossing((0.0, 0.0), &points[..1], 2.0)
        );
    }

    #[test]
    fn pins_are_removed_and_merged_back() {
        let u = DVector::from_vec(vec![1.0, 2.0, 3.0]);
        let pins = [(1, 9.0)];
        let rest = without(&u, &pins);
        assert_eq!(rest.as_slice(), &[1.0, 3.0]);
        assert_eq!(merged(&rest, &pins, 3).as_slice(), &[1.0, 9.0, 3.0]);
    }

    #[test]
    fn undetermined_parameters_have_no_standard_error_and_widen_the_rest_where_they_can() {
        let flat = Standing {
            class: Identifiability::NotIdentifiable,
            bound: None,
        };
        let standings = [Standing::DETERMINED, flat];
        // A flat parameter with a column of its own: the determined one's error is marginal
        // over it. JᵀJ = [[2, 1], [1, 2]], its inverse's first entry 2/3, s² = 1 / (3 - 2).
        let traded = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
        let cov = covariance_of_determined(&traded, 1.0, &standings);
        assert!(cov.std_errors[1].is_nan() && cov.matrix[(0, 1)].is_nan());
        assert!((cov.std_errors[0] - (2.0f64 / 3.0).sqrt()).abs() < 1e-12);
        // A flat parameter whose column vanishes (run to a limit): held where it is. One
        // column [1, 0, 1]: (JᵀJ)^-1 = 1/2, s² = 1 / (3 - 1).
        let vanished = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
        let cov = covariance_of_determined(&vanished, 1.0, &standings);
        assert!(cov.std_errors[1].is_nan());
        assert!((cov.std_errors[0] - 0.5).abs() < 1e-12);
    }
}
