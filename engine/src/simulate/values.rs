//! The values of a simulation: the integrator and its options, the initial state, events,
//! the rest and statistics of a run, and the sampled [`Trajectory`].

use super::mechanical::MechanicalEnergy;
use super::{ChannelSeries, Input};
use crate::oscillator::Oscillator;
use frictionid_models::FrictionModel;
use serde::{Deserialize, Serialize};

/// The time integrator.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "method", rename_all = "snake_case", deny_unknown_fields)]
pub enum Integrator {
    /// Adaptive Dormand-Prince 5(4) with dense output and event location
    /// ([`Dopri5`](super::Dopri5)), the default.
    #[default]
    Dopri5,
    /// The paper's fixed-step explicit Euler with step T_n / `steps_per_period` (paper: 1e6).
    Euler {
        /// Steps per undamped natural period T_n.
        steps_per_period: f64,
    },
    /// The exact propagator ([`ClosedForm`](super::ClosedForm)) for laws affine in v within
    /// each sliding mode (coulomb, viscous_coulomb, none) on an underdamped oscillator; an
    /// error otherwise.
    Exact,
    /// The exact propagator where it applies; Rodas4 where a stiffness estimate (spectral
    /// radius of the Jacobian times Dopri5's accuracy step) says an explicit method would be
    /// stability-limited; Dopri5 otherwise (see `auto.rs`).
    Auto,
    /// The stiff Rosenbrock method Rodas4 ([`Rodas4`](super::Rodas4)) with the model's
    /// Jacobian, for bristle and element models with stiff contacts (sigma0 of 1e6..1e9 N/m).
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

#[cfg(test)]
impl SimOptions {
    /// Dopri5 at rtol 1e-12 and atol 1e-14: simulations whose differences in a parameter
    /// are accurate enough to hold sensitivities against.
    pub(crate) fn tight_dopri5() -> Self {
        Self {
            rtol: 1e-12,
            atol: 1e-14,
            ..Self::default()
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
    /// The named channels a law that reads some takes its values from (a load, a
    /// temperature), linear in time between their samples (`None`: no channels).
    pub channels: Option<&'a ChannelSeries>,
    /// The end time and the sample times.
    pub grid: SampleGrid<'a>,
    /// The integrator and its tolerances and limits.
    pub opts: &'a SimOptions,
}
