//! `frictionid compare CONFIG [--models a,b]`: fit several models to the same records and rank
//! them by AIC, with BIC and RMS alongside, and their steady-state curves on one chart.

use super::fit::{fit_json, fit_options, peak_speed, record_plots};
use super::{load_inputs, print_json, say, warn, Outcome};
use crate::args::OutputArgs;
use crate::error::CliError;
use crate::plots;
use crate::progress::Progress;
use crate::report::{fmt_num, markdown_table, text_table, OutputDir};
use frictionid_engine::identify::{compare, FitOptions};
use frictionid_models::{default_model, names, FrictionModel};
use serde_json::json;
use std::path::Path;
use std::sync::Arc;

/// The models to compare: `--models`, else `[fit.options] models`, else every registered model.
/// A model named in `[model]` takes the values given there as its initial values.
fn models_to_compare(
    config: &Path,
    requested: Option<&[String]>,
    cfg: &crate::config::Config,
    from_config: Option<Vec<String>>,
) -> Result<Vec<Box<dyn FrictionModel>>, CliError> {
    let registered = names();
    let list: Vec<String> = match (requested, from_config) {
        (Some(r), _) => r.to_vec(),
        (None, Some(c)) => c,
        (None, None) => registered.clone(),
    };
    if list.is_empty() {
        return Err(CliError::Config(format!(
            "{}: no models to compare",
            config.display()
        )));
    }
    let mut models = Vec::new();
    for name in &list {
        let name = name.trim();
        if !registered.iter().any(|n| n == name) {
            let hint = frictionid_models::suggest::did_you_mean(
                name,
                registered.iter().map(String::as_str),
            );
            return Err(CliError::Config(format!(
                "unknown model `{name}` in the models to compare{hint}; registered models: {}",
                registered.join(", ")
            )));
        }
        let model = match &cfg.model {
            Some(m) if m.model.name() == name => m.model.clone(),
            _ => default_model(name)?,
        };
        models.push(model);
    }
    Ok(models)
}

/// Runs `frictionid compare`.
pub fn run(
    config: &Path,
    requested: Option<&[String]>,
    output: &OutputArgs,
) -> anyhow::Result<Outcome> {
    let inputs = load_inputs(config, "compare")?;
    let cfg = &inputs.config;
    if inputs.records.is_empty() {
        anyhow::bail!(
            "{}: compare needs at least one [[records]] entry",
            config.display()
        );
    }
    let extras = super::fit::extras(cfg)?;
    let models = models_to_compare(config, requested, cfg, extras.models.clone())?;
    // Options common to every model; per-model free lists and bounds are filtered by the
    // identifier to the parameters each model has.
    let mut opts: FitOptions = fit_options(cfg, models[0].as_ref(), None)?;
    let bar = Arc::new(Progress::new(
        models.len() as u64,
        format!("comparing {} models", models.len()),
        !output.quiet && !output.json,
    ));
    let b = bar.clone();
    let seen = Arc::new(std::sync::Mutex::new(std::collections::BTreeSet::new()));
    opts.progress = Some(Arc::new(move |p| {
        // Advance once per model, when its first iteration reports.
        if let Ok(mut s) = seen.lock() {
            if s.insert(p.model.clone()) {
                b.set_message(format!("fitting {}", p.model));
                b.inc(1);
            }
        }
    }));
    let comparison = compare(&cfg.oscillator, &models, &inputs.records, &opts)
        .map_err(|e| anyhow::anyhow!("{}: {e}", config.display()))?;
    bar.finish();
    if comparison.ranking.is_empty() {
        let why: Vec<String> = comparison
            .failed
            .iter()
            .map(|f| format!("{}: {}", f.model, f.error))
            .collect();
        anyhow::bail!(
            "{}: no model could be fitted ({})",
            config.display(),
            why.join("; ")
        );
    }

    let out = OutputDir::create(&output.out)?;
    let mut files = Vec::new();
    let best = &comparison.ranking[0];
    files.extend(record_plots(&out, best, "best_")?);
    let curves: Vec<(&str, &dyn FrictionModel)> = comparison
        .ranking
        .iter()
        .map(|f| (f.model.as_str(), f.fitted_model.as_ref()))
        .collect();
    let ss = "steady_state_curves.svg".to_string();
    plots::steady_state_curves(
        &out.path(&ss),
        &curves,
        best.oscillator.normal_force,
        peak_speed(best),
    )?;
    files.push(ss);
    files.push("report.md".into());
    files.push("report.json".into());

    let best_aic = best.aic;
    let headers = [
        "rank",
        "model",
        "AIC",
        "dAIC",
        "BIC",
        "rms residual [m/s]",
        "free",
        "converged",
    ];
    let rows: Vec<Vec<String>> = comparison
        .ranking
        .iter()
        .enumerate()
        .map(|(i, f)| {
            vec![
                (i + 1).to_string(),
                f.model.clone(),
                format!("{:.1}", f.aic),
                format!("{:.1}", f.aic - best_aic),
                format!("{:.1}", f.bic),
                fmt_num(f.rms_residual),
                f.free_parameters.to_string(),
                if f.converged { "yes" } else { "no" }.into(),
            ]
        })
        .collect();
    let report = json!({
        "command": "compare",
        "config": config.display().to_string(),
        "ranking": comparison.ranking.iter().map(fit_json).collect::<Vec<_>>(),
        "failed": comparison.failed,
        "wall_time_s": comparison.wall_time_s,
        "files": files,
    });
    let params_md: String = comparison
        .ranking
        .iter()
        .map(|f| {
            format!(
                "### {}\n\n{}\n",
                f.model,
                markdown_table(
                    &super::fit::PARAMETER_HEADERS,
                    &super::fit::parameter_rows(f)
                )
            )
        })
        .collect();
    let failed_md = if comparison.failed.is_empty() {
        String::new()
    } else {
        format!(
            "## Failed\n\n{}\n",
            comparison
                .failed
                .iter()
                .map(|f| format!("- `{}`: {}\n", f.model, f.error))
                .collect::<String>()
        )
    };
    let md = format!(
        "# frictionid compare\n\nConfig: `{}`. {} model(s) fitted to {} record(s), ranked by AIC (lower is better).\n\n{}\n## Parameters\n\n{}{}## Files\n\n{}",
        config.display(),
        comparison.ranking.len(),
        inputs.records.len(),
        markdown_table(&headers, &rows),
        params_md,
        failed_md,
        files.iter().map(|f| format!("- `{f}`\n")).collect::<String>()
    );
    out.write_text("report.md", &md)?;
    out.write_json("report.json", &report)?;
    for f in &comparison.failed {
        warn(&format!(
            "model `{}` could not be fitted: {}",
            f.model, f.error
        ));
    }
    say(
        output,
        &format!(
            "{}\nbest: {} (wall time {} s)\nwrote {}\n",
            text_table(&headers, &rows),
            best.model,
            fmt_num(comparison.wall_time_s),
            out.dir().display()
        ),
    );
    print_json(output, &report)?;
    Ok(Outcome::Done)
}
