//! The numerical replay of a law's states along a measured motion, for a law without an exact
//! step: each sample interval (constant velocity and normal force, the convention of the
//! `model_force` module) integrated on its own, by Dopri5 where it is not stiff and by Rodas4
//! where it is (or where Dopri5 needs too many steps), within a work budget pooled over the
//! record that grows with its samples and with the relaxations of the states along its
//! travel.

use crate::error::IntegrationFailure;
use crate::simulate::{Dopri5, OdeSystem, Rodas4, StepOutcome, Stepper};
use frictionid_models::{Derivatives, InternalStates, Interval};

const RTOL: f64 = 1e-8;
const ATOL: f64 = 1e-12;

/// Steps every sample interval adds to the record's budget, whatever the law: the budget
/// is pooled over the record, so that the transient after a reversal (a few hundred steps to
/// resolve at the replay's tolerance) draws on the quiet intervals around it.
pub const STEPS_PER_INTERVAL: u64 = 20;

/// The relaxations of the states over an interval (its travel times the law's rate of
/// relaxation per unit of travel) that add one step each to the budget, at most this many per
/// interval: past these the states have settled and a stiff-stable step covers the rest at
/// once.
pub const SETTLED_RELAXATIONS: f64 = 50.0;

/// An interval of more relaxations than this is integrated by Rodas4 (Dopri5 would be held
/// at its stability limit, about 3.3 relaxations per step).
const STIFF_RELAXATIONS: f64 = 3.0;

/// The steps Dopri5 may take in one interval before the interval is integrated by Rodas4
/// instead (the states stiffened within it: an element that started loading).
const EXPLICIT_CAP: f64 = 400.0;

/// The states at every sample time of `time` (`n_states` each), replayed from relaxed states
/// over the intervals `interval(i)` between samples i - 1 and i.
pub(crate) fn numerical_replay(
    law: &dyn InternalStates,
    time: &[f64],
    interval: impl Fn(usize) -> Interval,
) -> Result<Vec<f64>, IntegrationFailure> {
    let ns = law.n_states();
    let plan = ReplayPlan::new(law, time, interval);
    let mut replay = Replay::new(ns, ns, plan.budget);
    let derivatives = Derivatives::of(law);
    let mut z = vec![0.0; ns];
    let mut out = Vec::with_capacity(time.len() * ns);
    if !time.is_empty() {
        out.extend_from_slice(&z);
    }
    for (iv, &t0) in plan.intervals.iter().zip(time) {
        let system = ConstantMotion {
            derivatives,
            law,
            v: iv.v,
            normal: iv.normal,
        };
        replay.interval(&system, (t0, iv.dt), plan.relaxations(iv), &mut z)?;
        out.extend_from_slice(&z);
    }
    Ok(out)
}

/// The intervals of a replay, the relaxations of the law's states in each and the work the
/// record allows: [`STEPS_PER_INTERVAL`] steps per interval plus one per relaxation (up to
/// [`SETTLED_RELAXATIONS`]).
pub(crate) struct ReplayPlan {
    /// The intervals between samples i - 1 and i.
    pub intervals: Vec<Interval>,
    /// The law's relaxations per unit of travel ([`relaxation_rate`]).
    per_travel: f64,
    /// Steps the whole replay may take (accepted and rejected, both steppers).
    pub budget: f64,
}

impl ReplayPlan {
    /// The plan of `law`'s replay over the intervals `interval(i)` of the samples `time`.
    pub(crate) fn new(
        law: &dyn InternalStates,
        time: &[f64],
        interval: impl Fn(usize) -> Interval,
    ) -> Self {
        let intervals: Vec<Interval> = (1..time.len()).map(interval).collect();
        let mut plan = Self {
            per_travel: relaxation_rate(law, &intervals),
            intervals,
            budget: 0.0,
        };
        plan.budget = plan
            .intervals
            .iter()
            .map(|iv| STEPS_PER_INTERVAL as f64 + plan.relaxations(iv).min(SETTLED_RELAXATIONS))
            .sum();
        plan
    }

    /// The relaxations of the states over `iv` (infinite where they cannot be told).
    pub(crate) fn relaxations(&self, iv: &Interval) -> f64 {
        let r = self.per_travel * iv.travel();
        if r.is_nan() {
            f64::INFINITY
        } else {
            r
        }
    }
}

