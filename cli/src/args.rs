//! Command-line arguments (clap derive).

use clap::{Args, Parser, Subcommand};
use frictionid_engine::Axis;
use std::path::{Path, PathBuf};

/// Identify friction laws from measured motion: the free vibration of an oscillator, a driven
/// axis under a measured input, or a tribometer's force along its motion.
#[derive(Debug, Parser)]
#[command(
    name = "frictionid",
    version,
    about = "Identify friction laws from measured motion (a free vibration, a driven axis, a \
             tribometer): write a config from a data file, simulate, fit, compare laws and check \
             each fit against the energy balance",
    disable_help_subcommand = true,
    after_help = "Start from a data file:\n  frictionid init run.csv --mass 10.4 --stiffness 1982   (writes run.toml, commented)\n  \
                  frictionid compare run.toml\n\n\
                  The configuration's keys: `frictionid help config` (docs/config.md).\n\n\
                  Example:\n  frictionid compare fixtures/fmm-compare.toml --out results/\n\n\
                  Exit codes: 0 success (warnings allowed), 1 error (one line on stderr, no report),\n\
                  2 a fit (or compare's best model) did not converge, 3 a fit converged but one of\n\
                  its diagnostics failed; with 2 and 3 the report is written and says why."
)]
pub struct Cli {
    /// The subcommand.
    #[command(subcommand)]
    pub command: Command,
}

/// Output options shared by the commands that write a report.
#[derive(Debug, Clone, Args)]
pub struct OutputArgs {
    /// Output directory for report.json, report.md, report.html, plots and data files
    /// [default: frictionid-out/<config file stem>/<command>/].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Print nothing but errors and warnings.
    #[arg(long, short)]
    pub quiet: bool,
    /// Print report.json to standard output (instead of the summary table).
    #[arg(long)]
    pub json: bool,
}

/// The default parent of the output directories.
pub const DEFAULT_OUT: &str = "frictionid-out";

