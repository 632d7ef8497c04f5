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
//! # Sensitivities
//! [`simulate_sensitivities`] integrates the forward sensitivities of the motion with respect
//! to the law's parameters, the oscillator's properties and x0 beside the states, with their
//! jumps at turning points and sticks (`sensitivity/`): a velocity fit's Jacobian from one run.
//!
//! # Cost
//! Dopri5 is explicit: for bristle models its step is bounded by stability, about
//! 3.3 g(v) / (sigma0 |v|) while sliding. On the FMM case (2 s from 22 mm) LuGre and Dahl need
//! about 1.5e4 RHS evaluations at sigma0 = 1e5 N/m but about 1e6 at sigma0 = 1e7 N/m; a stiff
//! method would remove that bound. There is no stiffness abort: such runs finish.

mod auto;
mod block;
mod breakaway;
mod closed_form;
mod conditions;
mod dopri;
mod driver;
mod dynamics;
mod entry;
mod euler;
mod input;
mod jacobian;
pub(crate) mod mechanical;
mod recorders;
mod rodas;
mod root;
mod run;
mod sensitivity;
mod small_lu;
mod stepper;
mod values;

pub use closed_form::ClosedForm;
pub use conditions::{
    require_motion_conditions, require_simulable_conditions, ChannelSeries,
    MAX_SIMULATED_CONDITIONS,
};
pub use dopri::Dopri5;
pub use entry::{
    simulate, simulate_driven, simulate_velocity, simulate_velocity_watched, VelocityRun,
};
pub use euler::Euler;
pub use input::Input;
pub use mechanical::MechanicalEnergy;
pub use rodas::Rodas4;
pub use run::{REST_SWING_ATOLS, RODAS_ATOL_SCALE, RODAS_TOL_SCALE};
pub use sensitivity::{
    simulate_sensitivities, SampledSeries, Sensitivities, SensitivityParam, SENSITIVITY_STIFF_RATIO,
};
pub use stepper::{
    AffineMotion, IntervalStart, OdeSystem, StepCounts, StepOutcome, Stepper, Tolerance,
};
pub use values::{
    Event, EventKind, Initial, Integrator, Rest, RunInputs, SampleGrid, SimOptions, SimStats,
    Trajectory,
};

pub(crate) use dynamics::{Dynamics, Law, Start};
pub(crate) use recorders::{Recorder, SampleBlock};
