//! Records with response channels other than velocity, from the command line: an
//! interferometer-only record (displacement, exact Coulomb truth with seeded noise) fitted
//! from a config, and the one-line errors of channel keys and malformed channel files.

use assert_cmd::Command;
use frictionid_cli::testing::{fails_with_one_line, scratch_dir};
use frictionid_engine::exact::coulomb_free_vibration;
use frictionid_engine::synthetic::{add_gaussian_noise, uniform_times};
use frictionid_engine::Oscillator;
use std::path::Path;

const FMM: &str =
    "[oscillator]\nmass = 10.391\ndamping = 0.275\nstiffness = 1982.0\nnormal_force = 14.5\n";

/// The FMM record released at 14 mm as an interferometer sees it: displacement in um with
/// 5e-7 m noise, 1 nm quantisation.
fn interferometer_csv() -> String {
    let osc = Oscillator::fmm();
    let time = uniform_times(2.0, 1000.0);
    let exact = coulomb_free_vibration(&osc, 0.24 * osc.normal_force, 0.014, &time).unwrap();
    let mut x = exact.x;
    add_gaussian_noise(&mut x, 5e-7, 7);
    let mut s = String::from("t,x_um\n");
    for (t, x) in time.iter().zip(&x) {
        s.push_str(&format!("{t},{:.3}\n", x * 1e6));
    }
    s
}

const RECORD: &str = "[[records]]\nfile = \"x.csv\"\nx0 = 0.014\ntime_column = \"t\"\n\
                      displacement_column = \"x_um\"\ndisplacement_scale = 1e-6\n";

#[test]
fn a_displacement_only_record_is_fitted_from_a_config() {
    let dir = scratch_dir("channels", "interferometer");
    std::fs::write(dir.join("x.csv"), interferometer_csv()).unwrap();
    let config = format!("{FMM}[model]\ntype = \"coulomb\"\n{RECORD}");
    std::fs::write(dir.join("c.toml"), config).unwrap();
    let out = dir.join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_frictionid"))
        .arg("fit")
        .arg(dir.join("c.toml"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let mu = r["parameters"][0]["value"].as_f64().unwrap();
    assert!(((mu - 0.24) / 0.24).abs() < 1e-3, "mu = {mu}");
    assert_eq!(r["compared"], "displacement");
    let channel = &r["records"][0]["channels"][0];
    assert_eq!(channel["channel"], "displacement");
    let noise = channel["noise"].as_f64().unwrap();
    assert!((noise / 5e-7 - 1.0).abs() < 0.15, "noise {noise}");
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("| record | channel | unit | samples | rms residual | noise | rms/noise |"));
    let _ = std::fs::remove_dir_all(&dir);
}

fn fails(name: &str, config: &str, files: &[(&str, &str)]) -> String {
    let binary = Path::new(env!("CARGO_BIN_EXE_frictionid"));
    fails_with_one_line(binary, ("channels", name), "fit", config, files)
}

#[test]
fn channel_errors_name_the_file_and_the_key() {
    let csv = interferometer_csv();
    let files = [("x.csv", csv.as_str())];
    let model = "[model]\ntype = \"coulomb\"\n";
    let e = fails(
        "bad-noise",
        &format!("{FMM}{model}{RECORD}displacement_noise = -1.0\n"),
        &files,
    );
    assert!(
        e.contains("[[records]] entry 1 (`x.csv`): `displacement_noise` must be > 0"),
        "{e}"
    );
    let e = fails(
        "offset-without-velocity",
        &format!("{FMM}{model}[fit.options]\nvelocity_offset = true\n{RECORD}"),
        &files,
    );
    assert!(
        e.contains("record `x.csv`: [fit.options] velocity_offset = true needs a velocity channel (the record has: displacement)"),
        "{e}"
    );
    let e = fails(
        "no-column",
        &format!("{FMM}{model}{RECORD}acceleration_column = \"acc\"\n"),
        &files,
    );
    assert!(e.contains("x.csv: line 1: no column `acc`"), "{e}");
    let short = "t,x_um\n0,14000\n0.001,13999\n0.002\n";
    let e = fails(
        "short-row",
        &format!("{FMM}{model}{RECORD}"),
        &[("x.csv", short)],
    );
    assert!(e.contains("x.csv: line 4"), "{e}");
    let force_less = format!(
        "{FMM}{model}[fit.options]\ndomain = \"force\"\nforce_target = \"measured\"\n{RECORD}"
    );
    let e = fails("force-less", &force_less, &files);
    assert!(
        e.contains("record `x.csv`: [fit.options] force_target = \"measured\" but the record has no force channel (it has: displacement"),
        "{e}"
    );
}
