//! The report of `plan`: each candidate's predicted standard errors, the recommended records
//! and theirs, and the parameters out of reach with the change that would reach them.

use super::format::fmt_num;
use super::{render_files, render_opening, Render, Role, Sink, Table};
use crate::plan::reach::percent;
use crate::plan::{Criterion, Experiment, ExperimentInput, OutOfReach, Plan, SearchKind};
use serde::Serialize;
use std::collections::BTreeMap;

/// Standard errors by parameter name (`null`: not identifiable).
pub type ByParam = BTreeMap<String, Option<f64>>;

/// One free parameter.
#[derive(Debug, Clone, Serialize)]
pub struct PlanParam {
    /// Its name.
    pub name: String,
    /// Its unit.
    pub unit: String,
    /// Its assumed value.
    pub value: f64,
    /// Whether the design minimises its standard error.
    pub target: bool,
}

/// One candidate with its predictions.
#[derive(Debug, Clone, Serialize)]
pub struct PlanCandidate {
    /// Its index (0-based, as `recommended` names it).
    pub index: usize,
    /// The experiment.
    #[serde(flatten)]
    pub experiment: Experiment,
    /// The velocity noise it was planned with \[m/s\].
    pub planned_noise: f64,
    /// Whether it is recommended.
    pub recommended: bool,
    /// Each parameter's predicted standard error from this record and those already taken.
    pub predicted_std: ByParam,
    /// The same relative to the parameter's value.
    pub relative_std: ByParam,
}

/// The report of `plan`.
#[derive(Debug, Clone, Serialize)]
pub struct PlanReport {
    /// `"plan"`.
    pub command: String,
    /// The configuration the run came from, as the front end names it.
    pub config: String,
    /// The assumed law's name.
    pub model: String,
    /// Where the assumed values come from: `[model]` or the prior report.
    pub assumed_from: String,
    /// `"D"` or `"A"`.
    pub criterion: Criterion,
    /// How many records were asked for.
    pub choose: usize,
    /// How the set was found.
    pub search: SearchKind,
    /// Sets evaluated.
    pub sets_evaluated: usize,
    /// The relative standard error above which a parameter is out of reach.
    pub reach: f64,
    /// The noise's lag-one correlation.
    pub noise_correlation: f64,
    /// The free parameters.
    pub parameters: Vec<PlanParam>,
    /// Every candidate.
    pub candidates: Vec<PlanCandidate>,
    /// The recommended candidates' indices.
    pub recommended: Vec<usize>,
    /// The recommended set's predicted standard errors (with the records already taken).
    pub predicted_std: ByParam,
    /// The same relative to the values.
    pub relative_std: ByParam,
    /// The records already taken.
    pub taken: Vec<String>,
    /// Their predicted standard errors alone (`null` without records).
    pub taken_std: Option<ByParam>,
    /// The parameters out of reach.
    pub out_of_reach: Vec<OutOfReach>,
    /// Files written with the report.
    pub files: Vec<String>,
    /// The plan (for plots).
    #[serde(skip)]
    pub plan: Plan,
}

impl PlanReport {
    /// The report of `plan` for the law `model`, its values from `assumed_from`.
    pub fn new(plan: Plan, model: &str, assumed_from: &str, choose: usize) -> Self {
        let by_param = |std: &[Option<f64>]| -> ByParam {
            plan.parameters
                .iter()
                .zip(std)
                .map(|(p, s)| (p.name.clone(), s.filter(|x| x.is_finite())))
                .collect()
        };
        let relative = |std: &[Option<f64>]| -> ByParam {
            (0..plan.parameters.len())
                .map(|i| (plan.parameters[i].name.clone(), plan.relative(std, i)))
                .collect()
        };
        let candidates = plan
            .candidates
            .iter()
            .enumerate()
            .map(|(index, c)| PlanCandidate {
                index,
                experiment: c.experiment.clone(),
                planned_noise: c.velocity_noise,
                recommended: plan.recommended.contains(&index),
                predicted_std: by_param(&c.predicted_std),
                relative_std: relative(&c.predicted_std),
            })
            .collect();
        Self {
            command: "plan".into(),
            config: String::new(),
            model: model.to_string(),
            assumed_from: assumed_from.to_string(),
            criterion: plan.criterion,
            choose,
            search: plan.search,
            sets_evaluated: plan.evaluated,
            reach: plan.reach,
            noise_correlation: plan.correlation,
            parameters: plan
                .parameters
                .iter()
                .map(|p| PlanParam {
                    name: p.name.clone(),
                    unit: p.unit.clone(),
                    value: p.value,
                    target: p.target,
                })
                .collect(),
            candidates,
            recommended: plan.recommended.clone(),
            predicted_std: by_param(&plan.predicted_std),
            relative_std: relative(&plan.predicted_std),
            taken: plan.taken.clone(),
            taken_std: plan.taken_std.as_deref().map(by_param),
            out_of_reach: plan.out_of_reach.clone(),
            files: Vec::new(),
            plan,
        }
    }

