//! The report of `campaign`: every group's fits in one table, and the trends of the fitted
//! parameters against the numeric conditions.

use super::format::{fmt_criterion, fmt_estimate, fmt_num};
use super::{
    render_files, render_opening, CompareReport, FitReport, Render, Role, Sink, Status, Table,
    Verdict,
};
use crate::campaign::table::{campaign_csv, FitSummary};
use crate::campaign::{
    campaign_trends, CampaignRow, CampaignSpec, GroupResult, LineFit, RowVerdict, Trend, TrendForm,
};
use serde::Serialize;

/// Most rows of the results table a terminal summary shows.
const TERMINAL_ROWS: usize = 30;

/// The report `fit` or `compare` gives for one group's records.
#[derive(Debug, Clone)]
pub enum GroupReport {
    /// The `[model]` fitted alone.
    Fit(Box<FitReport>),
    /// The campaign's models compared.
    Compare(Box<CompareReport>),
}

/// One group in report.json.
#[derive(Debug, Clone, Serialize)]
pub struct GroupSummary {
    /// Its id (its reports are in `groups/<id>/`).
    pub id: String,
    /// The manifest lines of its rows.
    pub lines: Vec<usize>,
    /// Its records' files.
    pub files: Vec<String>,
    /// What its result is worth.
    pub verdict: RowVerdict,
    /// Its fits, one per model fitted.
    pub fits: Vec<FitSummary>,
}

/// A campaign's results. report.json holds `command`, `config`, `campaign` (the table as
/// given), `conditions`, `numeric_conditions`, `verdict`, `rows` (as campaign.csv), `groups`,
/// `trends`, `files` and `wall_time_s`.
#[derive(Debug, Clone, Serialize)]
pub struct CampaignReport {
    /// Always `campaign`.
    pub command: String,
    /// The configuration the run came from, as the front end names it.
    pub config: String,
    /// The `[campaign]` table.
    pub campaign: CampaignSpec,
    /// The condition columns, in manifest order.
    pub conditions: Vec<String>,
    /// The conditions whose every value is a number (the abscissae of the trends).
    pub numeric_conditions: Vec<String>,
    /// The worst of the groups' verdicts.
    pub verdict: RowVerdict,
    /// One row per group and model, in group order.
    pub rows: Vec<CampaignRow>,
    /// Each group's fits.
    pub groups: Vec<GroupSummary>,
    /// Each fitted parameter against each numeric condition.
    pub trends: Vec<Trend>,
    /// Files written with the report.
    pub files: Vec<String>,
    /// Wall time of this run (groups done in an earlier run not included) \[s\].
    pub wall_time_s: f64,
}

impl CampaignReport {
    /// The report of the groups' `results` (in group order), with trends.
    pub fn new(
        config: &str,
        campaign: &CampaignSpec,
        results: &[GroupResult],
        wall_time_s: f64,
    ) -> Self {
        let conditions = condition_names(results);
        let rows: Vec<CampaignRow> = results.iter().flat_map(|g| g.rows.clone()).collect();
        let numeric_conditions = numeric_conditions(&conditions, results);
        let trends = campaign_trends(&rows, &numeric_conditions);
        let groups = results
            .iter()
            .map(|g| GroupSummary {
                id: g.task.id.clone(),
                lines: g.task.lines.clone(),
                files: g
                    .task
                    .sources
                    .iter()
                    .filter_map(|s| s.file.clone())
                    .collect(),
                verdict: g.verdict,
                fits: g.fits.clone(),
            })
            .collect();
        Self {
            command: "campaign".into(),
            config: config.into(),
            campaign: campaign.clone(),
            verdict: results
                .iter()
                .map(|g| g.verdict)
                .max()
                .unwrap_or(RowVerdict::Ok),
            conditions,
            numeric_conditions,
            rows,
            groups,
            trends,
            files: Vec::new(),
            wall_time_s,
        }
    }

    /// campaign.csv.
    pub fn csv(&self) -> String {
        campaign_csv(&self.rows, &self.conditions)
    }

    /// The verdict a front end turns into its exit code: a group without a converged fit
    /// counts as not converged.
    pub fn exit_verdict(&self) -> Verdict {
        match self.verdict {
            RowVerdict::Ok => Verdict::Ok,
            RowVerdict::DiagnosticFailed => Verdict::DiagnosticFailed,
            RowVerdict::NotConverged | RowVerdict::Failed => Verdict::NotConverged,
        }
    }

