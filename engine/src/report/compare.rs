//! The report of `compare`: several models fitted to the same records, ranked by AIC.

use super::fit::{fit_json, parameter_table};
use super::format::{fmt_criterion, fmt_num};
use super::{render_files, Render, Role, Sink, Table};
use crate::identify::{Comparison, FitResult};
use serde::ser::SerializeMap;
use serde::{Serialize, Serializer};

/// A model comparison. report.json holds `ranking` (each fit as in the fit report),
/// `failed`, `wall_time_s`, `command`, `config` and `files`.
#[derive(Debug, Clone)]
pub struct CompareReport {
    /// The configuration the run came from, as the front end names it.
    pub config: String,
    /// The comparison; its ranking is never empty.
    pub comparison: Comparison,
    /// Number of records fitted.
    pub records: usize,
    /// Files written with the report.
    pub files: Vec<String>,
}

impl Serialize for CompareReport {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let c = &self.comparison;
        let ranking = c
            .ranking
            .iter()
            .map(fit_json)
            .collect::<Result<Vec<_>, _>>()
            .map_err(serde::ser::Error::custom)?;
        let mut map = serializer.serialize_map(Some(6))?;
        map.serialize_entry("command", "compare")?;
        map.serialize_entry("config", &self.config)?;
        map.serialize_entry("ranking", &ranking)?;
        map.serialize_entry("failed", &c.failed)?;
        map.serialize_entry("wall_time_s", &c.wall_time_s)?;
        map.serialize_entry("files", &self.files)?;
        map.end()
    }
}

impl CompareReport {
    /// The best fit (lowest AIC), if any model could be fitted.
    pub fn best(&self) -> Option<&FitResult> {
        self.comparison.ranking.first()
    }

    /// The ranking table.
    pub fn ranking_table(&self) -> Table {
        let best_aic = self.best().map(|b| b.aic).unwrap_or(f64::NAN);
        let rows = self
            .comparison
            .ranking
            .iter()
            .enumerate()
            .map(|(i, f)| {
                vec![
                    (i + 1).to_string(),
                    f.model.clone(),
                    fmt_criterion(f.aic),
                    fmt_criterion(f.aic - best_aic),
                    fmt_criterion(f.bic),
                    fmt_num(f.rms_residual),
                    f.free_parameters.to_string(),
                    if f.converged { "yes" } else { "no" }.into(),
                ]
            })
            .collect();
        let unit = self.best().map_or("m/s", |b| b.residual_unit.as_str());
        let rms = format!("rms residual [{unit}]");
        Table::new(
            &[
                "rank",
                "model",
                "AIC",
                "dAIC",
                "BIC",
                &rms,
                "free",
                "converged",
            ],
            rows,
        )
    }
}

impl Render for CompareReport {
    fn render(&self, sink: &mut dyn Sink) {
        let c = &self.comparison;
        sink.title("frictionid compare");
        sink.paragraph(
            &format!(
                "Config: `{}`. {} model(s) fitted to {} record(s), ranked by AIC (lower is better).",
                self.config,
                c.ranking.len(),
                self.records
            ),
            Role::Detail,
        );
        sink.table(&self.ranking_table(), Role::Summary);
        if let Some(best) = self.best() {
            sink.paragraph(
                &format!(
                    "best: {} (wall time {} s)",
                    best.model,
                    fmt_num(c.wall_time_s)
                ),
                Role::Brief,
            );
        }
        if let Some(verdict) = &c.verdict {
            sink.paragraph(&format!("verdict: {}", verdict.message), Role::Brief);
        }
        sink.heading(2, "Parameters", Role::Detail);
        for f in &c.ranking {
            sink.heading(3, &f.model, Role::Detail);
            sink.table(&parameter_table(f), Role::Detail);
        }
        if !c.failed.is_empty() {
            sink.heading(2, "Failed", Role::Detail);
            let items: Vec<String> = c
                .failed
                .iter()
                .map(|f| format!("`{}`: {}", f.model, f.error))
                .collect();
            sink.list(&items, Role::Detail);
        }
        render_files(sink, &self.files);
    }
}
