//! `frictionid compare CONFIG [--models a,b]`: fit several models to the same records, name
//! the law to use (held-out validation, parsimony, identifiability) and rank them by AIC, with
//! the recommended law's plots first and every law's steady-state curve on one chart.
//!
//! Without `--out`, a run with `--models a,b` writes into `compare-a-b/` beside the plain
//! run's `compare/`, so that a selection never overwrites the config's own comparison.

use super::{hooks, load_inputs, progress_bar, publish, warn, Outcome, REPORT_FILES};
use crate::args::OutputArgs;
use crate::plots::sets::{fit_record_plots, input_plots, steady_state_plot};
use crate::report::OutputDir;
use frictionid_engine::identify::FitResult;
use frictionid_engine::jobs::compare_job;
use std::collections::BTreeSet;
use std::path::Path;
use std::sync::Mutex;

/// Runs `frictionid compare`.
pub fn run(
    config: &Path,
    requested: Option<&[String]>,
    output: &OutputArgs,
) -> anyhow::Result<Outcome> {
    let inputs = load_inputs(config, "compare")?;
    let cfg = &inputs.config;
    let models = cfg
        .spec
        .models_to_compare(requested)
        .map_err(|e| cfg.error(e))?;
    let bar = progress_bar(
        output,
        models.len() as u64,
        &format!("comparing {} models", models.len()),
    );
    let b = bar.clone();
    let seen = Mutex::new(BTreeSet::new());
    let on_progress = move |p: &frictionid_engine::identify::Progress| {
        b.observe(p);
        // Advance once per model, when its first iteration reports.
        if seen
            .lock()
            .map(|mut s| s.insert(p.model.clone()))
            .unwrap_or(false)
        {
            b.inc(1);
        }
    };
    let mut report = compare_job(&cfg.spec, &models, &inputs.records, &hooks(on_progress))
        .map_err(|e| cfg.error(e))?;
    bar.finish();
    report.config = config.display().to_string();

    let out = OutputDir::create(&output.dir_for(config, &folder_name(requested)))?;
    let shown: Vec<FitResult> = report.shown_order().into_iter().cloned().collect();
    // The plots of the law the report recommends (else the lowest AIC's).
    let mut files = match shown.first() {
        Some(first) => fit_record_plots(&out, first, "best_")?,
        None => Vec::new(),
    };
    files.extend(input_plots(
        &out,
        &inputs.records,
        cfg.spec.oscillator.axis,
    )?);
    files.extend(steady_state_plot(&out, "steady_state_curves.svg", &shown)?);
    files.extend(REPORT_FILES.map(String::from));
    report.files = files;
    publish(&out, &report, output, config)?;
    for f in &report.comparison.failed {
        warn(&format!(
            "model `{}` could not be fitted: {}",
            f.model, f.error
        ));
    }
    for w in &report.comparison.warnings {
        warn(w);
    }
    // The exit code follows the law the report recommends, as its verdict box does.
    let verdict = report
        .recommended()
        .map(FitResult::verdict)
        .or_else(|| report.comparison.best_verdict());
    Ok(verdict.map_or(Outcome::Done, Outcome::from))
}

/// The output folder of a run (under `frictionid-out/<config stem>/` when `--out` is not
/// given): `compare` for the config's own models, `compare-<a>-<b>` for `--models a,b`
/// (each name's characters other than letters, digits and `_` as `_`; a selection of more
/// than 60 characters cut there and ended by its length, so the name stays a valid one).
pub fn folder_name(requested: Option<&[String]>) -> String {
    let Some(models) = requested.filter(|m| !m.is_empty()) else {
        return "compare".into();
    };
    let clean: Vec<String> = models
        .iter()
        .map(|m| {
            m.trim()
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || c == '_' {
                        c
                    } else {
                        '_'
                    }
                })
                .collect()
        })
        .collect();
    let joined = clean.join("-");
    if joined.len() <= 60 {
        format!("compare-{joined}")
    } else {
        let cut: String = joined.chars().take(60).collect();
        format!("compare-{cut}-{}", joined.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_selection_of_models_names_its_own_folder() {
        assert_eq!(folder_name(None), "compare");
        assert_eq!(folder_name(Some(&[])), "compare");
        let models = ["coulomb".to_string(), "stribeck".into(), "lugre".into()];
        assert_eq!(folder_name(Some(&models)), "compare-coulomb-stribeck-lugre");
        assert_eq!(folder_name(Some(&["a/b".to_string()])), "compare-a_b");
        let many: Vec<String> = (0..20).map(|i| format!("model_{i}")).collect();
        let long = folder_name(Some(&many));
        assert!(
            long.len() < 80 && long.starts_with("compare-model_0-"),
            "{long}"
        );
        assert_ne!(long, folder_name(Some(&many[..19])));
    }
}
