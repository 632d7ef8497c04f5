//! The report of `fit`: one model fitted to the records, with the energy-based force check.

use super::format::{
    column, fmt_criterion, fmt_estimate, fmt_num, fmt_opt, fmt_percent, fmt_std_error,
    fmt_to_error, on_axis, serialized_name,
};
use super::{render_files, render_opening, Render, Role, Sink, Status, Table, Verdict};
use crate::axis::Axis;
use crate::identify::values::EnergyForce;
use crate::identify::values::RecordFit;
use crate::identify::{FitResult, FittedParam};
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
    for_each_record(&mut v, fit, |record, r| {
        let top = r.axes.velocity.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if top > 0.0 && top.is_finite() {
            record.insert("max_speed".into(), top.into());
        }
    });
    Ok(v)
}

/// Calls `add` with each record's JSON object and its fit.
fn for_each_record(
    v: &mut serde_json::Value,
    fit: &FitResult,
    mut add: impl FnMut(&mut serde_json::Map<String, serde_json::Value>, &RecordFit),
) {
    let Some(records) = v.get_mut("records").and_then(|r| r.as_array_mut()) else {
        return;
    };
    for (record, r) in records.iter_mut().zip(&fit.records) {
        if let Some(obj) = record.as_object_mut() {
            add(obj, r);
        }
    }
}

/// A record's compared series as report.json's `series` object: the compared samples'
/// `time` and `velocity` (the measured motion), the `measured` and `fitted` series of the
/// compared quantity (the first of `channels`: the model force along the motion, offset
/// applied, in the force domain; the simulated response in the velocity domain) and, where
/// the energy check ran, the `model_force` along the measured motion.
fn series_json(r: &RecordFit) -> serde_json::Value {
    let mut series = serde_json::Map::new();
    let axes = &r.axes;
    let s = &r.series;
    for (key, values) in [
        ("time", &axes.time),
        ("velocity", &axes.velocity),
        ("measured", &s.measured),
        ("fitted", &s.fitted),
        ("model_force", &s.model_force),
    ] {
        if !values.is_empty() {
            series.insert(key.into(), values.clone().into());
        }
    }
    series.into()
}

impl Serialize for FitReport {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut v = fit_json(&self.fit).map_err(serde::ser::Error::custom)?;
        for_each_record(&mut v, &self.fit, |record, r| {
            record.insert("series".into(), series_json(r));
        });
        if let Some(obj) = v.as_object_mut() {
            obj.insert("command".into(), "fit".into());
            obj.insert("config".into(), self.config.clone().into());
            obj.insert("files".into(), self.files.clone().into());
        }
        v.serialize(serializer)
    }
}

/// `fixed`, `fitted`, or what bounds a parameter the records do not determine
/// (`fitted, > 3.1e6` for a lower bound at 95 %).
fn fit_status(p: &FittedParam) -> String {
    use crate::identify::Identifiability as I;
    match (p.free, p.identifiability, p.bound) {
        (false, _, _) => "fixed".into(),
        (true, Some(I::LowerBound), Some(b)) => format!("fitted, > {} at 95 %", fmt_num(b)),
        (true, Some(I::UpperBound), Some(b)) => format!("fitted, < {} at 95 %", fmt_num(b)),
        (true, Some(I::NotIdentifiable), _) => "fitted, not identifiable".into(),
        (true, _, _) => "fitted".into(),
    }
}

/// The parameter table of a fit; with an uncertainty budget, a last column names the source
/// that dominates each parameter's standard error.
pub fn parameter_table(fit: &FitResult) -> Table {
    let budget = has_budget(fit);
    let rows = fit
        .parameters
        .iter()
        .map(|p| {
            let mut row = vec![
                p.name.clone(),
                fmt_estimate(p.value, p.std_error),
                fmt_std_error(p.std_error),
                fmt_interval(p),
                p.unit.clone(),
                fit_status(p),
            ];
            if budget {
                row.push(dominant_source(p, fit.oscillator.axis));
            }
            row
        })
        .collect();
    let mut headers = vec![
        "parameter",
        "value",
        "std error",
        "95 % CI",
        "unit",
        "status",
    ];
    if budget {
        headers.push("dominant source");
    }
    Table::new(&headers, rows)
}

