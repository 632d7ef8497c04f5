//! Report values as Python dicts: the report.json structure (through the engine's serde
//! form) plus numpy arrays for the series report.json leaves out, and the report's text
//! forms (the terminal summary the CLI prints, report.md) that the Python result objects
//! show.

use crate::convert::{serialized, set_array};
use frictionid_cli::terminal::TerminalWriter;
use frictionid_engine::identify::{FitResult, FitSeries, ForceBalance};
use frictionid_engine::report::fit::verdict_line;
use frictionid_engine::report::markdown::MarkdownWriter;
use frictionid_engine::report::serialized_name;
use frictionid_engine::report::{
    CompareReport, EnergyRecord, EnergyReport, FitReport, Render, SimulateReport, Status,
};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// The report's JSON form as a dict.
fn report_dict<'py, T: serde::Serialize>(
    py: Python<'py>,
    report: &T,
) -> PyResult<Bound<'py, PyDict>> {
    Ok(serialized(py, report)?.cast_into::<PyDict>()?)
}

/// The list under `key` of `dict` (a report's `records` or `ranking`).
fn list_at<'py>(dict: &Bound<'py, PyDict>, key: &str) -> PyResult<Bound<'py, PyList>> {
    match dict.get_item(key)? {
        Some(item) => Ok(item.cast_into::<PyList>()?),
        None => Ok(PyList::empty(dict.py())),
    }
}

/// `simulate`: the report's keys, then `t, x, v, a, force, energy`, the other energies,
/// `energy_rate`, the internal states as `z1..zn` and `states` (a list of arrays), and
/// `noisy_velocity` when one was made.
pub fn simulate_dict<'py>(
    py: Python<'py>,
    report: &SimulateReport,
) -> PyResult<Bound<'py, PyDict>> {
    let dict = report_dict(py, report)?;
    let traj = &report.trajectory;
    for (key, values) in [
        ("t", traj.time.as_slice()),
        ("x", &traj.x),
        ("v", &traj.v),
        ("a", &traj.a),
        ("force", &traj.friction),
        ("stored", &traj.stored),
        ("energy_rate", &report.energy_rate),
    ]
    .into_iter()
    .chain(traj.mechanical.named_series())
    {
        set_array(&dict, key, values)?;
    }
    let states = PyList::empty(py);
    for (j, z) in traj.states.iter().enumerate() {
        set_array(&dict, &format!("z{}", j + 1), z)?;
        states.append(crate::convert::to_numpy(py, z))?;
    }
    dict.set_item("states", states)?;
    if let Some(noisy) = &report.noisy_velocity {
        set_array(&dict, "noisy_velocity", noisy)?;
    }
    Ok(dict)
}

/// Adds each record's series (`time`, `measured`, `fitted`, `energy_based_force`,
/// `model_force`, and an inverse-dynamics fit's force balance) to the record dicts of one fit.
fn add_record_series(fit_dict: &Bound<'_, PyDict>, fit: &FitResult) -> PyResult<()> {
    let records = list_at(fit_dict, "records")?;
    for (item, r) in records.iter().zip(&fit.records) {
        let d = item.cast_into::<PyDict>()?;
        // report.json's `series` lists: the arrays below hold them.
        if d.contains("series")? {
            d.del_item("series")?;
        }
        let FitSeries {
            measured,
            fitted,
            energy_based_force,
            model_force,
            balance,
        } = &r.series;
        for (key, values) in [
            ("time", &r.axes.time),
            ("measured", measured),
            ("fitted", fitted),
            ("energy_based_force", energy_based_force),
            ("model_force", model_force),
        ] {
            set_array(&d, key, values)?;
        }
        if let Some(b) = balance {
            add_force_balance(&d, b)?;
        }
    }
    Ok(())
}

/// An inverse-dynamics record's force balance: `input_force`, `inertia_force`,
/// `damping_force`, `restoring_force`, `friction_fitted`, `friction_balance` (arrays at the
/// compared samples) and `force_offset`.
fn add_force_balance(d: &Bound<'_, PyDict>, b: &ForceBalance) -> PyResult<()> {
    for (key, values) in [
        ("input_force", &b.input),
        ("inertia_force", &b.inertia),
        ("damping_force", &b.damping),
        ("restoring_force", &b.restoring),
        ("friction_fitted", &b.friction_fitted),
        ("friction_balance", &b.friction_balance),
    ] {
        set_array(d, key, values)?;
    }
    d.set_item("force_offset", b.offset)
}

/// `fit`: report.json's structure with the fitted series per record.
pub fn fit_dict<'py>(py: Python<'py>, report: &FitReport) -> PyResult<Bound<'py, PyDict>> {
    let dict = report_dict(py, report)?;
    add_record_series(&dict, &report.fit)?;
    Ok(dict)
}

