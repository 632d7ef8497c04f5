//! `init` and the readers on an instrument's export: a laser vibrometer's ASCII file of a
//! Stribeck release made by the engine's own simulator (truth known), 5 kHz, three `#` lines
//! holding commas, header `Time [s];Velocity [mm/s]`, semicolons, decimal commas and a
//! pre-trigger rest of 0.2 s. `init` then `compare` recommends Stribeck with its levels within
//! 1 %; the same file named in a hand-written config fits; bad inputs are one line naming the
//! file and the line or the key.

use assert_cmd::Command;
use frictionid_cli::testing::Says::Contains;
use frictionid_cli::testing::{
    assert_bad_inputs, fitted_value, read_report, runs_ok, scratch_dir, BadInput,
};
use frictionid_engine::synthetic::{add_gaussian_noise, release_records};
use frictionid_engine::Oscillator;
use frictionid_models::Stribeck;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// `frictionid COMMAND CONFIG --out OUT --quiet`, checked to succeed: report.json and stderr.
fn run_into(command: &str, config: &Path, out: &Path) -> (serde_json::Value, String) {
    runs_ok(
        frictionid()
            .arg(command)
            .arg(config)
            .arg("--out")
            .arg(out)
            .arg("--quiet")
            .output(),
        out,
    )
}

fn frictionid() -> Command {
    Command::new(env!("CARGO_BIN_EXE_frictionid"))
}

/// The truth: FMM rig, Stribeck friction.
const MU_C: f64 = 0.20;
const MU_S: f64 = 0.28;
const X0: f64 = 0.014;
const RATE: f64 = 5000.0;
const REST: f64 = 0.2;
const NOISE: f64 = 2e-4;

fn truth() -> Stribeck {
    Stribeck {
        mu_c: MU_C,
        mu_s: MU_S,
        v_s: 0.02,
        delta: 2.0,
        viscous: 3.0,
    }
}

/// The vibrometer export of the truth released at `REST` s, written in `dir`.
fn vibrometer_file(dir: &Path) -> PathBuf {
    let motion = release_records(&Oscillator::fmm(), &truth(), &[X0], 1.2, RATE, NOISE, 5)
        .unwrap()
        .remove(0);
    let rest_samples = (REST * RATE).round() as usize;
    let mut rest = vec![0.0; rest_samples];
    add_gaussian_noise(&mut rest, NOISE, 99);
    let mut text = String::from(
        "# Polytec PSV export, version 10.2, channel 1\n\
         # Sample rate: 5000,000 Hz, pre-trigger 20 %\n\
         # Velocity range: 100 mm/s, tracking filter off\n\
         Time [s];Velocity [mm/s]\n",
    );
    let velocity = rest.iter().chain(motion.velocity().iter());
    for (i, v) in velocity.enumerate() {
        let row = format!("{:.6};{:.6}", i as f64 / RATE, v * 1e3);
        let _ = writeln!(text, "{}", row.replace('.', ","));
    }
    let path = dir.join("vib.txt");
    std::fs::write(&path, text).unwrap();
    path
}

fn assert_levels(fit: &serde_json::Value) {
    let (mu_c, mu_s) = (fitted_value(fit, "mu_c"), fitted_value(fit, "mu_s"));
    assert!((mu_c / MU_C - 1.0).abs() < 0.01, "mu_c {mu_c}");
    assert!((mu_s / MU_S - 1.0).abs() < 0.01, "mu_s {mu_s}");
}