    /// The names of the targets, comma-separated.
    fn targets(&self) -> String {
        let named: Vec<&str> = self
            .parameters
            .iter()
            .filter(|p| p.target)
            .map(|p| p.name.as_str())
            .collect();
        named.join(", ")
    }

    /// The recommended set's table: parameter, value, predicted std, relative.
    pub fn set_table(&self) -> Table {
        let rows = self
            .parameters
            .iter()
            .map(|p| {
                let std = self.predicted_std.get(&p.name).copied().flatten();
                let rel = self.relative_std.get(&p.name).copied().flatten();
                vec![
                    format!("{}{}", p.name, if p.target { " *" } else { "" }),
                    p.unit.clone(),
                    fmt_num(p.value),
                    std.map_or("not identifiable".into(), fmt_num),
                    rel.map_or("-".into(), percent),
                ]
            })
            .collect();
        Table::new(
            &["parameter", "unit", "assumed", "predicted std", "relative"],
            rows,
        )
    }

    /// Every candidate's relative predicted standard error per parameter.
    pub fn candidate_table(&self) -> Table {
        let mut headers = vec!["#", "candidate", "settings"];
        headers.extend(self.parameters.iter().map(|p| p.name.as_str()));
        let rows = self
            .candidates
            .iter()
            .map(|c| {
                let mut row = vec![
                    format!("{}{}", c.index, if c.recommended { " *" } else { "" }),
                    c.experiment.name.clone(),
                    settings(&c.experiment, c.planned_noise),
                ];
                row.extend(self.parameters.iter().map(|p| {
                    c.relative_std
                        .get(&p.name)
                        .copied()
                        .flatten()
                        .map_or("n/i".into(), percent)
                }));
                row
            })
            .collect();
        Table::new(&headers, rows)
    }

    fn summary(&self) -> String {
        let names: Vec<String> = self
            .recommended
            .iter()
            .map(|&i| format!("{} (`{}`)", i, self.candidates[i].experiment.name))
            .collect();
        let criterion = match self.criterion {
            Criterion::D => "D-optimality",
            Criterion::A => "A-optimality",
        };
        let search = match self.search {
            SearchKind::Exhaustive => "every set",
            SearchKind::Greedy => "a greedy search with exchanges",
        };
        format!(
            "Recommended: {} of {} candidates, by {criterion} on {} ({search}, {} sets evaluated), \
             law `{}` at the values of {}.",
            names.join(", "),
            self.candidates.len(),
            self.targets(),
            self.sets_evaluated,
            self.model,
            self.assumed_from
        )
    }
}

/// A candidate's settings in words.
fn settings(e: &Experiment, noise: f64) -> String {
    let mut parts = vec![format!(
        "{} s at {} Hz",
        fmt_num(e.duration),
        fmt_num(e.sample_rate)
    )];
    if e.x0 != 0.0 {
        parts.push(format!("x0 {} m", fmt_num(e.x0)));
    }
    if let Some(n) = e.normal_force {
        parts.push(format!("N {} N", fmt_num(n)));
    }
    match &e.input {
        Some(ExperimentInput::Multisine(m)) => parts.push(format!(
            "multisine {} N rms, {}-{} Hz",
            fmt_num(m.amplitude),
            fmt_num(m.band[0]),
            fmt_num(m.band[1])
        )),
        Some(ExperimentInput::Given(_)) => parts.push("given input".into()),
        None => {}
    }
    parts.push(format!("noise {} m/s", fmt_num(noise)));
    parts.join(", ")
}

impl Render for PlanReport {
    fn render(&self, sink: &mut dyn Sink) {
        render_opening(sink, "plan", &self.config, &self.summary());
        sink.paragraph(&self.summary(), Role::Brief);
        sink.heading(2, "The recommended records", Role::Summary);
        sink.table(&self.set_table(), Role::Summary);
        sink.paragraph(
            "Predicted standard errors from the Fisher information of the simulated records at \
             the assumed values (the linearised fit; * marks the parameters the design \
             minimises), with the records already taken.",
            Role::Detail,
        );
        if !self.out_of_reach.is_empty() {
            sink.heading(2, "Out of reach", Role::Summary);
            let items: Vec<String> = self
                .out_of_reach
                .iter()
                .map(|o| o.message.clone())
                .collect();
            sink.list(&items, Role::Summary);
        }
        if !self.taken.is_empty() {
            sink.paragraph(
                &format!("Records already taken: {}.", self.taken.join(", ")),
                Role::Detail,
            );
        }
        sink.heading(2, "Candidates", Role::Detail);
        sink.paragraph(
            "Relative predicted standard error of each parameter from each candidate alone \
             (with the records already taken); * marks the recommended ones, n/i a parameter \
             the record does not identify.",
            Role::Detail,
        );
        sink.table(&self.candidate_table(), Role::Detail);
        render_files(sink, &self.files);
    }
}
