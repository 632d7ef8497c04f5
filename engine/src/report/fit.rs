//! The report of `fit`: one model fitted to the records, with the energy-based force check.

use super::format::{
    fmt_criterion, fmt_estimate, fmt_num, fmt_percent, fmt_std_error, fmt_to_error,
};
use super::{render_files, Render, Role, Sink, Table, Verdict};
use crate::identify::FitResult;
use serde::{Serialize, Serializer};

/// A fit and where it came from. report.json is the identifier's result (the fitted model's
/// parameters under `model_parameters`) with `command`, `config` and `files`.
#[derive(Debug, Clone)]
pub struct FitReport {
    /// The configuration the run came from, as the front end names it.
    pub config: String,
    /// The identifier's result.
    pub fit: FitResult,
    /// Files written with the report.
    pub files: Vec<String>,
}

/// The JSON object of one fit: the identifier's result with the fitted model under
/// `model_parameters`.
pub fn fit_json(fit: &FitResult) -> Result<serde_json::Value, serde_json::Error> {
    let mut v = serde_json::to_value(fit)?;
    if let Some(obj) = v.as_object_mut() {
        obj.remove("fitted_model");
        obj.insert(
            "model_parameters".into(),
            serde_json::to_value(&fit.fitted_model)?,
        );
    }
    Ok(v)
}

impl Serialize for FitReport {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut v = fit_json(&self.fit).map_err(serde::ser::Error::custom)?;
        if let Some(obj) = v.as_object_mut() {
            obj.insert("command".into(), "fit".into());
            obj.insert("config".into(), self.config.clone().into());
            obj.insert("files".into(), self.files.clone().into());
        }
        v.serialize(serializer)
    }
}

/// The parameter table of a fit.
pub fn parameter_table(fit: &FitResult) -> Table {
    let rows = fit
        .parameters
        .iter()
        .map(|p| {
            vec![
                p.name.clone(),
                fmt_estimate(p.value, p.std_error),
                fmt_std_error(p.std_error),
                p.ci95
                    .map(|[a, b]| {
                        format!(
                            "[{}, {}]",
                            fmt_to_error(a, p.std_error),
                            fmt_to_error(b, p.std_error)
                        )
                    })
                    .unwrap_or_else(|| "-".into()),
                p.unit.clone(),
                if p.free { "fitted" } else { "fixed" }.into(),
            ]
        })
        .collect();
    Table::new(
        &[
            "parameter",
            "value",
            "std error",
            "95 % CI",
            "unit",
            "status",
        ],
        rows,
    )
}

/// The per-record table of a fit: residual and the energy-based force check.
pub fn record_table(fit: &FitResult) -> Table {
    let rows = fit
        .records
        .iter()
        .map(|r| {
            let (m, re, pd) = match &r.energy_force {
                Some(e) => (
                    fmt_num(e.mean_abs),
                    fmt_num(e.reference),
                    fmt_percent(e.percent_difference),
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
        .collect();
    let rms = format!("rms residual [{}]", fit.residual_unit);
    Table::new(
        &[
            "record",
            "x0 [m]",
            &rms,
            "mean |F| Eq. 7 [N]",
            "model mean |F| [N]",
            "difference [%]",
        ],
        rows,
    )
}

/// The oscillator's derived quantities: k/m, c/m, the undamped natural frequency and the
/// damping ratio, with standard errors where the fit gives them.
pub fn oscillator_table(fit: &FitResult) -> Table {
    let osc = &fit.oscillator;
    let (m, c, k) = (osc.mass, osc.damping, osc.stiffness);
    let std_error = |name: &str| {
        fit.derived
            .iter()
            .find(|d| d.name == name)
            .and_then(|d| d.std_error)
    };
    let row = |name: &str, value: f64, se: Option<f64>, unit: &str| {
        vec![
            name.to_string(),
            fmt_estimate(value, se),
            fmt_std_error(se),
            unit.to_string(),
        ]
    };
    let omega = (k / m).sqrt();
    Table::new(
        &["quantity", "value", "std error", "unit"],
        vec![
            row("k/m", k / m, std_error("k/m"), "1/s²"),
            row("c/m", c / m, std_error("c/m"), "1/s"),
            row(
                "natural frequency sqrt(k/m)/2π",
                omega / (2.0 * std::f64::consts::PI),
                None,
                "Hz",
            ),
            row(
                "damping ratio c/(2 sqrt(k m))",
                c / (2.0 * (k * m).sqrt()),
                None,
                "1",
            ),
        ],
    )
}

impl FitReport {
    /// Done, not converged, or a failed diagnostic (the fit's own verdict).
    pub fn verdict(&self) -> Verdict {
        self.fit.verdict().into()
    }

    fn statistics_text(&self) -> String {
        let f = &self.fit;
        format!(
            "RMS {} residual {} {}; AIC {}; BIC {}; {} iterations, {} simulations, {} s.",
            f.compared,
            fmt_num(f.rms_residual),
            f.residual_unit,
            fmt_criterion(f.aic),
            fmt_criterion(f.bic),
            f.iterations,
            f.simulations,
            fmt_num(f.wall_time_s)
        )
    }

    fn terminal_text(&self) -> String {
        let f = &self.fit;
        format!(
            "{} ({}), rms {} residual {} {}, AIC {}",
            f.model,
            f.termination,
            f.compared,
            fmt_num(f.rms_residual),
            f.residual_unit,
            fmt_criterion(f.aic)
        )
    }
}

impl Render for FitReport {
    fn render(&self, sink: &mut dyn Sink) {
        let f = &self.fit;
        sink.title("frictionid fit");
        sink.paragraph(
            &format!(
                "Config: `{}`. Model `{}` fitted to {} record(s): {}.",
                self.config,
                f.model,
                f.records.len(),
                if f.converged {
                    "converged"
                } else {
                    "NOT converged"
                }
            ),
            Role::Detail,
        );
        sink.heading(2, "Parameters", Role::Detail);
        sink.table(&parameter_table(f), Role::Summary);
        sink.heading(2, "Oscillator", Role::Detail);
        sink.table(&oscillator_table(f), Role::Detail);
        sink.heading(2, "Records", Role::Detail);
        sink.table(&record_table(f), Role::Summary);
        sink.paragraph(&self.statistics_text(), Role::Detail);
        sink.paragraph(&self.terminal_text(), Role::Brief);
        if !f.warnings.is_empty() {
            sink.heading(2, "Warnings", Role::Detail);
            sink.list(&f.warnings, Role::Detail);
        }
        render_files(sink, &self.files);
    }
}
