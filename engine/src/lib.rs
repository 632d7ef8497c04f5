//! The frictionid engine: the oscillator of the paper's Eq. (1), the event-detecting ODE
//! engine, the energy analysis (Eqs. 2-7) and the least-squares identifier.
//!
//! Library code: values in, values out; no printing.

pub mod axis;
pub mod campaign;
pub mod data;
pub mod energy;
pub mod error;
pub mod exact;
pub mod export;
pub mod identify;
pub mod jobs;
pub mod oscillator;
pub mod record;
pub mod report;
pub mod simulate;
pub mod spec;
pub mod synthetic;
pub mod testing;

pub use axis::{Axis, Restoring};
pub use energy::{
    analyze_record, analyze_states, force_residuals, model_force_along, percent_difference,
    Differentiator, EnergyAnalysis, EnergyOptions, ForceResiduals, HalfCycle, MechanicalEnergy,
};
pub use error::EngineError;
pub use jobs::JobError;
pub use oscillator::Oscillator;
pub use record::Record;
pub use report::{CompareReport, EnergyReport, FitReport, ModelsReport, SimulateReport};
pub use simulate::{
    simulate, simulate_velocity, Event, EventKind, Initial, Integrator, Rest, SimOptions, SimStats,
    Trajectory,
};
pub use spec::{Hooks, Spec, SpecError};
