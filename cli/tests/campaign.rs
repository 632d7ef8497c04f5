//! `frictionid campaign` against independent truths: records simulated in this file by
//! solvers that are not the fitted simulation (the exact piecewise Coulomb solution of
//! `exact.rs`; Dahl's force along an imposed sinusoid in closed form per monotone segment),
//! on a 3 x 4 grid of conditions with two records per group. Every group must recover its
//! truth and the trends must recover the laws the truths follow. Then `--resume`, a bad row,
//! and the one-line errors of a bad manifest.

use frictionid_cli::testing::Says::Contains;
use frictionid_cli::testing::{
    assert_bad_inputs, fixtures_dir, runs_ok, scratch_dir, BadInput, FMM_OSCILLATOR,
};
use frictionid_engine::exact::coulomb_free_vibration;
use frictionid_engine::synthetic::add_gaussian_noise;
use frictionid_engine::Oscillator;
use serde_json::Value;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn binary() -> &'static Path {
    Path::new(env!("CARGO_BIN_EXE_frictionid"))
}

fn campaign(config: &Path, out: &Path, extra: &[&str]) -> Output {
    Command::new(binary())
        .arg("campaign")
        .arg(config)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .expect("runs")
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("readable")).expect("JSON")
}

/// The normal forces of the grid [N].
const NORMAL: [f64; 4] = [2.0, 4.0, 6.0, 8.0];

/// Coulomb's coefficient falls with the normal force: mu = 0.30 - 0.01 N.
fn coulomb_mu(n: f64) -> f64 {
    0.30 - 0.01 * n
}

/// Dahl's rest stiffness grows with the normal force: sigma0 = 2e4 N [N/m]; mu_c = 0.3.
fn dahl_sigma0(n: f64) -> f64 {
    2e4 * n
}
const DAHL_MU: f64 = 0.3;

fn write_csv(path: &Path, header: &str, columns: &[&[f64]]) {
    let mut text = format!("{header}\n");
    for i in 0..columns[0].len() {
        let row: Vec<String> = columns.iter().map(|c| c[i].to_string()).collect();
        text.push_str(&row.join(","));
        text.push('\n');
    }
    std::fs::write(path, text).expect("written");
}

/// The Coulomb campaign: the FMM rig released at 10, 15 and 20 mm under each normal force,
/// two records (noise seeds) per group; velocity at 500 Hz for 1 s with 2e-4 m/s noise.
fn coulomb_campaign(dir: &Path) -> PathBuf {
    let osc = Oscillator::fmm();
    let time: Vec<f64> = (0..500).map(|i| i as f64 * 2e-3).collect();
    let mut rows = String::from("file,normal_force,x0,repeat\n");
    let mut seed = 1;
    for &n in &NORMAL {
        for x0 in [0.010, 0.015, 0.020] {
            for repeat in 1..=2 {
                let exact =
                    coulomb_free_vibration(&osc, coulomb_mu(n) * n, x0, &time).expect("exact");
                let mut v = exact.v.clone();
                add_gaussian_noise(&mut v, 2e-4, seed);
                seed += 1;
                let file = format!("c-{n}-{x0}-{repeat}.csv");
                write_csv(&dir.join(&file), "time,velocity", &[&time, &v]);
                rows.push_str(&format!("{file},{n},{x0},{repeat}\n"));
            }
        }
    }
    std::fs::write(dir.join("runs.csv"), rows).expect("manifest");
    let config = dir.join("coulomb.toml");
    let text = format!(
        "{FMM_OSCILLATOR}[model]\ntype = \"coulomb\"\nmu = 0.2\n[fit]\nbounds = {{ mu = [0.0, 1.0] }}\n\
         [campaign]\nmanifest = \"runs.csv\"\ngroup_by = [\"normal_force\", \"x0\"]\n"
    );
    std::fs::write(&config, text).expect("config");
    config
}

/// Dahl's force (alpha = 1) along x = A sin(w t) from F = 0 at x = 0. On a monotone segment
/// in direction s from (x_s, F_s), dF/dx = s sigma0 (1 - s F / Fc) integrates to
/// F = s Fc (1 - (1 - s F_s / Fc) exp(-sigma0 |x - x_s| / Fc)); the segments turn at
/// w t = pi/2 + k pi, where x = +-A.
fn dahl_force(time: &[f64], amplitude: f64, omega: f64, sigma0: f64, fc: f64) -> Vec<f64> {
    let along = |s: f64, xs: f64, fs: f64, x: f64| {
        s * fc * (1.0 - (1.0 - s * fs / fc) * (-sigma0 * (x - xs).abs() / fc).exp())
    };
    time.iter()
        .map(|&t| {
            let phase = omega * t;
            let turns = if phase < PI / 2.0 {
                0
            } else {
                ((phase - PI / 2.0) / PI).floor() as usize + 1
            };
            let (mut xs, mut fs, mut s) = (0.0, 0.0, 1.0);
            for _ in 0..turns {
                let turn = s * amplitude;
                fs = along(s, xs, fs, turn);
                xs = turn;
                s = -s;
            }
            along(s, xs, fs, amplitude * phase.sin())
        })
        .collect()
}

