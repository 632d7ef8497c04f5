//! `frictionid campaign CONFIG [--jobs N] [--resume]`: fit every group of a manifest, as
//! `fit` (or `compare`, with `[campaign] models`) would fit a configuration listing its
//! records; tabulate the results (campaign.csv) and the parameters' trends.
//!
//! Each group's outcome is written as `groups/<id>/result.json` (atomically, after its own
//! reports) the moment it is done; campaign.csv and the reports are assembled from them at
//! the end. An interrupted run loses only the groups in flight, and `--resume` keeps the
//! groups whose result.json matches their task.

use super::{load_config, publish, warn, Outcome, REPORT_FILES};
use crate::args::OutputArgs;
use crate::config::{Config, MAX_RECORDS};
use crate::plots::trend_plots;
use crate::progress::Progress;
use crate::report::OutputDir;
use frictionid_engine::campaign::{plan_groups, CampaignSpec, GroupResult, GroupTask, Manifest};
use frictionid_engine::jobs::{
    campaign_group_job, campaign_model_names, campaign_models, GroupRun,
};
use frictionid_engine::report::{CampaignReport, GroupReport};
use frictionid_engine::spec::{Hooks, Spec};
use frictionid_models::FrictionModel;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The name of a group's result file in `groups/<id>/`.
pub const RESULT_FILE: &str = "result.json";

/// Everything a campaign runs on, checked before any fit.
pub struct Plan {
    /// The configuration.
    pub cfg: Config,
    /// Its `[campaign]` table (or the one a front end gave).
    pub campaign: CampaignSpec,
    /// The models compared in each group (`None`: the `[model]` fitted alone).
    pub models: Option<Vec<Box<dyn FrictionModel>>>,
    /// The groups, in manifest order.
    pub tasks: Vec<GroupTask>,
}

/// Runs `frictionid campaign`.
pub fn run(
    config: &Path,
    jobs: Option<usize>,
    resume: bool,
    output: &OutputArgs,
) -> anyhow::Result<Outcome> {
    let started = Instant::now();
    let plan = plan(load_config(config)?, None)?;
    let out = OutputDir::create(&output.dir_for(config, "campaign"))?;
    let results = run_groups(&plan, &out, jobs, resume, output, config)?;
    let report = write_campaign(&plan, &results, started, &out, output)?;
    for group in results
        .iter()
        .filter(|g| g.rows.iter().any(|r| r.error.is_some()))
    {
        if let Some(e) = group.rows.iter().find_map(|r| r.error.as_ref()) {
            warn(&format!("group `{}`: {e}", group.task.id));
        }
    }
    Ok(Outcome::from(report.exit_verdict()))
}

/// campaign.csv, the trend plots and the reports of the groups' `results` (in group order)
/// in `out`; returns the report.
pub fn write_campaign(
    plan: &Plan,
    results: &[GroupResult],
    started: Instant,
    out: &OutputDir,
    output: &OutputArgs,
) -> anyhow::Result<CampaignReport> {
    let config = &plan.cfg.path;
    let mut report = CampaignReport::new(
        &config.display().to_string(),
        &plan.campaign,
        results,
        started.elapsed().as_secs_f64(),
    );
    out.write_text("campaign.csv", &report.csv())?;
    let mut files = vec!["campaign.csv".to_string()];
    files.extend(trend_plots(out, &report)?);
    files.extend(REPORT_FILES.map(String::from));
    report.files = files;
    publish(out, &report, output, config)?;
    Ok(report)
}

/// The configuration `cfg`, its `[campaign]` table (or `campaign`, given by a front end),
/// the models and the groups: every error a user can fix before a fit runs.
pub fn plan(cfg: Config, campaign: Option<CampaignSpec>) -> anyhow::Result<Plan> {
    let campaign = campaign
        .or_else(|| cfg.campaign.clone())
        .ok_or_else(|| cfg.error("campaign needs a [campaign] table (manifest = \"runs.csv\")"))?;
    let models = campaign_models(&cfg.spec, &campaign).map_err(|e| cfg.error(e))?;
    let manifest = Manifest::load(&campaign.manifest, &cfg.base_dir).map_err(|e| cfg.error(e))?;
    let tasks = plan_groups(
        &manifest,
        &campaign,
        &cfg.record_defaults,
        cfg.spec.record_use(),
        &cfg.base_dir,
        MAX_RECORDS,
    )
    .map_err(|e| cfg.error(e))?;
    Ok(Plan {
        cfg,
        campaign,
        models,
        tasks,
    })
}

