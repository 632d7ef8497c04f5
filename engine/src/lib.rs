//! The frictionid engine: the oscillator of the paper's Eq. (1), the event-detecting ODE
//! engine, the energy analysis (Eqs. 2-7) and the least-squares identifier.
//!
//! Library code: values in, values out; no printing.
//!
//! A library user starts from the re-exports at this root: an [`Oscillator`] (m, c, k, N),
//! a friction law by its registry name ([`default_model`], a `Box<dyn` [`FrictionModel`]`>`),
//! measured motion as [`Record`]s, then [`simulate()`] (with [`SimOptions`], into a
//! [`Trajectory`]), [`fit()`] (with [`FitOptions`], into a [`FitResult`]) or [`compare()`] (into a
//! [`Comparison`]). A [`Spec`] is the serializable description of a whole run (what a config
//! file holds); the [`jobs`] run one command from it.
//!
//! The paper's flexure stage with Coulomb friction, released at 14 mm and sampled at 1 kHz,
//! and mu fitted back from the simulated velocity:
//!
//! ```
//! use frictionid_engine::{default_model, fit, simulate, FitOptions, Initial, Oscillator};
//! use frictionid_engine::{Record, SimOptions};
//!
//! // m = 10.391 kg, c = 0.275 N s/m, k = 1982 N/m, N = 14.5 N.
//! let osc = Oscillator::fmm();
//! let mut truth = default_model("coulomb")?;
//! truth.set_params(&[0.2])?;
//!
//! // Released from rest at 14 mm; 1.5 s at 1 kHz (the mass sticks after about 1.1 s).
//! let x0 = 0.014;
//! let times: Vec<f64> = (0..=1500).map(|i| f64::from(i) / 1000.0).collect();
//! let opts = SimOptions::default();
//! let motion = simulate(&osc, truth.as_ref(), &Initial::at_rest(x0), 1.5, &times, &opts)?;
//! let record = Record::new("x14mm", times, motion.v, x0);
//!
//! // Fit mu, starting from the law's default (the start is guessed from the record).
//! let start = default_model("coulomb")?;
//! let result = fit(&osc, start.as_ref(), &[record], &FitOptions::default())?;
//! let mu = result.value("mu").ok_or("no parameter mu")?;
//! assert!(result.converged);
//! assert!((mu - 0.2).abs() < 1e-6, "mu = {mu}");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![warn(unreachable_pub)]

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
pub mod plan;
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
pub use oscillator::Oscillator;
pub use record::Record;
pub use report::{CompareReport, EnergyReport, FitReport, ModelsReport, SimulateReport};
pub use simulate::{
    simulate, simulate_velocity, Event, EventKind, Initial, Integrator, Rest, SimOptions, SimStats,
    Trajectory,
};
pub use spec::{Hooks, Spec, SpecError};

// What a library user starts from: a law by its registry name, a fit and a comparison.
pub use frictionid_models::{default_model, FrictionModel};
pub use identify::{compare, fit, Comparison, FitOptions, FitResult};
