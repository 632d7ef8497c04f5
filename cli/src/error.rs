//! Typed errors of the CLI library (config, data, reports, plots).

use std::path::PathBuf;
use thiserror::Error;

/// Errors raised while loading configurations and data or writing outputs.
#[derive(Debug, Error)]
pub enum CliError {
    /// A malformed or inconsistent configuration file (the message names file, line or key).
    #[error("{0}")]
    Config(String),
    /// A record file that cannot be read.
    #[error(transparent)]
    Data(#[from] frictionid_engine::data::DataError),
    /// A model error.
    #[error(transparent)]
    Model(#[from] frictionid_models::ModelError),
    /// An engine error.
    #[error(transparent)]
    Engine(#[from] frictionid_engine::EngineError),
    /// An output file that cannot be written.
    #[error("{path}: cannot write: {reason}")]
    Write { path: PathBuf, reason: String },
    /// A plot that cannot be drawn.
    #[error("plot {path}: {reason}")]
    Plot { path: PathBuf, reason: String },
}
