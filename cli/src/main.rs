//! The `frictionid` binary: all logic lives in the `frictionid_cli` library.

fn main() -> std::process::ExitCode {
    frictionid_cli::main_with_args(std::env::args_os())
}
