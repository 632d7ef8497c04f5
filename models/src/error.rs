//! Typed errors of the model crate.

use thiserror::Error;

/// Errors raised when building, configuring or validating friction models.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ModelError {
    /// The `type` names no registered model.
    #[error("unknown friction model `{name}`{hint}; registered models: {registered}")]
    UnknownModel {
        name: String,
        hint: String,
        registered: String,
    },
    /// The table has no `type` key.
    #[error("the model table has no `type` key; registered models: {registered}")]
    MissingType { registered: String },
    /// A key names no parameter of the model.
    #[error("unknown parameter `{key}` for model `{model}`{hint}; its parameters: {params}")]
    UnknownParameter {
        model: String,
        key: String,
        hint: String,
        params: String,
    },
    /// A parameter lies outside its physical bounds.
    #[error(
        "parameter `{param}` of model `{model}` is {value}, outside its physical bounds {bounds}"
    )]
    OutOfBounds {
        model: String,
        param: String,
        value: f64,
        bounds: String,
    },
    /// A parameter vector of the wrong length.
    #[error("model `{model}` has {expected} parameters, got {got}")]
    ParamCount {
        model: String,
        expected: usize,
        got: usize,
    },
    /// A key of a model table whose value is inconsistent with the rest of the table (e.g. a
    /// per-element list of the wrong length).
    #[error("model `{model}`, key `{key}`: {message}")]
    BadKey {
        model: String,
        key: String,
        message: String,
    },
    /// A formula (of the `expression` model) that does not parse or names an unknown variable;
    /// `column` counts characters from 1.
    #[error("expression model: {message} at column {column} of `{formula}`")]
    Formula {
        message: String,
        column: usize,
        formula: String,
    },
    /// Any other malformed model table (wrong value type, ...).
    #[error("invalid model table: {0}")]
    Invalid(String),
}