    /// The results table as shown: conditions, model, verdict and each parameter with its
    /// standard error.
    pub fn results_table(&self) -> Table {
        let params = crate::campaign::table::parameter_names(&self.rows);
        let mut headers: Vec<String> = vec!["group".into()];
        headers.extend(self.conditions.iter().cloned());
        headers.extend(["model", "records", "dAIC", "verdict"].map(String::from));
        headers.extend(params.iter().cloned());
        let rows = self
            .rows
            .iter()
            .map(|r| {
                let mut cells = vec![r.group.clone()];
                cells.extend(
                    self.conditions
                        .iter()
                        .map(|c| r.condition(c).map_or("-".into(), |v| v.text())),
                );
                cells.extend([
                    r.model.clone(),
                    r.records.to_string(),
                    fmt_criterion(r.delta_aic.unwrap_or(f64::NAN)),
                    r.verdict.name().to_string(),
                ]);
                cells.extend(params.iter().map(|p| {
                    r.param(p)
                        .and_then(|c| c.value.map(|v| fmt_estimate(v, c.std_error)))
                        .unwrap_or_else(|| "-".into())
                }));
                cells
            })
            .collect();
        Table { headers, rows }
    }

    /// The trends table: per model, parameter and condition, the linear slope and the power
    /// law's exponent with their standard errors, and the better form.
    pub fn trends_table(&self) -> Table {
        let fit_cells = |f: &Option<LineFit>| match f {
            Some(f) => [
                fmt_estimate(f.a, f.a_std_error),
                fmt_estimate(f.b, f.b_std_error),
                fmt_num(f.aic),
            ],
            None => ["-".into(), "-".into(), "-".into()],
        };
        let rows = self
            .trends
            .iter()
            .map(|t| {
                let mut cells = vec![
                    t.model.clone(),
                    t.parameter.clone(),
                    t.condition.clone(),
                    t.points.to_string(),
                ];
                cells.extend(fit_cells(&t.linear));
                cells.extend(fit_cells(&t.power_law));
                cells.push(match t.better {
                    Some(TrendForm::Linear) => "linear".into(),
                    Some(TrendForm::PowerLaw) => "power law".into(),
                    None => "-".into(),
                });
                cells
            })
            .collect();
        Table::new(
            &[
                "model",
                "parameter",
                "condition",
                "groups",
                "intercept",
                "slope",
                "AIC (linear)",
                "prefactor",
                "exponent",
                "AIC (power law)",
                "better",
            ],
            rows,
        )
    }

    fn verdict_text(&self) -> (Status, String) {
        let count = |v: RowVerdict| self.groups.iter().filter(|g| g.verdict == v).count();
        let (failed, nc, flagged) = (
            count(RowVerdict::Failed),
            count(RowVerdict::NotConverged),
            count(RowVerdict::DiagnosticFailed),
        );
        let n = self.groups.len();
        if failed + nc + flagged == 0 {
            return (
                Status::Pass,
                format!("all {n} groups fitted and passed their checks."),
            );
        }
        let status = if failed + nc > 0 {
            Status::Fail
        } else {
            Status::Warn
        };
        (
            status,
            format!(
                "of {n} groups, {failed} could not be fitted, {nc} did not converge and {flagged} failed a diagnostic (see each group's row and report)."
            ),
        )
    }
}

/// The conditions whose values are numbers in every group that has one.
/// The conditions of the groups in order of first appearance: the manifest's columns, then
/// the channel means of groups whose records carry named channels.
fn condition_names(results: &[GroupResult]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for (name, _) in results.iter().flat_map(|g| &g.task.conditions) {
        if !names.contains(name) {
            names.push(name.clone());
        }
    }
    names
}

fn numeric_conditions(conditions: &[String], results: &[GroupResult]) -> Vec<String> {
    conditions
        .iter()
        .filter(|&name| {
            let values: Vec<_> = results
                .iter()
                .filter_map(|g| g.task.condition(name))
                .collect();
            !values.is_empty() && values.iter().all(|v| v.number().is_some())
        })
        .cloned()
        .collect()
}

