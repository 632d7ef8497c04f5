//! A campaign of a law that reads a record channel: a gearbox joint on a driven slide whose
//! unloaded Coulomb level grows with the temperature of each run (a manifest condition),
//! Tc = 1 + 0.04 T, its load coefficient the same in every run. Each record is the engine's
//! simulation of `coulomb_load` under a multisine input with the run's own load torque as a
//! named channel (velocity noise 1e-4 m/s), fitted in the velocity domain: every group
//! recovers its level and coefficient within 1 %, and the trends recover the growth of the
//! level with the temperature within 1 % and no trend of the coefficient. Each record also
//! carries its measured temperature as a channel, swinging 2 K about the run's temperature in
//! whole periods: the campaign takes its mean as the condition `temperature_mean`, equal to
//! the manifest's value, and trends the level against it as against the manifest's column.

use frictionid_cli::testing::{runs_ok, scratch_dir};
use frictionid_engine::simulate::{
    simulate_driven, ChannelSeries, Initial, Input, RunInputs, SampleGrid, SimOptions,
};
use frictionid_engine::synthetic::{add_gaussian_noise, uniform_times};
use frictionid_engine::testing::driven_slide;
use frictionid_engine::Oscillator;
use frictionid_models::CoulombLoad;
use serde_json::Value;
use std::f64::consts::PI;
use std::fmt::Write;
use std::path::Path;
use std::process::Command;

const MASS: f64 = 2.0;
const VISCOUS: f64 = 20.0;
const MU_LOAD: f64 = 0.05;
const TEMPERATURES: [f64; 4] = [20.0, 30.0, 40.0, 50.0];

/// The unloaded level at temperature `t` [N].
fn level(t: f64) -> f64 {
    1.0 + 0.04 * t
}

fn slide() -> Oscillator {
    driven_slide(MASS, 0.0)
}

/// The run at `temperature`: time, velocity (noisy, seed `seed`), input and load as CSV.
fn run_csv(temperature: f64, seed: u64) -> String {
    let time = uniform_times(2.0, 500.0);
    let u: Vec<f64> = time
        .iter()
        .map(|t| {
            12.0 * (2.0 * PI * 0.9 * t).sin()
                + 8.0 * (2.0 * PI * 1.9 * t + 1.0).sin()
                + 5.0 * (2.0 * PI * 3.3 * t + 2.0).sin()
        })
        .collect();
    let phase = 0.1 * temperature;
    let load: Vec<f64> = time
        .iter()
        .map(|t| 30.0 * (2.0 * PI * 0.6 * t + phase).sin() + 10.0 * (2.0 * PI * 1.7 * t).sin())
        .collect();
    let law = CoulombLoad {
        mu: level(temperature),
        mu_load: MU_LOAD,
        viscous: VISCOUS,
    };
    let input = Input::new(time.clone(), u.clone()).expect("an input");
    let channels = ChannelSeries::new("run")
        .with_channel("load", time.clone(), load.clone())
        .expect("a channel");
    let motion = simulate_driven(RunInputs {
        osc: &slide(),
        model: &law,
        init: &Initial::at_rest(0.0),
        input: Some(&input),
        channels: Some(&channels),
        grid: SampleGrid {
            t_end: 2.0,
            sample_times: &time,
        },
        opts: &SimOptions::default(),
    })
    .expect("a simulation");
    let mut v = motion.v;
    add_gaussian_noise(&mut v, 1e-4, seed);
    let mut csv = String::from("time,velocity,u,load,temp\n");
    for i in 0..time.len() {
        let measured = temperature + 2.0 * (2.0 * PI * time[i]).sin();
        let _ = writeln!(csv, "{},{},{},{},{measured}", time[i], v[i], u[i], load[i]);
    }
    csv
}

