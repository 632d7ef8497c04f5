//! The seam between the simulation driver and the time integrators.
//!
//! A [`Stepper`] advances an [`OdeSystem`] one step at a time and keeps the dense output of its
//! last accepted step; it knows nothing of segments, modes, events, sticking or sample grids.
//! The driver (`super::driver`) owns those: it resets the stepper at the start of each segment,
//! asks for steps until the event function changes sign at an accepted step's end or the end
//! time is reached, locates the event on the dense output and writes the samples. This is the split of
//! diffsol's `OdeSolverMethod` (a method implements `step`, `interpolate` and statistics; the
//! solve loop and root finding live apart), written for small dense systems.

use crate::error::IntegrationFailure;

/// A first-order system y' = f(t, y).
pub trait OdeSystem {
    /// Writes f(t, y) into `dy` (same length as `y`).
    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]);

    /// Writes the Jacobian df/dy at (t, y), row-major, into `jac` (len(y)^2 entries). The
    /// default takes forward differences of [`rhs`](OdeSystem::rhs) (allocating); systems
    /// with a closed form supply it (the stiff stepper calls this once per step).
    fn jacobian(&self, t: f64, y: &[f64], jac: &mut [f64]) {
        let n = y.len();
        let mut f0 = vec![0.0; n];
        let mut f1 = vec![0.0; n];
        let mut probe = y.to_vec();
        self.rhs(t, y, &mut f0);
        for j in 0..n {
            let step = f64::EPSILON.sqrt() * y[j].abs().max(1e-8);
            probe[j] = y[j] + step;
            self.rhs(t, &probe, &mut f1);
            probe[j] = y[j];
            for i in 0..n {
                if let Some(entry) = jac.get_mut(i * n + j) {
                    *entry = (f1[i] - f0[i]) / step;
                }
            }
        }
    }

    /// Writes df/dt at (t, y), the explicit dependence of f on time at fixed y, into `dfdt`
    /// (same length as `y`) and returns true; returns false, leaving `dfdt` as it is, when
    /// f does not depend on t (an autonomous system: the default). A Rosenbrock stepper
    /// (Rodas4) needs it in its stages, since its linearisation about the step's start
    /// would otherwise hold the time fixed there. It describes the system over a step
    /// starting at `t` and moving forward: where f's time dependence has a kink (a knot of a
    /// measured input), the rate of the stretch after `t`.
    fn time_derivative(&self, _t: f64, _y: &[f64], _dfdt: &mut [f64]) -> bool {
        false
    }

    /// When y = [x, v] obeys a linear oscillator equation (see [`AffineMotion`]): its
    /// coefficients, for closed-form propagation. `None` (the default) otherwise.
    fn affine_motion(&self) -> Option<AffineMotion> {
        None
    }
}

/// A segment of motion m x'' + damping x' + stiffness x + offset = 0 with y = [x, v] (a friction
/// law affine in v within a sliding mode, F = offset + b v, adds b to the damping).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AffineMotion {
    /// Mass [kg].
    pub mass: f64,
    /// Total viscous coefficient [N s/m].
    pub damping: f64,
    /// Stiffness [N/m].
    pub stiffness: f64,
    /// Constant force [N].
    pub offset: f64,
}

/// The error tolerances of an adaptive stepper: component i is resolved to
/// atol_i + rtol |y_i|.
#[derive(Debug, Clone, PartialEq)]
pub struct Tolerance {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance of each component.
    pub atol: Vec<f64>,
}

impl Tolerance {
    /// The same absolute tolerance `atol` for all `dim` components.
    pub fn uniform(dim: usize, rtol: f64, atol: f64) -> Self {
        Self {
            rtol,
            atol: vec![atol; dim],
        }
    }

    /// Multiplies each component's absolute tolerance by its entry of `scales` (components
    /// beyond `scales` keep theirs).
    pub fn scale_atol(&mut self, scales: &[f64]) {
        for (a, s) in self.atol.iter_mut().zip(scales) {
            *a *= s;
        }
    }

    /// The error scale of component `i` when it moves from `a` to `b` in a step.
    pub fn scale(&self, i: usize, a: f64, b: f64) -> f64 {
        self.atol[i] + a.abs().max(b.abs()) * self.rtol
    }

