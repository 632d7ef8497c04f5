//! Writes the friction-damper benchmark's records (`engine/benches/data/damper.rs`) to
//! `target/bench-data/damper/`, where `frictionid campaign`, the `damper` criterion bench and
//! `benches/scipy_damper.py` read them; prints the campaign config's path.
//!
//! Run: `cargo run --release -p frictionid-engine --example bench_data`

#[path = "../benches/data/damper.rs"]
mod damper;

use std::process::ExitCode;

fn main() -> ExitCode {
    let dir = damper::damper_dir();
    match damper::write_damper_data(&dir) {
        Ok(config) => {
            println!("{}", config.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!(
                "error: writing the damper records to {}: {e}",
                dir.display()
            );
            ExitCode::FAILURE
        }
    }
}
