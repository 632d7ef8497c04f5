//! The augmented run: segments between turning points as the plain driver takes them, the
//! sensitivities' jumps at each turning point, and the samples.

use super::super::driver::locate;
use super::super::dynamics::{Dynamics, Law, Start};
use super::super::stepper::{StepCounts, StepOutcome, Stepper};
use super::super::values::{SampleGrid, SimOptions, SimStats};
use super::super::{Dopri5, Rodas4, REST_SWING_ATOLS, RODAS_ATOL_SCALE, RODAS_TOL_SCALE};
use super::breakaway::apply_breakaway_jump;
use super::system::{Augmented, DirectTerms};
use super::{SampledSeries, Sensitivities, SensitivityParam};
use crate::error::{EngineError, IntegrationFailure};

/// Largest step as a fraction of the time scale (the plain run's).
const H_MAX_PERIODS: f64 = 1.0 / 8.0;

/// The stepper of an augmented run.
pub(super) enum Method {
    /// Dopri5, its error control over the states.
    Dopri5,
    /// Rodas4 for a stiff contact, at the plain stiff run's tolerances (`typical`: each
    /// state's typical size, for the differences of its Jacobian; `atol_scales`: the plain
    /// run's multipliers of the absolute tolerance), its error control over the states and
    /// its linear systems solved block by block ([`Rodas4::block_triangular`]).
    Rodas4 {
        typical: Vec<f64>,
        atol_scales: Vec<f64>,
    },
}

/// What an augmented run is made of.
pub(super) struct Setup<'a, 'b> {
    pub dynamics: Dynamics<'a>,
    pub terms: &'b DirectTerms<'a>,
    /// The states at t = 0.
    pub y0: &'b [f64],
    pub grid: SampleGrid<'b>,
    pub opts: &'b SimOptions,
    /// The run's time scale (the natural period or its length).
    pub period: f64,
    /// The series kept at the samples.
    pub kept: SampledSeries,
    /// The largest believable |dx/dp| and |dv/dp| of each parameter (see
    /// [`super::believable_sizes`]): a run whose sensitivities pass one has diverged.
    pub believable: Vec<(f64, f64)>,
    /// The stepper.
    pub method: Method,
}

/// A run in progress: the output and the book-keeping of turning points.
struct Run<'a, 'b> {
    setup: Setup<'a, 'b>,
    out: Sensitivities,
    next: usize,
    events: usize,
    last_turn: Option<f64>,
    /// The right-hand side of the states just before the last turning point.
    before_turn: Option<Vec<f64>>,
    /// Why the run gives no sensitivities, once it knows.
    given_up: Option<GivenUp>,
}

/// Why an augmented run gives no sensitivities.
#[derive(Debug, Clone, Copy, PartialEq)]
enum GivenUp {
    /// A sampled sensitivity passed its believable size.
    Diverged,
    /// A measured input broke a stick away arriving at the band's edge with zero slope (or
    /// a law parameter's edge had no derivative): the breakaway time has no derivative.
    TangentBreakaway,
}

/// Runs `setup` to its end time; `None` when the sensitivities diverged (the explicit
/// stepper, its steps set by the states' error alone, can run the sensitivities of a stiff
/// stretch at steps beyond its stability bound, where they grow without limit).
pub(super) fn run(setup: Setup<'_, '_>) -> Result<Option<Sensitivities>, EngineError> {
    let n = setup.y0.len();
    let n_params = setup.terms.params().len();
    let mut y = vec![0.0; n * (1 + n_params)];
    y[..n].copy_from_slice(setup.y0);
    for (j, p) in setup.terms.params().iter().enumerate() {
        if *p == SensitivityParam::StartDisplacement {
            y[n * (1 + j)] = 1.0;
        }
    }
    let samples = setup.grid.sample_times.len();
    let all = setup.kept == SampledSeries::All;
    let kept = |keep: bool| if keep { samples } else { 0 };
    let series = |keep: bool| vec![Vec::with_capacity(kept(keep)); n_params];
    let h_max = setup.period * H_MAX_PERIODS;
    let (rtol, atol) = (setup.opts.rtol, setup.opts.atol);
    let mut run = Run {
        out: Sensitivities {
            x: Vec::with_capacity(kept(all)),
            v: Vec::with_capacity(kept(all)),
            dx: series(all),
            dv: series(true),
            stats: SimStats::default(),
        },
        setup,
        next: 0,
        events: 0,
        last_turn: None,
        before_turn: None,
        given_up: None,
    };
    match &run.setup.method {
        Method::Dopri5 => {
            let mut stepper = Dopri5::new(y.len(), rtol, atol, h_max).controlling_first(n);
            let result = run.segments(&mut stepper, y, &[]);
            run.finish(result, stepper.counts())
        }
        Method::Rodas4 {
            typical,
            atol_scales,
        } => {
            let (rtol, atol) = (RODAS_TOL_SCALE * rtol, RODAS_ATOL_SCALE * atol);
            let mut stepper = Rodas4::new(y.len(), rtol, atol, h_max)
                .with_atol_scales(atol_scales)
                .controlling_first(n)
                .block_triangular(n);
            let typical = typical.clone();
            let result = run.segments(&mut stepper, y, &typical);
            run.finish(result, stepper.counts())
        }
    }
}