    /// Leaves every component from `controlled` on out of the error control (the norms run
    /// over the first `controlled` components only): forward sensitivities integrated beside
    /// the states they differentiate follow the states' steps.
    pub fn control_first(&mut self, controlled: usize) {
        self.atol.truncate(controlled);
    }

    /// The RMS over the controlled components of error / scale (Hairer's norm), for a step
    /// from `y` to `y_new` with local error estimate `err`.
    /// Inlined: a caller whose slices have a size known when compiling gets the unrolled sum.
    #[inline(always)]
    pub fn rms_norm(&self, y: &[f64], y_new: &[f64], err: &[f64]) -> f64 {
        let mut sum = 0.0;
        let controlled = y.len().min(self.atol.len());
        let atol = &self.atol[..controlled];
        for (((&a, &b), &e), &atol) in y.iter().zip(y_new).zip(err).zip(atol) {
            let sc = atol + a.abs().max(b.abs()) * self.rtol;
            sum += (e / sc) * (e / sc);
        }
        (sum / controlled.max(1) as f64).sqrt()
    }

    /// The first guess of a starting step from the state `y` and its slope `f`:
    /// 0.01 ||y|| / ||f|| in the error norm (1e-6 when either is negligible), and the two
    /// squared norms it was made from (Hairer, Norsett & Wanner, Sec. II.4).
    pub fn first_step_guess(&self, y: &[f64], f: &[f64]) -> (f64, f64, f64) {
        let (mut d0, mut d1) = (0.0, 0.0);
        for (i, (&yi, &fi)) in y.iter().zip(f).enumerate().take(self.atol.len()) {
            let sc = self.scale(i, yi, yi);
            d0 += (yi / sc) * (yi / sc);
            d1 += (fi / sc) * (fi / sc);
        }
        let h0 = if d0 < 1e-10 || d1 < 1e-10 {
            1e-6
        } else {
            0.01 * (d0 / d1).sqrt()
        };
        (h0, d0, d1)
    }
}

/// The outcome of one attempted step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepOutcome {
    /// The step was rejected by the error control; the stepper retries with a smaller step.
    Rejected,
    /// The step was accepted: `time` and `state` are its end, `interpolate` covers it.
    Accepted,
}

/// What the fallible [`Stepper`] operations return.
pub(super) type StepResult<T> = Result<T, IntegrationFailure>;

/// Fails when a step of size `h` at time `t` is lost in round-off (or is NaN).
pub(crate) fn ensure_resolvable(t: f64, h: f64) -> StepResult<()> {
    if 0.1 * h.abs() > f64::EPSILON * t.abs() && !h.is_nan() {
        Ok(())
    } else {
        Err(IntegrationFailure::StepSizeTooSmall { time: t, step: h })
    }
}

/// The rest of the way from `t` to `t_end` when a step `h` would end past it or within 1 % of
/// a step short of it (the last step of a segment), else `None`.
pub(crate) fn last_step(t: f64, h: f64, t_end: f64) -> Option<f64> {
    (t + 1.01 * h - t_end > 0.0).then_some(t_end - t)
}

/// Implements the [`Stepper`] accessors `time`, `previous_time`, `end_time`, `state` and
/// `counts` for a stepper that keeps its current time in `t`, the previous one in `t_prev`, the
/// end time in `t_end` (fields of the stepper, or of its field `$clock`, a [`StepControl`]),
/// the state in `y` and its work counters in `counts`; with a clock, `reached_end` too.
/// Where an interval starts: the time, the state there and the end time.
pub type IntervalStart<'a> = (f64, &'a [f64], f64);

macro_rules! current_point_accessors {
    ($($clock:ident)?) => {
        fn time(&self) -> f64 {
            self.$($clock.)?t
        }

        fn end_time(&self) -> f64 {
            self.$($clock.)?t_end
        }

        fn previous_time(&self) -> f64 {
            self.$($clock.)?t_prev
        }

        fn state(&self) -> &[f64] {
            &self.y
        }

        fn counts(&self) -> StepCounts {
            self.counts
        }

        $(
            fn reached_end(&self) -> bool {
                self.$clock.reached
            }

            fn has_step(&self) -> bool {
                self.$clock.has_step()
            }
        )?
    };
}
pub(crate) use current_point_accessors;

