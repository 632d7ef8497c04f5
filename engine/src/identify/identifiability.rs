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
//! `upper_bound`, or `not_identifiable`.
//!
//! A fit that hit the iteration limit only because such a parameter kept running on is
//! settled: the unbounded parameters are pinned where they are and the others re-optimised;
//! when that converges the fit counts as converged for them.

use super::layout::ParamKind;
use super::options::FitOptions;
use super::outcome::{Check, Finding, TerminationReason};
use super::problem::{FitProblem, ProblemParts};
use super::residuals::Residuals;
use super::starts::{run_start, MultiStart, RunSlot, StartRun};
use super::stats::{covariance, Covariance};
use crate::error::EngineError;
use frictionid_models::FrictionModel;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

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

/// What the records say about a fitted parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Identifiability {
    /// Bounded on both sides: the value and its standard error stand.
    Determined,
    /// Only smaller values are excluded (at 95 %): the parameter exceeds `bound`.
    LowerBound,
    /// Only larger values are excluded: the parameter is below `bound`.
    UpperBound,
    /// Neither side is bounded within the profile.
    NotIdentifiable,
}

impl Identifiability {
    /// Config-style name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Determined => "determined",
            Self::LowerBound => "lower_bound",
            Self::UpperBound => "upper_bound",
            Self::NotIdentifiable => "not_identifiable",
        }
    }
}

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
        progress: None,
        ..opts.clone()
    };
    let mut restarts = PROFILE_RESTARTS;
    loop {
        match profile_all(reference, &runs.best, &quiet, restarts > 0)? {
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

/// Profiles every flat parameter at `best`; with `restart`, stops at the first profile point
/// a `delta` below the best cost.
fn profile_all<R: Residuals + 'static>(
    reference: &FitProblem<R>,
    best: &StartRun,
    opts: &FitOptions,
    restart: bool,
) -> Result<Profiled, EngineError> {
    let mut standings = vec![Standing::DETERMINED; reference.layout.len()];
    let Some((slots, delta)) = flat_and_delta(reference, best)? else {
        return Ok(Profiled::Standings(standings));
    };
    let profile = Profile {
        reference,
        best,
        opts,
    };
    for j in slots {
        let (standing, lower) = profile.standing(j, delta);
        if let Some(u) = lower.filter(|_| restart) {
            return Ok(Profiled::Lower(u));
        }
        standings[j] = standing;
    }
    Ok(Profiled::Standings(standings))
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
        max_iterations: opts.max_iterations,
        pace: None,
    };
    let Ok(run) = run_start(problem, u, opts, slot) else {
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
    if let Some((jac, r)) = &runs.best.linearisation {
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
            let at_bound = p[j] <= layout[j].lower || p[j] >= layout[j].upper;
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
    iterations: u64,
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
        };
        run_start(sub, others.clone(), opts, slot).ok()?
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
}

impl<R: Residuals + 'static> Profile<'_, R> {
    /// Profile points (internal value, cost) on one side (`side` = ±1), stepping outward
    /// until the cost exceeds `limit`, a bound is reached or a step fails; a first step that
    /// fails is retried at half the distance (at most [`PROFILE_HALVINGS`] times).
    fn side(&self, j: usize, side: f64, limit: f64) -> Vec<ProfilePoint> {
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
            match pinned_fit(
                self.reference,
                &pins,
                &others,
                self.opts,
                PROFILE_ITERATIONS,
            ) {
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
                    if run.cost > limit {
                        break;
                    }
                }
            }
        }
        out
    }

    /// The standing of slot `j` for a cost rise `delta` (absolute), and the lowest profile
    /// point (internal coordinates) when its cost lies more than `delta` below the best.
    fn standing(&self, j: usize, delta: f64) -> (Standing, Option<DVector<f64>>) {
        let best = self.best.cost;
        // The two sides are independent refits: side by side on two threads.
        let (below, above) = if self.opts.parallel {
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
            .fold(best, f64::min);
        let pairs = |side: &[ProfilePoint]| -> Vec<(f64, f64)> {
            side.iter().map(|p| (p.u, p.cost)).collect()
        };
        let (below, above) = (pairs(&below), pairs(&above));
        let centre = (self.best.u[j], best);
        let f = &self.reference.layout[j];
        // A side that cannot be evaluated at all (too stiff to simulate) counts as open.
        let low = crossing(centre, &below, floor + delta).map(|u| f.to_physical(u));
        let high = crossing(centre, &above, floor + delta).map(|u| f.to_physical(u));
        let (class, bound) = match (low, high) {
            (Some(_), Some(_)) => (Identifiability::Determined, None),
            (Some(b), None) => (Identifiability::LowerBound, Some(b)),
            (None, Some(b)) => (Identifiability::UpperBound, Some(b)),
            (None, None) => (Identifiability::NotIdentifiable, None),
        };
        (Standing { class, bound }, lowest)
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
    let Some(run) = pinned_fit(reference, &pins, &others, opts, opts.max_iterations) else {
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

/// The covariance of the determined parameters alone (the others held where they are): the
/// columns of the rest are dropped, and their rows and columns come back as NaN.
pub fn covariance_of_determined(
    jac: &DMatrix<f64>,
    ssr: f64,
    standings: &[Standing],
) -> Covariance {
    let keep: Vec<usize> = (0..jac.ncols())
        .filter(|&j| standings.get(j).is_none_or(Standing::determined))
        .collect();
    if keep.len() == jac.ncols() {
        return covariance(jac, ssr);
    }
    let reduced = covariance(&jac.select_columns(&keep), ssr);
    let p = jac.ncols();
    let mut matrix = DMatrix::from_element(p, p, f64::NAN);
    let mut correlation = DMatrix::from_element(p, p, f64::NAN);
    let mut std_errors = vec![f64::NAN; p];
    for (a, &ja) in keep.iter().enumerate() {
        std_errors[ja] = reduced.std_errors[a];
        for (b, &jb) in keep.iter().enumerate() {
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
pub fn consistency_findings(model: &dyn FrictionModel) -> Vec<Finding> {
    match model.validate() {
        Ok(warnings) => warnings
            .into_iter()
            .map(|w| Finding::warn(Check::PhysicalConsistency, None, w))
            .collect(),
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
    fn pins_are_removed_and_merged_back() {
        let u = DVector::from_vec(vec![1.0, 2.0, 3.0]);
        let pins = [(1, 9.0)];
        let rest = without(&u, &pins);
        assert_eq!(rest.as_slice(), &[1.0, 3.0]);
        assert_eq!(merged(&rest, &pins, 3).as_slice(), &[1.0, 9.0, 3.0]);
    }

    #[test]
    fn dropped_parameters_have_no_standard_error_and_the_rest_keep_theirs() {
        let jac = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
        let flat = Standing {
            class: Identifiability::LowerBound,
            bound: Some(1.0),
        };
        let cov = covariance_of_determined(&jac, 1.0, &[Standing::DETERMINED, flat]);
        assert!(cov.std_errors[1].is_nan());
        // One column [1, 0, 1]: (JᵀJ)^-1 = 1/2, s² = 1 / (3 - 1).
        assert!((cov.std_errors[0] - 0.5).abs() < 1e-12);
    }
}
