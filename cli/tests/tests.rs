//! The command line's end-to-end tests, one module per subject, built into one binary (one
//! link instead of one per file).

mod campaign;
mod channels;
mod cli;
mod defects;
mod export;
mod fit_compare;
mod fixtures;
mod force_domain;
mod html_report;
mod outputs;
mod plan;
mod rotary;
mod simulate_input;
mod units;
