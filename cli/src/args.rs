//! Command-line arguments (clap derive).

use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

/// Identify friction models from the measured free vibration of an oscillator.
#[derive(Debug, Parser)]
#[command(
    name = "frictionid",
    version,
    about,
    after_help = "Example:\n  frictionid compare fixtures/fmm-compare.toml --out results/"
)]
pub struct Cli {
    /// The subcommand.
    #[command(subcommand)]
    pub command: Command,
}

/// Output options shared by the commands that write a report.
#[derive(Debug, Clone, Args)]
pub struct OutputArgs {
    /// Output directory for report.json, report.md, plots and data files.
    #[arg(long, value_name = "DIR", default_value = "frictionid-out")]
    pub out: PathBuf,
    /// Print nothing but errors and warnings.
    #[arg(long, short)]
    pub quiet: bool,
    /// Print report.json to standard output (instead of the summary table).
    #[arg(long)]
    pub json: bool,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// List every registered friction model with its parameters and equation.
    #[command(after_help = "Examples:\n  frictionid models\n  frictionid models --json")]
    Models {
        /// Print the listing as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Simulate a free vibration from the config's oscillator, model and simulation tables.
    #[command(
        after_help = "Example:\n  frictionid simulate fixtures/paper-140mm.toml --out sim-140mm/\n\nWrites trajectory.csv, report.json, report.md and SVG plots; with `noise` in\n[simulation] also record.csv, a noisy velocity record usable in [[records]]."
    )]
    Simulate {
        /// The TOML configuration file.
        config: PathBuf,
        #[command(flatten)]
        output: OutputArgs,
    },
    /// Fit the config's model to its records.
    #[command(after_help = "Example:\n  frictionid fit fixtures/fmm-fit.toml --out fit/")]
    Fit {
        /// The TOML configuration file.
        config: PathBuf,
        #[command(flatten)]
        output: OutputArgs,
    },
    /// Fit several models to the same records and rank them by AIC.
    #[command(
        after_help = "Examples:\n  frictionid compare fixtures/fmm-compare.toml\n  frictionid compare fixtures/fmm-compare.toml --models coulomb,stribeck,lugre"
    )]
    Compare {
        /// The TOML configuration file.
        config: PathBuf,
        /// Comma-separated model names (default: every registered model).
        #[arg(long, value_delimiter = ',', value_name = "A,B,...")]
        models: Option<Vec<String>>,
        #[command(flatten)]
        output: OutputArgs,
    },
    /// Energy-based friction force of each record (the paper's Eq. 7) against the reference.
    #[command(after_help = "Example:\n  frictionid energy fixtures/fmm-energy.toml --out energy/")]
    Energy {
        /// The TOML configuration file.
        config: PathBuf,
        #[command(flatten)]
        output: OutputArgs,
    },
}
