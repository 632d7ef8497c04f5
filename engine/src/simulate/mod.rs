//! The event-detecting simulation of the paper's Eq. (1), m x'' + c x' + k x + F_f = 0, with any
//! registered friction model.
//!
//! # Method
//! The motion is integrated in *segments* between zero-velocity events (turning points). In each
//! segment the sliding direction d = +1 or -1 is fixed, the event function is g = d v, and the
//! segment stops at the first accepted step where g <= 0; the crossing is located on the
//! integrator's dense output by the Illinois method to about 1e-12 s, the transition is applied
//! and a fresh segment is started from the event.
//!
//! - **Static laws with a set-valued force at v = 0** (`static_limit` is `Some`, e.g. coulomb,
//!   viscous_coulomb, stribeck) form a switched system with modes slip+, slip- and stick. Inside
//!   a slip segment the force is `slip_force(v, d, N)`: its set-valued part takes its sign from
//!   the mode, never from the (exactly or numerically zero) velocity. At a turning point the mass
//!   sticks when |k x| <= the static limit; in free vibration it then stays at rest for good.
//!   Otherwise it slips on in the direction -sgn(k x).
//! - **Smooth static laws** (`static_limit` is `None`, no internal states) and **dynamic models**
//!   (internal states z integrated with x and v) have no mode switch; the turning points are
//!   still located and the integration restarted there, so that no step straddles the kink of
//!   |v|. A motion whose swing between two turning points has fallen below `REST_SWING_ATOLS`
//!   times the absolute tolerance is declared at rest (the integrator cannot resolve it).
//!
//! # Driver and steppers
//! One driver (`driver.rs`) owns the segments, the mode decisions, event location (Illinois on
//! the dense output), sampling, budgets and statistics. The integrators implement the small
//! [`Stepper`] trait (reset, one step reporting an event sign change, dense output, counters)
//! over an [`OdeSystem`]: the adaptive Dormand-Prince 5(4) [`Dopri5`] ([`Integrator::Dopri5`],
//! the default), the paper's fixed-step explicit Euler with step T_n / n [`Euler`]
//! ([`Integrator::Euler`], linear between steps), Rodas4 for stiff bristles and the closed
//! form for affine laws; Dopri5 also integrates model states along a measured motion
//! (`energy::model_force_along`). A new integrator is one more `Stepper`.
//!
//! # Cost
//! Dopri5 is explicit: for bristle models its step is bounded by stability, about
//! 3.3 g(v) / (sigma0 |v|) while sliding. On the FMM case (2 s from 22 mm) LuGre and Dahl need
//! about 1.5e4 RHS evaluations at sigma0 = 1e5 N/m but about 1e6 at sigma0 = 1e7 N/m; a stiff
//! method would remove that bound. There is no stiffness abort: such runs finish.

mod auto;
mod block;
use block::BlockBuffer;
mod closed_form;
mod dopri;
mod driver;
mod euler;
mod input;
mod jacobian;
pub mod mechanical;
mod rodas;
mod root;
mod small_lu;
mod stepper;

pub use closed_form::ClosedForm;
pub use dopri::Dopri5;
pub use euler::Euler;
pub use input::Input;
pub use mechanical::MechanicalEnergy;
pub use rodas::Rodas4;
pub use stepper::{AffineMotion, OdeSystem, StepCounts, StepOutcome, Stepper, Tolerance};

use auto::resolve_method;
use driver::Driver;

use crate::axis::Restoring;
use crate::error::EngineError;
use crate::oscillator::Oscillator;
use frictionid_models::{sgn, Derivatives, FrictionModel, InternalStates, SwitchedLaw};
use serde::{Deserialize, Serialize};

/// A motion whose swing between consecutive turning points is below this many absolute
/// tolerances is declared at rest (smooth and dynamic models only).
pub const REST_SWING_ATOLS: f64 = 10.0;

/// Largest Dormand-Prince step, as a fraction of the undamped period (keeps one velocity zero
/// per step).
const H_MAX_PERIODS: f64 = 1.0 / 8.0;

/// Rodas4's relative tolerance as a multiple of the options' `rtol`. Its embedded error
/// estimate is of third order and overestimates the error of its fourth-order solution: at the
/// same nominal tolerance it is about 100 times more accurate than Dopri5 on the FMM cases
/// (LuGre, sigma0 = 1e7: 3e-11 m at rtol 2e-9, 2e-9 m at 2e-7). The scaling gives both
/// methods about the same accuracy for the same options.
pub const RODAS_TOL_SCALE: f64 = 100.0;