#[test]
fn init_then_compare_recommends_the_truth_from_a_vibrometer_export() {
    let dir = scratch_dir("init", "vibrometer");
    let data = vibrometer_file(&dir);
    let o = frictionid()
        .arg("init")
        .arg(&data)
        .args([
            "--mass",
            "10.391",
            "--damping",
            "0.275",
            "--stiffness",
            "1982",
        ])
        .args(["--normal-force", "14.5"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for says in [
        "semicolon-separated, decimal comma, header on line 4 after 3 preamble line(s)",
        "`Time [s]` -> time (x 1)",
        "`Velocity [mm/s]` -> velocity (x 0.001)",
        "at 5000.000000 Hz",
        "a pre-trigger rest until 0.2",
        "runs as written",
    ] {
        assert!(stdout.contains(says), "{says}: {stdout}");
    }
    let config = dir.join("vib.toml");
    let text = std::fs::read_to_string(&config).unwrap();
    assert!(text.contains("frictionid help config"), "{text}");
    let out = dir.join("compare");
    let (r, stderr) = run_into("compare", &config, &out);
    assert_eq!(r["verdict"]["recommended"], "stribeck", "{stderr}");
    let ranking = r["ranking"].as_array().unwrap();
    let stribeck = ranking.iter().find(|f| f["model"] == "stribeck").unwrap();
    assert_levels(stribeck);
}

#[test]
fn the_export_named_in_a_hand_written_config_fits() {
    let dir = scratch_dir("init", "by-hand");
    vibrometer_file(&dir);
    let config = dir.join("c.toml");
    std::fs::write(
        &config,
        "[oscillator]\nmass = 10.391\ndamping = 0.275\nstiffness = 1982.0\nnormal_force = 14.5\n\
         [model]\ntype = \"stribeck\"\n\
         [[records]]\nfile = \"vib.txt\"\nx0 = 0.014\nrelease = \"auto\"\n",
    )
    .unwrap();
    let out = dir.join("fit");
    let (r, stderr) = run_into("fit", &config, &out);
    assert_levels(&r);
    // The release found in the samples, then fitted: the instant to a twentieth of a sample.
    let found = r["records"][0]["release_time"].as_f64().unwrap();
    let shift = fitted_value(&r, "shift[vib.txt]");
    let fitted = found + shift;
    eprintln!("release found {found} s, fitted {fitted} s (truth {REST} s)");
    assert!(
        (fitted - REST).abs() < 0.05 / RATE,
        "release {fitted}: {stderr}"
    );
}

/// A file that does not read, a key misspelt, a decimal mark that contradicts the file: one
/// line each, naming the file and the line or the key, and no config written by `init`.
#[test]
fn bad_inputs_are_one_line_naming_the_file_and_the_line_or_key() {
    let good = "# a, b\nTime [s];Velocity [mm/s]\n0,0;0,0\n0,1;1,0\n0,2;2,0\n";
    let osc = "[oscillator]\nmass = 1.0\ndamping = 0.0\nstiffness = 1.0\n[[records]]\nfile = \"d.txt\"\nx0 = 0.01\nmin_samples = 3\n";
    let cases = [
        BadInput::new("decimal-typo", "fit", format!("{osc}decimal = \"coma\"\n"))
            .with_file("d.txt", good)
            .says(Contains(
                "unknown value `coma` in [[records]] (did you mean `comma`?)",
            )),
        BadInput::new("delimiter-typo", "fit", format!("{osc}delimter = \";\"\n"))
            .with_file("d.txt", good)
            .says(Contains(
                "unknown key `delimter` in [[records]] (did you mean `delimiter`?)",
            )),
        BadInput::new(
            "point-given",
            "energy",
            format!("{osc}decimal = \"point\"\n"),
        )
        .with_file("d.txt", good)
        .says(Contains(
            "d.txt: line 3: column `Time [s]`: `0,0` is not a number",
        )),
    ];
    assert_bad_inputs(
        Path::new(env!("CARGO_BIN_EXE_frictionid")),
        "init-bad",
        &cases,
    );
    let dir = scratch_dir("init", "bad");
    let data = dir.join("numbers.txt");
    std::fs::write(&data, "1,2\n3,4\n").unwrap();
    let o = frictionid().arg("init").arg(&data).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("numbers.txt: no header row"), "{stderr}");
    assert!(!dir.join("numbers.toml").exists());
    assert!(read_report(&dir).is_null());
}

/// The top help and each command's help point to the configuration reference and to `init`;
/// `help config` prints the reference itself.
#[test]
fn help_points_to_the_reference_and_prints_it() {
    let o = frictionid().arg("--help").output().unwrap();
    let top = String::from_utf8_lossy(&o.stdout);
    assert!(
        top.contains("frictionid help config") && top.contains("frictionid init"),
        "{top}"
    );
    for command in ["fit", "compare", "simulate", "energy", "init"] {
        let o = frictionid().args([command, "--help"]).output().unwrap();
        let help = String::from_utf8_lossy(&o.stdout);
        assert!(help.contains("frictionid help config"), "{command}: {help}");
    }
    let o = frictionid().args(["help", "config"]).output().unwrap();
    assert!(o.status.success());
    let reference =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/config.md"))
            .unwrap();
    assert_eq!(String::from_utf8_lossy(&o.stdout), reference);
    let o = frictionid().args(["help", "confg"]).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("did you mean `config`?"));
}
