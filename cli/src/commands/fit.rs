//! `frictionid fit CONFIG`: fit the config's model to its records (the paper's Fig. 8), with
//! the energy-based force check (Figs. 6, 12) and uncertainties.

use super::{hooks, load_inputs, progress_bar, publish, warn, Outcome, REPORT_FILES};
use crate::args::OutputArgs;
use crate::plots::sets::{fit_record_plots, input_plots, steady_state_plot};
use crate::report::OutputDir;
use frictionid_engine::jobs::fit_job;
use std::path::Path;

/// Runs `frictionid fit`.
pub fn run(config: &Path, output: &OutputArgs) -> anyhow::Result<Outcome> {
    let inputs = load_inputs(config, "fit")?;
    let cfg = &inputs.config;
    let model = cfg.require_model("fit")?;
    let iterations = cfg.spec.fit.search.max_iterations;
    let bar = progress_bar(
        output,
        iterations,
        &format!("fitting {}", model.model.name()),
    );
    let b = bar.clone();
    let mut report = fit_job(
        &cfg.spec,
        &inputs.records,
        &hooks(move |p| {
            b.observe(p);
            b.inc(1);
        }),
    )
    .map_err(|e| cfg.error(e))?;
    bar.finish();
    report.config = config.display().to_string();

    let out = OutputDir::create(&output.dir_for(config, "fit"))?;
    let mut files = fit_record_plots(&out, &report.fit, "")?;
    files.extend(input_plots(
        &out,
        &inputs.records,
        cfg.spec.oscillator.axis,
    )?);
    files.extend(steady_state_plot(
        &out,
        "steady_state.svg",
        std::slice::from_ref(&report.fit),
    )?);
    files.extend(REPORT_FILES.map(String::from));
    report.files = files;
    publish(&out, &report, output, config)?;
    for w in &report.fit.warnings {
        warn(w);
    }
    let outcome = Outcome::from(report.verdict());
    if outcome == Outcome::NotConverged {
        warn(&format!(
            "the fit did not converge ({}); the report is written",
            report.fit.termination
        ));
    }
    if outcome == Outcome::DiagnosticFailed {
        warn("a diagnostic of the fit failed (see `diagnostics` in the report); exit code 3");
    }
    Ok(outcome)
}
