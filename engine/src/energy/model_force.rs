//! A friction model's force along a measured motion, and its residuals against the
//! energy-based force.
//!
//! # The replay convention
//! A dynamic model's states obey z' = h(v(t), z, N(t)) along the measured motion, which is
//! known at its samples only. Between samples i-1 and i the motion is replayed at the constant
//! velocity v̄ = (v\[i-1\] + v\[i\]) / 2 under the constant normal force N̄ = (N\[i-1\] + N\[i\]) / 2
//! for the interval's duration ([`replay_interval`]): the displacement is the trapezoid's,
//! the same as a velocity linear between the samples would travel, and within the interval
//! the states see one velocity, so an interval with a reversal is one stretch at the mean
//! velocity of its ends. The force at sample i is `force(v[i], z_i, N[i])`, with the states
//! z_i reached at the end of interval i; the states start relaxed (z = 0) at the first sample.
//! Every replay, exact or numerical, follows this convention, so the replayed states are one
//! function of the data whichever way they are computed.
//!
//! # The path convention
//! Where a record measures its displacement, the replay can follow it instead
//! ([`states_along_path`], [`path_interval`]): between samples i-1 and i the states travel the
//! displacement's increment dx = x\[i\] - x\[i-1\], in its direction, while the laws'
//! rate-dependent terms (LuGre's and GMS's Stribeck curve) still read the speed |v̄| of the
//! velocity convention. The interval handed to the law is the one that does both: velocity
//! sgn(dx) |v̄| for |dx| / |v̄| (at |dx| / dt where v̄ = 0), so every law, stepped exactly or
//! integrated, with or without its sensitivities, follows it unchanged. A noisy velocity
//! channel whose v̄ dt flips sign near a reversal, where the displacement does not, no longer
//! moves the states back and forth there. The states of every built-in law evolve with the
//! distance travelled (their rates are |v| times a function of the direction, the states and
//! the speed), for which this is exact; a plugin law whose states also evolve with time sees
//! the interval's duration as |dx| / |v̄|. With a velocity-only record the displacement is
//! the velocity's trapezoid, whose increments are v̄ dt: the two conventions agree.
//!
//! # Exact steps
//! At constant v and N a law's states often have a closed form over the interval (LuGre's
//! bristle relaxes exponentially in the distance travelled; Dahl's force, and each GMS element
//! for sharpness 1 and 2, follow separable laws in the travel): a law with a
//! [`Propagator`](frictionid_models::Propagator) exact at its parameters is stepped by it, one
//! call per sample whatever its stiffness, and the same pass carries the states' sensitivities
//! to the parameters ([`force_derivatives_along`]): with the force's parameter gradient
//! ([`ParamGradients`](frictionid_models::ParamGradients)) and its state gradient, the
//! derivatives of the force along the motion, dF/dp + dF/dz dz/dp, from one replay.
//!
//! # Numerical replay
//! A law without an exact step (a plugin, GMS at another sharpness) has each interval
//! integrated on its own (the right-hand side jumps at the samples, where v̄ and N̄ change;
//! each interval starts with the step size the last ended on), under error control
//! (rtol 1e-8, atol 1e-12 per state): by the Dormand-Prince 5(4) pair where the interval is
//! not stiff, by the linearly implicit Rodas4 where it is or where Dopri5 needs more than a
//! few hundred steps (states that stiffen within the interval, as an element that starts
//! loading). Friction states relax with the distance travelled: an interval holds as many
//! relaxations as its travel times the law's rate per unit travel (the state Jacobian's rate
//! over the speed, taken once per replay at the record's RMS speed and mean normal force, at
//! the law's sliding states), and more than three make it stiff. Bristle models are stiff
//! while sliding: LuGre's and Dahl's states relax at sigma0 / (mu N) per metre, about 3e3 1/s
//! for sigma0 = 1e5 N/m at 0.1 m/s with mu N = 3.5 N, where Dopri5 would be held at its
//! stability limit (~3.3 / lambda). The work is budgeted over the whole record:
//! [`STEPS_PER_INTERVAL`] steps per interval plus one per relaxation (up to
//! [`SETTLED_RELAXATIONS`] per interval), so a long record, or one that travels far, is
//! allowed the work it needs and the transient after a reversal draws on the quiet intervals
//! around it; a law that needs more (a chattering or runaway law) fails with
//! [`IntegrationFailure::StepBudgetExceeded`]. The replay needs nothing of the model beyond
//! `state_derivative` (and the state Jacobian, by finite differences where the law has none),
//! so every registered model works unchanged. A law that also gives its states' rate's
//! parameter gradient has its force's derivatives from one replay too: its sensitivities are
//! integrated with its states (`integrated_sensitivities.rs`).
//!
//! [`IntegrationFailure::StepBudgetExceeded`]: crate::error::IntegrationFailure::StepBudgetExceeded

