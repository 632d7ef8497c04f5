//! Records with response channels other than velocity, from the command line: an
//! interferometer-only record (displacement, exact Coulomb truth with seeded noise) fitted
//! from a config, and the one-line errors of channel keys and malformed channel files.

use assert_cmd::Command;
use frictionid_cli::testing::Says::Contains;
use frictionid_cli::testing::{assert_bad_inputs, runs_ok, scratch_dir, BadInput};
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

/// Runs `fit` on `dir`/c.toml into `dir`/out and returns its report.json.
fn fit(dir: &Path) -> serde_json::Value {
    let out = dir.join("out");
    let run = Command::new(env!("CARGO_BIN_EXE_frictionid"))
        .arg("fit")
        .arg(dir.join("c.toml"))
        .arg("--out")
        .arg(&out)
        .output();
    runs_ok(run, &out).0
}

#[test]
fn a_displacement_only_record_is_fitted_from_a_config() {
    let dir = scratch_dir("channels", "interferometer");
    std::fs::write(dir.join("x.csv"), interferometer_csv()).unwrap();
    let config = format!("{FMM}[model]\ntype = \"coulomb\"\n{RECORD}");
    std::fs::write(dir.join("c.toml"), config).unwrap();
    let out = dir.join("out");
    let r = fit(&dir);
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

/// A vibrometer and an interferometer side by side, under their default column names
/// (`displacement`, `velocity`) and with no `x0`: the velocity fit releases the record from
/// its first displacement sample (14 mm plus its noise), as it would with
/// `displacement_column` named, and recovers mu = 0.24.
#[test]
fn a_record_with_a_displacement_channel_needs_no_x0() {
    let dir = scratch_dir("channels", "default-x");
    let osc = Oscillator::fmm();
    let time = uniform_times(1.5, 1000.0);
    let exact = coulomb_free_vibration(&osc, 0.24 * osc.normal_force, 0.014, &time).unwrap();
    let (mut x, mut v) = (exact.x, exact.v);
    add_gaussian_noise(&mut x, 5e-7, 3);
    add_gaussian_noise(&mut v, 2e-4, 4);
    let mut csv = String::from("time,displacement,velocity\n");
    for ((t, x), v) in time.iter().zip(&x).zip(&v) {
        csv.push_str(&format!("{t},{x:.9},{v:.9}\n"));
    }
    std::fs::write(dir.join("xv.csv"), csv).unwrap();
    let config = format!("{FMM}[model]\ntype = \"coulomb\"\n[[records]]\nfile = \"xv.csv\"\n");
    std::fs::write(dir.join("c.toml"), config).unwrap();
    let r = fit(&dir);
    let first: f64 = format!("{:.9}", x[0]).parse().unwrap();
    assert_eq!(r["records"][0]["x0"].as_f64(), Some(first));
    let mu = r["parameters"][0]["value"].as_f64().unwrap();
    assert!(((mu - 0.24) / 0.24).abs() < 1e-3, "mu = {mu}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Channel-key and channel-file errors: one line naming the file and the key (same checks
/// as the CLI's other bad-input tables).
#[test]
fn channel_errors_name_the_file_and_the_key() {
    let model = "[model]\ntype = \"coulomb\"\n";
    let interferometer = interferometer_csv();
    let case = |name, config: String| {
        BadInput::new(name, "fit", config).with_file("x.csv", interferometer.clone())
    };
    let short_row = "t,x_um\n0,14000\n0.001,13999\n0.002\n";
    let cases = [
        case(
            "bad-noise",
            format!("{FMM}{model}{RECORD}displacement_noise = -1.0\n"),
        )
        .says(Contains(
            "[[records]] entry 1 (`x.csv`): `displacement_noise` must be > 0",
        )),
        case(
            "offset-without-velocity",
            format!("{FMM}{model}[fit.options]\nvelocity_offset = true\n{RECORD}"),
        )
        .says(Contains("record `x.csv`: [fit.options] velocity_offset = true needs a velocity channel (the record has: displacement)")),
        case(
            "no-column",
            format!("{FMM}{model}{RECORD}acceleration_column = \"acc\"\n"),
        )
        .says(Contains("x.csv: line 1: no column `acc`")),
        BadInput::new("short-row", "fit", format!("{FMM}{model}{RECORD}"))
            .with_file("x.csv", short_row)
            .says(Contains("x.csv: line 4")),
        case(
            "force-less",
            format!("{FMM}{model}[fit.options]\ndomain = \"force\"\nforce_target = \"measured\"\n{RECORD}"),
        )
        .says(Contains("record `x.csv`: [fit.options] force_target = \"measured\" but the record has no force channel (it has: displacement")),
    ];
    assert_bad_inputs(
        Path::new(env!("CARGO_BIN_EXE_frictionid")),
        "channels",
        &cases,
    );
}
