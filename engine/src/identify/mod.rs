//! The least-squares identifier: fits any registered friction model (any subset of its
//! parameters, optionally the oscillator and per-record nuisance parameters) to one or more
//! measured velocity records, and compares models on the same records.

pub mod lm;
pub mod stats;

pub use lm::LevenbergMarquardt;
