//! `frictionid energy CONFIG`: the energy-based friction force of each record (the paper's
//! Eq. 7) against a reference force, with the paper's plots (Figs. 9-12).

use super::{load_inputs, print_json, say, Outcome};
use crate::args::OutputArgs;
use crate::config::{DifferentiatorMethod, EnergyConfig};
use crate::plots;
use crate::report::{fmt_num, markdown_table, text_table, OutputDir};
use anyhow::Context;
use frictionid_engine::energy::{
    analyze_record, mean_abs_where_defined, model_force_along, percent_difference, Differentiator,
    EnergyOptions,
};
use serde_json::json;
use std::path::Path;

/// The engine options for `[energy]` (engine defaults where not given).
pub fn energy_options(cfg: &EnergyConfig) -> EnergyOptions {
    let mut opts = EnergyOptions::default();
    match cfg.method {
        Some(DifferentiatorMethod::Paper) => opts.differentiator = Differentiator::Paper,
        Some(DifferentiatorMethod::SavitzkyGolay) | None => {
            if cfg.method.is_some() || cfg.window.is_some() || cfg.order.is_some() {
                let (w0, o0) = match opts.differentiator {
                    Differentiator::SavitzkyGolay { window, order } => (window, order),
                    _ => (21, 3),
                };
                opts.differentiator = Differentiator::SavitzkyGolay {
                    window: cfg.window.unwrap_or(w0),
                    order: cfg.order.unwrap_or(o0),
                };
            }
        }
    }
    if let Some(t) = cfg.velocity_threshold {
        opts.velocity_threshold = t;
    }
    opts
}

/// A file-name stem for a record's plots: its file name without extension.
pub fn plot_stem(record_name: &str) -> String {
    Path::new(record_name)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "record".into())
}

