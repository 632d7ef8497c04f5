//! The plugin binary `frictionid-plugin` end to end: it is the frictionid command line with the
//! plugin model `stribeck_power` added, so it lists, simulates, fits and compares that model
//! by name from a config.
//!
//! Oracles: the model's own metadata and the built-in registry (listing); the built-in
//! `stribeck` model, to which `stribeck_power` reduces at alpha = 1, energy dissipation and
//! the static limit (simulate); the parameters the committed fixture was made with (fit,
//! compare).

use frictionid_cli::testing::{read_report, run_ok, scratch_dir, FMM_OSCILLATOR};
use frictionid_models::FrictionModel;
use frictionid_plugin_example::StribeckPower;
use std::path::{Path, PathBuf};
use std::process::Command;

fn plugin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_frictionid-plugin"))
}

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures")
}

/// Runs the plugin binary with `args` and returns its stdout; fails the test on a non-zero
/// exit.
fn stdout_of(args: &[&str]) -> String {
    String::from_utf8(run_ok(plugin().args(args)).stdout).unwrap()
}

/// Runs `frictionid-plugin <command> <config> <extra...> --out <out> --quiet`; fails the test
/// on a non-zero exit.
fn run_into(out: &Path, command: &str, config: &Path, extra: &[&str]) {
    run_ok(
        plugin()
            .arg(command)
            .arg(config)
            .args(extra)
            .arg("--out")
            .arg(out)
            .arg("--quiet"),
    );
}

/// The named columns of a CSV file with a header row (comment lines starting with `#` skipped).
fn csv_columns(path: &Path, names: &[&str]) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let idx: Vec<usize> = names
        .iter()
        .map(|n| header.iter().position(|h| h == n).unwrap())
        .collect();
    let mut cols = vec![Vec::new(); names.len()];
    for line in lines {
        let fields: Vec<f64> = line.split(',').map(|f| f.parse().unwrap()).collect();
        for (c, &i) in cols.iter_mut().zip(&idx) {
            c.push(fields[i]);
        }
    }
    cols
}

const SIM: &str = "[simulation]\nx0 = 0.014\nduration = 2.0\nsample_rate = 1000.0\n";

/// Simulates `model` (a TOML `[model]` body) from the FMM stage at 14 mm; returns the
/// output directory.
fn simulate(name: &str, model: &str) -> PathBuf {
    let dir = scratch_dir("plugin", name);
    let config = dir.join("c.toml");
    std::fs::write(
        &config,
        format!("{FMM_OSCILLATOR}\n[model]\n{model}\n\n{SIM}"),
    )
    .unwrap();
    let out = dir.join("out");
    run_into(&out, "simulate", &config, &[]);
    out
}

#[test]
fn models_lists_the_plugin_model_and_every_builtin() {
    let text = stdout_of(&["models"]);
    let plugin = StribeckPower::default();
    assert!(text.contains("stribeck_power"), "{text}");
    assert!(text.contains(&plugin.equation()), "{text}");
    for p in plugin.param_info() {
        assert!(text.contains(&p.description), "{}: {text}", p.name);
    }
    for builtin in frictionid_models::names() {
        assert!(
            text.lines().any(|l| l.starts_with(builtin.as_str())),
            "{builtin} missing: {text}"
        );
    }
}