/// Every group's result in group order: those an earlier run wrote (with `resume`), the
/// others fitted on `jobs` threads (default: one per core).
fn run_groups(
    plan: &Plan,
    out: &OutputDir,
    jobs: Option<usize>,
    resume: bool,
    output: &OutputArgs,
    config: &Path,
) -> anyhow::Result<Vec<GroupResult>> {
    let groups_dir = out.dir().join("groups");
    let models = campaign_model_names(&plan.cfg.spec, plan.models.as_deref());
    let mut results: Vec<Option<GroupResult>> = plan
        .tasks
        .iter()
        .map(|t| {
            resume
                .then(|| written_result(&groups_dir, t, &models))
                .flatten()
        })
        .collect();
    let pending: Vec<usize> = (0..plan.tasks.len())
        .filter(|&i| results[i].is_none())
        .collect();
    let bar = Progress::items(
        pending.len() as u64,
        format!("fitting {} groups", pending.len()),
        !output.quiet && !output.json,
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.unwrap_or(0))
        .build()?;
    let fitted: Vec<(usize, anyhow::Result<GroupResult>)> = pool.install(|| {
        pending
            .par_iter()
            .map(|&i| {
                let result = fit_group(plan, &plan.tasks[i], &groups_dir, config);
                bar.item_done(&format!("group {}", plan.tasks[i].id));
                (i, result)
            })
            .collect()
    });
    bar.finish();
    for (i, result) in fitted {
        results[i] = Some(result?);
    }
    Ok(results.into_iter().flatten().collect())
}

/// The result an earlier run wrote for `task`, if it is there, readable, of the same task
/// (its manifest rows and `[record_defaults]`) and of the same `models`.
pub fn written_result(
    groups_dir: &Path,
    task: &GroupTask,
    models: &[String],
) -> Option<GroupResult> {
    let text = std::fs::read_to_string(group_dir(groups_dir, task).join(RESULT_FILE)).ok()?;
    let result: GroupResult = serde_json::from_str(&text).ok()?;
    let same_models = result.rows.iter().map(|r| &r.model).eq(models.iter());
    (result.task == *task && same_models).then_some(result)
}

fn group_dir(groups_dir: &Path, task: &GroupTask) -> PathBuf {
    groups_dir.join(&task.id)
}

/// Fits one group, writes its reports, then its result.json (last: its presence means the
/// group is done). A panic inside the fit becomes the group's failure, not the campaign's.
fn fit_group(
    plan: &Plan,
    task: &GroupTask,
    groups_dir: &Path,
    config: &Path,
) -> anyhow::Result<GroupResult> {
    let spec: &Spec = &plan.cfg.spec;
    let run = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        campaign_group_job(spec, plan.models.as_deref(), task, &Hooks::default())
    }))
    .unwrap_or_else(|_| GroupRun {
        result: GroupResult::failed(
            task,
            &campaign_model_names(spec, plan.models.as_deref()),
            "internal error while fitting this group",
        ),
        report: None,
    });
    let dir = OutputDir::create(&group_dir(groups_dir, task))?;
    if let Some(report) = run.report {
        write_group_report(&dir, report, config)?;
    }
    dir.write_json(RESULT_FILE, &run.result)?;
    Ok(run.result)
}

/// A group's own report.html, report.md and report.json, as `fit` or `compare` writes them.
fn write_group_report(dir: &OutputDir, report: GroupReport, config: &Path) -> anyhow::Result<()> {
    let silent = OutputArgs {
        out: None,
        quiet: true,
        json: false,
    };
    let name = config.display().to_string();
    match report {
        GroupReport::Fit(mut r) => {
            r.config = name;
            r.files = REPORT_FILES.map(String::from).to_vec();
            publish(dir, r.as_ref(), &silent, config)
        }
        GroupReport::Compare(mut r) => {
            r.config = name;
            r.files = REPORT_FILES.map(String::from).to_vec();
            publish(dir, r.as_ref(), &silent, config)
        }
    }
}