pub use super::force_derivatives::ForceDerivatives;
use super::force_derivatives::{walk_rows, ReplayedSamples, SensitivityReplay};
use super::integrated_sensitivities::{integrated_force_derivatives, SampledMotion};
use super::numerical_replay::numerical_replay;
use super::EnergyAnalysis;
use crate::error::EngineError;
use crate::oscillator::Oscillator;
use crate::record::{ConditionColumns, NormalForce};
use frictionid_models::{Derivatives, FrictionModel, Interval, Propagator};
use serde::Serialize;

pub use super::numerical_replay::{SETTLED_RELAXATIONS, STEPS_PER_INTERVAL};

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
/// force `normal` (constant, or one value per sample). Static models are evaluated sample by
/// sample, `model.force(v, &[], N)`; dynamic models have their states replayed along the
/// motion from relaxed states at the first sample (see the module docs).
pub fn model_force_with_normal(
    model: &dyn FrictionModel,
    time: &[f64],
    v: &[f64],
    normal: &NormalForce,
) -> Result<Vec<f64>, EngineError> {
    let states = states_along(model, MeasuredMotion { time, v, normal })?;
    Ok(forces_from_states(model, v, normal, &states))
}

/// The model's internal states at every sample of the motion (`n_states` values each, sample
/// after sample; empty for a static law), replayed from relaxed states at the first sample
/// under the convention of the module docs: by the law's exact step where it has one, else
/// integrated interval by interval within the work the record allows.
pub fn states_along(
    model: &dyn FrictionModel,
    motion: MeasuredMotion<'_>,
) -> Result<Vec<f64>, EngineError> {
    states_along_checked(model, motion.checked()?)
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
    /// The motion once [`check_motion`] accepts it, following its velocity.
    fn checked(self) -> Result<CheckedMotion<'a>, EngineError> {
        let MeasuredMotion { time, v, normal } = self;
        check_motion(time, v, normal)?;
        Ok(CheckedMotion {
            time,
            v,
            normal,
            displacement: None,
            intervals: None,
        })
    }
}

/// A motion already checked by [`check_motion`]: its sample times, velocities and normal
/// force, the displacement whose increments it travels (`None`: it follows the velocity), and
/// its replay intervals when they were computed once for every evaluation of a fit
/// ([`CheckedMotion::intervals`]; `None`: each replay computes them).
#[derive(Clone, Copy)]
pub(crate) struct CheckedMotion<'a> {
    pub time: &'a [f64],
    pub v: &'a [f64],
    pub normal: &'a NormalForce,
    pub displacement: Option<&'a [f64]>,
    pub intervals: Option<&'a [Interval]>,
}

impl<'a> CheckedMotion<'a> {
    /// The replay's interval ending at sample `i` (>= 1): [`path_interval`] along the
    /// displacement where the motion follows one, else [`replay_interval`].
    pub(crate) fn interval(&self, i: usize) -> Interval {
        if let Some(&kept) = self.intervals.and_then(|all| all.get(i.wrapping_sub(1))) {
            return kept;
        }
        match self.displacement {
            Some(x) => path_interval(self.time, self.v, x, self.normal, i),
            None => replay_interval(self.time, self.v, self.normal, i),
        }
    }

    /// Every interval of the replay, in order (the one ending at sample `i` at `i - 1`): they
    /// depend on the motion alone, so a fit, which replays the same motion at every
    /// evaluation, computes them once and hands them back in [`CheckedMotion::intervals`].
    pub(crate) fn intervals(&self) -> Vec<Interval> {
        (1..self.len()).map(|i| self.interval(i)).collect()
    }

