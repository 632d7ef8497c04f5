//! Helpers for end-to-end tests of a frictionid command line, shared by this crate's tests
//! and a plugin crate's (examples/plugin-model): scratch directories, the bundled fixtures,
//! the FMM rig as a config table and report.json of a run.
//!
//! Test support only: the functions panic when the file system fails them.

use std::path::{Path, PathBuf};

/// The paper's FMM rig (m 10.391 kg, c 0.275 N s/m, k 1982 N/m, N 14.5 N) as an
/// `[oscillator]` table.
pub const FMM_OSCILLATOR: &str =
    "[oscillator]\nmass = 10.391\ndamping = 0.275\nstiffness = 1982.0\nnormal_force = 14.5\n";

/// A fresh, empty directory `frictionid-<suite>-<name>-<process id>` in the system's
/// temporary directory.
///
/// # Panics
/// When the directory cannot be created.
pub fn scratch_dir(suite: &str, name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("frictionid-{suite}-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    if let Err(e) = std::fs::create_dir_all(&dir) {
        panic!("cannot create {}: {e}", dir.display());
    }
    dir
}

/// The repository's bundled fixtures (fixtures/).
pub fn fixtures_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures")
}

/// report.json in `out`, or `Null` when the run wrote none (a failed run writes none).
pub fn read_report(out: &Path) -> serde_json::Value {
    std::fs::read_to_string(out.join("report.json"))
        .ok()
        .and_then(|text| serde_json::from_str(&text).ok())
        .unwrap_or(serde_json::Value::Null)
}