/// Rodas4's absolute tolerance as a multiple of the options' `atol` (see
/// [`RODAS_TOL_SCALE`]); the rest threshold of the driver keeps the options' `atol`.
pub const RODAS_ATOL_SCALE: f64 = 100.0;

/// The time integrator.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "method", rename_all = "snake_case", deny_unknown_fields)]
pub enum Integrator {
    /// Adaptive Dormand-Prince 5(4) with dense output and event location ([`Dopri5`]), the
    /// default.
    #[default]
    Dopri5,
    /// The paper's fixed-step explicit Euler with step T_n / `steps_per_period` (paper: 1e6).
    Euler {
        /// Steps per undamped natural period T_n.
        steps_per_period: f64,
    },
    /// The exact propagator ([`ClosedForm`]) for laws affine in v within each sliding mode
    /// (coulomb, viscous_coulomb, none) on an underdamped oscillator; an error otherwise.
    Exact,
    /// The exact propagator where it applies; Rodas4 where a stiffness estimate (spectral
    /// radius of the Jacobian times Dopri5's accuracy step) says an explicit method would be
    /// stability-limited; Dopri5 otherwise (see `auto.rs`).
    Auto,
    /// The stiff Rosenbrock method Rodas4 ([`Rodas4`]) with the model's Jacobian, for
    /// bristle and element models with stiff contacts (sigma0 of 1e6..1e9 N/m).
    Rodas,
}

/// Options of [`simulate`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimOptions {
    /// The integrator.
    pub integrator: Integrator,
    /// Relative tolerance of the adaptive integrator (>= 1e-14).
    pub rtol: f64,
    /// Absolute tolerance of the adaptive integrator [m, m/s] (> 0); a model's internal state
    /// j is held to `atol` times its `state_tolerance_scales()[j]` (1 for deflections in
    /// metres, sigma0 for Dahl's force).
    pub atol: f64,
    /// Maximum number of steps (accepted and rejected) over the whole simulation.
    pub max_steps: u64,
    /// Maximum number of events (turning points and stick) over the whole simulation.
    pub max_events: usize,
}

impl Default for SimOptions {
    /// Dopri5 with rtol = 2e-9 and atol = 1e-11. On the paper's Coulomb cases this reproduces
    /// the exact solution to about 3e-10 m (rest position and 1 kHz samples), 4e-9 m/s and
    /// 6e-11 s (rest time) with about 2000 RHS evaluations for 6 half-cycles (`Exact` or
    /// `Auto`: to 1e-12 m with no RHS evaluation). Up to 20 million
    /// steps (a fit exploring very stiff bristle models should lower this) and 100 000 events.
    fn default() -> Self {
        Self {
            integrator: Integrator::Dopri5,
            rtol: 2e-9,
            atol: 1e-11,
            max_steps: 20_000_000,
            max_events: 100_000,
        }
    }
}

/// The initial state at t = 0.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Initial {
    /// Initial displacement [m].
    pub x0: f64,
    /// Initial velocity [m/s].
    #[serde(default)]
    pub v0: f64,
    /// Initial internal states (default: all zero). Must have the model's `n_states` entries.
    #[serde(default)]
    pub z0: Option<Vec<f64>>,
}

impl Initial {
    /// Released from rest at `x0` with relaxed internal states.
    pub fn at_rest(x0: f64) -> Self {
        Self {
            x0,
            v0: 0.0,
            z0: None,
        }
    }

    /// Displacement `x0` and velocity `v0`, relaxed internal states.
    pub fn new(x0: f64, v0: f64) -> Self {
        Self { x0, v0, z0: None }
    }
}

/// The kind of an event.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EventKind {
    /// The velocity crossed zero.
    TurningPoint,
    /// The mass stuck: for good in free vibration; under an input until the input
    /// overcomes the static friction ([`EventKind::Breakaway`]).
    Stick,
    /// A stuck mass broke away: the input less the restoring force left the static
    /// friction's band.
    Breakaway,
}

/// An event of the simulation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Event {
    /// Time [s].
    pub time: f64,
    /// What happened.
    pub kind: EventKind,
    /// Displacement at the event [m].
    pub displacement: f64,
}

