//! Which free parameters to profile: those the curvature at the optimum does not pin down.

use super::covariance::covariance_of_determined;
use super::profiles::PROFILE_DELTA;
use super::shared::{not_identifiable, redundant_columns};
use super::Standing;
use crate::error::EngineError;
use crate::identify::assessment::stats::{covariance, Covariance};
use crate::identify::problem::least_squares::FitProblem;
use crate::identify::problem::residuals::Residuals;
use crate::identify::search::starts::StartRun;
use crate::identify::values::layout::{FreeParam, ParamKind};
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
    let full = covariance(&jac, ssr);
    let variance = full.residual_variance;
    if !(variance.is_finite() && variance > 0.0) {
        return Ok(None);
    }
    // A column that is a combination of the others makes JᵀJ singular: only then is one
    // looked for (the QR factors of a long record's Jacobian are not free).
    let redundant = if full.singular {
        redundant_columns(&jac, &[])
    } else {
        Vec::new()
    };
    let slots = flat_slots(reference, (&jac, ssr, full), &p, &r, &redundant)
        .into_iter()
        .filter(|j| !redundant.contains(j))
        .collect();
    Ok(Some(Flat {
        slots,
        delta: PROFILE_DELTA * variance,
        redundant,
    }))
}

/// Free model parameters the records may not determine: those without effect at `p` (a
/// zero column: [`slots_without_effect`]), those whose standard error in the solver's
/// coordinates is missing or above [`FLAT_INTERNAL_SE`], those held at a bound (where the
/// curvature says nothing of the side beyond it), or (a model with internal states) those
/// whose Jacobian column is integration noise ([`noise_dominated`]); every one when the
/// Jacobian is rank-deficient apart from the parameters without effect and the
/// `redundant` ones.
///
/// The standard errors are those of the covariance the result reports
/// ([`covariance_of_determined`]): the parameters without effect and the redundant ones
/// set aside, a redundant one taken back where the others stay determined. A zero column
/// is orthogonal to every other, so setting it aside leaves the others' errors as they
/// were; a GMS element without load at the optimum made the whole Jacobian singular, and
/// every parameter of the law was profiled.
fn flat_slots<R: Residuals>(
    reference: &FitProblem<R>,
    (jac, ssr, full): (&DMatrix<f64>, f64, Covariance),
    p: &[f64],
    r: &DVector<f64>,
    redundant: &[usize],
) -> Vec<usize> {
    let layout = &reference.layout;
    let without_effect = slots_without_effect(layout, p, jac);
    let set_aside = [without_effect.as_slice(), redundant].concat();
    let cov = if set_aside.is_empty() {
        full
    } else {
        let standings = vec![Standing::DETERMINED; layout.len()];
        covariance_of_determined(jac, ssr, &not_identifiable(&standings, &set_aside))
    };
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

/// The largest change of any weighted residual (in units of its noise) that a change of a
/// free parameter by its own magnitude may make for the parameter to count as without effect.
pub(super) const NO_EFFECT: f64 = 1e-8;

/// The free parameters (slots of `layout`, at `values`) whose column of `jac` moves no
/// residual by [`NO_EFFECT`] of its noise over a change the size of their value (their
/// scale, when zero).
pub(crate) fn slots_without_effect(
    layout: &[FreeParam],
    values: &[f64],
    jac: &DMatrix<f64>,
) -> Vec<usize> {
    layout
        .iter()
        .zip(values)
        .enumerate()
        .filter(|&(j, (f, &p))| {
            let step = if p != 0.0 { p.abs() } else { f.scale.abs() };
            j < jac.ncols() && jac.column(j).iter().all(|d| (d * step).abs() <= NO_EFFECT)
        })
        .map(|(j, _)| j)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::search::strategy::{law_force_problem, offset_stroke};
    use crate::identify::values::outcome::TerminationReason;
    use crate::record::Record;
    use crate::testing::DamperStroke;
    use frictionid_models::Stribeck;
    use std::sync::Arc;

    /// The flat slots' names of Stribeck's law (its Coulomb level, static level, Stribeck
    /// speed and viscous coefficient free, the normal force 1 N) on a short damper stroke's
    /// force, at `values` of those four and no force offset. The stroke's frequency puts no
    /// sample on a reversal, where the speed would be zero.
    fn flat_names(values: [f64; 4]) -> Vec<String> {
        let (_, osc, mut opts) = offset_stroke(0.0);
        let stroke = DamperStroke {
            frequency: 2.0137,
            ..DamperStroke::short()
        }
        .record(4000);
        let free = ["mu_c", "mu_s", "v_s", "viscous"];
        opts.params.free = Some(free.iter().map(|s| (*s).into()).collect());
        let records: Arc<[Record]> = vec![stroke].into();
        let law = Stribeck::default();
        let (reference, _) = law_force_problem(&records, osc, &opts, &law);
        let names: Vec<&str> = reference.layout.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(
            names,
            ["mu_c", "mu_s", "v_s", "viscous", "force_offset[stroke]"]
        );
        let p = [values[0], values[1], values[2], values[3], 0.0];
        let best = StartRun {
            u: reference.internal(&p),
            cost: f64::NAN,
            iterations: 0,
            simulations: 0,
            termination: TerminationReason::GradientBelowTolerance,
            linearisation: None,
        };
        let flat = flat_and_delta(&reference, &best).unwrap().unwrap();
        flat.slots
            .iter()
            .map(|&j| reference.layout[j].name.clone())
            .collect()
    }

    /// Stribeck's law on a damper stroke with a Stribeck speed of 1e-12 m/s, far below
    /// every sampled speed: its static level and its speed change no residual (zero
    /// columns), which makes the Jacobian singular, while the Coulomb level and the viscous
    /// term are determined. Set aside, the zero columns leave the others' standard errors
    /// as they were: only they are profiled. At an ordinary Stribeck speed nothing is set
    /// aside and the same rule profiles what the curvature does not pin down.
    #[test]
    fn parameters_without_effect_are_profiled_and_leave_the_others_to_their_errors() {
        let mut flat = flat_names([40.0, 50.0, 1e-12, 100.0]);
        flat.sort();
        assert_eq!(flat, ["mu_s", "v_s"]);
        let flat = flat_names([40.0, 50.0, 0.01, 100.0]);
        assert!(!flat.contains(&"mu_c".to_string()), "{flat:?}");
        assert!(!flat.contains(&"viscous".to_string()), "{flat:?}");
    }
}
