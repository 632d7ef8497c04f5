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

/// The relaxations of the states (lambda dt, lambda the largest rate of the state Jacobian at
/// an interval's start) that add one step each to the budget, at most this many per interval:
/// past these the states have settled and a stiff-stable step covers the rest at once.
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
    let mut z = vec![0.0; ns];
    let mut out = Vec::with_capacity(time.len() * ns);
    let intervals = time.len().saturating_sub(1) as f64;
    let mut replay = Replay::new(law, STEPS_PER_INTERVAL as f64 * intervals);
    for i in 0..time.len() {
        if i > 0 {
            replay.interval(time[i - 1], interval(i), &mut z)?;
        }
        out.extend_from_slice(&z);
    }
    Ok(out)
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
struct Replay<'a> {
    law: &'a dyn InternalStates,
    derivatives: Derivatives<'a>,
    dopri: Dopri5,
    rodas: Rodas4,
    /// Steps the budget still allows (accepted and rejected, both steppers).
    left: f64,
    /// The whole budget so far.
    allowed: f64,
    jac: Vec<f64>,
}

impl<'a> Replay<'a> {
    fn new(law: &'a dyn InternalStates, budget: f64) -> Self {
        let n = law.n_states();
        Self {
            law,
            derivatives: Derivatives::of(law),
            dopri: Dopri5::new(n, RTOL, ATOL, f64::INFINITY),
            rodas: Rodas4::new(n, RTOL, ATOL, f64::INFINITY),
            left: budget,
            allowed: budget,
            jac: vec![0.0; n * n],
        }
    }

    /// The relaxations lambda dt of `interval` from the states `z` at its start (lambda the
    /// largest absolute row sum of the state Jacobian, a bound on its eigenvalues).
    fn relaxations(&mut self, interval: Interval, z: &[f64]) -> f64 {
        let n = z.len();
        self.derivatives
            .state_jacobian(interval.v, z, interval.normal, &mut self.jac);
        let rate = (0..n)
            .map(|i| {
                self.jac[i * n..(i + 1) * n]
                    .iter()
                    .map(|j| j.abs())
                    .sum::<f64>()
            })
            .fold(0.0, f64::max);
        let relaxations = rate * interval.dt;
        if relaxations.is_nan() {
            f64::INFINITY
        } else {
            relaxations
        }
    }

    /// Integrates `z` over `interval`, which starts at time `t0`: by Dopri5 unless the
    /// interval is stiff or Dopri5 needs more than [`EXPLICIT_CAP`] steps, else by Rodas4.
    fn interval(
        &mut self,
        t0: f64,
        interval: Interval,
        z: &mut [f64],
    ) -> Result<(), IntegrationFailure> {
        let relaxations = self.relaxations(interval, z);
        let credit = relaxations.min(SETTLED_RELAXATIONS);
        self.left += credit;
        self.allowed += credit;
        let system = ConstantMotion {
            derivatives: self.derivatives,
            law: self.law,
            v: interval.v,
            normal: interval.normal,
        };
        let span = (t0, t0 + interval.dt);
        if relaxations <= STIFF_RELAXATIONS {
            match run(
                &mut self.dopri,
                &system,
                span,
                z,
                self.left.min(EXPLICIT_CAP),
            ) {
                Ok(steps) => {
                    self.left -= steps;
                    z.copy_from_slice(self.dopri.state());
                    return Ok(());
                }
                Err(RunFailure::OverAllowance(steps)) => self.left -= steps,
                Err(RunFailure::Failed(failure)) => return Err(failure),
            }
        }
        match run(&mut self.rodas, &system, span, z, self.left) {
            Ok(steps) => {
                self.left -= steps;
                z.copy_from_slice(self.rodas.state());
                Ok(())
            }
            Err(RunFailure::OverAllowance(_)) => Err(IntegrationFailure::StepBudgetExceeded {
                time: self.rodas.time(),
                max_steps: self.allowed.ceil() as u64,
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
fn run<S: Stepper>(
    stepper: &mut S,
    system: &ConstantMotion<'_>,
    (t0, t1): (f64, f64),
    z: &[f64],
    limit: f64,
) -> Result<f64, RunFailure> {
    stepper
        .reset(system, t0, z, t1)
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
