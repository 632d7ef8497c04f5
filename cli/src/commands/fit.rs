//! `frictionid fit CONFIG`: fit the config's model to its records (the paper's Fig. 8), with
//! the energy-based force check (Figs. 6, 12) and uncertainties.

use super::energy::{energy_options, plot_stem};
use super::{load_inputs, print_json, say, warn, Outcome};
use crate::args::OutputArgs;
use crate::config::Config;
use crate::error::CliError;
use crate::plots;
use crate::progress::Progress;
use crate::report::{fmt_num, markdown_table, text_table, OutputDir};
use frictionid_engine::identify::{FitOptions, FitResult, OscillatorParam};
use frictionid_models::FrictionModel;
use serde::Deserialize;
use serde_json::json;
use std::path::Path;
use std::sync::Arc;

/// `[fit.options]`: identifier options beyond `free` and `bounds`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FitExtras {
    /// Oscillator properties to fit with the model: any of "mass", "damping", "stiffness".
    pub oscillator: Vec<String>,
    /// Fit a velocity offset per record.
    pub velocity_offset: bool,
    /// Fit a release-time shift per record.
    pub time_shift: bool,
    /// Number of starts (default: 1, or 4 when more than two model parameters are free).
    pub multistart: Option<usize>,
    /// Data-driven initial values for parameters the `[model]` table does not give
    /// (default true).
    pub guess: Option<bool>,
    /// Models compared by `compare` when `--models` is not given.
    pub models: Option<Vec<String>>,
}

const EXTRA_KEYS: [&str; 6] = [
    "oscillator",
    "velocity_offset",
    "time_shift",
    "multistart",
    "guess",
    "models",
];

/// Reads `[fit.options]`; unknown keys name the nearest valid one.
pub fn extras(cfg: &Config) -> Result<FitExtras, CliError> {
    let table = &cfg.fit.options;
    for key in table.keys() {
        if !EXTRA_KEYS.contains(&key.as_str()) {
            let hint = frictionid_models::suggest::did_you_mean(key, EXTRA_KEYS);
            return Err(CliError::Config(format!(
                "{}: unknown key `{key}` in [fit.options]{hint}; valid keys: {}",
                cfg.path.display(),
                EXTRA_KEYS.join(", ")
            )));
        }
    }
    let extras: FitExtras = toml::Value::Table(table.clone())
        .try_into()
        .map_err(|e| CliError::Config(format!("{}: [fit.options]: {e}", cfg.path.display())))?;
    for name in &extras.oscillator {
        if OscillatorParam::parse(name).is_none() {
            return Err(CliError::Config(format!(
                "{}: [fit.options] oscillator: `{name}` is not one of mass, damping, stiffness",
                cfg.path.display()
            )));
        }
    }
    Ok(extras)
}

/// The identifier options for `model` from the config (free list, bounds, initial values,
/// `[fit.options]`, integrator and energy options).
pub fn fit_options(
    cfg: &Config,
    model: &dyn FrictionModel,
    given: Option<&toml::Table>,
) -> Result<FitOptions, CliError> {
    let extras = extras(cfg)?;
    let names: Vec<String> = model.param_info().into_iter().map(|p| p.name).collect();
    let mut opts = FitOptions {
        free: cfg.fit.free.clone(),
        bounds: cfg
            .fit
            .bounds
            .iter()
            .map(|(k, [lo, hi])| (k.clone(), (*lo, *hi)))
            .collect(),
        guess: extras.guess.unwrap_or(true),
        keep_initial: given
            .map(|t| t.keys().filter(|k| names.contains(k)).cloned().collect())
            .unwrap_or_default(),
        oscillator: extras
            .oscillator
            .iter()
            .filter_map(|n| OscillatorParam::parse(n))
            .collect(),
        velocity_offset: extras.velocity_offset,
        time_shift: extras.time_shift,
        multistart: extras.multistart,
        energy: energy_options(&cfg.energy),
        ..FitOptions::default()
    };
    if let Some(n) = cfg.fit.max_iterations {
        opts.max_iterations = n;
    }
    if let Some(t) = cfg.fit.tolerance {
        opts.tolerance = Some(t);
    }
    Ok(opts)
}