/// The step-size control of an adaptive one-step method: its tolerance and largest step, and
/// where it stands (the ends of its last accepted step, the end of the interval, the size of
/// its next attempt and the flags of its last attempts).
#[derive(Debug, Clone)]
pub(crate) struct StepControl {
    /// The error tolerance.
    pub tol: Tolerance,
    /// The largest step.
    pub h_max: f64,
    /// Current time: the end of the last accepted step.
    pub t: f64,
    /// The start of the last accepted step.
    pub t_prev: f64,
    /// The end of the interval.
    pub t_end: f64,
    /// The size of the next attempt.
    pub h: f64,
    /// The size of the last accepted step.
    pub h_last: f64,
    /// The current attempt ends the interval.
    pub last: bool,
    /// The last accepted step reached the end of the interval.
    pub reached: bool,
    /// The attempt before was rejected.
    pub after_reject: bool,
}

impl StepControl {
    /// A control for `dim` components with tolerances `rtol`, `atol` and largest step
    /// |`h_max`|.
    pub(super) fn new(dim: usize, rtol: f64, atol: f64, h_max: f64) -> Self {
        Self {
            tol: Tolerance::uniform(dim, rtol, atol),
            h_max: h_max.abs(),
            t: 0.0,
            t_prev: 0.0,
            t_end: 0.0,
            h: 0.0,
            h_last: 0.0,
            last: false,
            reached: false,
            after_reject: false,
        }
    }

    /// Whether a step size was learnt (a restart keeps it; none yet before the first reset).
    pub(super) fn has_step(&self) -> bool {
        self.h > 0.0
    }

    /// Starts over at `t` in an interval ending at `t_end` (step sizes kept).
    pub(super) fn restart(&mut self, t: f64, t_end: f64) {
        (self.t, self.t_prev, self.t_end) = (t, t, t_end);
        (self.after_reject, self.last, self.reached) = (false, false, false);
    }

    /// Moves the end of the interval on to `t_end`; the next step starts where the last ended.
    pub(super) fn extend_to(&mut self, t_end: f64) {
        self.t_end = t_end;
        self.last = false;
        self.reached = false;
    }

    /// The size of the next attempt: an error when it is too small to resolve at the current
    /// time; shortened to the rest of the interval (and marked last) near its end.
    pub(super) fn next_attempt(&mut self) -> StepResult<f64> {
        ensure_resolvable(self.t, self.h)?;
        if let Some(rest) = last_step(self.t, self.h, self.t_end) {
            self.h = rest;
            self.last = true;
        }
        Ok(self.h)
    }

    /// Moves past an accepted step of size `h`.
    pub(super) fn advance(&mut self, h: f64) {
        self.t_prev = self.t;
        self.t += h;
        self.h_last = h;
        self.reached = self.last;
    }

    /// The theta in [0, 1] of `t` within the last accepted step (1 before any step).
    pub(super) fn fraction_of_last_step(&self, t: f64) -> f64 {
        if self.h_last > 0.0 {
            (t.clamp(self.t_prev, self.t) - self.t_prev) / self.h_last
        } else {
            1.0
        }
    }
}

/// Work counters of a stepper, summed since it was built.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StepCounts {
    /// Right-hand-side evaluations.
    pub rhs_evaluations: u64,
    /// Accepted steps.
    pub accepted: u64,
    /// Rejected steps.
    pub rejected: u64,
    /// Jacobian evaluations (stiff steppers; not included in `rhs_evaluations`).
    pub jacobian_evaluations: u64,
}

impl StepCounts {
    /// Accepted plus rejected steps (what the step budget counts).
    pub fn attempts(&self) -> u64 {
        self.accepted + self.rejected
    }
}

