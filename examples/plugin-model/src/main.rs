//! `frictionid-plugin`: the frictionid command line with the `stribeck_power` model added.

// Names the plugin crate so that its object code, and with it the typetag registration of
// `stribeck_power`, is linked into this binary.
use frictionid_plugin_example as _;

fn main() -> std::process::ExitCode {
    frictionid_cli::main_with_args(std::env::args_os())
}
