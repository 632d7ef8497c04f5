//! `frictionid models`: every registered friction model with its parameters.

use crate::terminal::TerminalWriter;
use frictionid_engine::report::json::to_json_text;
use frictionid_engine::report::ModelsReport;
use frictionid_engine::Axis;
use std::io::Write;

/// Runs `frictionid models [--json] [--quiet] [--axis rotary]`.
pub fn run(json: bool, quiet: bool, axis: Axis) -> anyhow::Result<()> {
    if quiet && !json {
        return Ok(());
    }
    let report = ModelsReport::on_axis(axis);
    let text = if json {
        to_json_text(&report)?
    } else {
        TerminalWriter::render(&report)
    };
    let _ = std::io::stdout().write_all(text.as_bytes());
    Ok(())
}