/// A progress bar fed by the identifier's observer.
pub fn progress_for(output: &OutputArgs, total: u64, message: &str) -> Arc<Progress> {
    Arc::new(Progress::new(total, message, !output.quiet && !output.json))
}

/// Rows of the parameter table.
pub fn parameter_rows(fit: &FitResult) -> Vec<Vec<String>> {
    fit.parameters
        .iter()
        .map(|p| {
            vec![
                p.name.clone(),
                fmt_num(p.value),
                p.std_error.map(fmt_num).unwrap_or_else(|| "-".into()),
                p.ci95
                    .map(|[a, b]| format!("[{}, {}]", fmt_num(a), fmt_num(b)))
                    .unwrap_or_else(|| "-".into()),
                p.unit.clone(),
                if p.free { "fitted" } else { "fixed" }.into(),
            ]
        })
        .collect()
}

/// Headers of [`parameter_rows`].
pub const PARAMETER_HEADERS: [&str; 6] = ["parameter", "value", "std error", "95 % CI", "unit", ""];

/// Rows of the per-record table.
pub fn record_rows(fit: &FitResult) -> Vec<Vec<String>> {
    fit.records
        .iter()
        .map(|r| {
            let (m, re, pd) = match &r.energy_force {
                Some(e) => (
                    fmt_num(e.mean_abs),
                    fmt_num(e.reference),
                    format!("{:.2}", e.percent_difference),
                ),
                None => ("-".into(), "-".into(), "-".into()),
            };
            vec![
                r.file.clone(),
                fmt_num(r.x0),
                fmt_num(r.rms_residual),
                m,
                re,
                pd,
            ]
        })
        .collect()
}

/// Headers of [`record_rows`].
pub const RECORD_HEADERS: [&str; 6] = [
    "record",
    "x0 [m]",
    "rms residual [m/s]",
    "mean |F| Eq. 7 [N]",
    "model mean |F| [N]",
    "difference [%]",
];

/// The JSON object of one fit (the identifier's result plus `free`, the record files as
/// written).
pub fn fit_json(fit: &FitResult) -> serde_json::Value {
    let mut v = serde_json::to_value(fit).unwrap_or(serde_json::Value::Null);
    if let Some(obj) = v.as_object_mut() {
        obj.remove("fitted_model");
        obj.insert("model_parameters".into(), json!(&fit.fitted_model));
    }
    v
}

/// Writes the velocity-fit and friction-force plots of every record; returns the file names.
pub fn record_plots(
    out: &OutputDir,
    fit: &FitResult,
    prefix: &str,
) -> Result<Vec<String>, CliError> {
    let mut files = Vec::new();
    for r in &fit.records {
        let stem = plot_stem(&r.file);
        let vf = format!("{prefix}{stem}_velocity_fit.svg");
        plots::velocity_fit(
            &out.path(&vf),
            &r.file,
            &r.time,
            &r.measured,
            &r.fitted,
            &fit.model,
        )?;
        files.push(vf);
        if !r.energy_based_force.is_empty() {
            let ff = format!("{prefix}{stem}_friction_force.svg");
            let shown: Vec<f64> = r
                .model_force
                .iter()
                .zip(&r.energy_based_force)
                .map(|(&m, e)| if e.is_finite() { m } else { f64::NAN })
                .collect();
            let label = format!("model ({})", fit.model);
            let reference = r.energy_force.as_ref().map(|e| e.reference);
            let ref_label = reference
                .map(|x| format!("model mean |F| ±{} N", fmt_num(x)))
                .unwrap_or_default();
            plots::friction_force(
                &out.path(&ff),
                &format!("{}: energy-based and model friction force", r.file),
                &r.time,
                &r.energy_based_force,
                Some((label.as_str(), shown.as_slice())),
                reference
                    .filter(|x| x.is_finite())
                    .map(|x| (ref_label.as_str(), x)),
            )?;
            files.push(ff);
        }
    }
    Ok(files)
}

