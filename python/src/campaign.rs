//! Campaigns from Python: the plan (groups as plain data), one group's fit (a task any
//! `concurrent.futures` executor can run in another process or on another machine: strings
//! in, a string out) and the assembly of the results into campaign.csv and the reports. The
//! CLI's own functions do the planning and the writing; the engine's group job the fits.

use crate::errors::value_error;
use frictionid_cli::args::OutputArgs;
use frictionid_cli::commands::campaign::{plan, write_campaign, Plan};
use frictionid_cli::config::Config;
use frictionid_cli::report::OutputDir;
use frictionid_engine::campaign::{CampaignSpec, GroupResult, GroupTask};
use frictionid_engine::jobs::{campaign_group_job, campaign_models};
use frictionid_engine::report::CampaignReport;
use frictionid_engine::spec::Hooks;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;

fn text_of<T: serde::Serialize>(value: &T) -> PyResult<String> {
    serde_json::to_string(value).map_err(value_error)
}

fn from_text<T: serde::de::DeserializeOwned>(text: &str, what: &str) -> PyResult<T> {
    serde_json::from_str(text).map_err(|e| value_error(format!("{what}: {e}")))
}

/// The campaign of `config_path`, with `manifest` (a path, relative to the working
/// directory) replacing its `[campaign] manifest` when given.
fn load_plan(config_path: &Path, manifest: Option<PathBuf>) -> PyResult<Plan> {
    let cfg = Config::load(config_path).map_err(value_error)?;
    let campaign = match manifest {
        Some(m) => {
            let absolute = std::path::absolute(&m).map_err(value_error)?;
            Some(CampaignSpec {
                manifest: absolute.display().to_string(),
                ..cfg.campaign.clone().unwrap_or_default()
            })
        }
        None => None,
    };
    plan(cfg, campaign).map_err(|e| value_error(format!("{e:#}")))
}

/// The plan of a campaign as plain data: (config text, `[campaign]` table as JSON, one JSON
/// task per group).
#[pyfunction]
#[pyo3(signature = (config_path, manifest = None))]
pub fn campaign_plan(
    config_path: PathBuf,
    manifest: Option<PathBuf>,
) -> PyResult<(String, String, Vec<String>)> {
    let plan = load_plan(&config_path, manifest)?;
    let text = std::fs::read_to_string(&config_path).map_err(value_error)?;
    let tasks = plan.tasks.iter().map(text_of).collect::<PyResult<_>>()?;
    Ok((text, text_of(&plan.campaign)?, tasks))
}

/// One group fitted, as the CLI fits it: the configuration (its path, for relative names,
/// and its text), the `[campaign]` table and the task, all JSON or text; returns the group's
/// result as JSON. Runs with the GIL released.
#[pyfunction]
pub fn campaign_group(
    py: Python<'_>,
    config_path: PathBuf,
    config_text: String,
    campaign: String,
    task: String,
) -> PyResult<String> {
    let cfg = Config::parse(&config_path, &config_text).map_err(value_error)?;
    let campaign: CampaignSpec = from_text(&campaign, "campaign")?;
    let task: GroupTask = from_text(&task, "task")?;
    let models = campaign_models(&cfg.spec, &campaign).map_err(value_error)?;
    let result = py.detach(|| {
        campaign_group_job(&cfg.spec, models.as_deref(), &task, &Hooks::default()).result
    });
    text_of(&result)
}

/// The groups' results (JSON, in group order) assembled: campaign.csv's text, and with `out`
/// the CLI's files written there (campaign.csv, trend plots, report.json/md/html).
#[pyfunction]
#[pyo3(signature = (config_path, results, manifest = None, out = None))]
pub fn campaign_assemble(
    config_path: PathBuf,
    results: Vec<String>,
    manifest: Option<PathBuf>,
    out: Option<PathBuf>,
) -> PyResult<String> {
    let results: Vec<GroupResult> = results
        .iter()
        .map(|r| from_text(r, "group result"))
        .collect::<PyResult<_>>()?;
    let Some(dir) = out else {
        let report = CampaignReport::new(
            &config_path.display().to_string(),
            &CampaignSpec::default(),
            &results,
            0.0,
        );
        return Ok(report.csv());
    };
    let plan = load_plan(&config_path, manifest)?;
    let out = OutputDir::create(&dir).map_err(value_error)?;
    let quiet = OutputArgs {
        out: Some(dir),
        quiet: true,
        json: false,
    };
    let report = write_campaign(&plan, &results, Instant::now(), &out, &quiet)
        .map_err(|e| value_error(format!("{e:#}")))?;
    Ok(report.csv())
}