/// The end of the motion.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rest {
    /// Time at which the mass came to rest [s].
    pub time: f64,
    /// Final displacement [m].
    pub displacement: f64,
}

/// Integration statistics, summed over all segments.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct SimStats {
    /// Right-hand-side evaluations of the integrator.
    pub rhs_evaluations: u64,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps.
    pub rejected_steps: u64,
    /// Number of events.
    pub events: usize,
    /// Jacobian evaluations of the stiff stepper (not counted in `rhs_evaluations`).
    #[serde(default)]
    pub jacobian_evaluations: u64,
}

/// A simulated trajectory sampled at the requested times.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Trajectory {
    /// Sample times [s].
    pub time: Vec<f64>,
    /// Displacement [m].
    pub x: Vec<f64>,
    /// Velocity [m/s].
    pub v: Vec<f64>,
    /// Acceleration [m/s^2] (0 at rest).
    pub a: Vec<f64>,
    /// `states[j][i]`: internal state j at sample i.
    pub states: Vec<Vec<f64>>,
    /// Friction force [N] (at rest: the static force balancing the spring, -k x).
    pub friction: Vec<f64>,
    /// Kinetic, potential and mechanical energy (the paper's E; without `stored`).
    #[serde(flatten)]
    pub mechanical: MechanicalEnergy,
    /// Energy stored in the friction model's internal states [J].
    pub stored: Vec<f64>,
    /// Events in time order.
    pub events: Vec<Event>,
    /// The rest time and final displacement, if the motion stopped before the end time.
    pub rest: Option<Rest>,
    /// Integration statistics.
    pub stats: SimStats,
}

impl Trajectory {
    /// The total energy at each sample: mechanical (KE + PE) plus the energy stored in the
    /// friction model's states \[J\]. A passive contact never lets it rise.
    pub fn total_energy(&self) -> Vec<f64> {
        self.mechanical
            .energy
            .iter()
            .zip(&self.stored)
            .map(|(e, s)| e + s)
            .collect()
    }

    /// Number of slip phases (half-cycles): the turning points, plus one if the simulation
    /// ended while still moving (no rest and a non-zero velocity at the last sample).
    pub fn half_cycles(&self) -> usize {
        let turning = self
            .events
            .iter()
            .filter(|e| e.kind == EventKind::TurningPoint)
            .count();
        let moving = self.rest.is_none() && self.v.last().is_some_and(|&v| v != 0.0);
        turning + usize::from(moving)
    }
}

/// Simulates the free vibration of `osc` with friction `model` from `init` up to `t_end`,
/// returning the states at `sample_times` (sorted, within [0, t_end]) from the dense output.
pub fn simulate(
    osc: &Oscillator,
    model: &dyn FrictionModel,
    init: &Initial,
    t_end: f64,
    sample_times: &[f64],
    opts: &SimOptions,
) -> Result<Trajectory, EngineError> {
    simulate_driven(RunInputs {
        osc,
        model,
        init,
        input: None,
        grid: SampleGrid {
            t_end,
            sample_times,
        },
        opts,
    })
}

/// The end time of a run and the times to sample it at (sorted, within [0, t_end]).
#[derive(Debug, Clone, Copy)]
pub struct SampleGrid<'a> {
    /// The end time [s].
    pub t_end: f64,
    /// The sample times [s].
    pub sample_times: &'a [f64],
}

/// What a run simulates: the axis, its friction law, the initial state, the measured input
/// driving it, the times to sample and the integrator's options.
#[derive(Clone, Copy)]
pub struct RunInputs<'a> {
    /// The oscillator (inertia, damping, restoring law).
    pub osc: &'a Oscillator,
    /// The friction law.
    pub model: &'a dyn FrictionModel,
    /// The initial state.
    pub init: &'a Initial,
    /// The measured input u(t) driving the axis (`None`: free vibration).
    pub input: Option<&'a Input>,
    /// The end time and the sample times.
    pub grid: SampleGrid<'a>,
    /// The integrator and its tolerances and limits.
    pub opts: &'a SimOptions,
}

