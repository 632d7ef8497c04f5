//! The frictionid command line as a library.
//!
//! The `frictionid` binary is one line: `frictionid_cli::main_with_args(std::env::args_os())`.
//! A crate that registers its own friction models (typetag) builds its own binary with the
//! same line; its models then appear in `frictionid models` and can be named in configs.
//!
//! Modules: [`args`] (clap), [`config`] (TOML into the engine's `Spec`), [`commands`] (one per
//! subcommand: load, run the engine's job, write), [`report`] (atomic output files and
//! tables), [`terminal`] (the terminal writer of report values), [`plots`] (SVG charts),
//! [`progress`] (progress bars), [`error`] (typed errors).
//!
//! Exit codes, decided in one place ([`main_with_args`], from the command's
//! [`commands::Outcome`]):
//! - 0: success, warnings allowed (also `--help` and `--version`);
//! - 1 ([`EXIT_ERROR`]): an error, bad arguments included, printed as one line on stderr
//!   (an internal panic too); no report is written;
//! - 2 ([`EXIT_NOT_CONVERGED`]): a fit did not converge (`compare`: the best-ranked model's
//!   fit); its report is written;
//! - 3 ([`EXIT_DIAGNOSTIC_FAILED`]): a fit converged but one of its diagnostics failed
//!   (`compare`: the best-ranked model's fit); its report is written.

pub mod args;
pub mod commands;
pub mod config;
pub mod error;
pub mod plots;
pub mod progress;
pub mod report;
pub mod terminal;
pub mod testing;

use args::{Cli, Command};
use clap::Parser;
use commands::Outcome;
use std::ffi::OsString;
use std::io::Write;
use std::process::ExitCode;

pub use config::Config;
pub use error::CliError;

/// Exit code of a fit that ran but did not converge.
pub const EXIT_NOT_CONVERGED: u8 = 2;
/// Exit code of a fit that converged but failed a diagnostic (report written).
pub const EXIT_DIAGNOSTIC_FAILED: u8 = 3;
/// Exit code of any error.
pub const EXIT_ERROR: u8 = 1;

/// Runs parsed arguments.
pub fn run(cli: Cli) -> anyhow::Result<Outcome> {
    match cli.command {
        Command::Init {
            datafile,
            out,
            rig,
            force,
            quiet,
        } => commands::init::run(&datafile, out.as_deref(), &rig, force, quiet)
            .map(|_| Outcome::Done),
        Command::Help { topic } => commands::help::run(topic.as_deref()).map(|_| Outcome::Done),
        Command::Models { json, quiet, axis } => {
            commands::models::run(json, quiet, axis).map(|_| Outcome::Done)
        }
        Command::Simulate { config, output } => commands::simulate::run(&config, &output),
        Command::Energy { config, output } => commands::energy::run(&config, &output),
        Command::Plan { config, output } => commands::plan::run(&config, &output),
        Command::Fit { config, output } => commands::fit::run(&config, &output),
        Command::Compare {
            config,
            models,
            output,
        } => commands::compare::run(&config, models.as_deref(), &output),
        Command::Campaign {
            config,
            jobs,
            resume,
            output,
        } => commands::campaign::run(&config, jobs.map(usize::from), resume, &output),
        Command::Export {
            report,
            lang,
            out,
            prefix,
            normal_force,
        } => commands::export::run(&report, &lang, out.as_deref(), prefix, normal_force),
    }
}

/// Collapses a message to one line.
fn one_line(msg: &str) -> String {
    msg.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Parses `args` (the first is the program name), runs the command and returns the exit code.
/// Errors are printed as one line on stderr; a panic is reported as one line too.
pub fn main_with_args<I, T>(args: I) -> ExitCode
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { EXIT_ERROR } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    std::panic::set_hook(Box::new(|info| {
        let msg = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_default();
        let at = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        let _ = writeln!(
            std::io::stderr(),
            "error: internal error{at}: {} (please report this)",
            one_line(&msg)
        );
    }));
    match std::panic::catch_unwind(|| run(cli)) {
        Ok(Ok(Outcome::Done)) => ExitCode::SUCCESS,
        Ok(Ok(Outcome::NotConverged)) => ExitCode::from(EXIT_NOT_CONVERGED),
        Ok(Ok(Outcome::DiagnosticFailed)) => ExitCode::from(EXIT_DIAGNOSTIC_FAILED),
        Ok(Err(e)) => {
            let _ = writeln!(std::io::stderr(), "error: {}", one_line(&format!("{e:#}")));
            ExitCode::from(EXIT_ERROR)
        }
        Err(_) => ExitCode::from(EXIT_ERROR),
    }
}
