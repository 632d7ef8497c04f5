//! A friction model's force along a measured motion, and its residuals against the
//! energy-based force.
//!
//! # Integrating the internal states
//! A dynamic model's states obey z' = f(v(t), z) with v the measured velocity, taken linear
//! between samples. Bristle models are stiff while sliding: LuGre's and Dahl's states relax
//! at a rate lambda ~ sigma0 |v| / (mu N), about 3e3 1/s for sigma0 = 1e5 N/m at 0.1 m/s with
//! mu N = 3.5 N, so a plain explicit step of dt = 1 ms (lambda dt ~ 3) would diverge. Each
//! sample interval is therefore integrated with the Dormand-Prince 5(4) pair under error
//! control (rtol 1e-8, atol 1e-12 per state). The controller shrinks the sub-step to what
//! accuracy needs in the transients after a reversal and to the method's stability limit
//! (~3.3 / lambda) while the state sits on its slow manifold, so the result stays stable and
//! accurate for any stiffness. The stepper runs on from one interval into the next (v and N are
//! continuous at the samples, so its step size and its last stage carry over): on the
//! tribometer record a GMS force takes about 1.2 steps per sample, where the Bogacki-Shampine
//! 3(2) pair this replaced took 2.4 at the same tolerance and 19 % more evaluations of f. An
//! interval in which v changes sign is split at the zero of the linear v: the states' rate,
//! odd in v, has a kink there that a step's error estimate would not see. It
//! needs nothing of the model beyond
//! `state_derivative`, so every registered model works unchanged.
//!
//! Bristles far stiffer than that (sigma0 = 1e7 N/m: lambda ~ 4e5 1/s) hold Dopri5 at its
//! stability limit, hundreds of sub-steps per sample; [`states_along_stiff`] integrates the
//! same intervals with Rodas4 (linearly implicit, no stability bound, the states' Jacobian by
//! forward differences), which the energy check falls back on when the explicit replay runs
//! out of its step budget.

use super::EnergyAnalysis;
use crate::error::{EngineError, IntegrationFailure};
use crate::oscillator::Oscillator;
use crate::record::NormalForce;
use crate::simulate::{Dopri5, OdeSystem, Rodas4, StepOutcome, Stepper};
use frictionid_models::{FrictionModel, InternalStates};
use serde::Serialize;

const RTOL: f64 = 1e-8;
const ATOL: f64 = 1e-12;
/// Fraction of a sample interval next to its ends where a reversal does not split it (a
/// piece that short could not be resolved in time; its kink is negligible).
const REVERSAL_MARGIN: f64 = 1e-6;
/// Total sub-step budget of one call (accepted and rejected).
const MAX_SUBSTEPS: u64 = 20_000_000;

/// The model force along a record against the energy-based force.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ForceResiduals {
    /// The model's friction force at every sample \[N\].
    pub model_force: Vec<f64>,
    /// Energy-based force minus model force \[N\]; NaN where the energy-based force is masked.
    pub residual: Vec<f64>,
    /// Root mean square of the residual over the samples used \[N\].
    pub rms: f64,
    /// Number of samples used (not masked).
    pub used: usize,
}

/// The friction force of `model` along the measured motion (`time`, `v`), with the oscillator's
/// normal force: [`model_force_with_normal`] with a constant N.
pub fn model_force_along(
    model: &dyn FrictionModel,
    osc: &Oscillator,
    time: &[f64],
    v: &[f64],
) -> Result<Vec<f64>, EngineError> {
    osc.validate()?;
    model_force_with_normal(model, time, v, &NormalForce::Constant(osc.normal_force))
}

/// The friction force of `model` along the measured motion (`time`, `v`) under the normal
/// force `normal` (constant, or one value per sample, taken linear between samples). Static
/// models are evaluated sample by sample, `model.force(v, &[], N)`; dynamic models have their
/// states integrated along v (linear between samples) from zero (relaxed bristles at the
/// first sample), see the module docs.
pub fn model_force_with_normal(
    model: &dyn FrictionModel,
    time: &[f64],
    v: &[f64],
    normal: &NormalForce,
) -> Result<Vec<f64>, EngineError> {
    let states = states_along(model, MeasuredMotion { time, v, normal }, MAX_SUBSTEPS)?;
    Ok(forces_from_states(model, v, normal, &states))
}

