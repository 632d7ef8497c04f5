//! Every crate builds its integration tests into one binary (`autotests = false`, one
//! `[[test]]` on `tests/tests.rs`, and a few named apart): a test file that is neither a
//! `[[test]]` nor a module of one would never be compiled, and its tests would never run.

use std::path::Path;

/// The crates whose tests/ folder holds one integration binary.
const CRATES: [&str; 5] = ["", "engine", "cli", "models", "examples/plugin-model"];

/// The files in `crate_dir`/tests that no target builds: neither the root of a `[[test]]`
/// (`path = "tests/NAME.rs"`) nor a `mod NAME;` of such a root.
fn unbuilt_test_files(crate_dir: &Path) -> Vec<String> {
    let read = |file: &Path| {
        std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()))
    };
    let manifest = read(&crate_dir.join("Cargo.toml"));
    let tests = crate_dir.join("tests");
    let stems: Vec<String> = std::fs::read_dir(&tests)
        .expect("tests folder")
        .filter_map(|entry| entry.ok()?.file_name().into_string().ok())
        .filter_map(|name| Some(name.strip_suffix(".rs")?.to_string()))
        .collect();
    let is_root = |stem: &str| manifest.contains(&format!("path = \"tests/{stem}.rs\""));
    let roots: Vec<String> = stems
        .iter()
        .filter(|stem| is_root(stem))
        .map(|stem| read(&tests.join(format!("{stem}.rs"))))
        .collect();
    let mut unbuilt: Vec<String> = stems
        .into_iter()
        .filter(|stem| {
            let module = format!("\nmod {stem};");
            !is_root(stem) && !roots.iter().any(|root| root.contains(&module))
        })
        .collect();
    unbuilt.sort();
    unbuilt
}

#[test]
fn every_test_file_is_built_into_a_test_binary() {
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR"));
    for krate in CRATES {
        let unbuilt = unbuilt_test_files(&workspace.join(krate));
        assert!(
            unbuilt.is_empty(),
            "{krate}/tests: {unbuilt:?} are neither a [[test]] nor a `mod` of one"
        );
    }
}
