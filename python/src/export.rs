//! `export`: a fit's (or a comparison's recommended) law as C, Rust or Python source, or a
//! compensation table, from report.json's structure (the package's `FitResult.export`).

use crate::errors::value_error;
use frictionid_engine::export::{export_report, ExportOptions, Lang};
use pyo3::prelude::*;

/// The source text of the law in `report_json` (report.json's text, or the dict a fit
/// returns, serialised): `lang` one of c, rust, python, table.
#[pyfunction]
#[pyo3(signature = (report_json, lang = "c", prefix = "fid_", normal_force = None))]
pub fn export(
    report_json: &str,
    lang: &str,
    prefix: &str,
    normal_force: Option<f64>,
) -> PyResult<String> {
    let lang: Lang = lang.parse().map_err(value_error)?;
    let report: serde_json::Value = serde_json::from_str(report_json).map_err(value_error)?;
    let opts = ExportOptions {
        lang,
        prefix: prefix.to_string(),
        normal_force,
    };
    export_report(&report, "a fit from Python", &opts).map_err(value_error)
}
