//! The force's derivatives along a measured motion for a law without an exact step (a plugin
//! law, typically): its states and their sensitivities to the parameters integrated together,
//! interval by interval, by the numerical replay's steppers (`numerical_replay.rs`).
//!
//! With the states' rate h(v, z, N; p) at the interval's constant v and N, the sensitivities
//! S = dz/dp (n_states x n_params) obey
//!
//!   S' = (dh/dz) S + dh/dp,
//!
//! from S = 0 (the replay starts from relaxed states whatever the parameters), integrated as
//! y = [z, s_1, ..., s_P] with s_j = dz/dp_j. The states' Jacobian dh/dz is the law's (or its
//! finite differences, `Derivatives`), dh/dp its `ParamGradients::state_param_gradient`. The
//! error control covers the states alone, so the augmented replay takes the plain replay's
//! steps: Dopri5's exactly, and Rodas4's up to the rounding of its linear systems, which it
//! solves block by block with the factors of the states' block ([`Rodas4::block_triangular`]).
//! Rodas4 needs the augmented system's Jacobian: the state Jacobian on the diagonal blocks,
//! and below them the derivative of s_j' in z, taken by forward differences of the
//! sensitivities' rates (one state Jacobian and rate gradient per state) at steps scaled by
//! the states' sliding values.
//!
//! [`Rodas4::block_triangular`]: crate::simulate::Rodas4::block_triangular
//!
//! The force's derivatives at the samples are then dF/dp + (dF/dz) S, as the exact steps'
//! replay gives them ([`SensitivityReplay`]): a fit's Jacobian costs one augmented replay in
//! place of one replay per parameter.

use super::force_derivatives::{walk_rows, ForceDerivatives, ReplayedSamples, SensitivityReplay};
use super::numerical_replay::{Replay, ReplayPlan};
use crate::record::{ConditionColumns, NormalForce};
use crate::simulate::OdeSystem;
use frictionid_models::start::TYPICAL_PRESLIDING_DISPLACEMENT;
use frictionid_models::{Derivatives, FrictionModel, InternalStates, Interval, ParamGradients};
use std::cell::RefCell;

/// A motion's samples and the intervals its replay moves through between them.
pub(crate) struct SampledMotion<'a> {
    time: &'a [f64],
    v: &'a [f64],
    normal: &'a NormalForce,
    /// The interval between samples i - 1 and i (i >= 1).
    interval: &'a dyn Fn(usize) -> Interval,
}

impl<'a> SampledMotion<'a> {
    /// The samples `time`, `v` and `normal` (checked, one of each per sample) replayed over
    /// `interval`.
    pub(crate) fn new(
        time: &'a [f64],
        v: &'a [f64],
        normal: &'a NormalForce,
        interval: &'a dyn Fn(usize) -> Interval,
    ) -> Self {
        Self {
            time,
            v,
            normal,
            interval,
        }
    }
}

/// The force of `model` at the samples `samples` (ascending) of `motion` and its derivatives
/// in every parameter, from one replay of the states with their sensitivities integrated
/// (module docs); `None` when the law has no parameter gradient of its force or of its
/// states' rate, or when the replay fails (the caller then takes difference quotients, whose
/// replays report the failure).
pub(crate) fn integrated_force_derivatives(
    model: &dyn FrictionModel,
    motion: SampledMotion<'_>,
    samples: &[usize],
    conditions: &ConditionColumns<'_>,
) -> Option<ForceDerivatives> {
    let gradients = model.param_gradients()?;
    let law = model.states()?;
    let (ns, np) = (law.n_states(), model.params().len());
    if ns == 0 {
        // No states to carry sensitivities (the caller differences the columns).
        return None;
    }
    let plan = ReplayPlan::new(law, motion.time, motion.interval);
    let system = SensitiveMotion::new(law, gradients, np, &plan.intervals)?;
    let mut replay = Replay::new(ns * (1 + np), ns, plan.budget);
    let mut y = vec![0.0; ns * (1 + np)];
    let mut rows = SensitivityReplay::new(model, gradients, Derivatives::of(law), np);
    let mut out = ForceDerivatives::for_samples(samples.len(), np);
    let at = ReplayedSamples {
        v: motion.v,
        normal: motion.normal,
        conditions,
    };
    walk_rows(&mut rows, at, samples, &mut out, |i, rows| {
        let iv = plan.intervals[i - 1];
        let span = (motion.time[i - 1], iv.dt);
        replay
            .interval(&system.at(iv), span, plan.relaxations(&iv), &mut y)
            .ok()?;
        rows.z.copy_from_slice(&y[..ns]);
        // Parameter by parameter in y, state by state in the rows' S.
        for (j, s) in y[ns..].chunks_exact(ns).enumerate() {
            for (r, &x) in s.iter().enumerate() {
                rows.sens[r * np + j] = x;
            }
        }
        Some(())
    })?;
    Some(out)
}

/// The law's states with their sensitivities: what stays the same over a replay.
struct SensitiveMotion<'a> {
    law: &'a dyn InternalStates,
    derivatives: Derivatives<'a>,
    gradients: &'a dyn ParamGradients,
    n_params: usize,
    /// Each state's scale for the difference quotients of the sensitivities' rate in z.
    scales: Vec<f64>,
    /// Buffers of the evaluations, allocated once per replay.
    scratch: RefCell<Scratch>,
}

