//! frictionid: identify friction models from the measured free vibration of an oscillator.
//!
//! This facade re-exports the workspace libraries.
pub use frictionid_cli as cli;
pub use frictionid_engine as engine;
pub use frictionid_models as models;