    /// The motion travelling the increments of `displacement`, once it has a finite value per
    /// sample.
    pub(crate) fn along(self, displacement: &'a [f64]) -> Result<Self, EngineError> {
        check_displacement(self.time, displacement)?;
        Ok(Self {
            displacement: Some(displacement),
            ..self
        })
    }

    /// Number of samples.
    pub(crate) fn len(&self) -> usize {
        self.time.len()
    }
}

/// The interval the replay moves through between samples `i - 1` and `i` (`i` >= 1): the mean
/// velocity and the mean normal force of its ends for its duration. The one place of the
/// replay convention (module docs).
pub fn replay_interval(time: &[f64], v: &[f64], normal: &NormalForce, i: usize) -> Interval {
    Interval {
        v: 0.5 * (v[i - 1] + v[i]),
        normal: 0.5 * (normal.at(i - 1) + normal.at(i)),
        dt: time[i] - time[i - 1],
    }
}

/// The interval the replay moves through between samples `i - 1` and `i` (`i` >= 1) along
/// the displacement `x`: the travel is its increment dx, in its direction, at the speed of
/// the velocity's interval ([`replay_interval`]: the mean |v| of its ends, which the laws'
/// rate-dependent terms read), for the time that speed takes over |dx|; where that speed is
/// zero, at the displacement's own rate |dx| / dt. An interval without travel is a stop for
/// its duration. The one place of the path convention (module docs).
pub fn path_interval(
    time: &[f64],
    v: &[f64],
    x: &[f64],
    normal: &NormalForce,
    i: usize,
) -> Interval {
    let along_v = replay_interval(time, v, normal, i);
    let dx = x[i] - x[i - 1];
    let travel = dx.abs();
    if travel == 0.0 {
        return Interval { v: 0.0, ..along_v };
    }
    let speed = along_v.v.abs();
    let speed = if speed > 0.0 && (travel / speed).is_finite() {
        speed
    } else {
        travel / along_v.dt
    };
    Interval {
        v: speed.copysign(dx),
        normal: along_v.normal,
        dt: travel / speed,
    }
}

/// [`states_along`] with the travel between samples taken from `displacement` (one value per
/// sample), the path convention of the module docs ([`path_interval`]).
pub fn states_along_path(
    model: &dyn FrictionModel,
    motion: MeasuredMotion<'_>,
    displacement: &[f64],
) -> Result<Vec<f64>, EngineError> {
    states_along_checked(model, motion.checked()?.along(displacement)?)
}

/// [`states_along`] of a motion already checked by [`check_motion`] (a fit checks it once,
/// not at every evaluation).
pub(crate) fn states_along_checked(
    model: &dyn FrictionModel,
    motion: CheckedMotion<'_>,
) -> Result<Vec<f64>, EngineError> {
    let Some(law) = model.states() else {
        return Ok(Vec::new());
    };
    match exact_propagator(model) {
        Some(propagator) => Ok(exact_replay(propagator, motion)),
        None => numerical_replay(law, motion.time, |i| motion.interval(i)).map_err(|failure| {
            EngineError::StateIntegration {
                model: model.name().to_string(),
                failure,
            }
        }),
    }
}

/// The law's propagator, where it has one exact at its current parameters.
fn exact_propagator(model: &dyn FrictionModel) -> Option<&dyn Propagator> {
    model
        .states()?
        .propagator()
        .filter(|p| p.propagates_exactly())
}

/// The states at every sample, stepped exactly interval by interval.
fn exact_replay(propagator: &dyn Propagator, motion: CheckedMotion<'_>) -> Vec<f64> {
    let ns = propagator.n_states();
    let mut z = vec![0.0; ns];
    let mut out = Vec::with_capacity(motion.len() * ns);
    for i in 0..motion.len() {
        if i > 0 {
            propagator.propagate(motion.interval(i), &mut z);
        }
        out.extend_from_slice(&z);
    }
    out
}