/// [`simulate`] of any [`RunInputs`], under the measured input when it has one: the axis
/// sticks while |u - R(q)| stays within the static friction and breaks away, at the time
/// located exactly on the piecewise-linear input, when it leaves it.
pub fn simulate_driven(inputs: RunInputs<'_>) -> Result<Trajectory, EngineError> {
    let n_samples = inputs.grid.sample_times.len();
    let mut rec = FullRecorder::new(inputs.osc, inputs.model, n_samples, inputs.model.n_states());
    let out = run(inputs, &mut rec)?;
    rec.finish_energies();
    Ok(Trajectory {
        events: out.events,
        rest: out.rest,
        stats: out.stats,
        ..rec.series
    })
}

/// The cheap variant for fitting: only the velocity at the sample times, written into
/// `v_out` (cleared first, so a buffer can be reused across calls). Same method and errors
/// as [`simulate`]; returns the statistics.
pub fn simulate_velocity(
    inputs: RunInputs<'_>,
    v_out: &mut Vec<f64>,
) -> Result<SimStats, EngineError> {
    let mut no_watch = |_: usize| false;
    let velocity = VelocityRun {
        v_out,
        watch: &mut no_watch,
    };
    simulate_velocity_watched(inputs, velocity)
}

/// Where [`simulate_velocity_watched`] writes, and who watches.
pub struct VelocityRun<'a> {
    /// The velocities at the sample times (cleared first).
    pub v_out: &'a mut Vec<f64>,
    /// Called after each step with the number of samples written so far; `true` stops the
    /// run with [`IntegrationFailure::Halted`].
    pub watch: &'a mut dyn FnMut(usize) -> bool,
}

/// [`simulate_velocity`] with a watch asked after every step: a fit stops the simulation of a
/// record once another record of the same evaluation has failed.
pub fn simulate_velocity_watched(
    inputs: RunInputs<'_>,
    run_to: VelocityRun<'_>,
) -> Result<SimStats, EngineError> {
    let VelocityRun { v_out, watch } = run_to;
    v_out.clear();
    v_out.reserve(inputs.grid.sample_times.len());
    let mut rec = VelocityRecorder { v: v_out, watch };
    Ok(run(inputs, &mut rec)?.stats)
}

/// Events, rest and statistics of a run.
pub(crate) struct RunOutput {
    pub events: Vec<Event>,
    pub rest: Option<Rest>,
    pub stats: SimStats,
}

/// Receives the samples.
pub(crate) trait Recorder {
    /// One sample: time, state, acceleration and friction force.
    fn sample(&mut self, t: f64, x: f64, v: f64, z: &[f64], a: f64, friction: f64);

    /// Whether the recorder reads accelerations and friction forces (when it does not, the
    /// driver may skip computing them: the values it passes are then meaningless).
    fn wants_forces(&self) -> bool {
        true
    }

    /// Whether the run should stop here (asked after every step; the samples written so far
    /// stay). Never, by default.
    fn halted(&mut self) -> bool {
        false
    }

    /// Consecutive samples of a law without internal states, as columns of equal length;
    /// the default records them one by one.
    fn sample_block(&mut self, block: &SampleBlock<'_>) {
        let columns = block.t.iter().zip(block.x).zip(block.v);
        for (((&t, &x), &v), (&a, &f)) in columns.zip(block.a.iter().zip(block.friction)) {
            self.sample(t, x, v, &[], a, f);
        }
    }
}

/// A run of samples of a law without internal states, one column per output.
pub(crate) struct SampleBlock<'a> {
    pub t: &'a [f64],
    pub x: &'a [f64],
    pub v: &'a [f64],
    pub a: &'a [f64],
    pub friction: &'a [f64],
}

/// Records every output into the series of a [`Trajectory`] (events, rest and statistics are
/// the run's, added after it).
struct FullRecorder<'a> {
    states: Option<&'a dyn InternalStates>,
    osc: Oscillator,
    normal: f64,
    series: Trajectory,
}

impl<'a> FullRecorder<'a> {
    fn new(osc: &Oscillator, model: &'a dyn FrictionModel, n: usize, n_states: usize) -> Self {
        let col = || Vec::with_capacity(n);
        Self {
            states: model.states(),
            osc: *osc,
            normal: osc.normal_force,
            series: Trajectory {
                time: col(),
                x: col(),
                v: col(),
                a: col(),
                states: (0..n_states).map(|_| col()).collect(),
                friction: col(),
                stored: col(),
                ..Trajectory::default()
            },
        }
    }
}