#[test]
fn models_json_describes_the_plugin_model_by_its_metadata() {
    let json: serde_json::Value = serde_json::from_str(&stdout_of(&["models", "--json"])).unwrap();
    let list = json.as_array().unwrap();
    let names: Vec<&str> = list.iter().map(|m| m["name"].as_str().unwrap()).collect();
    // Every model of the registry as linked into this test (the built-ins and the plugin).
    let mut registered = frictionid_models::names();
    registered.sort();
    let mut listed: Vec<String> = names.iter().map(|s| s.to_string()).collect();
    listed.sort();
    assert_eq!(listed, registered);
    assert!(names.contains(&"stribeck_power") && names.contains(&"gms"));
    let m = list.iter().find(|m| m["name"] == "stribeck_power").unwrap();
    assert_eq!(m["states"], 0);
    let info = StribeckPower::default().param_info();
    let params = m["parameters"].as_array().unwrap();
    assert_eq!(params.len(), info.len());
    for (p, i) in params.iter().zip(&info) {
        assert_eq!(p["name"], i.name.as_str());
        assert_eq!(p["unit"], i.unit.as_str());
        assert_eq!(p["default"].as_f64(), Some(i.default));
        assert_eq!(p["lower_exclusive"], i.lower_exclusive);
        assert_eq!(p["fixed_by_default"], i.fixed_by_default);
    }
    let v_ref = params.iter().find(|p| p["name"] == "v_ref").unwrap();
    assert_eq!(v_ref["fixed_by_default"], true);
}

#[test]
fn simulate_at_alpha_one_reproduces_the_builtin_stribeck() {
    let plugin = simulate(
        "alpha1",
        "type = \"stribeck_power\"\nmu_c = 0.2\nmu_s = 0.3\nv_s = 0.02\nviscous = 4.0\nalpha = 1.0",
    );
    let builtin = simulate(
        "builtin",
        "type = \"stribeck\"\nmu_c = 0.2\nmu_s = 0.3\nv_s = 0.02\nviscous = 4.0\ndelta = 2.0",
    );
    let cols = ["time", "x", "v"];
    let a = csv_columns(&plugin.join("trajectory.csv"), &cols);
    let b = csv_columns(&builtin.join("trajectory.csv"), &cols);
    assert_eq!(a[0].len(), 2001);
    assert_eq!(a[0], b[0]);
    for i in 0..a[0].len() {
        assert!((a[1][i] - b[1][i]).abs() < 1e-9, "x at t = {}", a[0][i]);
        assert!((a[2][i] - b[2][i]).abs() < 1e-8, "v at t = {}", a[0][i]);
    }
    let (ra, rb) = (read_report(&plugin), read_report(&builtin));
    assert_eq!(ra["half_cycles"], rb["half_cycles"]);
    let (ta, tb) = (
        ra["rest_time"].as_f64().unwrap(),
        rb["rest_time"].as_f64().unwrap(),
    );
    assert!((ta - tb).abs() < 1e-9, "{ta} vs {tb}");
}