/// `[lo, hi]` to the decimal the standard error supports, or `-`.
fn fmt_interval(p: &FittedParam) -> String {
    p.ci95
        .map(|[a, b]| {
            format!(
                "[{}, {}]",
                fmt_to_error(a, p.std_error),
                fmt_to_error(b, p.std_error)
            )
        })
        .unwrap_or_else(|| "-".into())
}

/// Whether any parameter carries the parts of its standard error.
fn has_budget(fit: &FitResult) -> bool {
    fit.parameters
        .iter()
        .any(|p| p.std_error_components.is_some())
}

/// The source with the largest part of `p`'s standard error, named as on `axis`, or `-`.
fn dominant_source(p: &FittedParam, axis: Axis) -> String {
    p.std_error_components
        .map(|c| property_label(c.dominant(), axis).to_string())
        .unwrap_or_else(|| "-".into())
}

/// A source of a standard error as a report shows it on `axis` (report.json keeps the
/// property's config name): the mass of a rotary axis is its `inertia`.
fn property_label(name: &str, axis: Axis) -> &str {
    if name == "mass" {
        axis.inertia_name()
    } else {
        name
    }
}

/// The uncertainty budget: per fitted parameter the part of its standard error from the data
/// and from each oscillator property, and their total; `None` without a budget.
pub fn budget_table(fit: &FitResult) -> Option<Table> {
    if !has_budget(fit) {
        return None;
    }
    let axis = fit.oscillator.axis;
    let rows = fit
        .parameters
        .iter()
        .filter_map(|p| p.std_error_components.map(|c| (p, c)))
        .map(|(p, c)| {
            let part = |x: f64| fmt_std_error(Some(x).filter(|x| *x > 0.0));
            vec![
                p.name.clone(),
                fmt_std_error(c.data),
                part(c.mass),
                part(c.damping),
                part(c.stiffness),
                part(c.normal_force),
                fmt_std_error(p.std_error),
                property_label(c.dominant(), axis).to_string(),
            ]
        })
        .collect();
    Some(Table::new(
        &[
            "parameter",
            "data",
            axis.inertia_name(),
            "damping",
            "stiffness",
            "normal_force",
            "total",
            "dominant",
        ],
        rows,
    ))
}

/// A fit's verdict as one sentence, and its status (the worst of convergence and the
/// diagnostics).
pub fn verdict_line(fit: &FitResult) -> (Status, String) {
    let problems = |status: Status| -> Vec<String> {
        fit.diagnostics
            .iter()
            .filter(|d| d.status == status)
            .map(|d| format!("`{}`", serialized_name(&d.check)))
            .collect()
    };
    match fit.verdict() {
        Verdict::NotConverged => (
            Status::Fail,
            format!(
                "not converged ({}): the values below are where the solver stopped.",
                fit.termination
            ),
        ),
        Verdict::DiagnosticFailed => (
            Status::Fail,
            format!(
                "converged, but a diagnostic failed ({}): read the diagnostics before using the values.",
                problems(Status::Fail).join(", ")
            ),
        ),
        Verdict::Ok => match (problems(Status::Warn), problems(Status::Skipped)) {
            (warned, skipped) if warned.is_empty() && skipped.is_empty() => {
                (Status::Pass, "converged; every diagnostic passed.".into())
            }
            (warned, skipped) if warned.is_empty() => (
                Status::Pass,
                format!(
                    "converged; every diagnostic that could judge passed ({} skipped: read why).",
                    skipped.join(", ")
                ),
            ),
            (warned, _) => (
                Status::Warn,
                format!("converged, with warnings ({}).", warned.join(", ")),
            ),
        },
    }
}

/// Every diagnostic of a fit: check, status, the value judged and the message.
pub fn diagnostics_table(fit: &FitResult) -> Table {
    let rows = fit
        .diagnostics
        .iter()
        .map(|d| {
            vec![
                serialized_name(&d.check),
                serialized_name(&d.status),
                fmt_opt(d.value),
                d.message.clone(),
            ]
        })
        .collect();
    Table::new(&["check", "status", "value", "message"], rows)
}