/// The largest measured speed of the records (for steady-state plots).
pub fn peak_speed(fit: &FitResult) -> f64 {
    fit.records
        .iter()
        .flat_map(|r| r.measured.iter())
        .fold(0.0f64, |m, v| m.max(v.abs()))
}

/// Runs `frictionid fit`.
pub fn run(config: &Path, output: &OutputArgs) -> anyhow::Result<Outcome> {
    let inputs = load_inputs(config, "fit")?;
    let cfg = &inputs.config;
    let model_cfg = cfg.require_model("fit")?;
    if inputs.records.is_empty() {
        anyhow::bail!(
            "{}: fit needs at least one [[records]] entry",
            config.display()
        );
    }
    let mut opts = fit_options(cfg, model_cfg.model.as_ref(), Some(&model_cfg.table))?;
    let bar = progress_for(
        output,
        opts.max_iterations,
        &format!("fitting {}", model_cfg.model.name()),
    );
    let b = bar.clone();
    opts.progress = Some(Arc::new(move |_p| b.inc(1)));
    let fit = frictionid_engine::identify::fit(
        &cfg.oscillator,
        model_cfg.model.as_ref(),
        &inputs.records,
        &opts,
    )
    .map_err(|e| anyhow::anyhow!("{}: {e}", config.display()))?;
    bar.finish();

    let out = OutputDir::create(&output.out)?;
    let mut files = record_plots(&out, &fit, "")?;
    let ss = "steady_state.svg".to_string();
    plots::steady_state_curves(
        &out.path(&ss),
        &[(fit.model.as_str(), fit.fitted_model.as_ref())],
        fit.oscillator.normal_force,
        peak_speed(&fit),
    )?;
    files.push(ss);
    files.push("report.md".into());
    files.push("report.json".into());
    let mut report = fit_json(&fit);
    if let Some(obj) = report.as_object_mut() {
        obj.insert("command".into(), json!("fit"));
        obj.insert("config".into(), json!(config.display().to_string()));
        obj.insert("files".into(), json!(files));
    }
    let md = format!(
        "# frictionid fit\n\nConfig: `{}`. Model `{}` fitted to {} record(s): {}.\n\n## Parameters\n\n{}\n## Records\n\n{}\nRMS residual {} m/s; AIC {}; BIC {}; {} iterations, {} simulations, {} s.\n\n{}## Files\n\n{}",
        config.display(),
        fit.model,
        fit.records.len(),
        if fit.converged { "converged" } else { "NOT converged" },
        markdown_table(&PARAMETER_HEADERS, &parameter_rows(&fit)),
        markdown_table(&RECORD_HEADERS, &record_rows(&fit)),
        fmt_num(fit.rms_residual),
        fmt_num(fit.aic),
        fmt_num(fit.bic),
        fit.iterations,
        fit.simulations,
        fmt_num(fit.wall_time_s),
        if fit.warnings.is_empty() {
            String::new()
        } else {
            format!(
                "## Warnings\n\n{}\n",
                fit.warnings.iter().map(|w| format!("- {w}\n")).collect::<String>()
            )
        },
        files.iter().map(|f| format!("- `{f}`\n")).collect::<String>()
    );
    out.write_text("report.md", &md)?;
    out.write_json("report.json", &report)?;
    for w in &fit.warnings {
        warn(w);
    }
    say(
        output,
        &format!(
            "{}\n{}\n{} ({}), rms residual {} m/s, AIC {}\nwrote {}\n",
            text_table(&PARAMETER_HEADERS, &parameter_rows(&fit)),
            text_table(&RECORD_HEADERS, &record_rows(&fit)),
            fit.model,
            fit.termination,
            fmt_num(fit.rms_residual),
            fmt_num(fit.aic),
            out.dir().display()
        ),
    );
    print_json(output, &report)?;
    if fit.converged {
        Ok(Outcome::Done)
    } else {
        warn(&format!(
            "the fit did not converge ({}); the report is written",
            fit.termination
        ));
        Ok(Outcome::NotConverged)
    }
}
