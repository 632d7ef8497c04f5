//! Why a spec cannot be built or used.

use frictionid_models::ModelError;
use thiserror::Error;

/// Why a spec cannot be built or used.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SpecError {
    /// A command needs a `[model]` the spec does not have.
    #[error("{purpose} needs a [model] table (e.g. type = \"coulomb\")")]
    MissingModel {
        /// The command.
        purpose: String,
    },
    /// A command needs a `[simulation]` the spec does not have.
    #[error("{purpose} needs a [simulation] table (x0, duration, sample_rate)")]
    MissingSimulation {
        /// The command.
        purpose: String,
    },
    /// `[fit] free` or `bounds` names a parameter the model does not have.
    #[error(
        "[fit] {key}: model `{model}` has no parameter `{name}`{hint}; its parameters: {known}"
    )]
    UnknownParameter {
        /// `free` or `bounds`.
        key: String,
        /// The model.
        model: String,
        /// The name as written.
        name: String,
        /// " (did you mean `x`?)" or empty.
        hint: String,
        /// The model's parameters, comma-separated.
        known: String,
    },
    /// A bound that is not an ordered interval.
    #[error("[fit] bounds: `{name}` = [{lower}, {upper}] is not an interval with lower < upper")]
    BadBounds {
        /// The parameter.
        name: String,
        /// Lower bound as written.
        lower: f64,
        /// Upper bound as written.
        upper: f64,
    },
    /// A `[fit.options]` value that cannot be used.
    #[error("{0}")]
    FitOption(String),
    /// A value out of range or a key missing in `[simulation]`.
    #[error("[simulation]: {0}")]
    Simulation(String),
    /// An empty list of models to compare.
    #[error("no models to compare")]
    NoModels,
    /// A model name that is not registered.
    #[error("unknown model `{name}` in the models to compare{hint}; registered models: {known}")]
    UnknownModel {
        /// The name as written.
        name: String,
        /// " (did you mean `x`?)" or empty.
        hint: String,
        /// Every registered name, comma-separated.
        known: String,
    },
    /// An oscillator property or its standard deviation out of range.
    #[error("[oscillator]: {0}")]
    Oscillator(String),
    /// A static law whose force at its start values is not finite on the data.
    #[error(
        "{key}: the force is {value} {place}, not a finite number: the law cannot be fitted there"
    )]
    NotFinite {
        /// The model's key and value as written.
        key: String,
        /// The force there (inf or NaN).
        value: f64,
        /// Where: at rest, or a record's velocity and time.
        place: String,
    },
    /// A value out of range or a key missing in `[plan]`.
    #[error("[plan]: {0}")]
    Plan(String),
    /// A model error.
    #[error(transparent)]
    Model(#[from] ModelError),
}
