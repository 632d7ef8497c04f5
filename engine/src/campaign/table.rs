//! The results table of a campaign: one row per group and model, and its CSV form.

use super::cell::condition_value;
pub(crate) use super::cell::CellValue;
use super::groups::GroupTask;
use crate::identify::{FitResult, FittedParam, Verdict};
use crate::oscillator::OscillatorProperty;
use serde::{Deserialize, Serialize};

/// What a row's fit is worth: the fit's [`Verdict`], or no fit at all.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RowVerdict {
    /// Converged, no diagnostic failed.
    Ok,
    /// Converged, a diagnostic failed.
    DiagnosticFailed,
    /// Did not converge.
    NotConverged,
    /// No fit: a record could not be read, or the model could not be fitted.
    Failed,
}

impl From<Verdict> for RowVerdict {
    fn from(v: Verdict) -> Self {
        match v {
            Verdict::Ok => Self::Ok,
            Verdict::NotConverged => Self::NotConverged,
            Verdict::DiagnosticFailed => Self::DiagnosticFailed,
        }
    }
}

impl RowVerdict {
    /// Its name in the table.
    pub fn name(self) -> &'static str {
        match self {
            Self::Ok => "ok",
            Self::DiagnosticFailed => "diagnostic_failed",
            Self::NotConverged => "not_converged",
            Self::Failed => "failed",
        }
    }
}

/// One fitted parameter in a row.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamCell {
    /// Name.
    pub name: String,
    /// Value.
    pub value: Option<f64>,
    /// Standard error.
    pub std_error: Option<f64>,
    /// `fixed`, `fitted`, or what the records say of it (`determined`, `lower_bound`,
    /// `upper_bound`, `not_identifiable`).
    pub status: String,
}

/// One row of campaign.csv: a group's fit of one model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CampaignRow {
    /// The group's id (its reports are in `groups/<id>/`).
    pub group: String,
    /// The group's conditions.
    pub conditions: Vec<(String, Option<CellValue>)>,
    /// The data file of a single-record group.
    pub file: Option<String>,
    /// The model.
    pub model: String,
    /// Records fitted.
    pub records: usize,
    /// RMS residual in the compared quantity's unit.
    pub rms_residual: Option<f64>,
    /// Akaike information criterion.
    pub aic: Option<f64>,
    /// AIC minus the group's best AIC (0 for the best, or for a single model).
    pub delta_aic: Option<f64>,
    /// Whether the fit converged.
    pub converged: bool,
    /// What the fit is worth.
    pub verdict: RowVerdict,
    /// The model's parameters (and fitted oscillator properties).
    pub parameters: Vec<ParamCell>,
    /// Why there is no fit (`verdict = failed`).
    pub error: Option<String>,
}

/// Whether `name` is an oscillator property (under any of its names), which joins a row's
/// parameters when it was fitted.
fn is_oscillator_property(name: &str) -> bool {
    OscillatorProperty::ALL
        .iter()
        .any(|p| p.keys().contains(&name))
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

fn param_cell(p: &FittedParam) -> ParamCell {
    let status = match (p.free, p.identifiability) {
        (false, _) => "fixed".to_string(),
        (true, Some(i)) => i.name().to_string(),
        (true, None) => "fitted".to_string(),
    };
    ParamCell {
        name: p.name.clone(),
        value: finite(p.value),
        std_error: p.std_error.and_then(finite),
        status,
    }
}

impl CampaignRow {
    /// The row of `fit`, a fit of group `task`.
    pub fn from_fit(task: &GroupTask, fit: &FitResult) -> Self {
        let names: Vec<String> = fit
            .fitted_model
            .param_info()
            .into_iter()
            .map(|p| p.name)
            .collect();
        let parameters = fit
            .parameters
            .iter()
            .filter(|p| names.contains(&p.name) || (p.free && is_oscillator_property(&p.name)))
            .map(param_cell)
            .collect();
        Self {
            converged: fit.converged,
            verdict: fit.verdict().into(),
            rms_residual: finite(fit.rms_residual),
            aic: finite(fit.aic),
            delta_aic: finite(fit.rank.map_or(0.0, |r| r.delta_aic)),
            parameters,
            error: None,
            ..Self::failed(task, &fit.model, "")
        }
    }

    /// The row of a model of group `task` that could not be fitted, and why.
    pub fn failed(task: &GroupTask, model: &str, error: &str) -> Self {
        Self {
            group: task.id.clone(),
            conditions: task.conditions.clone(),
            file: task.single_file().map(str::to_string),
            model: model.to_string(),
            records: task.sources.len(),
            rms_residual: None,
            aic: None,
            delta_aic: None,
            converged: false,
            verdict: RowVerdict::Failed,
            parameters: Vec::new(),
            error: Some(error.to_string()),
        }
    }

    /// The parameter `name`.
    pub fn param(&self, name: &str) -> Option<&ParamCell> {
        self.parameters.iter().find(|p| p.name == name)
    }

    /// The value of condition `name`.
    pub fn condition(&self, name: &str) -> Option<&CellValue> {
        condition_value(&self.conditions, name)
    }
}

/// A compact account of one fit of a group, for report.json.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitSummary {
    /// The model.
    pub model: String,
    /// What the fit is worth.
    pub verdict: RowVerdict,
    /// Why the solver stopped.
    pub termination: String,
    /// Solver iterations over all starts.
    pub iterations: u64,
    /// Starts.
    pub starts: usize,
    /// The messages of the diagnostics that warn or fail.
    pub warnings: Vec<String>,
    /// Wall time \[s\].
    pub wall_time_s: f64,
}