/// [`force_derivatives_along`] with the travel between samples taken from `displacement`
/// (one value per sample), the path convention of the module docs ([`path_interval`]).
pub fn force_derivatives_along_path(
    model: &dyn FrictionModel,
    motion: MeasuredMotion<'_>,
    displacement: &[f64],
    samples: &[usize],
) -> Result<Option<ForceDerivatives>, EngineError> {
    let motion = motion.checked()?.along(displacement)?;
    derivatives_without_conditions(model, motion, samples)
}

/// [`force_derivatives_checked`] at `samples` checked against the motion, for a law that
/// reads no conditions.
fn derivatives_without_conditions(
    model: &dyn FrictionModel,
    motion: CheckedMotion<'_>,
    samples: &[usize],
) -> Result<Option<ForceDerivatives>, EngineError> {
    check_samples(samples, motion.len())?;
    Ok(force_derivatives_checked(
        model,
        motion,
        samples,
        &ConditionColumns::none(),
    ))
}

/// Every sample index of `samples` lies within a motion of `len` samples.
fn check_samples(samples: &[usize], len: usize) -> Result<(), EngineError> {
    match samples.iter().find(|&&i| i >= len) {
        Some(bad) => Err(EngineError::InvalidInput(format!(
            "sample {bad} of a motion of {len} samples"
        ))),
        None => Ok(()),
    }
}

/// The force of `model` at the samples `samples` (ascending) of the motion and its
/// derivatives with respect to the model's parameters, from one replay of the states with
/// their sensitivities (module docs); `None` when the law has no parameter gradient, or has
/// states without a propagator exact at its parameters.
pub fn force_derivatives_along(
    model: &dyn FrictionModel,
    motion: MeasuredMotion<'_>,
    samples: &[usize],
) -> Result<Option<ForceDerivatives>, EngineError> {
    let motion = motion.checked()?;
    derivatives_without_conditions(model, motion, samples)
}

/// [`force_derivatives_along`] of a checked motion and samples within it, the law reading
/// its conditions from `conditions` (bound to its [`FrictionModel::conditions`]).
pub(crate) fn force_derivatives_checked(
    model: &dyn FrictionModel,
    motion: CheckedMotion<'_>,
    samples: &[usize],
    conditions: &ConditionColumns<'_>,
) -> Option<ForceDerivatives> {
    let gradients = model.param_gradients()?;
    let np = model.params().len();
    let mut out = ForceDerivatives::for_samples(samples.len(), np);
    let Some(law) = model.states() else {
        let mut at = vec![0.0; conditions.len()];
        for (k, &i) in samples.iter().enumerate() {
            let (v, normal) = (motion.v[i], motion.normal.at(i));
            conditions.fill(i, &mut at);
            out.force.push(model.force_in(v, &[], normal, &at));
            let row = &mut out.gradient[k * np..(k + 1) * np];
            gradients.force_param_gradient_in(v, &[], normal, &at, row);
        }
        return Some(out);
    };
    let Some(propagator) = exact_propagator(model) else {
        let replay = |i: usize| motion.interval(i);
        let motion = SampledMotion::new(motion.time, motion.v, motion.normal, &replay);
        return integrated_force_derivatives(model, motion, samples, conditions);
    };
    out.given = propagator.exact_sensitivities();
    if out.given.len() != np {
        return None;
    }
    let mut replay = SensitivityReplay::new(model, gradients, Derivatives::of(law), np);
    let at = ReplayedSamples {
        v: motion.v,
        normal: motion.normal,
        conditions,
    };
    walk_rows(&mut replay, at, samples, &mut out, |i, replay| {
        let (z, sens) = (&mut replay.z, &mut replay.sens);
        propagator.propagate_with_sensitivities(motion.interval(i), z, sens);
        Some(())
    })?;
    for (j, given) in out.given.iter().enumerate() {
        if !given {
            (0..samples.len()).for_each(|k| out.gradient[k * np + j] = f64::NAN);
        }
    }
    Some(out)
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
    forces_in(model, v, normal, states, indices, &ConditionColumns::none())
}

