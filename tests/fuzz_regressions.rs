//! Replays the fuzzers' regression inputs: every file under `fixtures/fuzz-regressions/<target>/`
//! goes through the same function as the fuzz target of that name (see `fuzz/fuzz_targets/`),
//! which must return (Ok or a clean one-line Err) without panicking.

use frictionid_cli::config::Config;
use frictionid_engine::data::{read_delimited, read_mat, read_uff58, DataFormat, ReadOptions};
use frictionid_models::formula;
use std::path::{Path, PathBuf};

fn inputs(target: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/fuzz-regressions")
        .join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let bytes = std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            (p, bytes)
        })
        .collect()
}

fn opts() -> ReadOptions {
    ReadOptions {
        min_samples: 2,
        ..ReadOptions::default()
    }
}

fn check_message(path: &Path, msg: &str) {
    assert!(
        !msg.contains('\n') && msg.len() < 1000,
        "{}: the error is not one short line: {msg}",
        path.display()
    );
}

#[test]
fn delimited_regressions() {
    for (path, data) in inputs("delimited") {
        let Some((&first, rest)) = data.split_first() else {
            continue;
        };
        // The same pick as the fuzz target: the first byte modulo 3.
        let formats = [DataFormat::Auto, DataFormat::Csv, DataFormat::Whitespace];
        let format = formats[usize::from(first % 3)];
        let text = String::from_utf8_lossy(rest);
        if let Err(e) = read_delimited(Path::new("fuzz.csv"), &text, format, &opts()) {
            check_message(&path, &e.to_string());
        }
    }
}

#[test]
fn uff58_regressions() {
    let files = inputs("uff58");
    assert!(!files.is_empty());
    for (path, data) in files {
        let text = String::from_utf8_lossy(&data);
        match read_uff58(Path::new("fuzz.uff"), &text, &opts()) {
            Ok(r) => assert!(
                r.time().iter().chain(r.velocity()).all(|v| v.is_finite()),
                "{}: non-finite samples accepted",
                path.display()
            ),
            Err(e) => check_message(&path, &e.to_string()),
        }
    }
}

#[test]
fn mat_regressions() {
    let files = inputs("mat");
    assert!(!files.is_empty());
    for (path, data) in files {
        match read_mat(Path::new("fuzz.mat"), &data, &opts()) {
            Ok(r) => assert!(
                r.time().iter().all(|v| v.is_finite()),
                "{}: non-finite samples accepted",
                path.display()
            ),
            Err(e) => check_message(&path, &e.to_string()),
        }
    }
}

#[test]
fn config_regressions() {
    for (path, data) in inputs("config") {
        let Some((&first, rest)) = data.split_first() else {
            continue;
        };
        let Ok(text) = std::str::from_utf8(rest) else {
            continue;
        };
        if first % 2 == 0 {
            if let Err(e) = Config::parse(Path::new("fuzz/config.toml"), text) {
                check_message(&path, &e.to_string());
            }
        } else {
            match formula::parse(text) {
                Ok(parsed) => {
                    let names: Vec<&str> =
                        parsed.variables().iter().map(|(n, _)| n.as_str()).collect();
                    if let Ok(f) = parsed.compile(&names) {
                        for x in [0.0, -1.0, 1e-3, 1e300, f64::MIN_POSITIVE] {
                            let _ = f.eval_by(|_| x);
                        }
                    }
                }
                Err(e) => check_message(&path, &e.to_string()),
            }
        }
    }
}
