//! The model crate's integration tests, one module per subject, built into one binary (one
//! link instead of one per file).

mod asymmetric;
mod conditions;
mod harness;
mod jacobian;
mod makkar_gms_expression;
mod models;
mod start;