impl<'a> SensitiveMotion<'a> {
    /// The augmented law of `law` with `n_params` parameters; `None` when its states' rate
    /// has no parameter gradient. The states' scales are their sliding values at the root
    /// mean square speed and mean normal force of `intervals` (the typical presliding
    /// displacement where a law gives none).
    fn new(
        law: &'a dyn InternalStates,
        gradients: &'a dyn ParamGradients,
        n_params: usize,
        intervals: &[Interval],
    ) -> Option<Self> {
        let ns = law.n_states();
        let n = intervals.len().max(1) as f64;
        let speed = (intervals.iter().map(|iv| iv.v * iv.v).sum::<f64>() / n).sqrt();
        let normal = intervals.iter().map(|iv| iv.normal).sum::<f64>() / n;
        let mut probe = vec![0.0; ns * n_params];
        if !gradients.state_param_gradient(speed, &vec![0.0; ns], normal, &mut probe) {
            return None;
        }
        let mut sliding = vec![0.0; ns];
        let slides = law.sliding_states(speed, normal, &mut sliding);
        let scales = sliding
            .iter()
            .map(|&z| {
                if slides && z.is_finite() && z != 0.0 {
                    z.abs()
                } else {
                    TYPICAL_PRESLIDING_DISPLACEMENT
                }
            })
            .collect();
        Some(Self {
            law,
            derivatives: Derivatives::of(law),
            gradients,
            n_params,
            scales,
            scratch: RefCell::new(Scratch {
                jac: vec![0.0; ns * ns],
                grad: vec![0.0; ns * n_params],
                probe: vec![0.0; ns],
                base: vec![0.0; ns * n_params],
                rates: vec![0.0; ns * n_params],
            }),
        })
    }

    /// The augmented system over the interval `iv` (its constant velocity and normal force).
    fn at(&self, iv: Interval) -> AtInterval<'_, 'a> {
        AtInterval {
            motion: self,
            v: iv.v,
            normal: iv.normal,
        }
    }
}

/// Buffers of one evaluation.
struct Scratch {
    /// dh/dz, n_states x n_states.
    jac: Vec<f64>,
    /// dh/dp, n_states x n_params.
    grad: Vec<f64>,
    /// A perturbed state.
    probe: Vec<f64>,
    /// S' at the state.
    base: Vec<f64>,
    /// S' at the perturbed state.
    rates: Vec<f64>,
}

/// The augmented system y = [z, S] (S row-major, n_states x n_params) at one interval's
/// velocity and normal force.
struct AtInterval<'m, 'a> {
    motion: &'m SensitiveMotion<'a>,
    v: f64,
    normal: f64,
}

impl AtInterval<'_, '_> {
    /// s_j' = (dh/dz) s_j + dh/dp_j for every parameter j at states `z` into `ds` (one block
    /// of n_states per parameter, as `s`), with `scratch`'s buffers.
    fn sensitivity_rates(&self, z: &[f64], s: &[f64], ds: &mut [f64], scratch: &mut Scratch) {
        let m = self.motion;
        let (ns, np) = (z.len(), m.n_params);
        m.derivatives
            .state_jacobian(self.v, z, self.normal, &mut scratch.jac);
        m.gradients
            .state_param_gradient(self.v, z, self.normal, &mut scratch.grad);
        for (j, (out, sj)) in ds.chunks_exact_mut(ns).zip(s.chunks_exact(ns)).enumerate() {
            for (r, o) in out.iter_mut().enumerate() {
                let row = &scratch.jac[r * ns..(r + 1) * ns];
                *o = scratch.grad[r * np + j] + row.iter().zip(sj).map(|(a, b)| a * b).sum::<f64>();
            }
        }
    }
}

impl OdeSystem for AtInterval<'_, '_> {
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        let ns = self.motion.law.n_states();
        let (z, s) = y.split_at(ns);
        let (dz, ds) = dy.split_at_mut(ns);
        self.motion.law.state_derivative(self.v, z, self.normal, dz);
        let mut scratch = self.motion.scratch.borrow_mut();
        self.sensitivity_rates(z, s, ds, &mut scratch);
    }

    /// The augmented Jacobian, row-major: dh/dz on the diagonal blocks (the states' and each
    /// parameter's column of S), and below the states' block the derivative of S' in z by
    /// forward differences.
    fn jacobian(&self, _t: f64, y: &[f64], jac: &mut [f64]) {
        let m = self.motion;
        let (ns, np) = (m.law.n_states(), m.n_params);
        let dim = y.len();
        let (z, s) = y.split_at(ns);
        jac.fill(0.0);
        let mut guard = m.scratch.borrow_mut();
        let scratch = &mut *guard;
        let mut base = std::mem::take(&mut scratch.base);
        self.sensitivity_rates(z, s, &mut base, scratch);
        // dh/dz (left by the call above) on every diagonal block.
        for block in 0..=np {
            for r in 0..ns {
                let row = (block * ns + r) * dim + block * ns;
                jac[row..row + ns].copy_from_slice(&scratch.jac[r * ns..(r + 1) * ns]);
            }
        }
        for c in 0..ns {
            let step = f64::EPSILON.sqrt() * z[c].abs().max(m.scales[c]);
            scratch.probe.copy_from_slice(z);
            scratch.probe[c] += step;
            let probe = std::mem::take(&mut scratch.probe);
            let mut rates = std::mem::take(&mut scratch.rates);
            self.sensitivity_rates(&probe, s, &mut rates, scratch);
            for (row, (&r1, &r0)) in rates.iter().zip(&base).enumerate() {
                jac[(ns + row) * dim + c] = (r1 - r0) / step;
            }
            scratch.probe = probe;
            scratch.rates = rates;
        }
        scratch.base = base;
    }
}

#[cfg(test)]
mod tests;
