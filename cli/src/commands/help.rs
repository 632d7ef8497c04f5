//! `frictionid help [config | COMMAND]`: the configuration reference (docs/config.md, built
//! into the binary, so it is there without the repository) or a command's help.

use crate::args::Cli;
use clap::CommandFactory;
use std::io::Write;

/// The configuration reference, docs/config.md.
pub const CONFIG_REFERENCE: &str = include_str!("../../../docs/config.md");

/// Runs `frictionid help [TOPIC]`.
pub fn run(topic: Option<&str>) -> anyhow::Result<()> {
    let mut cli = Cli::command();
    match topic {
        Some("config") | Some("config.md") | Some("configuration") => {
            let _ = std::io::stdout().write_all(CONFIG_REFERENCE.as_bytes());
            Ok(())
        }
        None => {
            cli.print_long_help()?;
            Ok(())
        }
        Some(name) => match cli.find_subcommand_mut(name) {
            Some(command) => {
                command.print_long_help()?;
                Ok(())
            }
            None => {
                let names: Vec<String> = Cli::command()
                    .get_subcommands()
                    .map(|c| c.get_name().to_string())
                    .chain(["config".to_string()])
                    .collect();
                Err(anyhow::anyhow!(
                    "no help topic `{name}`{}; topics: {}",
                    frictionid_models::suggest::did_you_mean(
                        name,
                        names.iter().map(String::as_str)
                    ),
                    names.join(", ")
                ))
            }
        },
    }
}