/// The model's internal states at every sample of the motion (`time`, `v`) under `normal`,
/// sample after sample (`n_states` values each; empty for a static law), integrated from
/// relaxed states at the first sample within `max_substeps` sub-steps (accepted and
/// rejected) for the whole motion: a fit rejects trial parameters whose states are so stiff,
/// or so little smooth, that they would need more (see
/// [`crate::identify::residuals::STEPS_PER_SAMPLE`]).
pub fn states_along(
    model: &dyn FrictionModel,
    motion: MeasuredMotion<'_>,
    max_substeps: u64,
) -> Result<Vec<f64>, EngineError> {
    states_along_checked(model, motion.checked()?, max_substeps)
}

/// A measured motion: its sample times, velocities and normal force (constant, or one value
/// per sample).
#[derive(Clone, Copy)]
pub struct MeasuredMotion<'a> {
    pub time: &'a [f64],
    pub v: &'a [f64],
    pub normal: &'a NormalForce,
}

impl<'a> MeasuredMotion<'a> {
    /// The motion once [`check_motion`] accepts it.
    fn checked(self) -> Result<CheckedMotion<'a>, EngineError> {
        let MeasuredMotion { time, v, normal } = self;
        check_motion(time, v, normal)?;
        Ok(CheckedMotion { time, v, normal })
    }
}

/// A motion already checked by [`check_motion`]: its sample times, velocities and normal
/// force.
#[derive(Clone, Copy)]
pub(crate) struct CheckedMotion<'a> {
    pub time: &'a [f64],
    pub v: &'a [f64],
    pub normal: &'a NormalForce,
}

/// [`states_along`] integrated with the stiff Rodas4 (see the module docs): for bristles
/// so stiff that the explicit replay would need many sub-steps per sample.
pub fn states_along_stiff(
    model: &dyn FrictionModel,
    motion: MeasuredMotion<'_>,
    max_substeps: u64,
) -> Result<Vec<f64>, EngineError> {
    let motion = motion.checked()?;
    let Some(states) = model.states() else {
        return Ok(Vec::new());
    };
    let stepper = Rodas4::new(states.n_states(), RTOL, ATOL, f64::INFINITY);
    replay(stepper, model, states, motion, max_substeps)
}

/// [`states_along`] of a motion already checked by [`check_motion`] (a fit checks it once,
/// not at every evaluation).
pub(crate) fn states_along_checked(
    model: &dyn FrictionModel,
    motion: CheckedMotion<'_>,
    max_substeps: u64,
) -> Result<Vec<f64>, EngineError> {
    let Some(states) = model.states() else {
        return Ok(Vec::new());
    };
    let stepper = Dopri5::new(states.n_states(), RTOL, ATOL, f64::INFINITY);
    replay(stepper, model, states, motion, max_substeps)
}

/// A stepper that can run on from one sample interval into the next (see the module docs).
trait ReplayStepper: Stepper {
    fn extend_to(&mut self, t_end: f64);
}

impl ReplayStepper for Dopri5 {
    fn extend_to(&mut self, t_end: f64) {
        Dopri5::extend_to(self, t_end);
    }
}

impl ReplayStepper for Rodas4 {
    fn extend_to(&mut self, t_end: f64) {
        Rodas4::extend_to(self, t_end);
    }
}

