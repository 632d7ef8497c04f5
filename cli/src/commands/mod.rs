//! The subcommands. Each returns an [`Outcome`]; errors propagate as `anyhow` to the edge.

pub mod compare;
pub mod energy;
pub mod fit;
pub mod models;
pub mod simulate;

use crate::args::OutputArgs;
use std::io::Write;

/// How a command ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Success.
    Done,
    /// A fit ran to its end without converging (its report is written): exit code 2.
    NotConverged,
}

/// Prints `text` to stdout unless `--quiet`, ignoring a closed pipe.
pub fn say(output: &OutputArgs, text: &str) {
    if !output.quiet && !output.json {
        let _ = std::io::stdout().write_all(text.as_bytes());
    }
}

/// Prints a warning line to stderr (shown even with `--quiet`).
pub fn warn(text: &str) {
    let _ = writeln!(std::io::stderr(), "warning: {text}");
}

/// With `--json`, prints the report to stdout.
pub fn print_json(output: &OutputArgs, report: &serde_json::Value) -> anyhow::Result<()> {
    if output.json {
        let text = serde_json::to_string_pretty(report)?;
        let _ = writeln!(std::io::stdout(), "{text}");
    }
    Ok(())
}

/// A checked configuration with its records read, for `fit`, `compare` and `energy`.
#[derive(Debug, Clone)]
pub struct Inputs {
    /// The configuration.
    pub config: crate::config::Config,
    /// The `[[records]]`, read and checked, in file order.
    pub records: Vec<frictionid_engine::Record>,
}

/// Loads `config`, prints the model's warnings to stderr and reads every record; `purpose`
/// (the command name) appears in the message when something it needs is missing.
pub fn load_inputs(config: &std::path::Path, purpose: &str) -> anyhow::Result<Inputs> {
    let cfg = crate::config::Config::load(config)?;
    if let Some(m) = &cfg.model {
        for w in &m.warnings {
            warn(&format!("{}: [model]: {w}", config.display()));
        }
    }
    let records = cfg.load_records(purpose)?;
    Ok(Inputs {
        config: cfg,
        records,
    })
}
