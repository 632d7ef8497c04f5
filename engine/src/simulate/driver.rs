//! The simulation driver: segments between turning points, the mode decision at each of them
//! (slip+, slip-, stick), event location on the stepper's dense output, sampling onto the
//! output grid, budgets and statistics. Any [`Stepper`] plugs in.

use super::block::{BlockBuffer, BLOCK};
use super::root::illinois;
use super::stepper::{AffineMotion, OdeSystem, StepOutcome, Stepper};
use super::{Dynamics, Event, EventKind, Law, Recorder, Rest, SimStats, Start};
use crate::error::{EngineError, IntegrationFailure};

/// Width of the final bracket of a turning point's time [s].
pub(crate) const EVENT_TOL: f64 = 1e-13;

/// The equation of motion within one segment: slip direction `dir` fixed.
struct Segment<'a> {
    dynamics: Dynamics<'a>,
    dir: f64,
}

impl OdeSystem for Segment<'_> {
    #[inline]
    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        self.dynamics.rhs(t, y, dy, self.dir);
    }

    fn jacobian(&self, t: f64, y: &[f64], jac: &mut [f64]) {
        self.dynamics.jacobian(t, y, self.dir, jac);
    }

    fn time_derivative(&self, t: f64, y: &[f64], dfdt: &mut [f64]) -> bool {
        self.dynamics.time_derivative(t, y, self.dir, dfdt)
    }

    fn affine_motion(&self) -> Option<AffineMotion> {
        self.dynamics.affine_motion(self.dir)
    }
}

/// How a segment ended.
enum SegmentEnd {
    /// The end time was reached while moving.
    Finished,
    /// The velocity reached zero at this time.
    Turn(f64),
}

/// Book-keeping of a run: sample cursor, events, rest and statistics.
pub(crate) struct Driver<'s, R: Recorder> {
    pub dynamics: Dynamics<'s>,
    pub samples: &'s [f64],
    pub next: usize,
    pub rec: &'s mut R,
    pub events: Vec<Event>,
    pub rest: Option<Rest>,
    pub stats: SimStats,
    pub max_events: usize,
    pub max_steps: u64,
    /// Displacement at the previous turning point (or the release from rest).
    pub last_turn: Option<f64>,
    /// Swing below which smooth and dynamic motions are declared at rest.
    pub rest_swing: f64,
    /// The columns of stateless samples on their way to the recorder.
    pub block: BlockBuffer,
}