/// A one-step time integrator with dense output.
///
/// Contract: after [`reset`](Stepper::reset) at (t, y) with an end time, each call of
/// [`step`](Stepper::step) attempts one step that never passes the end time; after an accepted
/// step [`time`](Stepper::time) and [`state`](Stepper::state) are the new point and
/// [`interpolate`](Stepper::interpolate) evaluates the dense output anywhere in
/// [`previous_time`](Stepper::previous_time) ..= `time`. Counters survive resets.
pub trait Stepper {
    /// Restarts at state `y` at time `t`, integrating towards `t_end` (> t). Errors: the
    /// stepper cannot integrate this system (e.g. the closed form needs an affine motion).
    fn reset<S: OdeSystem>(&mut self, system: &S, t: f64, y: &[f64], t_end: f64) -> StepResult<()>;

    /// Restarts at state `y` at time `t` towards `t_end`, keeping what the stepper learnt of
    /// the step size: for a sequence of intervals whose right-hand side jumps between them
    /// but keeps its scale (the sample intervals of a replayed motion). A reset while the
    /// stepper has no step size to keep.
    fn restart<S: OdeSystem>(
        &mut self,
        system: &S,
        t: f64,
        y: &[f64],
        t_end: f64,
    ) -> StepResult<()> {
        match self.has_step() {
            true => self.keep_step(system, (t, y, t_end)),
            false => self.reset(system, t, y, t_end),
        }
    }

    /// Whether the stepper has a step size from its last run that a restart can keep. By
    /// default none: a restart is a reset.
    fn has_step(&self) -> bool {
        false
    }

    /// Starts at (t, y) towards t_end with the step size of the last run; [`restart`]
    /// (Stepper::restart) calls it only where [`has_step`](Stepper::has_step). By default a
    /// reset.
    fn keep_step<S: OdeSystem>(&mut self, system: &S, at: IntervalStart) -> StepResult<()> {
        let (t, y, t_end) = at;
        self.reset(system, t, y, t_end)
    }

    /// Moves the end time on to `t_end` (after the current time) without starting afresh:
    /// the state and the step size carry over. Valid where the right-hand side is continuous
    /// at the current time (a knot of an input taken linear between its samples, where only
    /// its slope jumps).
    fn continue_to(&mut self, t_end: f64);

    /// Attempts one step. Errors: the step size became too small.
    fn step<S: OdeSystem>(&mut self, system: &S) -> StepResult<StepOutcome>;

    /// The time of the current state.
    fn time(&self) -> f64;

    /// The time at the start of the last accepted step (the reset time before any step).
    fn previous_time(&self) -> f64;

    /// The current state.
    fn state(&self) -> &[f64];

    /// The end time given to `reset`.
    fn end_time(&self) -> f64;

    /// Whether the current time is the end time given to `reset`. Steppers whose last step
    /// may land a rounding error short of it keep a flag instead.
    fn reached_end(&self) -> bool {
        self.time() >= self.end_time()
    }

    /// The dense output of the last accepted step at time `t` (clamped to the step) into `out`.
    fn interpolate(&self, t: f64, out: &mut [f64]);

    /// The dense output's displacement and velocity at each of `times` (ascending, within the
    /// last step) into `x` and `v` (as long as `times`), for a state without internal
    /// components; `buf` is scratch of the state's length. The default interpolates time by
    /// time; steppers with a cheaper sweep over a grid override it.
    fn interpolate_motion(&self, times: &[f64], x: &mut [f64], v: &mut [f64], buf: &mut [f64]) {
        for ((&t, xo), vo) in times.iter().zip(x).zip(v) {
            self.interpolate(t, buf);
            if let [xi, vi, ..] = *buf {
                (*xo, *vo) = (xi, vi);
            }
        }
    }

    /// Work counters since the stepper was built.
    fn counts(&self) -> StepCounts;
}

#[cfg(test)]
mod tests {
    use super::super::{Dopri5, Euler};
    use super::*;

    /// y' = -lambda y.
    struct Decay(f64);

