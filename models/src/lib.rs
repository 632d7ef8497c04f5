//! Friction models for frictionid: the [`FrictionModel`] trait, the typetag-based registry and
//! the built-in friction laws.
//!
//! Models are pure functions of sliding velocity, internal states, normal force and
//! parameters; they know nothing of solvers, files or the command line. The [`formula`]
//! module parses and compiles the formulas of the `expression` model.

pub mod builtin;
pub mod error;
pub mod formula;
pub mod model;
pub mod params;
pub mod registry;
pub mod start;
pub mod suggest;
pub mod testing;

pub use builtin::*;
pub use error::ModelError;
pub use model::{
    check_bounds, check_len, clone_model, decay, sgn, FrictionModel, GuessHint, Linearisation,
    ParamInfo, RigidLimit,
};
pub use params::{DeclaredParams, ParamSpec};
pub use registry::{build_json, build_toml, default_model, listings, names, Built, ModelListing};
pub use start::{StartContext, StribeckLevels};