impl Render for CampaignReport {
    fn render(&self, sink: &mut dyn Sink) {
        let summary = format!(
            "{} group(s) from the manifest `{}`, {} row(s).",
            self.groups.len(),
            self.campaign.manifest,
            self.rows.len()
        );
        render_opening(sink, "campaign", &self.config, &summary);
        let (status, text) = self.verdict_text();
        sink.verdict(status, &text);
        sink.paragraph(&format!("verdict: {text}"), Role::Brief);
        sink.heading(2, "Results", Role::Detail);
        // A terminal shows the table of a small campaign; a large one's is in the files.
        let role = if self.rows.len() <= TERMINAL_ROWS {
            Role::Summary
        } else {
            sink.paragraph(
                &format!("{} rows: see campaign.csv and report.html", self.rows.len()),
                Role::Brief,
            );
            Role::Detail
        };
        sink.table(&self.results_table(), role);
        let failures: Vec<String> = self
            .rows
            .iter()
            .filter_map(|r| {
                r.error
                    .as_ref()
                    .map(|e| format!("`{}` ({}): {e}", r.group, r.model))
            })
            .collect();
        if !failures.is_empty() {
            sink.heading(2, "Failed groups", Role::Detail);
            sink.list(&failures, Role::Summary);
        }
        if !self.trends.is_empty() {
            sink.heading(2, "Trends", Role::Detail);
            sink.paragraph(
                "Each fitted parameter against each numeric condition: y = intercept + slope x and y = prefactor x^exponent, weighted by 1/standard error², standard errors scaled by the reduced chi²; the better form has the lower AIC.",
                Role::Detail,
            );
            sink.table(&self.trends_table(), Role::Detail);
        }
        render_files(sink, &self.files);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::campaign::{CellValue, GroupTask, ParamCell};
    use crate::report::markdown::MarkdownWriter;

    fn group(id: &str, load: f64, lube: &str, verdict: RowVerdict, mu: f64) -> GroupResult {
        let task = GroupTask {
            id: id.into(),
            conditions: vec![
                ("load".into(), Some(CellValue::Number(load))),
                ("lube".into(), Some(CellValue::Text(lube.into()))),
            ],
            sources: Vec::new(),
            lines: vec![2],
            base_dir: ".".into(),
        };
        let mut row = CampaignRow::failed(&task, "coulomb", "");
        row.error = None;
        row.verdict = verdict;
        row.converged = verdict != RowVerdict::NotConverged;
        row.parameters = vec![ParamCell {
            name: "mu".into(),
            value: Some(mu),
            std_error: Some(0.001),
            status: "determined".into(),
        }];
        GroupResult {
            task,
            verdict,
            rows: vec![row],
            fits: Vec::new(),
        }
    }

    /// The worst group decides the verdict; a group without a converged fit leaves the
    /// trend; the text condition is no abscissa.
    #[test]
    fn verdict_numeric_conditions_and_trends_of_a_campaign() {
        let results = [
            group("001", 1.0, "oil", RowVerdict::Ok, 0.30),
            group("002", 2.0, "oil", RowVerdict::DiagnosticFailed, 0.28),
            group("003", 3.0, "dry", RowVerdict::Ok, 0.26),
            group("004", 4.0, "dry", RowVerdict::NotConverged, 9.0),
        ];
        let spec = CampaignSpec::default();
        let report = CampaignReport::new("c.toml", &spec, &results, 0.0);
        assert_eq!(report.verdict, RowVerdict::NotConverged);
        assert_eq!(report.exit_verdict(), Verdict::NotConverged);
        assert_eq!(report.numeric_conditions, ["load"]);
        assert_eq!(report.trends.len(), 1);
        let line = report.trends[0].linear.as_ref().unwrap();
        assert!((line.b + 0.02).abs() < 1e-12 && (line.a - 0.32).abs() < 1e-12);
        let flagged = CampaignReport::new("c.toml", &spec, &results[..3], 0.0);
        assert_eq!(flagged.exit_verdict(), Verdict::DiagnosticFailed);
        let md = MarkdownWriter::render(&report);
        assert!(
            md.contains("1 did not converge and 1 failed a diagnostic"),
            "{md}"
        );
        assert!(report.csv().starts_with("group,load,lube,file,model,"));
    }
}