fn campaign(dir: &Path) -> Value {
    let mut rows = String::from("file,temperature\n");
    for (k, &t) in TEMPERATURES.iter().enumerate() {
        let file = format!("run-{t}.csv");
        std::fs::write(dir.join(&file), run_csv(t, 40 + k as u64)).expect("a record");
        let _ = writeln!(rows, "{file},{t}");
    }
    std::fs::write(dir.join("runs.csv"), rows).expect("manifest");
    let config = dir.join("joint.toml");
    std::fs::write(
        &config,
        "[oscillator]\nmass = 2.0\ndamping = 0.0\nrestoring = { type = \"none\" }\n\
         [model]\ntype = \"coulomb_load\"\nmu = 1.5\nmu_load = 0.01\nviscous = 15.0\n\
         [record_defaults]\ninput_force_column = \"u\"\nchannels = { load = \"load\", temperature = \"temp\" }\n\
         [campaign]\nmanifest = \"runs.csv\"\n",
    )
    .expect("config");
    let out = dir.join("out");
    let (report, _) = runs_ok(
        Command::new(env!("CARGO_BIN_EXE_frictionid"))
            .arg("campaign")
            .arg(&config)
            .arg("--out")
            .arg(&out)
            .arg("--quiet")
            .output(),
        &out,
    );
    let csv = std::fs::read_to_string(out.join("campaign.csv")).expect("campaign.csv");
    let header = csv.lines().next().unwrap_or_default();
    for column in ["mu", "mu_load", "viscous", "mu_load_std_error"] {
        assert!(header.split(',').any(|c| c == column), "{header}");
    }
    assert_eq!(csv.lines().count(), 1 + TEMPERATURES.len());
    report
}

fn param(row: &Value, name: &str) -> (f64, f64) {
    let p = row["parameters"]
        .as_array()
        .and_then(|ps| ps.iter().find(|p| p["name"] == name))
        .expect("parameter");
    (
        p["value"].as_f64().expect("value"),
        p["std_error"].as_f64().unwrap_or(f64::NAN),
    )
}

fn condition(row: &Value, name: &str) -> f64 {
    row["conditions"]
        .as_array()
        .and_then(|cs| cs.iter().find(|c| c[0] == name))
        .and_then(|c| c[1].as_f64())
        .unwrap_or_else(|| panic!("a numeric condition {name}"))
}

/// The linear trend of `parameter` against `condition`: (slope, its standard error).
fn slope_against(report: &Value, parameter: &str, condition: &str) -> (f64, f64) {
    let trend = report["trends"]
        .as_array()
        .and_then(|ts| {
            ts.iter()
                .find(|t| t["parameter"] == parameter && t["condition"] == condition)
        })
        .unwrap_or_else(|| panic!("a trend of {parameter} against {condition}"));
    (
        trend["linear"]["b"].as_f64().expect("a slope"),
        trend["linear"]["b_std_error"].as_f64().expect("its error"),
    )
}

#[test]
fn a_campaign_of_a_load_reading_law_recovers_its_level_s_growth_with_the_temperature() {
    let dir = scratch_dir("campaign", "channels");
    let report = campaign(&dir);
    let rows = report["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), TEMPERATURES.len());
    for row in rows {
        let t = condition(row, "temperature");
        let measured = condition(row, "temperature_mean");
        assert!(
            (measured - t).abs() < 1e-9,
            "T = {t}: channel mean {measured}"
        );
        let (mu, mu_se) = param(row, "mu");
        let (mu_load, load_se) = param(row, "mu_load");
        eprintln!(
            "T = {t}: Tc = {mu:.5} +- {mu_se:.1e} (truth {}), mu_load = {mu_load:.5} +- \
             {load_se:.1e}",
            level(t)
        );
        assert!((mu / level(t) - 1.0).abs() < 0.01, "T = {t}: Tc {mu}");
        assert!(
            (mu - level(t)).abs() < 3.0 * mu_se,
            "T = {t}: Tc {mu} +- {mu_se}"
        );
        assert!((mu_load / MU_LOAD - 1.0).abs() < 0.01, "T = {t}: {mu_load}");
    }
    // Four points leave the line's own error estimate two degrees of freedom: the slope is
    // held to 1 % of the truth, its standard error to a fortieth of it, against the manifest's
    // temperature and against the mean of the measured one.
    for against in ["temperature", "temperature_mean"] {
        let (b, se) = slope_against(&report, "mu", against);
        eprintln!("d Tc / d {against} = {b:.6} +- {se:.1e} (truth 0.04)");
        assert!((b / 0.04 - 1.0).abs() < 0.01 && se < 1e-3, "{b} +- {se}");
    }
    let (b, se) = slope_against(&report, "mu_load", "temperature");
    eprintln!("d mu_load / d T = {b:.2e} +- {se:.1e} (truth 0)");
    // No trend: less than 0.5 % of the coefficient over the 30 K the campaign spans.
    assert!(b.abs() * 30.0 < 0.005 * MU_LOAD, "{b} +- {se}");
    let _ = std::fs::remove_dir_all(&dir);
}
