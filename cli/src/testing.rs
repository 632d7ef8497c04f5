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

/// The text of the fixture config `name` (under [`fixtures_dir`]) with its record files made
/// absolute, so that a test can write a variant of it anywhere.
///
/// # Panics
/// When the fixture cannot be read.
pub fn fixture_config(name: &str) -> String {
    let dir = fixtures_dir();
    std::fs::read_to_string(dir.join(name))
        .unwrap_or_else(|e| panic!("fixture {name}: {e}"))
        .replace("file = \"", &format!("file = \"{}/", dir.display()))
}

/// report.json in `out`, or `Null` when the run wrote none (a failed run writes none).
pub fn read_report(out: &Path) -> serde_json::Value {
    std::fs::read_to_string(out.join("report.json"))
        .ok()
        .and_then(|text| serde_json::from_str(&text).ok())
        .unwrap_or(serde_json::Value::Null)
}

/// The value of the fitted parameter `name` in a fit report (report.json), NaN when the
/// report has no such parameter.
pub fn fitted_value(report: &serde_json::Value, name: &str) -> f64 {
    report["parameters"]
        .as_array()
        .and_then(|p| p.iter().find(|p| p["name"] == name))
        .and_then(|p| p["value"].as_f64())
        .unwrap_or(f64::NAN)
}

/// The report of a run that must succeed: checks that `output` (a finished run of a command
/// that wrote its report into `out`) exited successfully, the failure message showing its
/// stderr, and returns report.json with the run's stderr.
///
/// # Panics
/// When the command could not run, exited unsuccessfully, or wrote no readable report.json.
pub fn runs_ok(
    output: std::io::Result<std::process::Output>,
    out: &Path,
) -> (serde_json::Value, String) {
    let o = output.unwrap_or_else(|e| panic!("cannot run the command: {e}"));
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "exit {:?}: {stderr}", o.status.code());
    let report = read_report(out);
    assert!(
        !report.is_null(),
        "no report.json in {}: {stderr}",
        out.display()
    );
    (report, stderr)
}

/// Runs `command` and checks that it exits successfully; returns its output.
///
/// # Panics
/// When it cannot run, or exits unsuccessfully (the message shows the command and its
/// stderr).
pub fn run_ok(command: &mut std::process::Command) -> std::process::Output {
    let o = match command.output() {
        Ok(o) => o,
        Err(e) => panic!("cannot run {command:?}: {e}"),
    };
    assert!(
        o.status.success(),
        "{command:?}: exit {:?}: {}",
        o.status.code(),
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// Runs `<binary> <command> CONFIG --out DIR` on `config` written into a fresh scratch
/// directory of `suite` (with the data `files` beside it) and checks the contract of bad
/// input: exit code 1, one line on stderr starting `error: `, no panic or backtrace, no
/// report.json. Returns that line.
///
/// # Panics
/// When the contract is broken, or the scratch files cannot be written.
pub fn fails_with_one_line(
    binary: &Path,
    (suite, name): (&str, &str),
    command: &str,
    config: &str,
    files: &[(&str, &str)],
) -> String {
    let dir = scratch_dir(suite, name);
    let write = |file: &str, text: &str| {
        if let Err(e) = std::fs::write(dir.join(file), text) {
            panic!("cannot write {file}: {e}");
        }
    };
    write("c.toml", config);
    for (file, text) in files {
        write(file, text);
    }
    let out = dir.join("out");
    let run = std::process::Command::new(binary)
        .arg(command)
        .arg(dir.join("c.toml"))
        .arg("--out")
        .arg(&out)
        .output();
    let o = match run {
        Ok(o) => o,
        Err(e) => panic!("cannot run {}: {e}", binary.display()),
    };
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(1), "exit code; stderr: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "one line: {stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    for bad in ["panicked", "backtrace", "internal error", "RUST_BACKTRACE"] {
        assert!(!stderr.contains(bad), "{stderr}");
    }
    assert!(!out.join("report.json").exists(), "no report.json");
    let _ = std::fs::remove_dir_all(&dir);
    stderr.trim_end().to_string()
}

/// What the one error line of a bad input must say.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Says<'a> {
    /// The line contains this text.
    Contains(&'a str),
    /// The line ends with this text.
    EndsWith(&'a str),
}

impl Says<'_> {
    /// Whether `line` says it.
    pub fn holds(&self, line: &str) -> bool {
        match self {
            Says::Contains(text) => line.contains(text),
            Says::EndsWith(text) => line.ends_with(text),
        }
    }
}

/// One bad input: `command` run on `config` (with the data `files` beside it), and what its
/// one error line must say. `name` names its scratch directory.
#[derive(Debug, Clone)]
pub struct BadInput<'a> {
    /// The case's name (its scratch directory).
    pub name: &'a str,
    /// The subcommand run.
    pub command: &'a str,
    /// The config file's text.
    pub config: String,
    /// Data files beside the config: (file name, text).
    pub files: Vec<(&'a str, String)>,
    /// What the error line says.
    pub says: Vec<Says<'a>>,
}

impl<'a> BadInput<'a> {
    /// `command` on `config`, with no data files and nothing yet to say.
    pub fn new(name: &'a str, command: &'a str, config: impl Into<String>) -> Self {
        BadInput {
            name,
            command,
            config: config.into(),
            files: Vec::new(),
            says: Vec::new(),
        }
    }

    /// With the data file `file` holding `text` beside the config.
    pub fn with_file(mut self, file: &'a str, text: impl Into<String>) -> Self {
        self.files.push((file, text.into()));
        self
    }

    /// The error line must also say `says`.
    pub fn says(mut self, says: Says<'a>) -> Self {
        self.says.push(says);
        self
    }
}

/// Runs every case through [`fails_with_one_line`] (suite `suite`) and checks that its line
/// says what the case expects.
///
/// # Panics
/// At the first case that breaks the contract or does not say what it should.
pub fn assert_bad_inputs(binary: &Path, suite: &str, cases: &[BadInput<'_>]) {
    for case in cases {
        let files: Vec<(&str, &str)> = case
            .files
            .iter()
            .map(|(file, text)| (*file, text.as_str()))
            .collect();
        let line = fails_with_one_line(
            binary,
            (suite, case.name),
            case.command,
            &case.config,
            &files,
        );
        for says in &case.says {
            assert!(says.holds(&line), "{}: {says:?} but: {line}", case.name);
        }
    }
}
