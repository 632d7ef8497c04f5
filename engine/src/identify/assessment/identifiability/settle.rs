//! Settling a best run: the profiles of its flat parameters (restarting the fit from a profile
//! point clearly below it), and an iteration limit caused only by unbounded parameters.

use super::flat::{flat_and_delta, Flat};
use super::pinned::{merged, pinned_fit, pinned_problem, without};
use super::profiles::{Profile, PROFILE_RESOLUTION};
use super::rigid_limit::{rigid_limit, Limit};
use super::shared::not_identifiable;
use super::Standing;
use crate::error::EngineError;
use crate::identify::problem::least_squares::FitProblem;
use crate::identify::problem::residuals::Residuals;
use crate::identify::search::starts::{run_start, MultiStart, RunSlot, StartRun};
use crate::identify::search::strategy::SimplerFit;
use crate::identify::values::fit_options::FitOptions;
use crate::identify::values::outcome::TerminationReason;
use nalgebra::DVector;
use rayon::prelude::*;

/// Times a profile that found a clearly lower cost restarts the fit from there.
pub const PROFILE_RESTARTS: usize = 2;

/// A best run settled: the runs, one standing per free parameter, and the slots found
/// redundant before profiling (not identifiable; the redundancy's finding names them).
pub(crate) struct Settled {
    pub runs: MultiStart,
    pub standings: Vec<Standing>,
    pub redundant: Vec<usize>,
}

/// Profiles the flat parameters at the best run, settles an iteration limit caused only by
/// unbounded ones, and returns the runs with one standing per free parameter. A parameter
/// whose column is a combination of the others' is not profiled: the records fix only the
/// combination, and its profile (re-optimised along the combination until a box bound
/// stops it) would say no more than that. A profile
/// point whose cost lies a [`PROFILE_DELTA`](super::PROFILE_DELTA) rise below the best (the
/// fit stopped in a local minimum or on a plateau the profile stepped off) restarts the
/// solver there, and the profiles are taken again at the better optimum. `limit_stage`: the
/// model's rigid-limit law as the staged search fitted it, which starts the limit's fit.
pub(crate) fn settle<R: Residuals + 'static>(
    reference: &FitProblem<R>,
    mut runs: MultiStart,
    opts: &FitOptions,
    limit_stage: Option<&SimplerFit>,
) -> Result<Settled, EngineError> {
    let quiet = FitOptions {
        hooks: opts.hooks.quiet(),
        ..opts.clone()
    };
    let limit = rigid_limit(reference, &runs.best, &quiet, limit_stage);
    let mut restarts = PROFILE_RESTARTS;
    loop {
        match profile_all(reference, &runs.best, &quiet, limit.as_ref(), restarts > 0)? {
            Profiled::Standings {
                standings,
                redundant,
            } => {
                let runs = finish(reference, runs, &standings, &quiet);
                return Ok(Settled {
                    runs,
                    standings,
                    redundant,
                });
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
    standings: &[Standing],
    opts: &FitOptions,
) -> MultiStart {
    settle_convergence(reference, &mut runs, standings, opts);
    runs
}

/// What the profiles of a best run found.
enum Profiled {
    /// One standing per free parameter, and the slots not profiled for being redundant.
    Standings {
        standings: Vec<Standing>,
        redundant: Vec<usize>,
    },
    /// A point (internal coordinates) clearly below the best cost.
    Lower(DVector<f64>),
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
    let Some(Flat {
        mut slots,
        delta,
        redundant,
    }) = flat_and_delta(reference, best)?
    else {
        return Ok(Profiled::Standings {
            standings,
            redundant: Vec::new(),
        });
    };
    let open_limit = limit.filter(|l| l.cost <= best.cost + delta * l.rise_factor());
    if let Some(l) = open_limit {
        if l.cost < best.cost - delta && restart {
            if let Some(u) = l.approach(reference, best, delta) {
                return Ok(Profiled::Lower(u));
            }
        }
        l.plan_profiles(best.cost + delta, &mut slots, &mut standings);
        slots.retain(|j| !redundant.contains(j));
    }
    standings = not_identifiable(&standings, &redundant);
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
    Ok(Profiled::Standings {
        standings,
        redundant,
    })
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
