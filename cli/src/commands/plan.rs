//! `frictionid plan CONFIG`: which records to take next, from `[plan]`'s candidates at the
//! assumed law (`[model]` or a previous fit's report), with the records already taken.

use super::{load_config, publish, Outcome, REPORT_FILES};
use crate::args::OutputArgs;
use crate::config::Config;
use crate::error::CliError;
use crate::plots::plan_plots;
use crate::report::OutputDir;
use frictionid_engine::data::{RecordSource, RecordUse};
use frictionid_engine::jobs::{plan_job, PlanInputs};
use frictionid_engine::report::PlanReport;
use frictionid_engine::spec::prior_model;
use frictionid_engine::spec::PlanSpec;
use frictionid_engine::{FrictionModel, Record};
use std::path::Path;

/// Runs `frictionid plan`.
pub fn run(config: &Path, output: &OutputArgs) -> anyhow::Result<Outcome> {
    let mut report = report(config)?;
    let out = OutputDir::create(&output.dir_for(config, "plan"))?;
    let mut files = plan_plots(&out, &report)?;
    files.extend(REPORT_FILES.map(String::from));
    report.files = files;
    for o in &report.out_of_reach {
        super::warn(&o.message.replace('`', ""));
    }
    publish(&out, &report, output, config)?;
    Ok(Outcome::Done)
}

/// `frictionid plan`'s report of `config`, no file written: the `[plan]` table's candidates
/// with their inputs, the noise record, the prior and the records already taken.
pub fn report(config: &Path) -> anyhow::Result<PlanReport> {
    let cfg = load_config(config)?;
    let plan = cfg
        .plan
        .clone()
        .ok_or_else(|| cfg.error("plan needs a [plan] table (candidates, choose)"))?;
    let taken = if cfg.records.is_empty() {
        Vec::new()
    } else {
        cfg.load_records("plan")?
    };
    let inputs = candidate_inputs(&cfg, &plan)?;
    let noise_record = plan
        .noise_record
        .as_ref()
        .map(|s| read_source(&cfg, s, "noise_record"))
        .transpose()?;
    let prior = plan
        .prior
        .as_ref()
        .map(|p| read_prior(&cfg, p))
        .transpose()?;
    let mut report = plan_job(
        &cfg.spec,
        &plan,
        PlanInputs {
            taken: &taken,
            candidate_inputs: &inputs,
            noise_record: noise_record.as_ref(),
            prior,
        },
    )
    .map_err(|e| cfg.error(e))?;
    report.config = config.display().to_string();
    Ok(report)
}

/// Each candidate's input record (`None` where it names no file).
fn candidate_inputs(cfg: &Config, plan: &PlanSpec) -> Result<Vec<Option<Record>>, CliError> {
    plan.candidates
        .iter()
        .enumerate()
        .map(|(i, c)| {
            c.input
                .as_ref()
                .map(|s| read_source(cfg, s, &format!("candidate {}: input", i + 1)))
                .transpose()
        })
        .collect()
}

/// Reads a file a `[plan]` key names, as a `[[records]]` entry is read.
fn read_source(cfg: &Config, source: &RecordSource, key: &str) -> Result<Record, CliError> {
    if source.file.is_none() {
        return Err(cfg.error(format!("[plan]: {key}: missing `file`")));
    }
    source
        .resolve_for(1, &cfg.base_dir, RecordUse::Replayed)
        .map_err(|e| cfg.error(format!("[plan]: {key}: {e}")))?
        .load()
        .map_err(CliError::from)
}

/// The fitted law of the report `path` names (a report's directory or its report.json,
/// relative to the config), with its name for the report.
fn read_prior(cfg: &Config, path: &Path) -> Result<(Box<dyn FrictionModel>, String), CliError> {
    let mut file = cfg.base_dir.join(path);
    if file.is_dir() {
        file = file.join("report.json");
    }
    let text = std::fs::read_to_string(&file)
        .map_err(|e| cfg.error(format!("[plan]: prior `{}`: {e}", file.display())))?;
    let value: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| cfg.error(format!("[plan]: prior `{}`: {e}", file.display())))?;
    let law = prior_model(&value).map_err(|e| cfg.error(e))?;
    Ok((law, path.display().to_string()))
}
