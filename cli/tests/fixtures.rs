//! The bundled fixtures end to end: `simulate` on the paper's configs against the exact
//! Coulomb solution, the synthetic FMM records against their documented truth, and the UFF
//! dataset 58 twins (written by pyuff) and the MAT-file twins (written by SciPy's `savemat`)
//! against their CSV record.

use assert_cmd::Command;
use frictionid_cli::testing::{fixtures_dir, read_report, runs_ok, scratch_dir};
use frictionid_engine::data::{read_record, Channel, DataFormat, ReadOptions};
use frictionid_engine::exact::coulomb_free_vibration;
use frictionid_engine::Oscillator;
use std::path::PathBuf;

fn frictionid() -> Command {
    Command::new(env!("CARGO_BIN_EXE_frictionid"))
}

fn paper_oscillator() -> Oscillator {
    Oscillator::new(10.391, 0.275, 1982.0, 10.391 * 9.81).unwrap()
}

/// Runs `simulate` on a fixture config and returns report.json.
fn simulate(config: &str, name: &str) -> (serde_json::Value, PathBuf) {
    let out = scratch_dir("fx", name);
    let o = frictionid()
        .arg("simulate")
        .arg(fixtures_dir().join(config))
        .arg("--out")
        .arg(&out)
        .arg("--json")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let file: serde_json::Value = read_report(&out);
    assert_eq!(stdout, file, "--json prints report.json");
    (file, out)
}

