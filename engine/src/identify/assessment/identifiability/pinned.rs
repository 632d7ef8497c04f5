//! Refits with some free parameters pinned: the problem without them, and the points with and
//! without their slots.

use crate::identify::problem::least_squares::{FitProblem, ProblemParts};
use crate::identify::problem::residuals::Residuals;
use crate::identify::search::starts::{run_start, RunSlot, StartRun};
use crate::identify::values::fit_options::FitOptions;
use crate::identify::values::layout::ParamKind;
use crate::identify::values::outcome::TerminationReason;
use frictionid_models::FrictionModel;
use nalgebra::DVector;

/// The problem with the free parameters `pins` (slot, internal value) fixed at those values.
pub(super) fn pinned_problem<R: Residuals>(
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
pub(super) fn without(u: &DVector<f64>, pins: &[(usize, f64)]) -> DVector<f64> {
    let kept: Vec<f64> = (0..u.len())
        .filter(|j| !pins.iter().any(|(p, _)| p == j))
        .map(|j| u[j])
        .collect();
    DVector::from_vec(kept)
}

/// The full internal point from the others' values and the pins.
pub(super) fn merged(others: &DVector<f64>, pins: &[(usize, f64)], n: usize) -> DVector<f64> {
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
pub(super) fn pinned_fit<R: Residuals + 'static>(
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pins_are_removed_and_merged_back() {
        let u = DVector::from_vec(vec![1.0, 2.0, 3.0]);
        let pins = [(1, 9.0)];
        let rest = without(&u, &pins);
        assert_eq!(rest.as_slice(), &[1.0, 3.0]);
        assert_eq!(merged(&rest, &pins, 3).as_slice(), &[1.0, 9.0, 3.0]);
    }
}
