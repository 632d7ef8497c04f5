//! `frictionid energy CONFIG`: the energy-based friction force of each record (the paper's
//! Eq. 7) against a reference force, with the paper's plots (Figs. 9-12).

use super::{load_inputs, publish, Outcome, REPORT_FILES};
use crate::args::OutputArgs;
use crate::plots::sets::{energy_plots, input_plots};
use crate::report::OutputDir;
use frictionid_engine::jobs::energy_job;
use frictionid_engine::spec::Hooks;
use std::path::Path;

/// Runs `frictionid energy`.
pub fn run(config: &Path, output: &OutputArgs) -> anyhow::Result<Outcome> {
    let inputs = load_inputs(config, "energy")?;
    let cfg = &inputs.config;
    let mut report =
        energy_job(&cfg.spec, &inputs.records, &Hooks::default()).map_err(|e| cfg.error(e))?;
    report.config = config.display().to_string();
    let out = OutputDir::create(&output.dir_for(config, "energy"))?;
    let mut files = energy_plots(&out, &report)?;
    files.extend(input_plots(
        &out,
        &inputs.records,
        cfg.spec.oscillator.axis,
    )?);
    files.extend(REPORT_FILES.map(String::from));
    report.files = files;
    publish(&out, &report, output, config)?;
    Ok(Outcome::Done)
}
