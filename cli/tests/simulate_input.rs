//! `simulate` driven by a measured input (`[simulation] input`): a slide without a spring
//! pushed by a constant force against Coulomb friction and viscous damping, against the
//! closed form of m v' = F - F_c - c v from rest, v(t) = (F - F_c) / c (1 - exp(-c t / m));
//! the input is plotted (input.svg) as `fit` plots a record's, and named in the report.

use frictionid_cli::testing::{assert_bad_inputs, runs_ok, scratch_dir, BadInput, Says};
use std::path::Path;
use std::process::Command;

const MASS: f64 = 2.0;
const DAMPING: f64 = 4.0;
const PUSH: f64 = 10.0;
const COULOMB: f64 = 2.0;

/// The slide (no restoring force; the Coulomb level is a force over N = 1) and a one-second
/// simulation at 1 kHz driven by `drive.csv`, from rest at 0 (no `x0`: a driven axis starts
/// where it is).
fn config(input: &str) -> String {
    format!(
        "[oscillator]\nmass = {MASS}\ndamping = {DAMPING}\nnormal_force = 1.0\n\
         restoring = {{ type = \"none\" }}\n[model]\ntype = \"coulomb\"\nmu = {COULOMB}\n\
         [simulation]\nduration = 1.0\n{input}"
    )
}

/// u = PUSH at 100 Hz over 1.2 s.
fn drive_csv() -> String {
    let mut csv = String::from("time,u\n");
    for i in 0..=120 {
        csv.push_str(&format!("{},{PUSH}\n", i as f64 * 0.01));
    }
    csv
}

/// Runs `simulate` on `cfg` into `out` and returns its report.json.
fn simulate(cfg: &Path, out: &Path) -> serde_json::Value {
    let run = Command::new(env!("CARGO_BIN_EXE_frictionid"))
        .args([
            "simulate",
            cfg.to_str().unwrap_or_default(),
            "--quiet",
            "--out",
        ])
        .arg(out)
        .output();
    runs_ok(run, out).0
}

#[test]
fn a_driven_simulation_follows_the_closed_form_and_plots_its_input() {
    let dir = scratch_dir("simulate-input", "push");
    std::fs::write(dir.join("drive.csv"), drive_csv()).unwrap();
    let cfg = dir.join("c.toml");
    let input = "input = { file = \"drive.csv\", input_force_column = \"u\" }\n";
    std::fs::write(&cfg, config(input)).unwrap();
    let out = dir.join("out");
    let report = simulate(&cfg, &out);
    let trajectory = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let mut lines = trajectory.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let (t_col, v_col) = (column(&header, "time"), column(&header, "v"));
    let mut worst: f64 = 0.0;
    for line in lines {
        let fields: Vec<f64> = line.split(',').map(|f| f.parse().unwrap()).collect();
        let t = fields[t_col];
        let exact = (PUSH - COULOMB) / DAMPING * (1.0 - (-DAMPING * t / MASS).exp());
        worst = worst.max((fields[v_col] - exact).abs());
    }
    assert!(worst < 1e-7, "worst velocity error {worst} m/s");
    let svg = std::fs::read_to_string(out.join("input.svg")).unwrap();
    assert!(svg.contains("input u [N]") && svg.contains("measured input"));
    assert_eq!(report["input_file"], "drive.csv");
    let files: Vec<&str> = report["files"]
        .as_array()
        .map(|f| f.iter().filter_map(|x| x.as_str()).collect())
        .unwrap_or_default();
    assert!(files.contains(&"input.svg"), "{files:?}");
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("| input | `drive.csv` |"), "{md}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A free vibration draws no input plot and names none.
#[test]
fn a_free_vibration_has_no_input_plot() {
    let dir = scratch_dir("simulate-input", "free");
    let cfg = dir.join("c.toml");
    std::fs::write(
        &cfg,
        "[oscillator]\nmass = 10.391\ndamping = 0.275\nstiffness = 1982.0\nnormal_force = 14.5\n\
         [model]\ntype = \"coulomb\"\nmu = 0.24\n[simulation]\nx0 = 0.014\nduration = 1.0\n",
    )
    .unwrap();
    let out = dir.join("out");
    simulate(&cfg, &out);
    assert!(!out.join("input.svg").exists());
    let report = std::fs::read_to_string(out.join("report.json")).unwrap();
    assert!(!report.contains("input_file"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// An input without its file or without an input column: one line naming the key.
#[test]
fn a_bad_input_is_named() {
    let binary = Path::new(env!("CARGO_BIN_EXE_frictionid"));
    assert_bad_inputs(
        binary,
        "simulate-input",
        &[
            BadInput::new(
                "no-file",
                "simulate",
                config("input = { input_force_column = \"u\" }\n"),
            )
            .says(Says::EndsWith(
                "[simulation]: input: missing `file` (the input's data file)",
            )),
            BadInput::new(
                "no-column",
                "simulate",
                config("input = { file = \"drive.csv\", velocity_column = \"u\" }\n"),
            )
            .with_file("drive.csv", drive_csv())
            .says(Says::Contains(
                "[simulation]: input (`drive.csv`): no input force channel (the file has: \
                 velocity); name its column with `input_force_column`",
            )),
        ],
    );
}

fn column(header: &[&str], name: &str) -> usize {
    header
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}