impl Run<'_, '_> {
    /// The run's output after `result`, with the work counted in `counts`.
    fn finish(
        mut self,
        result: Result<(), EngineError>,
        counts: StepCounts,
    ) -> Result<Option<Sensitivities>, EngineError> {
        let explicit = matches!(self.setup.method, Method::Dopri5);
        self.out.stats = SimStats {
            rhs_evaluations: counts.rhs_evaluations,
            steps: counts.accepted,
            rejected_steps: counts.rejected,
            events: self.events,
            // Every right-hand side of the augmented system evaluates the states' Jacobian;
            // the stiff stepper's Jacobian of it evaluates it once more per state.
            jacobian_evaluations: match explicit {
                true => counts.rhs_evaluations,
                false => {
                    let per_jacobian = 1 + self.setup.y0.len() as u64;
                    counts.rhs_evaluations + per_jacobian * counts.jacobian_evaluations
                }
            },
        };
        result.map(|()| self.given_up.is_none().then_some(self.out))
    }
}

impl Run<'_, '_> {
    fn n(&self) -> usize {
        self.setup.y0.len()
    }

    fn segments<S: Stepper>(
        &mut self,
        stepper: &mut S,
        mut y: Vec<f64>,
        typical: &[f64],
    ) -> Result<(), EngineError> {
        let t_end = self.setup.grid.t_end;
        let tiny = 1e-13 * (1.0 + t_end);
        let mut t = 0.0;
        loop {
            let start = self.decide(t, &y);
            self.jump(t, &mut y, start);
            let dir = match start {
                Start::Slip(dir) => dir,
                Start::Rest => match self.stick(t, &mut y)? {
                    Some((t_b, dir)) => {
                        t = t_b;
                        dir
                    }
                    None => return Ok(()),
                },
            };
            if t_end - t <= tiny {
                self.fill(&y, Some(dir));
                return Ok(());
            }
            let system = Augmented::new(self.setup.dynamics, dir, self.setup.terms, typical);
            let stop = self.setup.dynamics.stop_after(t, t_end);
            stepper.reset(&system, t, &y, stop)?;
            match self.advance(stepper, &system, &mut y)? {
                None => return Ok(()),
                Some(t_e) => {
                    self.count_event(t_e)?;
                    t = t_e;
                }
            }
        }
    }

    /// Steps through one segment; at a turning point leaves the augmented state there in `y`
    /// (v = 0) and returns its time, `None` at the end time.
    fn advance<S: Stepper>(
        &mut self,
        stepper: &mut S,
        system: &Augmented<'_, '_>,
        y: &mut [f64],
    ) -> Result<Option<f64>, EngineError> {
        let dir = system.dir;
        let n = self.n();
        loop {
            if stepper.counts().attempts() >= self.setup.opts.max_steps {
                return Err(IntegrationFailure::StepBudgetExceeded {
                    time: stepper.time(),
                    max_steps: self.setup.opts.max_steps,
                }
                .into());
            }
            if stepper.step(system)? == StepOutcome::Rejected {
                continue;
            }
            if stepper.state().iter().any(|v| !v.is_finite()) {
                return Err(IntegrationFailure::NonFiniteState {
                    time: stepper.time(),
                    state: stepper.state()[..n].to_vec(),
                }
                .into());
            }
            if dir * stepper.state()[1] <= 0.0 {
                let lo = stepper.previous_time();
                let g = |t: f64| {
                    stepper.interpolate(t, y);
                    Some(dir * y[1])
                };
                let t_e = locate(g, lo, stepper.time())
                    .ok_or(IntegrationFailure::EventNotLocated { time: lo })?;
                self.write(stepper, t_e, y);
                stepper.interpolate(t_e, y);
                y[1] = 0.0;
                let mut f = vec![0.0; n];
                system.dynamics.rhs(t_e, &y[..n], &mut f, dir);
                self.before_turn = Some(f);
                return Ok(Some(t_e));
            }
            let t_end = self.setup.grid.t_end;
            if stepper.reached_end() && stepper.end_time() < t_end {
                // A knot of the input: on to the next, as the plain driver goes.
                self.write(stepper, stepper.time(), y);
                stepper.continue_to(self.setup.dynamics.stop_after(stepper.time(), t_end));
                continue;
            }
            if stepper.reached_end() {
                self.write(stepper, t_end, y);
                y.copy_from_slice(stepper.state());
                self.fill(y, Some(dir));
                return Ok(None);
            }
            self.write(stepper, stepper.time(), y);
        }
    }

