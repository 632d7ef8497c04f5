//! `frictionid compare CONFIG [--models a,b]`: fit several models to the same records and rank
//! them by AIC, with BIC and RMS alongside, and their steady-state curves on one chart.

use super::{hooks, load_inputs, progress_bar, publish, warn, Outcome, REPORT_FILES};
use crate::args::OutputArgs;
use crate::plots::sets::{fit_record_plots, input_plots, steady_state_plot};
use crate::report::OutputDir;
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

    let out = OutputDir::create(&output.dir_for(config, "compare"))?;
    let ranking = &report.comparison.ranking;
    let mut files = match ranking.first() {
        Some(best) => fit_record_plots(&out, best, "best_")?,
        None => Vec::new(),
    };
    files.extend(input_plots(
        &out,
        &inputs.records,
        cfg.spec.oscillator.axis,
    )?);
    files.extend(steady_state_plot(&out, "steady_state_curves.svg", ranking)?);
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
    Ok(report
        .comparison
        .best_verdict()
        .map_or(Outcome::Done, Outcome::from))
}