impl Recorder for FullRecorder<'_> {
    fn sample(&mut self, t: f64, x: f64, v: f64, z: &[f64], a: f64, friction: f64) {
        let out = &mut self.series;
        out.time.push(t);
        out.x.push(x);
        out.v.push(v);
        out.a.push(a);
        for (col, &zj) in out.states.iter_mut().zip(z) {
            col.push(zj);
        }
        out.friction.push(friction);
        // Static laws store nothing: the column is filled once at the end.
        if let (false, Some(states)) = (z.is_empty(), self.states) {
            out.stored.push(states.stored_energy(z, self.normal));
        }
    }

    fn sample_block(&mut self, block: &SampleBlock<'_>) {
        let out = &mut self.series;
        out.time.extend_from_slice(block.t);
        out.x.extend_from_slice(block.x);
        out.v.extend_from_slice(block.v);
        out.a.extend_from_slice(block.a);
        out.friction.extend_from_slice(block.friction);
    }
}

impl FullRecorder<'_> {
    /// The energy columns from the recorded states, in one pass each after the run (the
    /// per-sample work stays with the samples themselves).
    fn finish_energies(&mut self) {
        let out = &mut self.series;
        out.mechanical = MechanicalEnergy::of(&self.osc, &out.x, &out.v);
        if out.stored.len() < out.time.len() {
            out.stored.resize(out.time.len(), 0.0);
        }
    }
}

struct VelocityRecorder<'a> {
    v: &'a mut Vec<f64>,
    watch: &'a mut dyn FnMut(usize) -> bool,
}

impl Recorder for VelocityRecorder<'_> {
    fn sample(&mut self, _t: f64, _x: f64, v: f64, _z: &[f64], _a: f64, _friction: f64) {
        self.v.push(v);
    }

    fn wants_forces(&self) -> bool {
        false
    }

    fn sample_block(&mut self, block: &SampleBlock<'_>) {
        self.v.extend_from_slice(block.v);
    }

    fn halted(&mut self) -> bool {
        (self.watch)(self.v.len())
    }
}

/// How the friction law is treated.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Law<'a> {
    /// Static law with a set-valued force at v = 0: switched system (slip+, slip-, stick).
    Switched { limit: f64 },
    /// Smooth static law: no mode switch, restart at turning points.
    Smooth,
    /// Dynamic model with internal states integrated alongside x and v: its states' law
    /// and derivatives, fetched once for the run.
    Dynamic {
        states: &'a dyn InternalStates,
        derivatives: Derivatives<'a>,
    },
}

/// The equation of motion with its friction law.
#[derive(Clone, Copy)]
pub(crate) struct Dynamics<'a> {
    pub mass: f64,
    pub damping: f64,
    pub stiffness: f64,
    pub restoring: Restoring,
    pub normal: f64,
    pub model: &'a dyn FrictionModel,
    /// The law's switched-system facts, fetched once for the run.
    pub switching: Option<&'a dyn SwitchedLaw>,
    pub law: Law<'a>,
    /// The measured input (`None`: free vibration).
    pub input: Option<&'a Input>,
    /// The constant force F_0 of the balance (see [`Oscillator::input_offset`]).
    pub input_offset: f64,
}

/// What happens at a state with (possibly) zero velocity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Start {
    /// Slip in this direction (+1 or -1).
    Slip(f64),
    /// The mass stays at rest.
    Rest,
}

impl<'a> Dynamics<'a> {
    /// The equation of motion of `osc` with `model` (its law classified at the normal force).
    pub(crate) fn new(osc: &Oscillator, model: &'a dyn FrictionModel) -> Result<Self, EngineError> {
        Ok(Self {
            mass: osc.mass,
            damping: osc.damping,
            stiffness: osc.stiffness,
            restoring: osc.restoring,
            normal: osc.normal_force,
            model,
            switching: model.switching(),
            law: classify_law(model, osc.normal_force)?,
            input: None,
            input_offset: osc.input_offset,
        })
    }

    /// The same equation of motion driven by `input`.
    pub(crate) fn driven_by(self, input: Option<&'a Input>) -> Self {
        Self { input, ..self }
    }
}

