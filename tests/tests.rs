//! The cross-crate tests of the facade, one module per subject, built into one binary (one
//! link instead of one per file).

mod fuzz_regressions;
mod gms;
mod hostile;
mod layout;
mod properties;
mod record_config;