/// `compare`: report.json's structure with the fitted series per record of every ranked fit.
pub fn compare_dict<'py>(py: Python<'py>, report: &CompareReport) -> PyResult<Bound<'py, PyDict>> {
    let dict = report_dict(py, report)?;
    let ranking = list_at(&dict, "ranking")?;
    for (item, fit) in ranking.iter().zip(&report.comparison.ranking) {
        add_record_series(&item.cast_into::<PyDict>()?, fit)?;
    }
    Ok(dict)
}

/// The energy analysis's series of one record.
fn add_energy_series(d: &Bound<'_, PyDict>, r: &EnergyRecord) -> PyResult<()> {
    let a = &r.analysis;
    for (key, values) in [
        ("time", a.time.as_slice()),
        ("x", &a.x),
        ("v", &a.v),
        ("a", &a.a),
        ("de_dt", &a.de_dt),
        ("friction", &a.friction),
    ]
    .into_iter()
    .chain(a.mechanical.named_series())
    {
        set_array(d, key, values)?;
    }
    if let Some(f) = &r.model_force {
        set_array(d, "model_force", f)?;
    }
    Ok(())
}

/// `energy`: report.json's structure with the series of every record's analysis.
pub fn energy_dict<'py>(py: Python<'py>, report: &EnergyReport) -> PyResult<Bound<'py, PyDict>> {
    let dict = report_dict(py, report)?;
    let records = list_at(&dict, "records")?;
    for (item, r) in records.iter().zip(&report.records) {
        add_energy_series(&item.cast_into::<PyDict>()?, r)?;
    }
    if let Some(name) = &report.reference_model {
        dict.set_item("reference_model", name)?;
    }
    Ok(dict)
}

/// A report's text forms: `text`, the summary `frictionid` prints, and `markdown`, report.md.
pub fn texts<'py>(py: Python<'py>, report: &dyn Render) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("text", TerminalWriter::render(report))?;
    d.set_item("markdown", MarkdownWriter::render(report))?;
    Ok(d)
}

/// Adds a verdict to a report's texts: `verdict`, its sentence, and `status` (`pass`,
/// `warn` or `fail`).
fn set_verdict(d: &Bound<'_, PyDict>, (status, text): (Status, String)) -> PyResult<()> {
    d.set_item("verdict", text)?;
    d.set_item("status", serialized_name(&status))
}

/// A fit's text forms with its verdict.
fn fit_texts<'py>(py: Python<'py>, report: &FitReport) -> PyResult<Bound<'py, PyDict>> {
    let d = texts(py, report)?;
    set_verdict(&d, verdict_line(&report.fit))?;
    Ok(d)
}

/// A comparison's text forms with its verdict, plus `laws`: each ranked fit's own, by model
/// name (a fit report of that law alone).
pub fn compare_texts<'py>(py: Python<'py>, report: &CompareReport) -> PyResult<Bound<'py, PyDict>> {
    let d = texts(py, report)?;
    if let Some(verdict) = report.verdict_line() {
        set_verdict(&d, verdict)?;
    }
    let laws = PyDict::new(py);
    for fit in &report.comparison.ranking {
        let alone = FitReport {
            config: report.config.clone(),
            fit: fit.clone(),
            files: Vec::new(),
        };
        laws.set_item(&fit.model, fit_texts(py, &alone)?)?;
    }
    d.set_item("laws", laws)?;
    Ok(d)
}

/// A report's dict and its text forms, as the native functions return them.
pub type WithTexts<'py> = (Bound<'py, PyDict>, Bound<'py, PyDict>);

/// `fit`'s dict and texts.
pub fn fit_output<'py>(py: Python<'py>, report: &FitReport) -> PyResult<WithTexts<'py>> {
    Ok((fit_dict(py, report)?, fit_texts(py, report)?))
}

/// `compare`'s dict and texts (with every law's).
pub fn compare_output<'py>(py: Python<'py>, report: &CompareReport) -> PyResult<WithTexts<'py>> {
    Ok((compare_dict(py, report)?, compare_texts(py, report)?))
}

/// `energy`'s dict and texts.
pub fn energy_output<'py>(py: Python<'py>, report: &EnergyReport) -> PyResult<WithTexts<'py>> {
    Ok((energy_dict(py, report)?, texts(py, report)?))
}

/// `simulate`'s dict and texts.
pub fn simulate_output<'py>(py: Python<'py>, report: &SimulateReport) -> PyResult<WithTexts<'py>> {
    Ok((simulate_dict(py, report)?, texts(py, report)?))
}