/// How many times the law's states relax per unit of travel: the largest absolute row sum of
/// its state Jacobian (a bound on the rates of its eigenvalues) over the speed, at the root
/// mean square speed and the mean normal force of `intervals`, at the law's sliding states
/// there (where a law whose states stiffen as they load is stiffest) or at relaxed states.
/// Friction states relax with the distance travelled (a bristle within its presliding
/// displacement), so this one rate counts the relaxations of every interval.
fn relaxation_rate(law: &dyn InternalStates, intervals: &[Interval]) -> f64 {
    let n = intervals.len().max(1) as f64;
    let speed = (intervals.iter().map(|iv| iv.v * iv.v).sum::<f64>() / n).sqrt();
    let normal = intervals.iter().map(|iv| iv.normal).sum::<f64>() / n;
    if speed == 0.0 {
        return 0.0;
    }
    let ns = law.n_states();
    let mut z = vec![0.0; ns];
    if !law.sliding_states(speed, normal, &mut z) {
        z.iter_mut().for_each(|x| *x = 0.0);
    }
    let mut jac = vec![0.0; ns * ns];
    Derivatives::of(law).state_jacobian(speed, &z, normal, &mut jac);
    let rate = jac
        .chunks(ns.max(1))
        .map(|row| row.iter().map(|j| j.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    rate / speed
}

/// The states' equation over one interval: z' = h(v, z, N) at constant v and N.
struct ConstantMotion<'a> {
    derivatives: Derivatives<'a>,
    law: &'a dyn InternalStates,
    v: f64,
    normal: f64,
}

impl OdeSystem for ConstantMotion<'_> {
    fn rhs(&self, _t: f64, z: &[f64], dz: &mut [f64]) {
        self.law.state_derivative(self.v, z, self.normal, dz);
    }

    fn jacobian(&self, _t: f64, z: &[f64], jac: &mut [f64]) {
        self.derivatives.state_jacobian(self.v, z, self.normal, jac);
    }
}

/// The replay's steppers and the work it may still do.
pub(crate) struct Replay {
    dopri: Dopri5,
    rodas: Rodas4,
    /// Steps the budget still allows (accepted and rejected, both steppers).
    left: f64,
    /// The whole budget.
    budget: f64,
}

impl Replay {
    /// Steppers for `dim` equations, within `budget` steps: the `states` first under error
    /// control, and after them (when `dim` is larger) their sensitivities, one block of
    /// `states` per parameter, which follow the states' steps (Rodas4 solving their block
    /// lower triangular systems block by block, [`Rodas4::block_triangular`]).
    pub(crate) fn new(dim: usize, states: usize, budget: f64) -> Self {
        let rodas = Rodas4::new(dim, RTOL, ATOL, f64::INFINITY).controlling_first(states);
        Self {
            dopri: Dopri5::new(dim, RTOL, ATOL, f64::INFINITY).controlling_first(states),
            rodas: if dim > states {
                rodas.block_triangular(states)
            } else {
                rodas
            },
            left: budget,
            budget,
        }
    }

    /// Integrates `y` by `system` over the interval of duration `dt` starting at `t0`, which
    /// holds `relaxations` of the states: by Dopri5 unless that makes it stiff or Dopri5 needs
    /// more than [`EXPLICIT_CAP`] steps, else by Rodas4.
    pub(crate) fn interval<S: OdeSystem>(
        &mut self,
        system: &S,
        (t0, dt): (f64, f64),
        relaxations: f64,
        y: &mut [f64],
    ) -> Result<(), IntegrationFailure> {
        let span = (t0, t0 + dt);
        if relaxations <= STIFF_RELAXATIONS {
            match run(
                &mut self.dopri,
                system,
                span,
                y,
                self.left.min(EXPLICIT_CAP),
            ) {
                Ok(steps) => {
                    self.left -= steps;
                    y.copy_from_slice(self.dopri.state());
                    return Ok(());
                }
                Err(RunFailure::OverAllowance(steps)) => self.left -= steps,
                Err(RunFailure::Failed(failure)) => return Err(failure),
            }
        }
        match run(&mut self.rodas, system, span, y, self.left) {
            Ok(steps) => {
                self.left -= steps;
                y.copy_from_slice(self.rodas.state());
                Ok(())
            }
            Err(RunFailure::OverAllowance(_)) => Err(IntegrationFailure::StepBudgetExceeded {
                time: self.rodas.time(),
                max_steps: self.budget.ceil() as u64,
            }),
            Err(RunFailure::Failed(failure)) => Err(failure),
        }
    }
}

/// Why an interval's run stopped short.
enum RunFailure {
    /// It needed more than its limit of steps (this many were taken).
    OverAllowance(f64),
    /// The stepper failed.
    Failed(IntegrationFailure),
}

/// Runs `stepper` from `z` over `(t0, t1)` within `limit` steps (accepted and rejected),
/// refusing non-finite states; the steps taken.
fn run<T: Stepper, S: OdeSystem>(
    stepper: &mut T,
    system: &S,
    (t0, t1): (f64, f64),
    z: &[f64],
    limit: f64,
) -> Result<f64, RunFailure> {
    stepper
        .restart(system, t0, z, t1)
        .map_err(RunFailure::Failed)?;
    let start = stepper.counts().attempts();
    while !stepper.reached_end() {
        let steps = (stepper.counts().attempts() - start) as f64;
        if steps >= limit {
            return Err(RunFailure::OverAllowance(steps));
        }
        let outcome = stepper.step(system).map_err(RunFailure::Failed)?;
        let state = stepper.state();
        if outcome != StepOutcome::Rejected && state.iter().any(|x| !x.is_finite()) {
            return Err(RunFailure::Failed(IntegrationFailure::NonFiniteState {
                time: stepper.time(),
                state: state.to_vec(),
            }));
        }
    }
    Ok((stepper.counts().attempts() - start) as f64)
}

