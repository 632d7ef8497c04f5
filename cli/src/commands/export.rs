//! `frictionid export`: a report's fitted law as C, Rust or Python source, or as a
//! compensation table. Reads report.json, asks the engine for the text, writes it atomically.

use crate::report::write_atomic;
use anyhow::Context;
use frictionid_engine::export::{export_report, ExportOptions, Lang};
use std::io::Write;
use std::path::{Path, PathBuf};

use super::Outcome;

/// report.json of `path`: the file itself, or the one in the directory.
fn report_path(path: &Path) -> PathBuf {
    if path.is_dir() {
        path.join("report.json")
    } else {
        path.to_path_buf()
    }
}

/// Runs `frictionid export REPORT --lang LANG [--out FILE] [--prefix P] [--normal-force N]`.
pub fn run(
    report: &Path,
    lang: &str,
    out: Option<&Path>,
    prefix: String,
    normal_force: Option<f64>,
) -> anyhow::Result<Outcome> {
    let lang: Lang = lang
        .parse()
        .map_err(|e: String| anyhow::anyhow!("--lang: {e}"))?;
    let path = report_path(report);
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("cannot read {}", path.display()))?;
    let value: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{} is not JSON", path.display()))?;
    let opts = ExportOptions {
        lang,
        prefix,
        normal_force,
    };
    let source = export_report(&value, &path.display().to_string(), &opts)
        .with_context(|| path.display().to_string())?;
    match out {
        Some(file) => write_atomic(file, source.as_bytes())?,
        None => {
            let _ = std::io::stdout().write_all(source.as_bytes());
        }
    }
    Ok(Outcome::Done)
}
