//! The plugin example's tests, one module per subject, built into one binary (one link
//! instead of one per file).

mod cli;
mod engine_fit;
mod invariants;
mod model;
