//! Friction models for frictionid: the [`FrictionModel`] trait, the typetag-based registry and
//! the built-in friction laws.
//!
//! Models are pure functions of sliding velocity, internal states, normal force and
//! parameters; they know nothing of solvers, files or the command line. The [`formula`]
//! module parses and compiles the formulas of the `expression` model.

pub mod builtin;
pub mod conditions;
pub mod error;
pub mod formula;
pub mod hints;
pub mod interval;
pub mod linearisation;
pub mod model;
pub mod param_info;
pub mod params;
pub mod registry;
pub mod start;
pub mod suggest;
pub mod testing;

pub use builtin::*;
pub use conditions::{condition_value, Condition};
pub use error::ModelError;
pub use hints::{GuessHint, StartContext};
pub use interval::Interval;
pub use linearisation::Linearisation;
pub use model::{
    clone_model, decay, sgn, Derivatives, FrictionModel, InternalStates, Jacobians, ParamGradients,
    Propagator, RigidLimit, Staging, SwitchedLaw,
};
pub use param_info::{check_bounds, check_len, ParamInfo};
pub use params::{DeclaredParams, ParamSpec};
pub use registry::{build_json, build_toml, default_model, listings, names, Built, ModelListing};
pub use start::StribeckLevels;