impl<R: Recorder> Driver<'_, R> {
    /// Runs the whole simulation from `y0` at t = 0 to `t_end` with `stepper`.
    pub(super) fn run<S: Stepper>(
        &mut self,
        stepper: &mut S,
        y0: &[f64],
        t_end: f64,
    ) -> Result<(), EngineError> {
        let result = self.run_segments(stepper, y0, t_end);
        let counts = stepper.counts();
        self.stats.rhs_evaluations = counts.rhs_evaluations;
        self.stats.steps = counts.accepted;
        self.stats.rejected_steps = counts.rejected;
        self.stats.jacobian_evaluations = counts.jacobian_evaluations;
        result
    }

    fn run_segments<S: Stepper>(
        &mut self,
        stepper: &mut S,
        y0: &[f64],
        t_end: f64,
    ) -> Result<(), EngineError> {
        let mut t = 0.0;
        let mut y = y0.to_vec();
        // Below this remaining time a segment is not started (the step would underflow).
        let tiny = 1e-13 * (1.0 + t_end);
        loop {
            let Some((t_start, dir)) = self.decide(t, &y, t_end)? else {
                return Ok(());
            };
            t = t_start;
            if t_end - t <= tiny {
                self.fill_end(&y, dir);
                return Ok(());
            }
            let segment = Segment {
                dynamics: self.dynamics,
                dir,
            };
            stepper.reset(&segment, t, &y, self.dynamics.stop_after(t, t_end))?;
            match self.advance(stepper, &segment, &mut y, t_end)? {
                SegmentEnd::Finished => return Ok(()),
                SegmentEnd::Turn(t_e) => {
                    if let Some(v) = y.get_mut(1) {
                        *v = 0.0;
                    }
                    self.turning_point(t_e, y.first().copied().unwrap_or(0.0))?;
                    t = t_e;
                }
            }
        }
    }

    /// Steps through one segment, writing its samples; at a turning point leaves the state
    /// there in `y`.
    fn advance<S: Stepper>(
        &mut self,
        stepper: &mut S,
        segment: &Segment<'_>,
        y: &mut [f64],
        t_end: f64,
    ) -> Result<SegmentEnd, EngineError> {
        let dir = segment.dir;
        let event = |state: &[f64]| dir * state.get(1).copied().unwrap_or(0.0);
        loop {
            if stepper.counts().attempts() >= self.max_steps {
                return Err(IntegrationFailure::StepBudgetExceeded {
                    time: stepper.time(),
                    max_steps: self.max_steps,
                }
                .into());
            }
            if stepper.step(segment)? == StepOutcome::Rejected {
                continue;
            }
            if self.rec.halted() {
                return Err(IntegrationFailure::Halted {
                    time: stepper.previous_time(),
                }
                .into());
            }
            if stepper.state().iter().any(|v| !v.is_finite()) {
                return Err(IntegrationFailure::NonFiniteState {
                    time: stepper.time(),
                    state: stepper.state().to_vec(),
                }
                .into());
            }
            // The event function is positive inside the segment: <= 0 at the step's end means
            // it changed sign within the step (or ended on zero).
            if event(stepper.state()) <= 0.0 {
                let t_e = self.locate_turn(stepper, &event, y)?;
                self.write_samples(stepper, t_e, dir, y);
                stepper.interpolate(t_e, y);
                return Ok(SegmentEnd::Turn(t_e));
            }
            if stepper.reached_end() && stepper.end_time() < t_end {
                self.write_samples(stepper, stepper.time(), dir, y);
                stepper.continue_to(self.dynamics.stop_after(stepper.time(), t_end));
                continue;
            }
            if stepper.reached_end() {
                self.write_samples(stepper, t_end, dir, y);
                y.copy_from_slice(stepper.state());
                self.fill_end(y, dir);
                return Ok(SegmentEnd::Finished);
            }
            self.write_samples(stepper, stepper.time(), dir, y);
        }
    }

    /// The time of the zero of the event function inside the last step.
    fn locate_turn<S: Stepper>(
        &self,
        stepper: &S,
        event: &impl Fn(&[f64]) -> f64,
        buf: &mut [f64],
    ) -> Result<f64, EngineError> {
        let lo = stepper.previous_time();
        let g = |t: f64| {
            stepper.interpolate(t, buf);
            Some(event(buf))
        };
        locate(g, lo, stepper.time())
            .ok_or_else(|| IntegrationFailure::EventNotLocated { time: lo }.into())
    }

    /// Writes the samples with time <= `until` from the dense output of the last step.
    fn write_samples<S: Stepper>(&mut self, stepper: &S, until: f64, dir: f64, buf: &mut [f64]) {
        if buf.len() == 2 {
            return self.write_stateless_samples(stepper, until, dir, buf);
        }
        let samples = self.samples;
        while let Some(&ts) = samples.get(self.next) {
            if ts > until {
                break;
            }
            stepper.interpolate(ts, buf);
            self.write_moving(ts, buf, dir);
        }
    }

    /// [`Driver::write_samples`] for a law without internal states: in blocks.
    fn write_stateless_samples<S: Stepper>(
        &mut self,
        stepper: &S,
        until: f64,
        dir: f64,
        scratch: &mut [f64],
    ) {
        let pending = self.samples.get(self.next..).unwrap_or_default();
        // A linear scan: an ODE step holds a few samples, a binary search over the rest of
        // the record cost more than the step's dense output.
        let due = &pending[..pending.iter().take_while(|&&t| t <= until).count()];
        let motion = self.rec.wants_forces().then_some((&self.dynamics, dir));
        for times in due.chunks(BLOCK) {
            self.block.moving(stepper, times, scratch, motion);
            self.rec.sample_block(&self.block.view(times));
        }
        self.next += due.len();
    }

    /// Writes one sample of a moving state in direction `dir` (its force and acceleration
    /// only for a recorder that reads them: a fit's velocity samples of a LuGre model spent a
    /// twentieth of the simulation on forces nobody read).
    fn write_moving(&mut self, t: f64, y: &[f64], dir: f64) {
        if let [x, v, z @ ..] = y {
            let (a, f) = if self.rec.wants_forces() {
                let f = self.dynamics.force(t, *x, *v, z, dir);
                (self.dynamics.accel(t, *x, *v, f), f)
            } else {
                (f64::NAN, f64::NAN)
            };
            self.rec.sample(t, *x, *v, z, a, f);
        }
        self.next += 1;
    }

    /// Fills the remaining samples before `until` (all of them with `None`) with the state
    /// at rest `y` (v = 0, a = 0, the friction holding u - R(x)).
    fn fill_rest(&mut self, y: &[f64], until: Option<f64>) {
        let pending = self.samples.get(self.next..).unwrap_or_default();
        let due = match until {
            None => pending.len(),
            Some(t) => pending.partition_point(|&ts| ts < t),
        };
        let due = &pending[..due];
        let dynamics = self.dynamics;
        if let [x, _] = y {
            for times in due.chunks(BLOCK) {
                if dynamics.driven() {
                    let held = |i: usize| dynamics.held_force(times[i], *x);
                    self.block.at_rest(times.len(), *x, held);
                } else {
                    let held = dynamics.held_force(0.0, *x);
                    self.block.at_rest(times.len(), *x, |_| held);
                }
                self.rec.sample_block(&self.block.view(times));
            }
        } else if let [x, _, z @ ..] = y {
            for &ts in due {
                self.rec
                    .sample(ts, *x, 0.0, z, 0.0, dynamics.held_force(ts, *x));
            }
        }
        self.next += due.len();
    }

    /// Fills every remaining sample with the (moving) state `y` at the end time.
    fn fill_end(&mut self, y: &[f64], dir: f64) {
        while let Some(&ts) = self.samples.get(self.next) {
            self.write_moving(ts, y, dir);
        }
    }

    fn push_event(&mut self, time: f64, kind: EventKind, x: f64) -> Result<(), EngineError> {
        if self.events.len() >= self.max_events {
            return Err(IntegrationFailure::EventBudgetExceeded {
                time,
                max_events: self.max_events,
            }
            .into());
        }
        self.events.push(Event {
            time,
            kind,
            displacement: x,
        });
        self.stats.events = self.events.len();
        Ok(())
    }

    /// Records a turning point at (t, x).
    fn turning_point(&mut self, t: f64, x: f64) -> Result<(), EngineError> {
        self.push_event(t, EventKind::TurningPoint, x)
    }

    /// Decides the mode at time `t` for state `y` (a turning point or the start): returns the
    /// time the next segment starts at (later than `t` after a stick that an input ends)
    /// and its slip direction, or `None` after recording the rest and filling the remaining
    /// samples.
    fn decide(&mut self, t: f64, y: &[f64], t_end: f64) -> Result<Option<(f64, f64)>, EngineError> {
        let [x, v, z @ ..] = y else {
            return Ok(None);
        };
        let mut start = self.dynamics.start(t, *x, *v, z);
        let driven = self.dynamics.driven();
        if *v == 0.0 && !driven && !matches!(self.dynamics.law, Law::Switched { .. }) {
            if let Some(prev) = self.last_turn {
                if (x - prev).abs() < self.rest_swing {
                    start = Start::Rest;
                }
            }
        }
        if *v == 0.0 {
            self.last_turn = Some(*x);
        }
        match start {
            Start::Slip(d) => Ok(Some((t, d))),
            Start::Rest => {
                self.push_event(t, EventKind::Stick, *x)?;
                if let Some(resume) = self.dynamics.breakaway(t, *x, t_end) {
                    self.fill_rest(y, Some(resume.0));
                    self.push_event(resume.0, EventKind::Breakaway, *x)?;
                    return Ok(Some(resume));
                }
                self.rest = Some(Rest {
                    time: t,
                    displacement: *x,
                });
                self.fill_rest(y, None);
                Ok(None)
            }
        }
    }
}

/// Locates the zero of `g` in (lo, hi] where g(hi) <= 0. At the start of a segment g(lo) may
/// be 0; a point with g > 0 is then searched on a geometric grid towards `lo`.
pub(super) fn locate(mut g: impl FnMut(f64) -> Option<f64>, lo: f64, hi: f64) -> Option<f64> {
    let g_hi = g(hi)?;
    if g_hi == 0.0 {
        return Some(hi);
    }
    let mut a = lo;
    let mut g_a = g(lo)?;
    if g_a <= 0.0 {
        let mut s = hi - lo;
        let mut found = false;
        for _ in 0..60 {
            s *= 0.5;
            let tt = lo + s;
            let gt = g(tt)?;
            if gt > 0.0 {
                a = tt;
                g_a = gt;
                found = true;
                break;
            }
        }
        if !found {
            return Some(lo);
        }
    }
    illinois(&mut g, a, g_a, hi, g_hi, EVENT_TOL)
}