/// The per-record table of a fit: residual and the energy-based force check, and the sliding
/// samples compared when `min_speed` selected them.
pub fn record_table(fit: &FitResult) -> Table {
    let table = energy_record_table(fit);
    match sliding_column(fit) {
        Some((header, cells)) => table.with_column(&header, cells),
        None => table,
    }
}

/// The header and cells (`kept of defined`) of the sliding samples each record compared,
/// when `[fit.options] min_speed` selected them.
pub fn sliding_column(fit: &FitResult) -> Option<(String, Vec<String>)> {
    let min_speed = fit.records.iter().find_map(|r| r.sliding)?.min_speed;
    let cells = fit
        .records
        .iter()
        .map(|r| {
            r.sliding
                .map_or("-".into(), |s| format!("{} of {}", s.kept, s.of))
        })
        .collect();
    let unit = on_axis(fit.oscillator.axis, "m/s");
    Some((
        format!("samples with |v| >= {} {unit}", fmt_num(min_speed)),
        cells,
    ))
}

/// The record, x0 and residual of each record, with the energy check's columns where it ran
/// on any record (none on a driven axis: no columns of dashes).
fn energy_record_table(fit: &FitResult) -> Table {
    let checked = fit.records.iter().any(|r| r.energy_force.is_some());
    let rows = fit
        .records
        .iter()
        .map(|r| {
            let mut row = vec![r.file.clone(), fmt_num(r.x0), fmt_num(r.rms_residual)];
            if checked {
                row.extend(energy_cells(r.energy_force.as_ref()));
            }
            row
        })
        .collect();
    let axis = fit.oscillator.axis;
    let rms = format!("rms residual [{}]", fit.residual_unit);
    let (x0, mean, model_mean) = (
        column(axis, "x0", "m"),
        column(axis, "mean F sgn(v) Eq. 7", "N"),
        column(axis, "model mean F sgn(v)", "N"),
    );
    let mut headers = vec!["record", &x0, &rms];
    if checked {
        headers.extend([
            mean.as_str(),
            &model_mean,
            "difference [%]",
            "dissipated [J]",
            "model dissipated [J]",
            "difference [%]",
        ]);
    }
    Table::new(&headers, rows)
}

/// The energy check's cells of a record: Eq. 7's mean against the model's, the dissipated
/// energy against the model's, each difference `skipped` where that part could not judge.
fn energy_cells(ef: Option<&EnergyForce>) -> [String; 6] {
    let Some(e) = ef else {
        return std::array::from_fn(|_| "-".into());
    };
    let judged = |skip: bool, percent: f64| {
        if skip {
            "skipped".to_string()
        } else {
            fmt_percent(percent)
        }
    };
    [
        fmt_num(e.mean_abs),
        fmt_num(e.reference),
        judged(e.eq7_skipped.is_some(), e.percent_difference),
        fmt_num(e.dissipated),
        fmt_num(e.model_dissipated),
        judged(
            e.dissipation_skipped.is_some(),
            e.dissipation_percent_difference,
        ),
    ]
}

/// Every compared channel of every record: its RMS residual against the noise level its
/// residuals were weighted by (`-`: unweighted).
pub fn channel_table(fit: &FitResult) -> Table {
    let rows = fit
        .records
        .iter()
        .flat_map(|r| r.channels.iter().map(move |c| (r, c)))
        .map(|(r, c)| {
            let (noise, ratio) = match c.noise {
                Some(n) => (fmt_num(n), fmt_num(c.rms_residual / n)),
                None => ("-".into(), "-".into()),
            };
            vec![
                r.file.clone(),
                c.channel.clone(),
                c.unit.clone(),
                c.samples.to_string(),
                fmt_num(c.rms_residual),
                noise,
                ratio,
            ]
        })
        .collect();
    Table::new(
        &[
            "record",
            "channel",
            "unit",
            "samples",
            "rms residual",
            "noise",
            "rms/noise",
        ],
        rows,
    )
}

