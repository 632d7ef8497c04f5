//! A configuration file run from Python: the job `frictionid <command>` runs on it, returned
//! as the module's functions return theirs (the report's dict with its series, and its text
//! forms). The CLI's report folder is written only when `out` names one.

use crate::api::{models, run_job};
use crate::convert::serialized;
use crate::errors::{job_error_as, value_error};
use crate::outputs::{compare_output, energy_output, fit_output, simulate_output};
use frictionid_cli::args::OutputArgs;
use frictionid_cli::commands::{self, load_config, load_inputs};
use frictionid_cli::config::Config;
use frictionid_engine::jobs::{compare_job, energy_job, fit_job, simulate_job, JobError};
use frictionid_engine::report::{CompareReport, EnergyReport, FitReport, SimulateReport};
use frictionid_engine::spec::Hooks;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::path::{Path, PathBuf};

/// The commands [`run`] knows besides `models`.
const COMMANDS: [&str; 5] = ["simulate", "fit", "compare", "energy", "plan"];

/// A configuration problem (the file, its records) as a `ValueError` with the CLI's text.
fn config_error(e: impl Into<anyhow::Error>) -> PyErr {
    value_error(format!("{:#}", e.into()))
}

/// A job's error named after the configuration, as the CLI prints it.
fn job_error_in(cfg: &Config, e: JobError) -> PyErr {
    job_error_as(&e, cfg.error(&e).to_string())
}

/// `frictionid fit`'s report of `config`, no file written.
fn fit_report(config: &Path, hooks: &Hooks) -> PyResult<FitReport> {
    let inputs = load_inputs(config, "fit").map_err(config_error)?;
    let cfg = &inputs.config;
    cfg.require_model("fit").map_err(config_error)?;
    let mut report =
        fit_job(&cfg.spec, &inputs.records, hooks).map_err(|e| job_error_in(cfg, e))?;
    report.config = config.display().to_string();
    Ok(report)
}

/// `frictionid compare`'s report of `config` (the models it lists), no file written.
fn compare_report(config: &Path, hooks: &Hooks) -> PyResult<CompareReport> {
    let inputs = load_inputs(config, "compare").map_err(config_error)?;
    let cfg = &inputs.config;
    let models = cfg
        .spec
        .models_to_compare(None)
        .map_err(|e| config_error(cfg.error(e)))?;
    let mut report = compare_job(&cfg.spec, &models, &inputs.records, hooks)
        .map_err(|e| job_error_in(cfg, e))?;
    report.config = config.display().to_string();
    Ok(report)
}

/// `frictionid energy`'s report of `config`, no file written.
fn energy_report(config: &Path, hooks: &Hooks) -> PyResult<EnergyReport> {
    let inputs = load_inputs(config, "energy").map_err(config_error)?;
    let cfg = &inputs.config;
    let mut report =
        energy_job(&cfg.spec, &inputs.records, hooks).map_err(|e| job_error_in(cfg, e))?;
    report.config = config.display().to_string();
    Ok(report)
}

/// `frictionid simulate`'s report of `config`, no file written.
fn simulate_report(config: &Path) -> PyResult<SimulateReport> {
    let cfg = load_config(config).map_err(config_error)?;
    cfg.require_model("simulate").map_err(config_error)?;
    cfg.require_simulation("simulate").map_err(config_error)?;
    let input = cfg.load_simulation_input().map_err(config_error)?;
    let mut report = simulate_job(&cfg.spec, input.as_ref()).map_err(|e| job_error_in(&cfg, e))?;
    report.config = config.display().to_string();
    Ok(report)
}

/// The report of `command` on `config` as `(dict, texts)`.
fn computed<'py>(py: Python<'py>, config: PathBuf, command: &str) -> PyResult<Bound<'py, PyTuple>> {
    if command == "plan" {
        let report = py
            .detach(|| commands::plan::report(&config))
            .map_err(config_error)?;
        return PyTuple::new(py, [serialized(py, &report)?, PyDict::new(py).into_any()]);
    }
    let (dict, texts) = match command {
        "fit" => fit_output(py, &run_job(py, move |h| fit_report(&config, &h))?)?,
        "compare" => compare_output(py, &run_job(py, move |h| compare_report(&config, &h))?)?,
        "energy" => energy_output(py, &run_job(py, move |h| energy_report(&config, &h))?)?,
        _ => simulate_output(py, &run_job(py, move |_| simulate_report(&config))?)?,
    };
    PyTuple::new(py, [dict.into_any(), texts.into_any()])
}

/// Writes the CLI's report folder of `command` on `config` into `out`, exactly as
/// `frictionid <command> <config> --quiet --out <out>` does.
fn write_folder(py: Python<'_>, config: &Path, command: &str, out: PathBuf) -> PyResult<()> {
    let output = OutputArgs {
        out: Some(out),
        quiet: true,
        json: false,
    };
    let ran = py.detach(|| match command {
        "fit" => commands::fit::run(config, &output),
        "compare" => commands::compare::run(config, None, &output),
        "energy" => commands::energy::run(config, &output),
        "plan" => commands::plan::run(config, &output),
        _ => commands::simulate::run(config, &output),
    });
    ran.map(|_| ()).map_err(config_error)
}

/// Runs `command` (`fit`, `compare`, `energy`, `simulate`, `plan` or `models`) on a configuration
/// file as the CLI does; returns `(dict, texts)` as the module's functions do (`models`: the
/// listing). With `out`, the CLI's report folder is written there too (the job runs again,
/// in the CLI's own code, so the folder is exactly the CLI's); without it nothing is written.
#[pyfunction]
#[pyo3(signature = (config_path, command = "fit", out = None))]
pub fn run<'py>(
    py: Python<'py>,
    config_path: PathBuf,
    command: &str,
    out: Option<PathBuf>,
) -> PyResult<Bound<'py, PyAny>> {
    if command == "models" {
        return models(py, "linear");
    }
    if !COMMANDS.contains(&command) {
        return Err(value_error(format!(
            "unknown command `{command}`; one of: simulate, fit, compare, energy, plan, models"
        )));
    }
    let result = computed(py, config_path.clone(), command)?;
    if let Some(dir) = out {
        write_folder(py, &config_path, command, dir)?;
    }
    Ok(result.into_any())
}
