//! Which free parameters to profile: those the curvature at the optimum does not pin down.

use super::profiles::PROFILE_DELTA;
use super::shared::redundant_columns;
use crate::error::EngineError;
use crate::identify::assessment::stats::covariance;
use crate::identify::problem::least_squares::FitProblem;
use crate::identify::problem::residuals::Residuals;
use crate::identify::search::starts::StartRun;
use crate::identify::values::layout::ParamKind;
use nalgebra::{DMatrix, DVector};

/// Standard error in the solver's coordinates above which a parameter is profiled.
pub const FLAT_INTERNAL_SE: f64 = 1.0;

/// What the curvature at a best run says before any profile.
pub(super) struct Flat {
    /// The slots to profile.
    pub slots: Vec<usize>,
    /// The profile's cost rise.
    pub delta: f64,
    /// The slots whose column is a combination of the other free parameters' columns
    /// ([`redundant_columns`]): not identifiable one by one, whatever a profile would find.
    pub redundant: Vec<usize>,
}

/// The flat and the redundant slots at `best` and the profile's cost rise; `None` without
/// a residual variance.
pub(super) fn flat_and_delta<R: Residuals>(
    reference: &FitProblem<R>,
    best: &StartRun,
) -> Result<Option<Flat>, EngineError> {
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
    let redundant = redundant_columns(&jac, &[]);
    let slots = flat_slots(reference, &jac, ssr, &p, &r)
        .into_iter()
        .filter(|j| !redundant.contains(j))
        .collect();
    Ok(Some(Flat {
        slots,
        delta: PROFILE_DELTA * variance,
        redundant,
    }))
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