/// What the replays' tests share: the laws with states they run, and the comparison of two
/// replays' states.
#[cfg(test)]
pub(crate) mod checks {
    use frictionid_models::{Dahl, FrictionModel, Gms, LuGre};

    /// Dahl, LuGre and GMS at their defaults.
    pub(crate) fn laws_with_states() -> [Box<dyn FrictionModel>; 3] {
        [
            Box::new(Dahl::default()),
            Box::new(LuGre::default()),
            Box::new(Gms::default()),
        ]
    }

    /// Each of `model`'s states in `numerical` (interleaved, one row per sample) is within
    /// `1e-6` of the state's largest value in `exact`, plus `allowance`.
    pub(crate) fn assert_states_agree(
        model: &dyn FrictionModel,
        exact: &[f64],
        numerical: &[f64],
        allowance: f64,
    ) {
        let ns = model.states().map_or(0, |law| law.n_states());
        for j in 0..ns {
            let scale = exact
                .iter()
                .skip(j)
                .step_by(ns)
                .fold(0.0f64, |a, z| a.max(z.abs()));
            let worst = exact
                .iter()
                .zip(numerical)
                .skip(j)
                .step_by(ns)
                .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
            assert!(
                worst <= 1e-6 * scale + allowance,
                "{} state {j}: {worst:e} of {scale:e}",
                model.name()
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::checks::{assert_states_agree, laws_with_states};
    use super::*;
    use crate::energy::model_force::{replay_interval, states_along, MeasuredMotion};
    use crate::record::NormalForce;
    use frictionid_models::{FrictionModel, Gms};
    use std::f64::consts::PI;

    /// A motion of `seconds` at 1 kHz: v(t) from `velocity`, N swinging around 14.5 N.
    fn motion(seconds: f64, velocity: impl Fn(f64) -> f64) -> (Vec<f64>, Vec<f64>, NormalForce) {
        let time: Vec<f64> = (0..=(seconds * 1000.0) as usize)
            .map(|i| i as f64 * 1e-3)
            .collect();
        let v = time.iter().map(|&t| velocity(t)).collect();
        let normal = time
            .iter()
            .map(|&t| 14.5 + 2.0 * (2.0 * PI * 0.3 * t).sin())
            .collect();
        (time, v, NormalForce::Sampled(normal))
    }

    /// The numerical replay follows the replay's convention: on a motion with reversals and
    /// slow and fast stretches it gives the exact steps' states of Dahl, LuGre and GMS to its
    /// tolerance: 1e-6 of each state's largest value (rtol 1e-8 per step), and at most the
    /// absolute tolerance per interval (1e-12 each, which dominates for GMS's deflections of
    /// micrometres).
    #[test]
    fn the_numerical_replay_follows_the_exact_steps() {
        let (time, v, normal) = motion(4.0, |t| {
            0.15 * (2.0 * PI * 1.1 * t).sin() * (2.0 * PI * 0.2 * t).cos() + 2e-3
        });
        for model in laws_with_states() {
            let law = model.states().expect("a law with states");
            let exact = states_along(
                model.as_ref(),
                MeasuredMotion {
                    time: &time,
                    v: &v,
                    normal: &normal,
                },
            )
            .expect("exact steps");
            let numerical =
                numerical_replay(law, &time, |i| replay_interval(&time, &v, &normal, i))
                    .expect("a numerical replay");
            let allowance = ATOL * (time.len() - 1) as f64;
            assert_states_agree(model.as_ref(), &exact, &numerical, allowance);
        }
    }

    /// A 40 s run at 2 mm/s (40 001 samples) of a law without exact steps (GMS at sharpness 3)
    /// ends within its budget, whose share per sample stays what a short record gets.
    #[test]
    fn a_long_slow_run_is_replayed_within_its_budget() {
        let (time, v, normal) = motion(40.0, |t| 2e-3 * (2.0 * PI * 0.05 * t).cos());
        let gms = Gms {
            sharpness: 3.0,
            ..Gms::default()
        };
        let law = gms.states().expect("states");
        let states = numerical_replay(law, &time, |i| replay_interval(&time, &v, &normal, i))
            .expect("the run's replay");
        assert_eq!(states.len(), 3 * time.len());
        assert!(states.iter().all(|z| z.is_finite()));
    }
}