impl Dynamics<'_> {
    /// The friction force in slip direction `dir` (static laws) or from the states (dynamic).
    #[inline]
    pub fn force(&self, v: f64, z: &[f64], dir: f64) -> f64 {
        match self.law {
            Law::Dynamic { .. } => self.model.force(v, z, self.normal),
            _ => self.slip_force(v, dir),
        }
    }

    /// The force of a static law slipping in direction `dir` (its force at `v` when it is
    /// not a switched law).
    #[inline]
    pub fn slip_force(&self, v: f64, dir: f64) -> f64 {
        match self.switching {
            Some(law) => law.slip_force(v, dir, self.normal),
            None => self.model.force(v, &[], self.normal),
        }
    }

    /// The restoring force R(x).
    #[inline]
    pub fn restoring_force(&self, x: f64) -> f64 {
        self.restoring.law().force(x, self.stiffness)
    }

    /// dR/dx at x.
    #[inline]
    pub fn restoring_stiffness(&self, x: f64) -> f64 {
        self.restoring.law().stiffness(x, self.stiffness)
    }

    /// The external force u(t) - F_0 (0 in free vibration).
    #[inline]
    pub fn input_at(&self, t: f64) -> f64 {
        self.input.map_or(0.0, |u| u.at(t)) - self.input_offset
    }

    /// Whether an input or a constant force acts (else the motion is free vibration).
    #[inline]
    pub fn driven(&self) -> bool {
        self.input.is_some() || self.input_offset != 0.0
    }

    /// The force the contact holds at rest at (t, x): u(t) - F_0 - R(x) (the static
    /// friction that keeps the mass where it is).
    #[inline]
    pub fn held_force(&self, t: f64, x: f64) -> f64 {
        if self.driven() {
            self.input_at(t) - self.restoring_force(x)
        } else {
            -self.restoring_force(x)
        }
    }

    /// The acceleration at time `t` for friction force `f`.
    #[inline]
    pub fn accel(&self, t: f64, x: f64, v: f64, f: f64) -> f64 {
        -(self.damping * v + self.restoring_force(x) + f - self.input_at(t)) / self.mass
    }

    /// The right-hand side of the first-order system y = [x, v, z...] at time `t` in
    /// direction `dir`.
    #[inline]
    pub fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64], dir: f64) {
        let ([x, v, z @ ..], [dx, dv, dz @ ..]) = (y, dy) else {
            return;
        };
        let f = match self.law {
            Law::Dynamic { states, .. } => {
                states.state_derivative_and_force(*v, z, self.normal, dz)
            }
            _ => self.slip_force(*v, dir),
        };
        *dx = *v;
        *dv = self.accel(t, *x, *v, f);
    }

    /// The segment's linear equation when the law is affine in v in direction `dir`, on a
    /// linear spring in free vibration.
    pub fn affine_motion(&self, dir: f64) -> Option<AffineMotion> {
        if matches!(self.law, Law::Dynamic { .. })
            || self.driven()
            || !self.restoring.law().is_linear_spring()
        {
            return None;
        }
        let (offset, slope) = self.switching?.affine_slip(dir, self.normal)?;
        Some(AffineMotion {
            mass: self.mass,
            damping: self.damping + slope,
            stiffness: self.stiffness,
            offset,
        })
    }

    /// Whether every sliding mode of this law is solved in closed form.
    pub fn closed_form_applies(&self) -> bool {
        [1.0, -1.0].into_iter().all(|dir| {
            self.affine_motion(dir)
                .is_some_and(|m| ClosedForm::supports(&m))
        })
    }

    /// The mode at the start of a segment from state (x, v, z) at time `t`: with a
    /// set-valued law the mass sticks while the force it must hold, |u - R(x)|, is within
    /// the static limit.
    pub fn start(&self, t: f64, x: f64, v: f64, z: &[f64]) -> Start {
        if v != 0.0 {
            return Start::Slip(sgn(v));
        }
        match self.law {
            Law::Switched { limit } => {
                let held = self.held_force(t, x);
                if held.abs() <= limit {
                    return Start::Rest;
                }
                let dir = sgn(held);
                let a = self.accel(t, x, 0.0, self.slip_force(0.0, dir));
                if dir * a > 0.0 {
                    Start::Slip(dir)
                } else {
                    Start::Rest
                }
            }
            Law::Smooth | Law::Dynamic { .. } => {
                let a = self.accel(t, x, 0.0, self.force(0.0, z, 0.0));
                if a == 0.0 || !a.is_finite() {
                    Start::Rest
                } else {
                    Start::Slip(sgn(a))
                }
            }
        }
    }
}

