//! The command line's end-to-end tests, one module per subject, built into one binary (one
//! link instead of one per file).

mod beyond_speed;
mod campaign;
mod campaign_channels;
mod channels;
mod cli;
mod compare_report;
mod defects;
mod down_weighted_marks;
mod driven_keys;
mod excluded_marks;
mod export;
mod fit_compare;
mod fixtures;
mod force_domain;
mod html;
mod html_report;
mod init;
mod outputs;
mod plan;
mod rotary;
mod simulate_channels;
mod simulate_input;
mod units;