/// The states at every sample, integrated interval after interval with `stepper`.
fn replay<S: ReplayStepper>(
    mut stepper: S,
    model: &dyn FrictionModel,
    states: &dyn InternalStates,
    motion: CheckedMotion<'_>,
    max_substeps: u64,
) -> Result<Vec<f64>, EngineError> {
    let CheckedMotion { time, v, normal } = motion;
    let ns = states.n_states();
    let mut z = vec![0.0; ns];
    let mut out = Vec::with_capacity(v.len() * ns);
    if ns == 0 {
        return Ok(out);
    }
    for i in 0..time.len() {
        if i > 0 {
            let along = AlongMotion {
                states,
                n0: normal.at(i - 1),
                n1: normal.at(i),
                t0: time[i - 1],
                v0: v[i - 1],
                v1: v[i],
                span: time[i] - time[i - 1],
            };
            let start = if i == 1 {
                Start::Fresh
            } else {
                Start::Continued
            };
            integrate_interval(&mut stepper, &along, &mut z, start, max_substeps).map_err(
                |failure| EngineError::StateIntegration {
                    model: model.name().to_string(),
                    failure,
                },
            )?;
        }
        out.extend_from_slice(&z);
    }
    Ok(out)
}

/// The model's force at every sample from its states there ([`states_along`]).
pub fn forces_from_states(
    model: &dyn FrictionModel,
    v: &[f64],
    normal: &NormalForce,
    states: &[f64],
) -> Vec<f64> {
    forces_at(model, v, normal, states, 0..v.len())
}

/// The model's force at the samples `indices` from its states at every sample
/// ([`states_along`]; empty for a static law).
pub fn forces_at(
    model: &dyn FrictionModel,
    v: &[f64],
    normal: &NormalForce,
    states: &[f64],
    indices: impl Iterator<Item = usize>,
) -> Vec<f64> {
    let ns = model.n_states();
    indices
        .map(|i| model.force(v[i], &states[i * ns..(i + 1) * ns], normal.at(i)))
        .collect()
}

/// Equal lengths, finite samples, strictly increasing time, a finite non-negative normal force.
pub(crate) fn check_motion(
    time: &[f64],
    v: &[f64],
    normal: &NormalForce,
) -> Result<(), EngineError> {
    if time.len() != v.len() {
        return Err(EngineError::InvalidInput(format!(
            "{} time stamps but {} velocities",
            time.len(),
            v.len()
        )));
    }
    if let Some(i) = (0..time.len()).find(|&i| !(time[i].is_finite() && v[i].is_finite())) {
        return Err(EngineError::InvalidInput(format!(
            "sample {i} is not finite (t = {}, v = {})",
            time[i], v[i]
        )));
    }
    if let Err(crate::record::TimeError::NotIncreasing { index, .. }) =
        crate::record::check_time(time)
    {
        return Err(EngineError::InvalidInput(format!(
            "time is not strictly increasing at sample {index}"
        )));
    }
    let values: &[f64] = match normal {
        NormalForce::Constant(n) => std::slice::from_ref(n),
        NormalForce::Sampled(values) if values.len() != time.len() => {
            return Err(EngineError::InvalidInput(format!(
                "{} time stamps but {} normal-force samples",
                time.len(),
                values.len()
            )))
        }
        NormalForce::Sampled(values) => values,
    };
    if let Some(n) = values.iter().find(|n| !(n.is_finite() && **n >= 0.0)) {
        return Err(EngineError::InvalidInput(format!(
            "the normal force must be finite and >= 0, got {n}"
        )));
    }
    Ok(())
}

/// The model's force along the analysed motion against the energy-based force, on the samples
/// where the latter is not masked.
pub fn force_residuals(
    analysis: &EnergyAnalysis,
    model: &dyn FrictionModel,
    osc: &Oscillator,
) -> Result<ForceResiduals, EngineError> {
    let model_force = model_force_along(model, osc, &analysis.time, &analysis.v)?;
    if analysis.friction.len() != model_force.len() {
        return Err(EngineError::InvalidInput(format!(
            "analysis has {} forces for {} samples",
            analysis.friction.len(),
            model_force.len()
        )));
    }
    let residual: Vec<f64> = analysis
        .friction
        .iter()
        .zip(&model_force)
        .map(|(&f, &m)| if f.is_nan() { f64::NAN } else { f - m })
        .collect();
    let (sum, used) = residual
        .iter()
        .filter(|r| !r.is_nan())
        .fold((0.0, 0usize), |(s, n), r| (s + r * r, n + 1));
    if used == 0 {
        return Err(EngineError::InvalidInput(
            "no unmasked samples to compare the model force with".into(),
        ));
    }
    let rms = (sum / used as f64).sqrt();
    if !rms.is_finite() {
        return Err(EngineError::InvalidInput(format!(
            "model `{}` gives a non-finite force along the motion",
            model.name()
        )));
    }
    Ok(ForceResiduals {
        model_force,
        residual,
        rms,
        used,
    })
}