/// Validates the inputs, builds the driver and runs it over the chosen stepper.
pub(crate) fn run<R: Recorder>(
    inputs: RunInputs<'_>,
    rec: &mut R,
) -> Result<RunOutput, EngineError> {
    let RunInputs {
        osc,
        model,
        init,
        input,
        grid: SampleGrid {
            t_end,
            sample_times,
        },
        opts,
    } = inputs;
    osc.validate()?;
    model.check()?;
    let y0 = initial_state(model, init)?;
    check_times(t_end, sample_times)?;
    check_options(opts)?;
    let dynamics = Dynamics::new(osc, model)?.driven_by(input);
    let mut driver = Driver {
        dynamics,
        samples: sample_times,
        next: 0,
        rec,
        events: Vec::new(),
        rest: None,
        stats: SimStats::default(),
        max_events: opts.max_events,
        max_steps: opts.max_steps,
        last_turn: None,
        rest_swing: REST_SWING_ATOLS * opts.atol,
        block: BlockBuffer::new(),
    };
    let period = time_scale(osc, t_end);
    let atol_scales = component_tolerance_scales(model, y0.len());
    match resolve_method(opts.integrator, &dynamics, &y0, period)? {
        Integrator::Exact => driver.run(&mut ClosedForm::new(), &y0, t_end)?,
        Integrator::Euler { steps_per_period } => {
            let Some(period) = osc.period() else {
                return Err(EngineError::InvalidInput(
                    "the Euler integrator's step is a fraction of the natural period, and \
                     an axis without a restoring force has none: use dopri5 or auto"
                        .into(),
                ));
            };
            let mut stepper = Euler::new(y0.len(), period / steps_per_period);
            driver.run(&mut stepper, &y0, t_end)?;
        }
        Integrator::Rodas => {
            let h_max = period * H_MAX_PERIODS;
            let (rtol, atol) = (RODAS_TOL_SCALE * opts.rtol, RODAS_ATOL_SCALE * opts.atol);
            let mut stepper =
                Rodas4::new(y0.len(), rtol, atol, h_max).with_atol_scales(&atol_scales);
            driver.run(&mut stepper, &y0, t_end)?;
        }
        Integrator::Dopri5 | Integrator::Auto => {
            let h_max = period * H_MAX_PERIODS;
            // One absolute tolerance for all components (see `component_tolerance_scales`).
            let mut stepper = Dopri5::new(y0.len(), opts.rtol, opts.atol, h_max);
            driver.run(&mut stepper, &y0, t_end)?;
        }
    }
    Ok(RunOutput {
        events: driver.events,
        rest: driver.rest,
        stats: driver.stats,
    })
}

/// The time scale of a run: the natural period of small motions, or, on an axis without
/// one (no restoring force), the run's length. The largest step and `auto`'s stiffness
/// estimate are fractions of it.
fn time_scale(osc: &Oscillator, t_end: f64) -> f64 {
    osc.period()
        .unwrap_or(if t_end > 0.0 { t_end } else { 1.0 })
}

/// The multipliers of Rodas4's absolute tolerance for the `dim` components [x, v, z...]: 1
/// for x and v, the model's [`InternalStates::state_tolerance_scales`] for its states (1 in
/// place of a declared scale that is not finite and > 0). Dahl at sigma0 = 1e7 N/m: 17 394 ->
/// 10 056 RHS evaluations with them alone, 1e-8 m of x kept.
///
/// Dopri5 keeps one absolute tolerance for every component: its steps on bristle models are
/// bounded by stability, not accuracy (Dahl at 1e7: 1 032 676 and 1 026 016 RHS without and
/// with the scales), and the default options' trajectories, which the identification tests
/// pin down, stay as they were (with the scales Dahl at the default 1e5 took 16 % fewer RHS
/// evaluations, but its force no longer matched a three-element Dahl held in newtons to the
/// 1e-5 N of `simulate_custom`'s test).
fn component_tolerance_scales(model: &dyn FrictionModel, dim: usize) -> Vec<f64> {
    let mut scales = vec![1.0, 1.0];
    if let Some(states) = model.states().filter(|s| s.n_states() > 0) {
        let usable = |s: f64| if s.is_finite() && s > 0.0 { s } else { 1.0 };
        scales.extend(states.state_tolerance_scales().into_iter().map(usable));
    }
    scales.resize(dim, 1.0);
    scales
}