/// The oscillator's derived quantities: k/m (where the restoring law has a stiffness k),
/// c/m, the undamped natural frequency of small motions and their damping ratio (where
/// there is a restoring force), with standard errors where the fit gives them. On a rotary
/// axis the inertia's symbol is J (report.json keeps the names `k/m`, `c/m`).
pub fn oscillator_table(fit: &FitResult) -> Table {
    let osc = &fit.oscillator;
    let (m, c, k) = (osc.mass, osc.damping, osc.stiffness);
    let std_error = |name: &str| {
        fit.derived
            .iter()
            .find(|d| d.name == name)
            .and_then(|d| d.std_error)
    };
    let row = |name: String, value: f64, se: Option<f64>, unit: &str| {
        vec![
            name,
            fmt_estimate(value, se),
            fmt_std_error(se),
            unit.to_string(),
        ]
    };
    let j = if osc.axis.is_linear() { "m" } else { "J" };
    let mut rows = Vec::new();
    if osc.restoring.law().reads_stiffness() {
        rows.push(row(format!("k/{j}"), k / m, std_error("k/m"), "1/s²"));
    }
    // No damping given nor fitted: c/m = 0 says nothing.
    if c != 0.0 || std_error("c/m").is_some() {
        rows.push(row(format!("c/{j}"), c / m, std_error("c/m"), "1/s"));
    }
    let small = osc.small_motion_stiffness();
    // The stiffness of small motions: k of the linear spring, else R'(0).
    let r0 = if osc.has_linear_spring() {
        "k"
    } else {
        "R'(0)"
    };
    if small > 0.0 {
        rows.push(row(
            format!("natural frequency sqrt({r0}/{j})/2π"),
            osc.omega_n() / (2.0 * std::f64::consts::PI),
            None,
            "Hz",
        ));
        rows.push(row(
            format!("damping ratio c/(2 sqrt({r0} {j}))"),
            c / (2.0 * (small * m).sqrt()),
            None,
            "1",
        ));
    }
    Table::new(&["quantity", "value", "std error", "unit"], rows)
}

impl FitReport {
    /// Done, not converged, or a failed diagnostic (the fit's own verdict).
    pub fn verdict(&self) -> Verdict {
        self.fit.verdict()
    }

    fn statistics_text(&self) -> String {
        let f = &self.fit;
        format!(
            "RMS {} residual {} {}; AIC {}; BIC {}; {} iterations, {} simulations, {} s. Search `{}`: {} of {} starts reached the best cost within its statistical tolerance; start {} ({}) won.",
            f.compared,
            fmt_num(f.rms_residual),
            f.residual_unit,
            fmt_criterion(f.aic),
            fmt_criterion(f.bic),
            f.iterations,
            f.simulations,
            fmt_num(f.wall_time_s),
            f.search.name(),
            f.starts_at_best,
            f.starts,
            f.best_start,
            f.best_start_origin
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
        let outcome = if f.converged {
            "converged"
        } else {
            "NOT converged"
        };
        let summary = format!(
            "Model `{}` fitted to {} record(s): {outcome}.",
            f.model,
            f.records.len()
        );
        render_opening(sink, "fit", &self.config, &summary);
        let (status, verdict) = verdict_line(f);
        sink.verdict(status, &verdict);
        sink.heading(2, "Diagnostics", Role::Detail);
        sink.table(&diagnostics_table(f), Role::Detail);
        sink.heading(2, "Parameters", Role::Detail);
        sink.table(&parameter_table(f), Role::Summary);
        if let Some(budget) = budget_table(f) {
            sink.heading(2, "Uncertainty budget", Role::Detail);
            sink.paragraph(
                "Standard error of each fitted parameter from the data and from the stated \
                 standard deviation of each oscillator property (refits at +-1 sigma); the \
                 total is their root sum of squares and gives the 95 % interval (`-`: a \
                 property known exactly).",
                Role::Detail,
            );
            sink.table(&budget, Role::Detail);
        }
        let oscillator = oscillator_table(f);
        if !oscillator.rows.is_empty() {
            sink.heading(2, "Oscillator", Role::Detail);
            sink.table(&oscillator, Role::Detail);
        }
        sink.heading(2, "Records", Role::Detail);
        sink.table(&record_table(f), Role::Summary);
        sink.table(&channel_table(f), Role::Detail);
        sink.paragraph(&self.statistics_text(), Role::Detail);
        sink.paragraph(&self.terminal_text(), Role::Brief);
        render_files(sink, &self.files);
    }
}