/// The states' equation along one sample interval: z' = f(v(t), z, N(t)) with v linear from
/// (t0, v0) to (t0 + span, v1) and N linear from n0 to n1.
struct AlongMotion<'a> {
    states: &'a dyn InternalStates,
    n0: f64,
    n1: f64,
    t0: f64,
    v0: f64,
    v1: f64,
    span: f64,
}

impl AlongMotion<'_> {
    /// Where v changes sign inside the interval: the states' rate, odd in v, has a kink there
    /// that a step must not straddle (its error estimate assumes a smooth right-hand side). A
    /// reversal within [`REVERSAL_MARGIN`] of an end is left to the step ending there.
    fn reversal(&self) -> Option<f64> {
        let share = self.v0 / (self.v0 - self.v1);
        let inside = REVERSAL_MARGIN..1.0 - REVERSAL_MARGIN;
        (self.v0 * self.v1 < 0.0 && inside.contains(&share)).then_some(self.t0 + self.span * share)
    }
}

impl OdeSystem for AlongMotion<'_> {
    fn rhs(&self, t: f64, z: &[f64], dz: &mut [f64]) {
        let s = (t - self.t0) / self.span;
        let v = self.v0 + (self.v1 - self.v0) * s;
        let normal = self.n0 + (self.n1 - self.n0) * s;
        self.states.state_derivative(v, z, normal, dz);
    }
}

/// How an interval's integration begins.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Start {
    /// From the states `z` (the first interval).
    Fresh,
    /// Where the previous interval ended: the stepper's state is `z` and z' is continuous at
    /// the knot (v and N are), so the stepper carries its last stage over.
    Continued,
}

/// Integrates the states `z` over one sample interval (the stepper keeps its step size
/// across intervals).
fn integrate_interval<S: ReplayStepper>(
    stepper: &mut S,
    along: &AlongMotion<'_>,
    z: &mut [f64],
    start: Start,
    max_substeps: u64,
) -> Result<(), IntegrationFailure> {
    let t_end = along.t0 + along.span;
    for (k, stop) in along.reversal().into_iter().chain([t_end]).enumerate() {
        match start {
            Start::Fresh if k == 0 => stepper.reset(along, along.t0, z, stop)?,
            _ => stepper.extend_to(stop),
        }
        run_to_stop(stepper, along, max_substeps)?;
    }
    z.copy_from_slice(stepper.state());
    Ok(())
}

/// Steps to the stepper's end time within the sub-step budget, refusing non-finite states.
fn run_to_stop<S: ReplayStepper>(
    stepper: &mut S,
    along: &AlongMotion<'_>,
    max_substeps: u64,
) -> Result<(), IntegrationFailure> {
    while !stepper.reached_end() {
        if stepper.counts().attempts() >= max_substeps {
            return Err(IntegrationFailure::StepBudgetExceeded {
                time: stepper.time(),
                max_steps: max_substeps,
            });
        }
        // No events along a measured motion: the event function stays positive.
        let outcome = stepper.step(along)?;
        let state = stepper.state();
        if outcome != StepOutcome::Rejected && state.iter().any(|x| !x.is_finite()) {
            return Err(IntegrationFailure::NonFiniteState {
                time: stepper.time(),
                state: state.to_vec(),
            });
        }
    }
    Ok(())
}