impl OutputArgs {
    /// The output directory of `command` run on `config`: `--out` if given, else
    /// `frictionid-out/<config file stem>/<command>/`, so that commands and configs never
    /// mix their files.
    pub fn dir_for(&self, config: &Path, command: &str) -> PathBuf {
        match &self.out {
            Some(dir) => dir.clone(),
            None => {
                let stem = config
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_else(|| "config".into());
                Path::new(DEFAULT_OUT).join(stem).join(command)
            }
        }
    }
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Read a data file (delimiter, decimal mark, preamble, header units, sample rate, a
    /// pre-trigger rest) and write a commented configuration for it.
    #[command(
        after_help = "Examples:\n  frictionid init run.txt --mass 10.391 --stiffness 1982 --normal-force 14.5\n  \
                      frictionid init drive.csv --mass 2.0 --out drive.toml\n\n\
                      Prints what it found and writes CONFIG (default: DATAFILE with .toml); the lines\n\
                      marked \"<- SET\" need the rig's values that were not given here.\n\
                      The configuration's keys: `frictionid help config`."
    )]
    Init {
        /// The data file (delimited text).
        datafile: PathBuf,
        /// The configuration file to write [default: DATAFILE with the extension .toml].
        #[arg(long, value_name = "CONFIG")]
        out: Option<PathBuf>,
        /// The rig's values.
        #[command(flatten)]
        rig: RigValues,
        /// Replace CONFIG if it exists.
        #[arg(long)]
        force: bool,
        /// Print nothing but errors.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Print help: `frictionid help config` prints the configuration reference
    /// (docs/config.md); `frictionid help COMMAND` a command's help.
    Help {
        /// `config`, or a command's name.
        topic: Option<String>,
    },
    /// List every registered friction model with its parameters and equation.
    #[command(
        after_help = "Examples:\n  frictionid models\n  frictionid models --json\n  frictionid models --axis rotary"
    )]
    Models {
        /// Print the listing as JSON.
        #[arg(long)]
        json: bool,
        /// The axis whose units the parameters are listed in: `linear` (m, N, kg) or
        /// `rotary` (rad, N m, kg m^2).
        #[arg(long, default_value = "linear", value_parser = parse_axis)]
        axis: Axis,
        /// Print nothing (accepted for symmetry with the other commands).
        #[arg(long, short)]
        quiet: bool,
    },
    /// Simulate a free vibration from the config's oscillator, model and simulation tables.
    #[command(
        after_help = "Example:\n  frictionid simulate fixtures/paper-140mm.toml --out sim-140mm/\n\nWrites trajectory.csv, report.json, report.md, report.html and SVG plots; with `noise` in\n[simulation] also record.csv, a noisy velocity record usable in [[records]].\n\n\
                      The configuration's keys: `frictionid help config`; a config from a data file: `frictionid init DATAFILE`."
    )]
    Simulate {
        /// The TOML configuration file.
        config: PathBuf,
        #[command(flatten)]
        output: OutputArgs,
    },
    /// Fit the config's model to its records.
    #[command(
        after_help = "Example:\n  frictionid fit fixtures/fmm-fit.toml --out fit/\n\n\
                      Exit codes: 0 converged (warnings allowed), 1 error, 2 not converged,\n\
                      3 a diagnostic failed (the report says which).\n\n\
                      The configuration's keys: `frictionid help config`; a config from a data file: `frictionid init DATAFILE`."
    )]
    Fit {
        /// The TOML configuration file.
        config: PathBuf,
        #[command(flatten)]
        output: OutputArgs,
    },
    /// Fit several models to the same records and rank them by AIC.
    #[command(
        after_help = "Examples:\n  frictionid compare fixtures/fmm-compare.toml\n  frictionid compare fixtures/fmm-compare.toml --models coulomb,stribeck,lugre\n\n\
                      The configuration's keys: `frictionid help config`; a config from a data file: `frictionid init DATAFILE`."
    )]
    Compare {
        /// The TOML configuration file.
        config: PathBuf,
        /// Comma-separated model names [default: the config's `[fit.options] models`, else
        /// every registered model].
        #[arg(long, value_delimiter = ',', value_name = "A,B,...")]
        models: Option<Vec<String>>,
        #[command(flatten)]
        output: OutputArgs,
    },
    /// Fit every group of a campaign manifest, tabulate the parameters against the
    /// conditions and fit their trends.
    #[command(
        after_help = "Example:\n  frictionid campaign fixtures/campaign/campaign.toml --out campaign/\n\n\
                      Writes campaign.csv (one row per group and model), report.json, report.md,\n\
                      report.html with trend plots, and each group's reports under groups/<id>/.\n\
                      Exit codes: 0 every group fitted cleanly, 1 error before any fit, 2 a group\n\
                      could not be fitted or did not converge, 3 a group's fit failed a diagnostic.\n\n\
                      The configuration's keys: `frictionid help config`."
    )]
    Campaign {
        /// The TOML configuration file, with a [campaign] table.
        config: PathBuf,
        /// Groups fitted at the same time [default: one per core].
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
        jobs: Option<u16>,
        /// Keep the groups whose results an earlier run wrote (groups/<id>/result.json) and
        /// fit only the others.
        #[arg(long)]
        resume: bool,
        #[command(flatten)]
        output: OutputArgs,
    },
    /// Which records to take next: each candidate experiment's predicted standard errors
    /// from the Fisher information at the assumed law, the recommended set, and the
    /// parameters out of reach with the smallest change that would reach them.
    #[command(
        after_help = "Example:\n  frictionid plan fixtures/plan-stribeck.toml --out plan/\n\n\
                      Writes report.json, report.md, report.html and predicted_std.svg."
    )]
    Plan {
        /// The TOML configuration file, with a [plan] table.
        config: PathBuf,
        #[command(flatten)]
        output: OutputArgs,
    },
    /// Energy-based friction force of each record (the paper's Eq. 7) against the reference.
    #[command(
        after_help = "Example:\n  frictionid energy fixtures/fmm-energy.toml --out energy/\n\n\
                      The configuration's keys: `frictionid help config`; a config from a data file: `frictionid init DATAFILE`."
    )]
    Energy {
        /// The TOML configuration file.
        config: PathBuf,
        #[command(flatten)]
        output: OutputArgs,
    },
    /// Write the fitted law of a `fit` report (or a `compare` report's recommended law) as
    /// C, Rust or Python source, or as a steady-state compensation table.
    #[command(
        after_help = "Examples:\n  frictionid export fit/ --lang c --out lugre.c\n  frictionid export fit/report.json --lang rust --out law.rs\n  frictionid export compare/ --lang table --out table.csv --normal-force 14.5"
    )]
    Export {
        /// A report's directory or its report.json.
        report: PathBuf,
        /// The target: c, rust, python or table.
        #[arg(long, value_name = "LANG")]
        lang: String,
        /// The output file [default: standard output].
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
        /// The prefix of the C identifiers (several laws in one program).
        #[arg(long, default_value = "fid_", value_name = "PREFIX")]
        prefix: String,
        /// The normal force of the compensation table [N] [default: the report's].
        #[arg(long, value_name = "N")]
        normal_force: Option<f64>,
    },
}

/// The rig's values given on the command line (SI units; N m and kg m^2 on a rotary axis).
#[derive(Debug, Clone, Default, Args)]
pub struct RigValues {
    /// The moving mass [kg] (the moment of inertia [kg m^2] on a rotary axis).
    #[arg(long, value_name = "KG")]
    pub mass: Option<f64>,
    /// Viscous damping [N s/m] (0 when not given).
    #[arg(long, value_name = "C")]
    pub damping: Option<f64>,
    /// The spring's stiffness [N/m]; 0 for none (a driven axis, a free mass).
    #[arg(long, value_name = "K")]
    pub stiffness: Option<f64>,
    /// The contact's normal force [N] (without it the friction levels are forces).
    #[arg(long, value_name = "N")]
    pub normal_force: Option<f64>,
    /// The release displacement [m] (default: estimated from the velocity and fitted).
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub x0: Option<f64>,
    /// `linear` or `rotary` [default: from the columns' units, else linear].
    #[arg(long, value_parser = parse_axis)]
    pub axis: Option<Axis>,
}

/// An axis as `[oscillator] axis` spells it: `linear` or `rotary`.
fn parse_axis(text: &str) -> Result<Axis, String> {
    text.parse()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_output_directories_are_per_config_and_command() {
        let args = OutputArgs {
            out: None,
            quiet: false,
            json: false,
        };
        let cfg = Path::new("fixtures/fmm-fit.toml");
        assert_eq!(
            args.dir_for(cfg, "fit"),
            Path::new("frictionid-out/fmm-fit/fit")
        );
        assert_ne!(args.dir_for(cfg, "fit"), args.dir_for(cfg, "energy"));
        let explicit = OutputArgs {
            out: Some("results".into()),
            ..args
        };
        assert_eq!(explicit.dir_for(cfg, "fit"), Path::new("results"));
    }
}