#[test]
fn simulate_paper_140mm_stops_where_the_exact_solution_does() {
    let (r, out) = simulate("paper-140mm.toml", "p140");
    let osc = paper_oscillator();
    let exact = coulomb_free_vibration(&osc, 0.24 * osc.normal_force, 0.140, &[]).unwrap();
    assert_eq!(r["command"], "simulate");
    let xf = r["final_displacement"].as_f64().unwrap();
    assert!((xf - exact.final_displacement).abs() < 1e-6, "{xf}");
    assert!((xf * 1e3 + 9.297).abs() < 1e-3, "{xf}");
    let rest = r["rest_time"].as_f64().unwrap();
    assert!((rest - exact.rest_time).abs() < 1e-5, "{rest}");
    assert_eq!(
        r["half_cycles"].as_u64().unwrap() as usize,
        exact.half_cycles()
    );
    // Every turning point of the exact solution is an event at the same time and place.
    let events = r["events"].as_array().unwrap();
    for (t, x) in exact.turning_times.iter().zip(&exact.turning_displacements) {
        assert!(
            events
                .iter()
                .any(|e| (e["time"].as_f64().unwrap() - t).abs() < 1e-5
                    && (e["displacement"].as_f64().unwrap() - x).abs() < 1e-6),
            "no event at t = {t}"
        );
    }
    for key in ["rhs_evaluations", "steps", "rejected_steps"] {
        assert!(r["stats"][key].is_u64(), "{key}");
    }
    assert!(r["wall_time_s"].as_f64().unwrap() >= 0.0);
    // The trajectory file holds the exact solution at its sample times.
    let traj = read_record(
        &out.join("trajectory.csv"),
        &ReadOptions::default().with_column(Channel::Velocity, "x"),
    )
    .unwrap();
    let ex = coulomb_free_vibration(&osc, 0.24 * osc.normal_force, 0.140, traj.time()).unwrap();
    let err = traj
        .velocity()
        .iter()
        .zip(&ex.x)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(err < 1e-6, "max |x - x_exact| = {err}");
    for f in ["report.md", "displacement_velocity.svg", "energy.svg"] {
        assert!(out.join(f).exists(), "{f}");
    }
    assert!(!out.join("record.csv").exists());
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn simulate_paper_110mm_stops_where_the_exact_solution_does() {
    let (r, out) = simulate("paper-110mm.toml", "p110");
    let osc = paper_oscillator();
    let exact = coulomb_free_vibration(&osc, 0.24 * osc.normal_force, 0.110, &[]).unwrap();
    let xf = r["final_displacement"].as_f64().unwrap();
    assert!((xf - exact.final_displacement).abs() < 1e-6, "{xf}");
    assert!((xf * 1e3 - 10.529).abs() < 1e-3, "{xf}");
    assert_eq!(r["half_cycles"].as_u64().unwrap(), 4);
    let _ = std::fs::remove_dir_all(&out);
}

/// The committed FMM records are the exact Coulomb solution (the documented truth) plus
/// noise of the documented size.
#[test]
fn fmm_records_match_their_documented_truth() {
    let osc = Oscillator::fmm();
    for (file, x0) in [
        ("x10mm.csv", 0.010),
        ("x14mm.csv", 0.014),
        ("x22mm.csv", 0.022),
    ] {
        let r = read_record(&fixtures_dir().join(file), &ReadOptions::default()).unwrap();
        assert_eq!(r.len(), 2001, "{file}");
        assert!((r.time()[2000] - 2.0).abs() < 1e-12);
        let exact = coulomb_free_vibration(&osc, 0.24 * 14.5, x0, r.time()).unwrap();
        let n = r.len() as f64;
        let resid: Vec<f64> = r
            .velocity()
            .iter()
            .zip(&exact.v)
            .map(|(a, b)| a - b)
            .collect();
        let mean = resid.iter().sum::<f64>() / n;
        let sd = (resid.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / n).sqrt();
        assert!(mean.abs() < 2e-5, "{file}: mean {mean}");
        assert!((sd / 2e-4 - 1.0).abs() < 0.08, "{file}: sd {sd}");
    }
}

#[test]
fn simulate_with_noise_writes_a_record_usable_in_records() {
    let (r, out) = simulate("fmm-sim-14mm.toml", "n14");
    assert_eq!(r["noise"].as_f64(), Some(2e-4));
    let rec = read_record(&out.join("record.csv"), &ReadOptions::default()).unwrap();
    let committed =
        read_record(&fixtures_dir().join("x14mm.csv"), &ReadOptions::default()).unwrap();
    // Same config and seed: the committed fixture is reproduced.
    assert_eq!(rec.time(), committed.time());
    let worst = rec
        .velocity()
        .iter()
        .zip(committed.velocity())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "{worst}");
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn uff_twins_read_to_the_csv_record() {
    let csv = read_record(&fixtures_dir().join("x14mm.csv"), &ReadOptions::default()).unwrap();
    for (file, rel) in [("x14mm.uff", 1e-11), ("x14mm-single.uff", 1e-5)] {
        let uff = read_record(&fixtures_dir().join(file), &ReadOptions::default()).unwrap();
        assert_eq!(uff.len(), csv.len(), "{file}");
        for (a, b) in uff.time().iter().zip(csv.time()) {
            assert!((a - b).abs() < 1e-12, "{file}: t {a} vs {b}");
        }
        let scale = csv.velocity().iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (a, b) in uff.velocity().iter().zip(csv.velocity()) {
            assert!(
                (a - b).abs() <= rel * b.abs() + 1e-15 * scale,
                "{file}: v {a} vs {b}"
            );
        }
        assert_eq!((uff.x0, uff.v0, uff.weight), (csv.x0, csv.v0, csv.weight));
    }
}

#[test]
fn uff_record_in_a_config_reads_like_its_csv_twin() {
    let dir = scratch_dir("fx", "uffcfg");
    let cfg = format!(
        "[oscillator]\nmass = 10.391\ndamping = 0.275\nstiffness = 1982.0\nnormal_force = 14.5\n\
         [[records]]\nfile = \"{}\"\nx0 = 0.014\n[[records]]\nfile = \"{}\"\nx0 = 0.014\nformat = \"uff58\"\n",
        fixtures_dir().join("x14mm.csv").display(),
        fixtures_dir().join("x14mm.uff").display()
    );
    let path = dir.join("c.toml");
    std::fs::write(&path, cfg).unwrap();
    let c = frictionid_cli::Config::load(&path).unwrap();
    let recs = c.load_records("test").unwrap();
    assert_eq!(recs[0].x0, 0.014);
    assert_eq!(recs[1].x0, 0.014);
    assert_eq!(recs[0].len(), recs[1].len());
    let _ = std::fs::remove_dir_all(&dir);
}

/// `velocity` of `mat` against the CSV twin's, within `rel` of each value plus `abs`.
fn assert_twin(file: &str, mat: &frictionid_engine::Record, rel: f64, abs: f64) {
    let csv = read_record(&fixtures_dir().join("x14mm.csv"), &ReadOptions::default()).unwrap();
    assert_eq!(mat.len(), csv.len(), "{file}");
    assert_eq!(mat.time(), csv.time(), "{file}: time");
    for (a, b) in mat.velocity().iter().zip(csv.velocity()) {
        assert!((a - b).abs() <= rel * b.abs() + abs, "{file}: v {a} vs {b}");
    }
    assert_eq!((mat.x0, mat.v0, mat.weight), (csv.x0, csv.v0, csv.weight));
}

/// SciPy's `savemat` output (fixtures/make_mat.py) reads to the CSV record: a 1xN time and an
/// Nx1 velocity uncompressed and in double precision (exact); compressed, a single-precision
/// velocity (to its 24-bit mantissa) and an int32 velocity in um/s (to its rounding).
#[test]
fn mat_twins_read_to_the_csv_record() {
    let read = |file: &str, opts: ReadOptions| {
        read_record(&fixtures_dir().join(file), &opts).unwrap_or_else(|e| panic!("{e}"))
    };
    assert_twin(
        "x14mm.mat",
        &read("x14mm.mat", ReadOptions::default()),
        0.0,
        0.0,
    );
    let compressed = "x14mm-compressed.mat";
    let single = read(compressed, ReadOptions::default());
    assert_twin(compressed, &single, 2f64.powi(-24), 0.0);
    let counts = ReadOptions::default()
        .with_column(Channel::Velocity, "velocity_um_s")
        .with_scale(Channel::Velocity, 1e-6);
    assert_twin(compressed, &read(compressed, counts), 0.0, 0.5e-6);
    let by_format = ReadOptions {
        format: DataFormat::Mat,
        ..ReadOptions::default()
    };
    let copy = scratch_dir("fx", "matfmt").join("x14mm.bin");
    std::fs::copy(fixtures_dir().join("x14mm.mat"), &copy).unwrap();
    let record = read_record(&copy, &by_format).unwrap();
    assert_twin("x14mm.bin", &record, 0.0, 0.0);
}

/// A variable missing or unusable is one line naming the file, the variable and the key; a
/// near name is suggested.
#[test]
fn mat_errors_name_the_file_variable_and_key() {
    let path = fixtures_dir().join("x14mm-compressed.mat");
    let file = path.display().to_string();
    for (column, says) in [
        (
            "velocty",
            "velocity_column: no variable `velocty` (did you mean `velocity`?); the file has: \
             time, velocity, velocity_um_s, note, rig, both",
        ),
        (
            "rig",
            "velocity_column: variable `rig` is a struct; save each channel as its own \
             numeric variable",
        ),
        (
            "both",
            "velocity_column: variable `both` is a 2001x2 matrix; store each channel as a 1xN \
             or Nx1 vector",
        ),
        (
            "note",
            "velocity_column: variable `note` is text (a char array), not a numeric vector",
        ),
    ] {
        let opts = ReadOptions::default().with_column(Channel::Velocity, column);
        let e = read_record(&path, &opts).unwrap_err().to_string();
        assert_eq!(e, format!("{file}: {says}"));
    }
    let csv_as_mat = ReadOptions {
        format: DataFormat::Mat,
        ..ReadOptions::default()
    };
    let e = read_record(&fixtures_dir().join("x14mm.csv"), &csv_as_mat)
        .unwrap_err()
        .to_string();
    assert!(e.contains("x14mm.csv: not a MAT-file of level 5"), "{e}");
}

/// `energy` on the FMM records recovers the true Coulomb force mu N = 3.48 N (the records'
/// documented truth) to within 1 %.
#[test]
fn energy_recovers_the_true_friction_force() {
    let out = scratch_dir("fx", "energy");
    let o = frictionid()
        .arg("energy")
        .arg(fixtures_dir().join("fmm-energy.toml"))
        .arg("--out")
        .arg(&out)
        .arg("--quiet")
        .output()
        .unwrap();
    let (r, _) = runs_ok(Ok(o.clone()), &out);
    assert!(o.stdout.is_empty(), "--quiet prints nothing");
    assert_eq!(r["command"], "energy");
    let recs = r["records"].as_array().unwrap();
    let names: Vec<&str> = recs.iter().map(|x| x["file"].as_str().unwrap()).collect();
    assert_eq!(names, ["x10mm.csv", "x14mm.csv", "x22mm.csv"]);
    let truth = 0.24 * 14.5;
    for rec in recs {
        let reference = rec["reference"].as_f64().unwrap();
        assert!((reference - truth).abs() < 1e-12, "{reference}");
        let f = rec["mean_abs_force"].as_f64().unwrap();
        assert!((f / truth - 1.0).abs() < 0.01, "{f}");
        let pd = rec["percent_difference"].as_f64().unwrap();
        assert!((pd - 100.0 * (f - truth) / truth).abs() < 1e-9);
        let hc = rec["half_cycle_forces"].as_array().unwrap();
        assert!(!hc.is_empty());
        for h in hc {
            assert!((h.as_f64().unwrap() / truth - 1.0).abs() < 0.03, "{h}");
        }
    }
    for stem in ["x10mm", "x14mm", "x22mm"] {
        for kind in ["displacement_acceleration", "energy", "friction_force"] {
            assert!(out.join(format!("{stem}_{kind}.svg")).exists());
        }
    }
    let _ = std::fs::remove_dir_all(&out);
}