/// The Dahl campaign: a tribometer imposing x = A sin(2 pi t), A = 0.5, 1 and 2 mm, under
/// each normal force, two records (noise seeds) per group; force at 1 kHz for 1.5 s with
/// 0.01 N noise. m, c, k are unknown: a measured force needs only the normal force, and no
/// record needs x0 (its motion is replayed as measured).
fn dahl_campaign(dir: &Path) -> PathBuf {
    let omega = 2.0 * PI;
    let time: Vec<f64> = (0..1500).map(|i| i as f64 * 1e-3).collect();
    let mut rows = String::from("file,normal_force,amplitude_mm\n");
    let mut seed = 100;
    for &n in &NORMAL {
        for amplitude_mm in [0.5, 1.0, 2.0] {
            let a = amplitude_mm * 1e-3;
            let x: Vec<f64> = time.iter().map(|t| a * (omega * t).sin()).collect();
            let v: Vec<f64> = time.iter().map(|t| a * omega * (omega * t).cos()).collect();
            for repeat in 1..=2 {
                let mut f = dahl_force(&time, a, omega, dahl_sigma0(n), DAHL_MU * n);
                add_gaussian_noise(&mut f, 0.01, seed);
                seed += 1;
                let file = format!("d-{n}-{amplitude_mm}-{repeat}.csv");
                write_csv(
                    &dir.join(&file),
                    "time,displacement,velocity,force",
                    &[&time, &x, &v, &f],
                );
                rows.push_str(&format!("{file},{n},{amplitude_mm}\n"));
            }
        }
    }
    std::fs::write(dir.join("runs.csv"), rows).expect("manifest");
    let config = dir.join("dahl.toml");
    let text = "[oscillator]\n[model]\ntype = \"dahl\"\nalpha = 1.0\n[fit]\nfree = [\"sigma0\", \"mu_c\"]\n\
                [fit.options]\ndomain = \"force\"\n\
                [campaign]\nmanifest = \"runs.csv\"\ngroup_by = [\"normal_force\", \"amplitude_mm\"]\n";
    std::fs::write(&config, text).expect("config");
    config
}

/// The rows of report.json for `model`.
fn rows_of<'a>(report: &'a Value, model: &str) -> Vec<&'a Value> {
    report["rows"]
        .as_array()
        .expect("rows")
        .iter()
        .filter(|r| r["model"] == model)
        .collect()
}

fn condition(row: &Value, name: &str) -> f64 {
    row["conditions"]
        .as_array()
        .expect("conditions")
        .iter()
        .find(|c| c[0] == name)
        .and_then(|c| c[1].as_f64())
        .expect("numeric condition")
}

fn param(row: &Value, name: &str) -> (f64, f64) {
    let p = row["parameters"]
        .as_array()
        .expect("parameters")
        .iter()
        .find(|p| p["name"] == name)
        .expect("parameter");
    (
        p["value"].as_f64().expect("value"),
        p["std_error"].as_f64().unwrap_or(f64::NAN),
    )
}

/// The linear trend of `parameter` against `condition`: (slope, its standard error).
fn linear_slope(report: &Value, parameter: &str, condition: &str) -> (f64, f64) {
    let t = report["trends"]
        .as_array()
        .expect("trends")
        .iter()
        .find(|t| t["parameter"] == parameter && t["condition"] == condition)
        .expect("trend");
    let line = &t["linear"];
    (
        line["b"].as_f64().expect("slope"),
        line["b_std_error"].as_f64().expect("se"),
    )
}

