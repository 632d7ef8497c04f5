//! The `frictionid` binary: all logic lives in the `frictionid_cli` library.

mod allocator;

fn main() -> std::process::ExitCode {
    allocator::keep_freed_memory();
    frictionid_cli::main_with_args(std::env::args_os())
}
