//! `frictionid simulate CONFIG`: one motion from `[oscillator]`, `[model]` and
//! `[simulation]`, free or driven by the measured input `[simulation] input` names; writes
//! trajectory.csv, optional record.csv (noisy velocity), plots (the input's among them),
//! report.md and report.json.

use super::{load_config, publish, Outcome, REPORT_FILES};
use crate::args::OutputArgs;
use crate::plots::sets::simulate_plots;
use crate::report::{csv_columns, OutputDir};
use frictionid_engine::jobs::simulate_job;
use frictionid_engine::report::SimulateReport;
use frictionid_engine::Trajectory;
use std::path::Path;

/// trajectory.csv: time, x, v, a, internal states z1..zn, friction, energies.
fn trajectory_csv(traj: &Trajectory) -> String {
    let state_names: Vec<String> = (1..=traj.states.len()).map(|j| format!("z{j}")).collect();
    let mut cols: Vec<(&str, &[f64])> = vec![
        ("time", &traj.time),
        ("x", &traj.x),
        ("v", &traj.v),
        ("a", &traj.a),
    ];
    for (name, z) in state_names.iter().zip(&traj.states) {
        cols.push((name, z));
    }
    cols.extend([
        ("friction", traj.friction.as_slice()),
        ("kinetic", traj.mechanical.kinetic.as_slice()),
        ("potential", traj.mechanical.potential.as_slice()),
        ("stored", traj.stored.as_slice()),
        ("energy", traj.mechanical.energy.as_slice()),
    ]);
    csv_columns(&cols)
}

/// record.csv: the noisy velocity with a comment line saying how it was made.
fn record_csv(report: &SimulateReport, noisy: &[f64]) -> String {
    let header = format!(
        "# synthetic velocity record: frictionid simulate {}; model {}; x0 = {} m; noise sigma = {} m/s; seed = {}\n",
        report.config,
        report.model_json(),
        report.x0,
        report.noise.unwrap_or(0.0),
        report.seed.unwrap_or(0)
    );
    header + &csv_columns(&[("time", &report.trajectory.time), ("velocity", noisy)])
}

/// Writes the data files; returns their names.
fn write_data(out: &OutputDir, report: &SimulateReport) -> anyhow::Result<Vec<String>> {
    let mut files = vec!["trajectory.csv".to_string()];
    out.write_text("trajectory.csv", &trajectory_csv(&report.trajectory))?;
    if let Some(noisy) = &report.noisy_velocity {
        out.write_text("record.csv", &record_csv(report, noisy))?;
        files.push("record.csv".into());
    }
    Ok(files)
}

/// Runs `frictionid simulate`.
pub fn run(config: &Path, output: &OutputArgs) -> anyhow::Result<Outcome> {
    let cfg = load_config(config)?;
    cfg.require_model("simulate")?;
    cfg.require_simulation("simulate")?;
    let input = cfg.load_simulation_input()?;
    let mut report = simulate_job(&cfg.spec, input.as_ref()).map_err(|e| cfg.error(e))?;
    report.config = config.display().to_string();
    // Everything is computed; now write, report.json last.
    let out = OutputDir::create(&output.dir_for(config, "simulate"))?;
    let mut files = write_data(&out, &report)?;
    files.extend(simulate_plots(&out, &report)?);
    files.extend(REPORT_FILES.map(String::from));
    report.files = files;
    publish(&out, &report, output, config)?;
    Ok(Outcome::Done)
}