#[test]
fn a_coulomb_campaign_recovers_each_group_and_the_fall_of_mu_with_the_normal_force() {
    let dir = scratch_dir("campaign", "coulomb");
    let config = coulomb_campaign(&dir);
    let out = dir.join("out");
    let (report, _) = runs_ok(Ok(campaign(&config, &out, &["--quiet"])), &out);
    let rows = rows_of(&report, "coulomb");
    assert_eq!(rows.len(), 12);
    for row in &rows {
        assert_eq!(row["records"], 2);
        let n = condition(row, "normal_force");
        let (mu, se) = param(row, "mu");
        let truth = coulomb_mu(n);
        eprintln!("coulomb N = {n}: mu = {mu:.6} +- {se:.1e} (truth {truth})");
        assert!(
            (mu - truth).abs() < 0.005 * truth,
            "N = {n}: mu {mu} vs {truth}"
        );
        assert!(
            (mu - truth).abs() < 5.0 * se,
            "N = {n}: mu {mu} +- {se} vs {truth}"
        );
    }
    let (slope, se) = linear_slope(&report, "mu", "normal_force");
    eprintln!("coulomb trend: d mu / d N = {slope:.6} +- {se:.1e} (truth -0.01)");
    assert!(
        (slope + 0.01).abs() < 3.0 * se && se < 1e-3,
        "{slope} +- {se}"
    );
    let (x0_slope, x0_se) = linear_slope(&report, "mu", "x0");
    assert!(
        x0_slope.abs() < 3.0 * x0_se + 1e-9,
        "mu does not depend on x0: {x0_slope} +- {x0_se}"
    );
    let csv = std::fs::read_to_string(out.join("campaign.csv")).expect("csv");
    assert!(csv.starts_with("group,normal_force,x0,repeat,file,model,records,rms_residual,aic,delta_aic,converged,verdict,error,mu,mu_std_error,mu_status\n"), "{csv}");
    assert_eq!(csv.lines().count(), 13);
    assert!(out
        .join("groups")
        .join("001-2_0.01")
        .join("report.json")
        .exists());
    assert!(out.join("trend_coulomb_mu_normal_force.svg").exists());
}

#[test]
fn a_dahl_campaign_recovers_each_group_and_the_rise_of_the_stiffness_with_the_normal_force() {
    let dir = scratch_dir("campaign", "dahl");
    let config = dahl_campaign(&dir);
    let out = dir.join("out");
    let (report, _) = runs_ok(Ok(campaign(&config, &out, &["--quiet"])), &out);
    let rows = rows_of(&report, "dahl");
    assert_eq!(rows.len(), 12);
    for row in &rows {
        let n = condition(row, "normal_force");
        let (sigma0, se) = param(row, "sigma0");
        let (mu_c, mu_se) = param(row, "mu_c");
        eprintln!("dahl N = {n}, A = {} mm: sigma0 = {sigma0:.4e} +- {se:.1e} (truth {:.1e}), mu_c = {mu_c:.5} +- {mu_se:.1e}", condition(row, "amplitude_mm"), dahl_sigma0(n));
        assert!(
            (sigma0 - dahl_sigma0(n)).abs() < 0.05 * dahl_sigma0(n),
            "N = {n}: sigma0 {sigma0}"
        );
        assert!(
            (mu_c - DAHL_MU).abs() < 0.005 * DAHL_MU,
            "N = {n}: mu_c {mu_c}"
        );
    }
    let (slope, se) = linear_slope(&report, "sigma0", "normal_force");
    eprintln!("dahl trend: d sigma0 / d N = {slope:.1} +- {se:.1} (truth 2e4)");
    assert!(
        (slope - 2e4).abs() < 3.0 * se && se < 0.05 * 2e4,
        "{slope} +- {se}"
    );
}

/// The fixture campaign (three FMM records, each alone) copied into `dir` with its records
/// made absolute and `extra` rows appended to its manifest.
fn fixture_campaign(dir: &Path, extra: &str) -> PathBuf {
    let fixtures = fixtures_dir();
    let config = dir.join("campaign.toml");
    std::fs::copy(fixtures.join("campaign/campaign.toml"), &config).expect("config");
    let runs = std::fs::read_to_string(fixtures.join("campaign/runs.csv")).expect("manifest");
    let absolute = runs.replace("../", &format!("{}/", fixtures.display()));
    std::fs::write(dir.join("runs.csv"), absolute + extra).expect("manifest");
    config
}