/// How the engine treats `model`'s law: dynamic, switched (with its static limit) or smooth.
fn classify_law(model: &dyn FrictionModel, normal: f64) -> Result<Law<'_>, EngineError> {
    if let Some(states) = model.states().filter(|s| s.n_states() > 0) {
        let derivatives = Derivatives::of(states);
        return Ok(Law::Dynamic {
            states,
            derivatives,
        });
    }
    match model.switching().and_then(|law| law.static_limit(normal)) {
        Some(limit) if limit.is_finite() && limit >= 0.0 => Ok(Law::Switched { limit }),
        Some(limit) => Err(EngineError::InvalidInput(format!(
            "model `{}` reports a static limit of {limit} N",
            model.name()
        ))),
        None => Ok(Law::Smooth),
    }
}

fn initial_state(model: &dyn FrictionModel, init: &Initial) -> Result<Vec<f64>, EngineError> {
    if !init.x0.is_finite() || !init.v0.is_finite() {
        return Err(EngineError::InvalidInput(format!(
            "initial conditions must be finite (x0 = {}, v0 = {})",
            init.x0, init.v0
        )));
    }
    let n = model.n_states();
    let mut y = Vec::with_capacity(2 + n);
    y.push(init.x0);
    y.push(init.v0);
    match &init.z0 {
        None => y.resize(2 + n, 0.0),
        Some(z0) => {
            if z0.len() != n {
                return Err(EngineError::InvalidInput(format!(
                    "model `{}` has {n} internal states, z0 has {}",
                    model.name(),
                    z0.len()
                )));
            }
            if let Some(bad) = z0.iter().find(|z| !z.is_finite()) {
                return Err(EngineError::InvalidInput(format!(
                    "initial internal states must be finite, got {bad}"
                )));
            }
            y.extend_from_slice(z0);
        }
    }
    Ok(y)
}

fn check_times(t_end: f64, times: &[f64]) -> Result<(), EngineError> {
    if !(t_end.is_finite() && t_end >= 0.0) {
        return Err(EngineError::InvalidInput(format!(
            "the end time must be finite and >= 0, got {t_end}"
        )));
    }
    // One branch-free pass for the common case (NaN fails every comparison, and ascending
    // times between a first >= 0 and a last <= t_end all lie in [0, t_end]); the diagnosis
    // below names the first bad sample.
    let in_order = times.first().is_none_or(|&t| t >= 0.0)
        && times.last().is_none_or(|&t| t <= t_end)
        && times.windows(2).fold(true, |ok, w| ok & (w[0] <= w[1]));
    if in_order {
        return Ok(());
    }
    for (i, &t) in times.iter().enumerate() {
        if !(t.is_finite() && (0.0..=t_end).contains(&t)) {
            return Err(EngineError::InvalidInput(format!(
                "sample time {i} (t = {t} s) lies outside [0, {t_end}] s"
            )));
        }
    }
    if let Err(crate::record::TimeError::NotIncreasing {
        index,
        time,
        previous,
    }) = crate::record::check_sorted(times)
    {
        return Err(EngineError::InvalidInput(format!(
            "sample times are not sorted at index {index} ({time} s after {previous} s)"
        )));
    }
    Ok(())
}

fn check_options(opts: &SimOptions) -> Result<(), EngineError> {
    let bad = |what: String| Err(EngineError::InvalidInput(what));
    if !(opts.rtol.is_finite() && opts.rtol >= 1e-14 && opts.rtol < 1.0) {
        return bad(format!("rtol must lie in [1e-14, 1), got {}", opts.rtol));
    }
    if !(opts.atol.is_finite() && opts.atol > 0.0) {
        return bad(format!("atol must be finite and > 0, got {}", opts.atol));
    }
    if opts.max_steps == 0 {
        return bad("max_steps must be >= 1".into());
    }
    if let Integrator::Euler { steps_per_period } = opts.integrator {
        if !(steps_per_period.is_finite() && steps_per_period >= 1.0) {
            return bad(format!(
                "Euler steps_per_period must be finite and >= 1, got {steps_per_period}"
            ));
        }
    }
    Ok(())
}
