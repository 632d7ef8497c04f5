//! The subcommands: each loads its inputs, runs the engine's job and writes the report.
//! Errors propagate as `anyhow` to the edge ([`crate::main_with_args`] decides exit codes).

pub mod campaign;
pub mod compare;
pub mod energy;
pub mod export;
pub mod fit;
pub mod help;
pub mod init;
pub mod models;
pub mod plan;
pub mod simulate;

use crate::args::OutputArgs;
use crate::error::CliError;
use crate::progress::Progress;
use crate::report::OutputDir;
use crate::terminal::TerminalWriter;
use frictionid_engine::report::html::{HtmlWriter, Page};
use frictionid_engine::report::json::to_json_text;
use frictionid_engine::report::markdown::MarkdownWriter;
use frictionid_engine::report::{Render, Verdict};
use frictionid_engine::spec::Hooks;
use serde::Serialize;
use std::io::Write;
use std::path::Path;
use std::sync::Arc;

/// How a command ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Success.
    Done,
    /// A fit ran to its end without converging (its report is written): exit code 2.
    NotConverged,
    /// A fit converged but a diagnostic failed (its report is written): exit code 3.
    DiagnosticFailed,
}

impl From<Verdict> for Outcome {
    fn from(v: Verdict) -> Self {
        match v {
            Verdict::Ok => Self::Done,
            Verdict::NotConverged => Self::NotConverged,
            Verdict::DiagnosticFailed => Self::DiagnosticFailed,
        }
    }
}

/// report.html of `report`: the plots written in `out` inline, `config` echoed.
fn html_page(out: &OutputDir, report: &dyn Render, config: &Path) -> String {
    let config_text = std::fs::read_to_string(config).ok();
    let config_name = config.display().to_string();
    let plot = |name: &str| {
        name.ends_with(".svg")
            .then(|| std::fs::read_to_string(out.path(name)).ok())
            .flatten()
    };
    let page = Page {
        plot: &plot,
        config: config_text.as_deref().map(|t| (config_name.as_str(), t)),
    };
    HtmlWriter::render(report, &page)
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

/// A checked configuration with its records read, for `fit`, `compare` and `energy`.
#[derive(Debug, Clone)]
pub struct Inputs {
    /// The configuration.
    pub config: crate::config::Config,
    /// The `[[records]]`, read and checked, in file order.
    pub records: Vec<frictionid_engine::Record>,
}

/// Loads `config` and prints the model's warnings to stderr.
pub fn load_config(config: &std::path::Path) -> anyhow::Result<crate::config::Config> {
    let cfg = crate::config::Config::load(config)?;
    for assumed in cfg.spec.assumptions() {
        warn(&format!("{}: {assumed}", config.display()));
    }
    if let Some(m) = &cfg.spec.model {
        for w in &m.warnings {
            warn(&format!("{}: [model]: {w}", config.display()));
        }
    }
    Ok(cfg)
}

/// Loads `config` and reads every record; `purpose` (the command name) appears in the
/// message when something it needs is missing.
pub fn load_inputs(config: &std::path::Path, purpose: &str) -> anyhow::Result<Inputs> {
    let cfg = load_config(config)?;
    let records = cfg.load_records(purpose)?;
    Ok(Inputs {
        config: cfg,
        records,
    })
}

/// A progress bar over `total` units (hidden with `--quiet` or `--json`).
pub fn progress_bar(output: &OutputArgs, total: u64, message: &str) -> Arc<Progress> {
    Arc::new(Progress::new(total, message, !output.quiet && !output.json))
}

/// Hooks whose progress callback is `on_progress`.
pub fn hooks(
    on_progress: impl Fn(&frictionid_engine::identify::Progress) + Send + Sync + 'static,
) -> Hooks {
    Hooks {
        progress: Some(Arc::new(on_progress)),
        ..Hooks::default()
    }
}

/// The names of the report files, listed last in a report's `files`.
pub const REPORT_FILES: [&str; 3] = ["report.html", "report.md", "report.json"];

/// Writes report.html, report.md and then report.json (its presence means the run
/// completed), prints the terminal summary (or, with `--json`, report.json) and the output
/// directory. `config` is echoed in report.html.
pub fn publish<R: Render + Serialize>(
    out: &OutputDir,
    report: &R,
    output: &OutputArgs,
    config: &Path,
) -> anyhow::Result<()> {
    let json = to_json_text(report).map_err(|e| CliError::Write {
        path: out.path("report.json"),
        reason: e.to_string(),
    })?;
    out.write_text("report.html", &html_page(out, report, config))?;
    out.write_text("report.md", &MarkdownWriter::render(report))?;
    out.write_text("report.json", &json)?;
    say(
        output,
        &format!(
            "{}wrote {}\n",
            TerminalWriter::render(report),
            out.dir().display()
        ),
    );
    if output.json {
        let _ = std::io::stdout().write_all(json.as_bytes());
    }
    Ok(())
}