/// Runs `frictionid energy`.
pub fn run(config: &Path, output: &OutputArgs) -> anyhow::Result<Outcome> {
    let inputs = load_inputs(config, "energy")?;
    let cfg = &inputs.config;
    let osc = &cfg.oscillator;
    let opts = energy_options(&cfg.energy);
    // The reference: `[model]` as given, else `reference_force`, else a Coulomb fit to the
    // same records (the paper's procedure: fit mu, then compare with mu N).
    let fitted;
    let model: Option<&dyn frictionid_models::FrictionModel> = match (
        &cfg.model,
        cfg.energy.reference_force,
    ) {
        (Some(m), _) => Some(m.model.as_ref()),
        (None, Some(_)) => None,
        (None, None) => {
            let coulomb = frictionid_models::Coulomb::default();
            let fit_opts = super::fit::fit_options(cfg, &coulomb, None)?;
            fitted = frictionid_engine::identify::fit(osc, &coulomb, &inputs.records, &fit_opts)
                    .map_err(|e| {
                        anyhow::anyhow!(
                            "{}: no [model] or reference_force, and the Coulomb fit for a reference failed: {e}",
                            config.display()
                        )
                    })?;
            Some(fitted.fitted_model.as_ref())
        }
    };
    struct One {
        name: String,
        analysis: frictionid_engine::energy::EnergyAnalysis,
        model_force: Option<Vec<f64>>,
        reference: f64,
    }
    let mut results = Vec::new();
    for record in &inputs.records {
        let analysis = analyze_record(record, osc, &opts)
            .with_context(|| format!("record `{}`", record.name))?;
        let model_force = model
            .map(|m| model_force_along(m, osc, &analysis.time, &analysis.v))
            .transpose()
            .with_context(|| format!("record `{}`", record.name))?;
        // The reference: as given, or the model's mean |force| over the samples the energy
        // estimate uses (mu N for Coulomb friction).
        let reference = match (cfg.energy.reference_force, &model_force) {
            (Some(r), _) => r,
            (None, Some(f)) => mean_abs_where_defined(f, &analysis.friction),
            (None, None) => f64::NAN,
        };
        results.push(One {
            name: record.name.clone(),
            analysis,
            model_force,
            reference,
        });
    }

    let out = OutputDir::create(&output.out)?;
    let mut files = Vec::new();
    let mut rows = Vec::new();
    let mut json_records = Vec::new();
    for r in &results {
        let a = &r.analysis;
        let stem = plot_stem(&r.name);
        let xa = format!("{stem}_displacement_acceleration.svg");
        plots::displacement_acceleration(
            &out.path(&xa),
            &format!("{}: displacement and acceleration", r.name),
            &a.time,
            &a.x,
            &a.a,
        )?;
        let en = format!("{stem}_energy.svg");
        plots::energy_rate(
            &out.path(&en),
            &format!("{}: energy and dissipation rate", r.name),
            &a.time,
            &a.energy,
            &a.de_dt,
        )?;
        let ff = format!("{stem}_friction_force.svg");
        let model_label = model.map(|m| format!("model ({})", m.name()));
        // The model force where the energy estimate is defined (not masked).
        let model_shown: Option<Vec<f64>> = r.model_force.as_ref().map(|f| {
            f.iter()
                .zip(&a.friction)
                .map(|(&m, e)| if e.is_finite() { m } else { f64::NAN })
                .collect()
        });
        let ref_label = format!("reference ±{} N", fmt_num(r.reference));
        plots::friction_force(
            &out.path(&ff),
            &format!("{}: friction force", r.name),
            &a.time,
            &a.friction,
            model_label.as_deref().zip(model_shown.as_deref()),
            Some((ref_label.as_str(), r.reference)).filter(|(_, v)| v.is_finite()),
        )?;
        files.extend([xa, en, ff]);
        let pd = percent_difference(a.mean_abs_force, r.reference);
        let half: Vec<f64> = a.half_cycles.iter().map(|h| h.force).collect();
        rows.push(vec![
            r.name.clone(),
            fmt_num(a.mean_abs_force),
            fmt_num(a.half_cycle_mean),
            fmt_num(r.reference),
            format!("{pd:.2}"),
            a.half_cycles.len().to_string(),
        ]);
        json_records.push(json!({
            "file": r.name,
            "mean_abs_force": a.mean_abs_force,
            "reference": r.reference,
            "percent_difference": pd,
            "half_cycle_forces": half,
            "half_cycle_mean": a.half_cycle_mean,
            "half_cycle_std": a.half_cycle_std,
            "half_cycles": &a.half_cycles,
            "masked": a.masked,
            "samples": a.time.len(),
        }));
    }
    files.push("report.md".into());
    files.push("report.json".into());
    let report = json!({
        "command": "energy",
        "config": config.display().to_string(),
        "oscillator": osc,
        "model": cfg.model.as_ref().map(|m| &m.model),
        "options": {
            "differentiator": &opts.differentiator,
            "velocity_threshold": opts.velocity_threshold,
        },
        "records": json_records,
        "files": files,
    });
    let headers = [
        "record",
        "mean |F| [N]",
        "half-cycle mean [N]",
        "reference [N]",
        "difference [%]",
        "half-cycles",
    ];
    let md = format!(
        "# frictionid energy\n\nConfig: `{}`. Energy-based friction force (Eq. 7) of each record against the reference force.\n\n{}\n## Files\n\n{}",
        config.display(),
        markdown_table(&headers, &rows),
        files.iter().map(|f| format!("- `{f}`\n")).collect::<String>()
    );
    out.write_text("report.md", &md)?;
    out.write_json("report.json", &report)?;
    say(
        output,
        &format!(
            "{}\nwrote {}\n",
            text_table(&headers, &rows),
            out.dir().display()
        ),
    );
    print_json(output, &report)?;
    Ok(Outcome::Done)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn energy_config_maps_onto_engine_options() {
        let d = EnergyOptions::default();
        assert_eq!(energy_options(&EnergyConfig::default()), d);
        let o = energy_options(&EnergyConfig {
            method: Some(DifferentiatorMethod::Paper),
            velocity_threshold: Some(2e-3),
            ..EnergyConfig::default()
        });
        assert_eq!(o.differentiator, Differentiator::Paper);
        assert_eq!(o.velocity_threshold, 2e-3);
        let o = energy_options(&EnergyConfig {
            window: Some(41),
            ..EnergyConfig::default()
        });
        match (o.differentiator, d.differentiator) {
            (
                Differentiator::SavitzkyGolay { window, order },
                Differentiator::SavitzkyGolay { order: order0, .. },
            ) => assert_eq!((window, order), (41, order0)),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn plot_stems_come_from_file_names() {
        assert_eq!(plot_stem("data/x14mm.csv"), "x14mm");
        assert_eq!(plot_stem("x14mm.uff"), "x14mm");
    }
}
