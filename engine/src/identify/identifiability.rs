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

/// Profiles the flat parameters at the best run, settles an iteration limit caused only by
/// unbounded ones, and returns the runs with one standing per free parameter.
pub fn settle<R: Residuals + 'static>(
    reference: &FitProblem<R>,
    mut runs: MultiStart,
    opts: &FitOptions,
) -> Result<(MultiStart, Vec<Standing>), EngineError> {
    let n = reference.layout.len();
    let mut standings = vec![Standing::DETERMINED; n];
    if n == 0 {
        return Ok((runs, standings));
    }
    let quiet = FitOptions {
        progress: None,
        ..opts.clone()
    };
    let p = reference.physical(&runs.best.u);
    let (jac, r) = reference.jacobian_physical(&p)?;
    let ssr = r.norm_squared();
    let variance = covariance(&jac, ssr).residual_variance;
    if !(variance.is_finite() && variance > 0.0) {
        return Ok((runs, standings));
    }
    for j in flat_slots(reference, &jac, ssr, &p) {
        let profile = Profile {
            reference,
            best: &runs.best,
            opts: &quiet,
        };
        standings[j] = profile.standing(j, PROFILE_DELTA * variance);
    }
    settle_convergence(reference, &mut runs, &standings, &quiet);
    Ok((runs, standings))
}

/// Free model parameters the records may not determine: every one when the Jacobian is
/// rank-deficient, else those whose standard error in the solver's coordinates is missing
/// or above [`FLAT_INTERNAL_SE`].
fn flat_slots<R: Residuals>(
    reference: &FitProblem<R>,
    jac: &DMatrix<f64>,
    ssr: f64,
    p: &[f64],
) -> Vec<usize> {
    let layout = &reference.layout;
    let cov = covariance(jac, ssr);
    (0..layout.len())
        .filter(|&j| {
            let se = cov.std_errors[j] * layout[j].internal_derivative(p[j]).abs();
            let fine = !cov.singular && se.is_finite() && se > 0.0 && se <= FLAT_INTERNAL_SE;
            matches!(layout[j].kind, ParamKind::Model(_)) && !fine
        })
        .collect()
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
        }
    } else {
        let slot = RunSlot {
            start: 0,
            starts: 1,
            max_iterations: iterations,
        };
        run_start(sub, others.clone(), opts, slot).ok()?
    };
    run.cost.is_finite().then_some(run)
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
    fn side(&self, j: usize, side: f64, limit: f64) -> Vec<(f64, f64)> {
        let f = &self.reference.layout[j];
        let (lo, hi) = f.internal_bounds();
        let centre = self.best.u[j];
        let mut step = if f.log {
            std::f64::consts::LN_10
        } else {
            centre.abs().max(1.0)
        };
        let mut others = without(&self.best.u, &[(j, centre)]);
        let mut out: Vec<(f64, f64)> = Vec::new();
        let mut halvings = 0;
        while out.len() < PROFILE_STEPS {
            let previous = out.last().map_or(centre, |&(v, _)| v);
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
                    out.push((u, run.cost));
                    others = run.u;
                    if run.cost > limit {
                        break;
                    }
                }
            }
        }
        out
    }

    /// The standing of slot `j` for a cost rise `delta` (absolute).
    fn standing(&self, j: usize, delta: f64) -> Standing {
        let best = self.best.cost;
        let below = self.side(j, -1.0, best + delta);
        let above = self.side(j, 1.0, best + delta);
        // A profile that found a lower cost (a parameter still running on) measures from it.
        let floor = below
            .iter()
            .chain(&above)
            .map(|&(_, c)| c)
            .fold(best, f64::min);
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
        Standing { class, bound }
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
