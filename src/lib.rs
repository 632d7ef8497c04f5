//! frictionid: identify friction models from the measured free vibration of an oscillator.
//!
//! This facade re-exports the workspace libraries: [`models`] (the friction laws and their
//! registry), [`engine`] (simulation, energy analysis, identification; its root names what a
//! library user starts from, with a worked fit) and [`cli`] (the command line as a library).
//!
//! ```
//! use frictionid::engine::Oscillator;
//! use frictionid::models::{default_model, names};
//!
//! // Every registered law by name, and one of them at its defaults.
//! assert!(names().iter().any(|n| n == "lugre"));
//! let law = default_model("stribeck")?;
//! let osc = Oscillator::fmm();
//! // Its steady sliding force at 0.1 m/s under the paper's 14.5 N normal force.
//! let force = law.steady_state(0.1, osc.normal_force);
//! assert!(force > 0.0 && force < osc.normal_force);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
pub use frictionid_cli as cli;
pub use frictionid_engine as engine;
pub use frictionid_models as models;