    /// A stick from time `t` at the augmented state `y`: its samples at rest, and, where a
    /// measured input breaks it away, the breakaway's time and direction with the
    /// sensitivities' jump there applied to `y` (`None`: it lasts to the end, or the jump
    /// cannot be taken and the run is given up).
    fn stick(&mut self, t: f64, y: &mut [f64]) -> Result<Option<(f64, f64)>, EngineError> {
        self.count_event(t)?;
        let t_end = self.setup.grid.t_end;
        let dynamics = self.setup.dynamics;
        let Some((t_b, dir)) = dynamics.breakaway(t, y[0], t_end) else {
            self.fill(y, None);
            return Ok(None);
        };
        self.fill_until(y, t_b);
        self.count_event(t_b)?;
        if apply_breakaway_jump(&dynamics, self.setup.terms, t_b, dir, y).is_none() {
            self.given_up = Some(GivenUp::TangentBreakaway);
            return Ok(None);
        }
        Ok(Some((t_b, dir)))
    }

    /// The mode at a turning point or the start (time `t`), as the plain driver decides it.
    fn decide(&mut self, t: f64, y: &[f64]) -> Start {
        let [x, v, z @ ..] = &y[..self.n()] else {
            return Start::Rest;
        };
        let dynamics = &self.setup.dynamics;
        let mut start = dynamics.start(t, *x, *v, z);
        let switched = matches!(dynamics.law, Law::Switched { .. });
        if *v == 0.0 && !dynamics.driven() && !switched {
            let swing = REST_SWING_ATOLS * self.setup.opts.atol;
            if self.last_turn.is_some_and(|prev| (x - prev).abs() < swing) {
                start = Start::Rest;
            }
        }
        if *v == 0.0 {
            self.last_turn = Some(*x);
        }
        start
    }

    /// The sensitivities' jump at the turning point just reached (if any, at time `t`) into
    /// `start`: s += (f- - f+) dt_e/dp with dt_e/dp = -s_v / a-.
    fn jump(&mut self, t: f64, y: &mut [f64], start: Start) {
        let Some(before) = self.before_turn.take() else {
            return;
        };
        let n = self.n();
        let a_before = before[1];
        if a_before == 0.0 || !a_before.is_finite() {
            return;
        }
        let mut after = vec![0.0; n];
        if let Start::Slip(dir) = start {
            self.setup.dynamics.rhs(t, &y[..n], &mut after, dir);
        }
        for s in y[n..].chunks_exact_mut(n) {
            let dt_dp = -s[1] / a_before;
            for ((si, &b), &a) in s.iter_mut().zip(&before).zip(&after) {
                *si += (b - a) * dt_dp;
            }
        }
    }

    fn count_event(&mut self, time: f64) -> Result<(), EngineError> {
        self.events += 1;
        if self.events > self.setup.opts.max_events {
            return Err(IntegrationFailure::EventBudgetExceeded {
                time,
                max_events: self.setup.opts.max_events,
            }
            .into());
        }
        Ok(())
    }

    /// Writes the samples with time <= `until` from the last step's dense output.
    fn write<S: Stepper>(&mut self, stepper: &S, until: f64, buf: &mut [f64]) {
        while let Some(&ts) = self.setup.grid.sample_times.get(self.next) {
            if ts > until {
                break;
            }
            stepper.interpolate(ts, buf);
            self.push(buf, true);
        }
    }

    /// Writes the samples before `t` at rest with the augmented state `y`.
    fn fill_until(&mut self, y: &[f64], t: f64) {
        while self
            .setup
            .grid
            .sample_times
            .get(self.next)
            .is_some_and(|&ts| ts < t)
        {
            self.push(y, false);
        }
    }

    /// Writes every remaining sample with the augmented state `y`: moving in direction `dir`
    /// at the end time, or at rest (`None`: v and its sensitivities 0).
    fn fill(&mut self, y: &[f64], dir: Option<f64>) {
        while self.next < self.setup.grid.sample_times.len() {
            self.push(y, dir.is_some());
        }
    }

    fn push(&mut self, y: &[f64], moving: bool) {
        let n = self.n();
        let all = self.setup.kept == SampledSeries::All;
        let out = &mut self.out;
        if all {
            out.x.push(y[0]);
            out.v.push(if moving { y[1] } else { 0.0 });
        }
        for ((j, s), &(dx_max, dv_max)) in y[n..]
            .chunks_exact(n)
            .enumerate()
            .zip(&self.setup.believable)
        {
            if all {
                out.dx[j].push(s[0]);
            }
            out.dv[j].push(if moving { s[1] } else { 0.0 });
            // Written so that NaN counts as diverged.
            if !(s[0].abs() <= dx_max && s[1].abs() <= dv_max) {
                self.given_up.get_or_insert(GivenUp::Diverged);
            }
        }
        self.next += 1;
    }
}