#[test]
fn simulate_of_the_fixture_truth_dissipates_and_sticks_within_the_static_limit() {
    let truth = "type = \"stribeck_power\"\nmu_c = 0.2\nmu_s = 0.3\nv_s = 0.02\nviscous = 4.0\nalpha = 1.6\nv_ref = 0.1";
    let out = simulate("truth", truth);
    let cols = csv_columns(&out.join("trajectory.csv"), &["time", "v", "energy"]);
    let (v, e) = (&cols[1], &cols[2]);
    // Energy never increases (to round-off of the 1e-9 relative tolerance).
    for w in e.windows(2) {
        assert!(w[1] <= w[0] + 1e-12, "{} -> {}", w[0], w[1]);
    }
    let report: serde_json::Value = read_report(&out);
    // At rest the spring force is within the breakaway limit mu_s N = 4.35 N.
    let rest = report["final_displacement"].as_f64().unwrap();
    assert!(1982.0 * rest.abs() <= 0.3 * 14.5 + 1e-9, "rest at {rest}");
    assert!(report["rest_time"].as_f64().is_some());
    // Every half-cycle loses at least the Coulomb work: |x_a| - |x_b| >= 2 mu_c N / k.
    let turning: Vec<f64> = report["events"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|ev| ev["kind"] == "turning_point")
        .map(|ev| ev["displacement"].as_f64().unwrap())
        .collect();
    let mut amplitudes = vec![0.014];
    amplitudes.extend(turning.iter().map(|x| x.abs()));
    for w in amplitudes.windows(2) {
        assert!(w[0] - w[1] >= 2.0 * 0.2 * 14.5 / 1982.0, "{w:?}");
    }
    // The committed record x14mm.csv is this trajectory plus the documented noise: the
    // difference has zero mean and a standard deviation of 2e-4 m/s.
    let rec = csv_columns(&fixtures().join("x14mm.csv"), &["time", "velocity"]);
    assert_eq!(rec[0], cols[0]);
    let d: Vec<f64> = rec[1].iter().zip(v).map(|(a, b)| a - b).collect();
    let n = d.len() as f64;
    let mean = d.iter().sum::<f64>() / n;
    let sd = (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt();
    assert!(mean.abs() < 4.0 * 2e-4 / n.sqrt(), "mean {mean}");
    assert!((sd - 2e-4).abs() < 0.05 * 2e-4, "sd {sd}");
}

/// The parameters `fixtures/sim-*.toml` made the records with.
const TRUTH: [(&str, f64); 5] = [
    ("mu_c", 0.2),
    ("mu_s", 0.3),
    ("v_s", 0.02),
    ("viscous", 4.0),
    ("alpha", 1.6),
];
const NOISE: f64 = 2e-4;

/// Checks a fitted `stribeck_power` (a fit's JSON) against the truth: every free parameter
/// within 3 % and its 95 % interval containing the truth, v_ref fixed, residuals at the noise.
fn check_recovers_truth(fit: &serde_json::Value) {
    assert_eq!(fit["model"], "stribeck_power");
    assert_eq!(fit["converged"], true, "{}", fit["termination"]);
    let rms = fit["rms_residual"].as_f64().unwrap();
    assert!((rms - NOISE).abs() < 0.05 * NOISE, "rms {rms}");
    let params = fit["parameters"].as_array().unwrap();
    let get = |name: &str| params.iter().find(|p| p["name"] == name).unwrap();
    for (name, truth) in TRUTH {
        let p = get(name);
        assert_eq!(p["free"], true, "{name}");
        let value = p["value"].as_f64().unwrap();
        assert!(
            (value - truth).abs() < 0.03 * truth,
            "{name} = {value}, truth {truth}"
        );
        let ci: Vec<f64> = p["ci95"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert!(
            ci[0] < truth && truth < ci[1],
            "{name}: 95 % CI {ci:?} vs {truth}"
        );
    }
    assert_eq!(get("v_ref")["free"], false);
    assert_eq!(get("v_ref")["value"].as_f64(), Some(0.1));
}

#[test]
fn fit_recovers_the_parameters_the_fixture_was_made_with() {
    let out = scratch_dir("plugin", "fit").join("out");
    run_into(&out, "fit", &fixtures().join("fit.toml"), &[]);
    let report: serde_json::Value = read_report(&out);
    assert_eq!(report["command"], "fit");
    check_recovers_truth(&report);
    assert_eq!(report["records"].as_array().unwrap().len(), 3);
}

#[test]
fn compare_ranks_the_plugin_model_above_coulomb() {
    let out = scratch_dir("plugin", "compare").join("out");
    let models = ["--models", "coulomb,stribeck_power"];
    run_into(&out, "compare", &fixtures().join("compare.toml"), &models);
    let report: serde_json::Value = read_report(&out);
    assert_eq!(report["failed"].as_array().map(Vec::len), Some(0));
    let ranking = report["ranking"].as_array().unwrap();
    let order: Vec<&str> = ranking
        .iter()
        .map(|f| f["model"].as_str().unwrap())
        .collect();
    assert_eq!(order, ["stribeck_power", "coulomb"]);
    let aic: Vec<f64> = ranking.iter().map(|f| f["aic"].as_f64().unwrap()).collect();
    assert!(aic[0] < aic[1], "{aic:?}");
    // The true model reaches the noise; Coulomb cannot (no Stribeck dip, no drag).
    check_recovers_truth(&ranking[0]);
    assert!(ranking[1]["rms_residual"].as_f64().unwrap() > 5.0 * NOISE);
}