/// [`forces_at`] with the law reading its conditions from `conditions` (bound to its
/// [`FrictionModel::conditions`]): `force_in` at each sample.
pub fn forces_in(
    model: &dyn FrictionModel,
    v: &[f64],
    normal: &NormalForce,
    states: &[f64],
    indices: impl Iterator<Item = usize>,
    conditions: &ConditionColumns<'_>,
) -> Vec<f64> {
    let ns = model.n_states();
    let mut at = vec![0.0; conditions.len()];
    indices
        .map(|i| {
            conditions.fill(i, &mut at);
            model.force_in(v[i], &states[i * ns..(i + 1) * ns], normal.at(i), &at)
        })
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

/// A displacement to replay along: one finite value per sample of `time`.
pub(crate) fn check_displacement(time: &[f64], x: &[f64]) -> Result<(), EngineError> {
    if time.len() != x.len() {
        return Err(EngineError::InvalidInput(format!(
            "{} time stamps but {} displacements",
            time.len(),
            x.len()
        )));
    }
    match x.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(EngineError::InvalidInput(format!(
            "displacement sample {i} is not finite ({})",
            x[i]
        ))),
        None => Ok(()),
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::energy::numerical_replay::checks::{assert_states_agree, laws_with_states};
    use std::f64::consts::PI;

    /// A 3 s stroke at 1 kHz: its displacement, and a velocity channel whose noise (a
    /// deterministic jitter of 4 mm/s, a fifth of the peak speed) flips its sign near each
    /// reversal, under a normal force swinging around 14.5 N.
    fn noisy_stroke() -> (Vec<f64>, Vec<f64>, Vec<f64>, NormalForce) {
        let time: Vec<f64> = (0..3000).map(|i| i as f64 * 1e-3).collect();
        let w = 2.0 * PI * 1.5;
        let x = time.iter().map(|&t| 2e-3 * (w * t).sin()).collect();
        let v = time
            .iter()
            .enumerate()
            .map(|(i, &t)| 2e-3 * w * (w * t).cos() + 4e-3 * (i as f64 * 2.399_963).sin())
            .collect();
        let normal = time
            .iter()
            .map(|&t| 14.5 + 2.0 * (2.0 * PI * 0.3 * t).sin())
            .collect();
        (time, x, v, NormalForce::Sampled(normal))
    }

    /// Along the displacement each interval travels the displacement's increment in its
    /// direction at the velocity's speed; an interval whose velocity is zero moves at the
    /// displacement's rate, one without travel stops.
    #[test]
    fn path_intervals_travel_the_displacement_at_the_velocitys_speed() {
        let time = [0.0, 1e-3, 2e-3, 3e-3, 4e-3];
        let v = [0.02, -0.01, 0.01, 0.0, 0.0];
        let x = [0.0, 1e-5, 1.2e-5, 0.7e-5, 0.7e-5];
        let normal = NormalForce::Constant(2.0);
        let at = |i| path_interval(&time, &v, &x, &normal, i);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
        // (v, travel, dt) of each interval.
        let expected = [
            (0.005, 1e-5, 2e-3),
            (2e-3, 2e-6, 1e-3),
            (-0.005, 5e-6, 1e-3),
            (0.0, 0.0, 1e-3),
        ];
        for (i, (v, travel, dt)) in (1..).zip(expected) {
            let interval = at(i);
            assert!(
                close(interval.v, v) && close(interval.travel(), travel) && close(interval.dt, dt),
                "interval {i}: {interval:?}"
            );
            assert_eq!(interval.normal, 2.0);
        }
    }

    /// Every law's numerical replay along the displacement gives its exact steps' states:
    /// the interval is the same for both.
    #[test]
    fn exact_and_numerical_replays_agree_along_the_displacement() {
        let (time, x, v, normal) = noisy_stroke();
        let motion = CheckedMotion {
            time: &time,
            v: &v,
            normal: &normal,
            displacement: None,
            intervals: None,
        }
        .along(&x)
        .expect("a valid displacement");
        for model in laws_with_states() {
            let law = model.states().expect("a law with states");
            let exact = states_along_checked(model.as_ref(), motion).expect("exact steps");
            let numerical =
                numerical_replay(law, &time, |i| motion.interval(i)).expect("a numerical replay");
            let allowance = 1e-12 * time.len() as f64;
            assert_states_agree(model.as_ref(), &exact, &numerical, allowance);
        }
    }
}