impl FitSummary {
    /// The summary of `fit`.
    pub fn of(fit: &FitResult) -> Self {
        Self {
            model: fit.model.clone(),
            verdict: fit.verdict().into(),
            termination: fit.termination.to_string(),
            iterations: fit.iterations,
            starts: fit.starts,
            warnings: fit.warnings.clone(),
            wall_time_s: fit.wall_time_s,
        }
    }
}

/// The outcome of one group: its rows (one per model) and fit summaries. Written as
/// `groups/<id>/result.json`; a campaign is assembled from these.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GroupResult {
    /// The group as it was fitted (a resumed run refits a group whose task changed).
    pub task: GroupTask,
    /// What the group's result is worth: its best fit's verdict, `failed` without a fit.
    pub verdict: RowVerdict,
    /// One row per model, in the order the models were asked for.
    pub rows: Vec<CampaignRow>,
    /// One summary per fitted model.
    pub fits: Vec<FitSummary>,
}

impl GroupResult {
    /// The result of a group that gave no fit: a failed row per model in `models`, `error`
    /// the reason.
    pub fn failed(task: &GroupTask, models: &[String], error: &str) -> Self {
        Self {
            task: task.clone(),
            verdict: RowVerdict::Failed,
            rows: models
                .iter()
                .map(|m| CampaignRow::failed(task, m, error))
                .collect(),
            fits: Vec::new(),
        }
    }
}

/// The fixed columns between the conditions and the parameters.
const FIXED_COLUMNS: [&str; 9] = [
    "file",
    "model",
    "records",
    "rms_residual",
    "aic",
    "delta_aic",
    "converged",
    "verdict",
    "error",
];

/// The parameter names of `rows`, in order of first appearance.
pub(crate) fn parameter_names(rows: &[CampaignRow]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for p in rows.iter().flat_map(|r| &r.parameters) {
        if !names.contains(&p.name) {
            names.push(p.name.clone());
        }
    }
    names
}

/// campaign.csv: `group`, the conditions, `file`, `model`, `records`, `rms_residual`,
/// `aic`, `delta_aic`, `converged`, `verdict`, `error`, then per parameter `<name>`,
/// `<name>_std_error`, `<name>_status`. Numbers are written in their shortest exact form.
pub(crate) fn campaign_csv(rows: &[CampaignRow], conditions: &[String]) -> String {
    let params = parameter_names(rows);
    let mut header: Vec<String> = vec!["group".into()];
    header.extend(conditions.iter().cloned());
    header.extend(FIXED_COLUMNS.iter().map(|c| c.to_string()));
    for p in &params {
        header.extend([p.clone(), format!("{p}_std_error"), format!("{p}_status")]);
    }
    let mut text = csv_line(&header);
    for row in rows {
        text.push_str(&csv_line(&row_cells(row, conditions, &params)));
    }
    text
}

fn num(x: Option<f64>) -> String {
    x.map(|x| x.to_string()).unwrap_or_default()
}

fn row_cells(row: &CampaignRow, conditions: &[String], params: &[String]) -> Vec<String> {
    let mut cells = vec![row.group.clone()];
    cells.extend(
        conditions
            .iter()
            .map(|c| row.condition(c).map(CellValue::text).unwrap_or_default()),
    );
    cells.extend([
        row.file.clone().unwrap_or_default(),
        row.model.clone(),
        row.records.to_string(),
        num(row.rms_residual),
        num(row.aic),
        num(row.delta_aic),
        row.converged.to_string(),
        row.verdict.name().to_string(),
        row.error.clone().unwrap_or_default(),
    ]);
    for name in params {
        match row.param(name) {
            Some(p) => cells.extend([num(p.value), num(p.std_error), p.status.clone()]),
            None => cells.extend([String::new(), String::new(), String::new()]),
        }
    }
    cells
}

/// One CSV line; cells with a comma, quote or line break are quoted.
fn csv_line(cells: &[String]) -> String {
    let quoted: Vec<String> = cells
        .iter()
        .map(|c| {
            if c.contains([',', '"', '\n', '\r']) {
                format!("\"{}\"", c.replace('"', "\"\"").replace(['\n', '\r'], " "))
            } else {
                c.clone()
            }
        })
        .collect();
    quoted.join(",") + "\n"
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::campaign::manifest::split_cells;

    #[test]
    fn csv_cells_round_trip_through_the_manifest_reader() {
        let cells: Vec<String> = ["a,b", "say \"hi\"", "plain", ""]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let line = csv_line(&cells);
        assert_eq!(split_cells(line.trim_end()), cells);
    }

    #[test]
    fn verdicts_order_from_ok_to_failed() {
        assert!(RowVerdict::Ok < RowVerdict::DiagnosticFailed);
        assert!(RowVerdict::DiagnosticFailed < RowVerdict::NotConverged);
        assert!(RowVerdict::NotConverged < RowVerdict::Failed);
        assert_eq!(CellValue::parse("5", true), CellValue::Number(5.0));
        assert_eq!(CellValue::parse("5", false), CellValue::Text("5".into()));
    }
}
