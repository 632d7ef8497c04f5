//! The report of `compare`: several models fitted to the same records, the law to use
//! first and why ([`super::recommendation`]), then the ranking by AIC with each law's
//! held-out score, each law's diagnostics and parameters (the recommended law first).

use super::fit::{diagnostics_table, fit_json, parameter_table, sliding_column, verdict_line};
use super::format::{fmt_criterion, fmt_num, fmt_opt};
use super::recommendation::{recommendation, recommended_fit};
use super::{render_files, render_opening, Render, Role, Sink, Status, Table};
use crate::identify::{Check, Comparison, FitResult};

use serde::ser::SerializeMap;
use serde::{Serialize, Serializer};

/// A model comparison. report.json holds `recommended` (the law to use, or null),
/// `validation_scheme`, `ranking` (each fit as in the fit report, with its held-out score),
/// `verdict` (see [`crate::identify::ComparisonVerdict`]), `failed`, `wall_time_s`, `command`,
/// `config` and `files`.
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
            .map(|f| ranked_json(c, f))
            .collect::<Result<Vec<_>, _>>()
            .map_err(serde::ser::Error::custom)?;
        let recommended = c.verdict.as_ref().and_then(|v| v.recommended.as_deref());
        let mut map = serializer.serialize_map(Some(12))?;
        map.serialize_entry("command", "compare")?;
        map.serialize_entry("config", &self.config)?;
        map.serialize_entry("recommended", &recommended)?;
        map.serialize_entry("validation_scheme", &c.validation_scheme)?;
        map.serialize_entry("ranking", &ranking)?;
        map.serialize_entry("verdict", &c.verdict)?;
        map.serialize_entry("failed", &c.failed)?;
        map.serialize_entry("warnings", &c.warnings)?;
        map.serialize_entry("wall_time_s", &c.wall_time_s)?;
        map.serialize_entry("validation_wall_time_s", &c.validation_wall_time_s)?;
        map.serialize_entry("files", &self.files)?;
        map.end()
    }
}

/// A ranked fit as in the fit report, with its held-out score: `validation_rms`,
/// `validation_rms_spread` (the folds' standard deviation) and `validation_folds`.
fn ranked_json(c: &Comparison, f: &FitResult) -> Result<serde_json::Value, serde_json::Error> {
    let mut v = fit_json(f)?;
    let score = c.validation.iter().find(|s| s.model == f.model);
    if let Some(obj) = v.as_object_mut() {
        obj.insert(
            "validation_rms".into(),
            serde_json::to_value(score.and_then(|s| s.validation_rms))?,
        );
        obj.insert(
            "validation_rms_spread".into(),
            serde_json::to_value(score.and_then(|s| s.validation_rms_spread))?,
        );
        obj.insert(
            "validation_folds".into(),
            serde_json::to_value(score.map(|s| s.folds.clone()).unwrap_or_default())?,
        );
    }
    Ok(v)
}

impl CompareReport {
    /// The comparison's verdict sentence (the law to use first, then why), with the status of
    /// the recommended fit (`None` when no model could be fitted).
    pub fn verdict_line(&self) -> Option<(Status, String)> {
        let r = recommendation(&self.comparison)?;
        Some((
            r.status,
            format!("recommended: {}; {}.", r.headline, r.reasons.join("; ")),
        ))
    }

    /// The recommended fit, if the verdict names one.
    pub fn recommended(&self) -> Option<&FitResult> {
        recommended_fit(&self.comparison)
    }

    /// The best fit (lowest AIC), if any model could be fitted.
    pub fn best(&self) -> Option<&FitResult> {
        self.comparison.ranking.first()
    }

    /// The fits in the order a report shows them: the recommended first, then the ranking.
    pub fn shown_order(&self) -> Vec<&FitResult> {
        let first = self.recommended();
        first
            .into_iter()
            .chain(
                self.comparison
                    .ranking
                    .iter()
                    .filter(|f| Some(f.model.as_str()) != first.map(|r| r.model.as_str())),
            )
            .collect()
    }