/// A run cut short leaves some groups' result.json and no campaign.csv (written last); the
/// resumed run fits only the missing groups (their count in its progress lines), refits one
/// whose result.json is unreadable, and writes the same campaign.csv as a full run.
#[test]
fn resume_fits_only_the_missing_groups_and_gives_the_same_table() {
    let dir = scratch_dir("campaign", "resume");
    let config = coulomb_campaign(&dir);
    let full = dir.join("full");
    assert_eq!(
        campaign(&config, &full, &["--quiet"]).status.code(),
        Some(0)
    );
    let expected = std::fs::read_to_string(full.join("campaign.csv")).expect("csv");

    let cut = dir.join("cut");
    std::fs::create_dir_all(cut.join("groups")).expect("dir");
    let groups: Vec<String> = (1..=12)
        .map(|i| {
            format!(
                "{i:03}-{}_{}",
                NORMAL[(i - 1) / 3],
                [0.01, 0.015, 0.02][(i - 1) % 3]
            )
        })
        .collect();
    for id in &groups[..7] {
        let from = full.join("groups").join(id).join("result.json");
        std::fs::create_dir_all(cut.join("groups").join(id)).expect("dir");
        std::fs::copy(&from, cut.join("groups").join(id).join("result.json")).expect("copied");
    }
    std::fs::write(
        cut.join("groups").join(&groups[6]).join("result.json"),
        "{\"task\": ",
    )
    .expect("torn");
    let o = campaign(&config, &cut, &["--resume", "--jobs", "2"]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    let fitted: Vec<&str> = stderr.lines().filter(|l| l.contains("] group ")).collect();
    assert_eq!(fitted.len(), 6, "{stderr}");
    assert!(fitted.iter().all(|l| l.ends_with("/6)")), "{stderr}");
    assert_eq!(
        std::fs::read_to_string(cut.join("campaign.csv")).expect("csv"),
        expected
    );
}

/// A row whose file is missing, one whose file is not a record and one of a velocity-only
/// record without `x0` (nothing to release it from) fail alone: their rows say why, the
/// others are fitted, and the exit code says a group has no fit.
#[test]
fn a_bad_file_fails_its_row_only() {
    let dir = scratch_dir("campaign", "bad-row");
    std::fs::write(dir.join("garbage.csv"), "not,a\nrecord,at all\n").expect("garbage");
    std::fs::copy(fixtures_dir().join("x14mm.csv"), dir.join("no-x0.csv")).expect("copy");
    let config = fixture_campaign(
        &dir,
        "missing.csv,0.01,10,C\ngarbage.csv,0.01,10,C\nno-x0.csv,,10,C\n",
    );
    let out = dir.join("out");
    let o = campaign(&config, &out, &["--quiet"]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let report = read_json(&out.join("report.json"));
    let rows = rows_of(&report, "coulomb");
    assert_eq!(rows.len(), 6);
    for row in &rows[..3] {
        assert_eq!(row["verdict"], "ok", "{row}");
        assert!((param(row, "mu").0 - 0.24).abs() < 1e-3);
    }
    for (row, file) in rows[3..]
        .iter()
        .zip(["missing.csv", "garbage.csv", "no-x0.csv"])
    {
        assert_eq!(row["verdict"], "failed");
        assert_eq!(row["file"], file);
        assert!(
            row["error"].as_str().expect("error").contains(file),
            "{row}"
        );
    }
    assert_eq!(
        rows[5]["error"],
        "[[records]] entry 7 (`no-x0.csv`): missing `x0` (the release displacement, m)"
    );
    let csv = std::fs::read_to_string(out.join("campaign.csv")).expect("csv");
    assert_eq!(csv.lines().count(), 7);
    assert!(stderr.contains("warning: group `004-missing`"), "{stderr}");
}

/// Mistakes found before any fit: one line naming the manifest, its line and column, exit 1.
#[test]
fn manifest_errors_are_one_line_and_name_line_and_column() {
    let config =
        |table: &str| format!("{FMM_OSCILLATOR}[model]\ntype = \"coulomb\"\n[campaign]\n{table}\n");
    let runs = "manifest = \"runs.csv\"";
    assert_bad_inputs(
        binary(),
        "campaign",
        &[
            BadInput::new(
                "no-table",
                "campaign",
                format!("{FMM_OSCILLATOR}[model]\ntype = \"coulomb\"\n"),
            )
            .says(Contains("campaign needs a [campaign] table")),
            BadInput::new("no-manifest", "campaign", config(runs))
                .says(Contains("runs.csv: cannot read the manifest")),
            BadInput::new("typed-cell", "campaign", config(runs))
                .with_file("runs.csv", "file,x0\na.csv,0.01\nb.csv,ten\n")
                .says(Contains("runs.csv:3: column `x0`: cannot use `ten`")),
            BadInput::new(
                "group-column",
                "campaign",
                config(&format!("{runs}\ngroup_by = [\"lubricnt\"]")),
            )
            .with_file("runs.csv", "file,x0,lubricant\na.csv,0.01,oil\n")
            .says(Contains(
                "no column `lubricnt` in runs.csv (did you mean `lubricant`?)",
            )),
            BadInput::new("zero-weight", "campaign", config(runs))
                .with_file("runs.csv", "file,weight\na.csv,0\n")
                .says(Contains(
                    "runs.csv:2: [[records]] entry 2 (`a.csv`): `weight` must be > 0, got 0",
                )),
            BadInput::new(
                "unknown-model",
                "campaign",
                config(&format!("{runs}\nmodels = [\"colomb\"]")),
            )
            .with_file("runs.csv", "file,x0\na.csv,0.01\n")
            .says(Contains("did you mean `coulomb`")),
        ],
    );
}