    impl OdeSystem for Decay {
        fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
            for (d, &v) in dy.iter_mut().zip(y) {
                *d = -self.0 * v;
            }
        }
    }

    /// x' = v, v' = -x: x = cos t, v = -sin t from (1, 0).
    struct Harmonic;

    impl OdeSystem for Harmonic {
        fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
            dy[0] = y[1];
            dy[1] = -y[0];
        }
    }

    /// Steps to the end time, checking the dense output against `exact` inside every step.
    fn run_to_end<S: Stepper>(
        stepper: &mut S,
        system: &impl OdeSystem,
        exact: impl Fn(f64) -> f64,
        dense_tol: f64,
    ) -> f64 {
        let mut out = [0.0];
        let mut worst: f64 = 0.0;
        while !stepper.reached_end() {
            if let Ok(StepOutcome::Accepted) = stepper.step(system) {
                let mid = 0.5 * (stepper.previous_time() + stepper.time());
                stepper.interpolate(mid, &mut out);
                worst = worst.max((out[0] - exact(mid)).abs());
            }
        }
        assert!(worst < dense_tol, "dense output error {worst}");
        stepper.state()[0]
    }

    #[test]
    fn dopri5_integrates_exponential_decay_and_its_dense_output() {
        let mut s = Dopri5::new(1, 1e-10, 1e-12, 1.0);
        assert!(s.reset(&Decay(2.0), 0.0, &[1.0], 1.5).is_ok());
        let end = run_to_end(&mut s, &Decay(2.0), |t| (-2.0 * t).exp(), 1e-9);
        assert_eq!(s.time(), 1.5);
        assert!((end - (-3.0f64).exp()).abs() < 1e-10, "{end}");
        let c = s.counts();
        // Two RHS for the starting step, six per attempt (first same as last).
        assert_eq!(c.rhs_evaluations, 2 + 6 * c.attempts());
    }

    #[test]
    fn dopri5_reports_the_step_where_the_velocity_changes_sign() {
        let mut s = Dopri5::new(2, 1e-9, 1e-12, 0.5);
        assert!(s.reset(&Harmonic, 0.0, &[1.0, 0.0], 10.0).is_ok());
        // v = -sin t < 0 on (0, pi): the event function -v is positive until pi.
        loop {
            match s.step(&Harmonic) {
                Ok(StepOutcome::Accepted) if -s.state()[1] <= 0.0 => break,
                Ok(_) => assert!(s.time() < std::f64::consts::PI),
                Err(e) => panic!("{e}"),
            }
        }
        let pi = std::f64::consts::PI;
        assert!(s.previous_time() < pi && pi <= s.time());
        let mut y = [0.0; 2];
        s.interpolate(pi, &mut y);
        assert!((y[0] + 1.0).abs() < 1e-8 && y[1].abs() < 1e-8, "{y:?}");
    }

    #[test]
    fn scaled_absolute_tolerances_weigh_each_component_by_its_own() {
        let mut tol = Tolerance::uniform(3, 0.0, 1e-9);
        tol.scale_atol(&[1.0, 1.0, 1e7]);
        assert_eq!(tol.atol, vec![1e-9, 1e-9, 1e-2]);
        // An error of 1e-2 in the scaled component weighs as 1e-9 in the others.
        let (y, err) = ([0.0; 3], [1e-9, 0.0, 1e-2]);
        let norm = tol.rms_norm(&y, &y, &err);
        assert!((norm - (2.0f64 / 3.0).sqrt()).abs() < 1e-12, "{norm}");
        assert_eq!(tol.scale(2, 0.0, 0.0), 1e-2);
    }

    #[test]
    fn euler_takes_fixed_steps_and_interpolates_linearly() {
        let mut s = Euler::new(1, 0.1);
        assert!(s.reset(&Decay(1.0), 0.0, &[1.0], 1.0).is_ok());
        let mut steps = 0;
        while !s.reached_end() {
            assert!(s.step(&Decay(1.0)).is_ok());
            steps += 1;
        }
        assert_eq!(steps, 10);
        assert!((s.state()[0] - 0.9f64.powi(10)).abs() < 1e-14);
        let mut y = [0.0];
        s.interpolate(0.95, &mut y);
        let expected = 0.5 * (0.9f64.powi(9) + 0.9f64.powi(10));
        assert!((y[0] - expected).abs() < 1e-14, "{}", y[0]);
        assert_eq!(s.counts().rhs_evaluations, 10);
    }
}
