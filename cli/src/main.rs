//! The `frictionid` binary: all logic lives in the `frictionid_cli` library.

/// mimalloc: glibc's malloc gave the fits' buffers (residual vectors and Jacobians of 50 to
/// 300 kB) back to the system and faulted them in again at every evaluation, a sixth of a
/// Coulomb fit's time; mimalloc keeps them (the results are the same to the bit).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> std::process::ExitCode {
    frictionid_cli::main_with_args(std::env::args_os())
}