    /// The ranking table: by AIC, with each law's place in the verdict.
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
                    verdict_cell(&self.comparison, f),
                    fmt_criterion(f.aic),
                    fmt_criterion(f.aic - best_aic),
                    fmt_opt(f.rank.as_ref().map(|r| r.akaike_weight)),
                    fmt_criterion(f.bic),
                    fmt_num(f.rms_residual),
                    validation_cell(&self.comparison, f),
                    f.free_parameters.to_string(),
                    converged_cell(f),
                ]
            })
            .collect();
        let unit = self.best().map_or("m/s", |b| b.residual_unit.as_str());
        let rms = format!("rms residual [{unit}]");
        Table::new(
            &[
                "rank",
                "model",
                "verdict",
                "AIC",
                "dAIC",
                "Akaike weight",
                "BIC",
                &rms,
                "held-out rms (spread)",
                "free",
                "converged",
            ],
            rows,
        )
    }
}

/// A law's place in the verdict: `recommended`, `set aside`, or `-`.
fn verdict_cell(c: &Comparison, f: &FitResult) -> String {
    let Some(v) = &c.verdict else {
        return "-".into();
    };
    if v.recommended.as_deref() == Some(f.model.as_str()) {
        "recommended".into()
    } else if v.set_aside.iter().any(|s| s.model == f.model) {
        "set aside".into()
    } else {
        "-".into()
    }
}

/// The sliding samples each record compared (the same for every model), when
/// `[fit.options] min_speed` selected them.
fn sliding_table(fit: &FitResult) -> Option<Table> {
    let (header, cells) = sliding_column(fit)?;
    let rows = fit
        .records
        .iter()
        .zip(cells)
        .map(|(r, cell)| vec![r.file.clone(), cell])
        .collect();
    Some(Table::new(&["record", &header], rows))
}

/// A law's held-out RMS and the folds' spread, or `-` when it has none.
fn validation_cell(c: &Comparison, f: &FitResult) -> String {
    let score = c.validation.iter().find(|s| s.model == f.model);
    match score.and_then(|s| s.validation_rms.zip(s.validation_rms_spread)) {
        Some((rms, spread)) => format!("{} ({})", fmt_num(rms), fmt_num(spread)),
        None => "-".into(),
    }
}

/// `yes`, `no`, or `yes, no model parameter settled` when the convergence finding warns.
fn converged_cell(fit: &FitResult) -> String {
    let warned = fit
        .diagnostics
        .iter()
        .any(|d| d.check == Check::Convergence && d.status == Status::Warn);
    match (fit.converged, warned) {
        (false, _) => "no".into(),
        (true, true) => "yes, no model parameter settled".into(),
        (true, false) => "yes".into(),
    }
}

impl Render for CompareReport {
    fn render(&self, sink: &mut dyn Sink) {
        let c = &self.comparison;
        let summary = format!(
            "{} model(s) fitted to {} record(s): the law to use first, then why; the ranking by AIC (lower is better) is information.",
            c.ranking.len(),
            self.records
        );
        render_opening(sink, "compare", &self.config, &summary);
        if let Some(r) = recommendation(c) {
            sink.recommendation(r.status, &r.headline, &r.reasons);
        }
        sink.heading(2, "Ranking", Role::Detail);
        sink.table(&self.ranking_table(), Role::Summary);
        if let Some(table) = self.best().and_then(sliding_table) {
            sink.table(&table, Role::Summary);
        }
        if let Some(verdict) = &c.verdict {
            sink.paragraph(
                &format!("information criteria: {}", verdict.information_criteria),
                Role::Detail,
            );
        }
        sink.paragraph(
            &format!(
                "wall time {} s (held-out validation {} s)",
                fmt_num(c.wall_time_s),
                fmt_num(c.validation_wall_time_s)
            ),
            Role::Brief,
        );
        // The recommended law's plots before the details of every law.
        let plots: Vec<String> = self
            .files
            .iter()
            .filter(|f| f.starts_with("best_") || f.as_str() == "steady_state_curves.svg")
            .cloned()
            .collect();
        sink.figures(&plots);
        let shown = self.shown_order();
        sink.heading(2, "Parameters", Role::Detail);
        for f in &shown {
            sink.heading(3, &f.model, Role::Detail);
            sink.table(&parameter_table(f), Role::Detail);
        }
        sink.heading(2, "Diagnostics", Role::Detail);
        for f in &shown {
            sink.heading(3, &f.model, Role::Detail);
            sink.paragraph(&verdict_line(f).1, Role::Detail);
            sink.table(&diagnostics_table(f), Role::Detail);
        }
        if !c.warnings.is_empty() {
            sink.heading(2, "Warnings", Role::Detail);
            sink.list(&c.warnings, Role::Detail);
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
