//! Conversions between Python objects and the values the engine reads and writes.
//!
//! Tables (oscillator, model, fit options) travel as JSON values: Python's `json.dumps` on
//! the way in (so a dict is read exactly as the same TOML table would be by serde), and
//! `json.loads` on the way out (so a report is the same structure as report.json). Series
//! travel as float64 numpy arrays.

use crate::errors::value_error;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A Python object (dict, list, number, string, None) as a JSON value; `what` names it in
/// the error message.
pub fn to_json(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<serde_json::Value> {
    let json = obj.py().import("json")?;
    let text: String = json
        .call_method1("dumps", (obj,))
        .map_err(|e| value_error(format!("{what}: not a JSON-like value: {e}")))?
        .extract()?;
    serde_json::from_str(&text).map_err(|e| value_error(format!("{what}: {e}")))
}

/// A JSON value as a Python object (dicts, lists, floats, ints, strings, None).
pub fn from_json<'py>(py: Python<'py>, value: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(value_error)?;
    py.import("json")?.call_method1("loads", (text,))
}

/// A serializable value (a report) as a Python dict, list or scalar.
pub fn serialized<'py, T: serde::Serialize>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let json = serde_json::to_value(value).map_err(value_error)?;
    from_json(py, &json)
}

/// A one-dimensional array-like (numpy array of any real dtype, list, tuple) as f64 values.
pub fn to_f64_vec(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    let numpy = obj.py().import("numpy")?;
    let array = numpy
        .call_method1("ascontiguousarray", (obj, "float64"))
        .map_err(|e| value_error(format!("{what}: not an array of numbers: {e}")))?;
    let readonly: PyReadonlyArray1<'_, f64> = array.extract().map_err(|_| {
        let ndim: usize = array.getattr("ndim").and_then(|n| n.extract()).unwrap_or(0);
        value_error(format!(
            "{what}: expected a one-dimensional array, got {ndim} dimensions"
        ))
    })?;
    let values = readonly
        .as_slice()
        .map_err(|e| value_error(format!("{what}: {e}")))?;
    Ok(values.to_vec())
}

/// `values` as a float64 numpy array.
pub fn to_numpy<'py>(py: Python<'py>, values: &[f64]) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, values)
}

/// Sets `key` of `dict` to a numpy array of `values`.
pub fn set_array(dict: &Bound<'_, PyDict>, key: &str, values: &[f64]) -> PyResult<()> {
    dict.set_item(key, to_numpy(dict.py(), values))
}
