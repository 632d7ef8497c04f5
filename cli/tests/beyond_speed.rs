//! A law beyond speed from the command line: a gearbox's load torque named in
//! `[[records]] channels`, read with its unit, fitted by `coulomb_load` along the measured
//! motion, plotted beside the record; and the one-line error of a record without it.

use assert_cmd::Command;
use frictionid_cli::testing::{fitted_value, runs_ok, scratch_dir};
use std::f64::consts::PI;
use std::path::Path;

const CONFIG: &str = "[oscillator]\n\n[model]\ntype = \"coulomb_load\"\nmu = 1.5\nmu_load = 0.01\n\
                      viscous = 3.0\n\n[fit.options]\ndomain = \"force\"\n\n[[records]]\n\
                      file = \"joint.csv\"\n";

/// The record: F = (2 + 0.03 |load|) sgn(v) + 5 v written in closed form, the load in mN m.
fn joint_csv(with_load: bool) -> String {
    let mut csv = String::from(if with_load {
        "time,velocity,force,Load torque [mN m]\n"
    } else {
        "time,velocity,force\n"
    });
    for i in 0..2000 {
        let t = i as f64 / 200.0;
        // As written (12 decimals): the force follows the velocity the reader sees, whose
        // sign at the reversals is that of its rounded value.
        let v: f64 = format!("{:.12}", 0.5 * (2.0 * PI * t / 3.0).sin())
            .parse()
            .unwrap();
        let load = 30.0 * (2.0 * PI * 0.13 * t).sin() + 10.0 * (2.0 * PI * 0.41 * t + 1.0).sin();
        // sgn(v), 0 at rest (std's signum gives +-1 at +-0).
        let s = if v == 0.0 { 0.0 } else { f64::signum(v) };
        let f = (2.0 + 0.03 * f64::abs(load)) * s + 5.0 * v;
        csv.push_str(&format!("{t},{v},{f:.12}"));
        if with_load {
            csv.push_str(&format!(",{:.9}", load * 1e3));
        }
        csv.push('\n');
    }
    csv
}

fn run(dir: &Path, channels: &str) -> std::io::Result<std::process::Output> {
    std::fs::write(dir.join("c.toml"), format!("{CONFIG}{channels}")).unwrap();
    Command::new(env!("CARGO_BIN_EXE_frictionid"))
        .arg("fit")
        .arg(dir.join("c.toml"))
        .arg("--out")
        .arg(dir.join("out"))
        .output()
}

#[test]
fn a_gearbox_load_channel_is_read_fitted_and_plotted() {
    let dir = scratch_dir("beyond", "gearbox");
    std::fs::write(dir.join("joint.csv"), joint_csv(true)).unwrap();
    let (r, _) = runs_ok(
        run(&dir, "channels = { load = \"Load torque\" }\n"),
        &dir.join("out"),
    );
    let value = |name: &str| fitted_value(&r, name);
    for (name, truth) in [("mu", 2.0), ("mu_load", 0.03), ("viscous", 5.0)] {
        let got = value(name);
        assert!((got / truth - 1.0).abs() < 1e-3, "{name} = {got}");
    }
    assert!(dir.join("out/joint_channels.svg").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_record_without_the_channel_a_law_reads_is_one_line_naming_both() {
    let dir = scratch_dir("beyond", "no-load");
    std::fs::write(dir.join("joint.csv"), joint_csv(false)).unwrap();
    let o = run(&dir, "").unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{stderr}");
    let line = stderr
        .lines()
        .find(|l| l.contains("channel `load`"))
        .unwrap_or_else(|| panic!("{stderr}"));
    assert!(line.contains("joint.csv"), "{line}");
    let _ = std::fs::remove_dir_all(&dir);
}
