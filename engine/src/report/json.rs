//! The JSON writer: report.json is the report value serialized, keys in sorted order.

use serde::Serialize;

/// The report as a JSON value (object keys sorted).
pub fn to_json<T: Serialize>(report: &T) -> Result<serde_json::Value, serde_json::Error> {
    serde_json::to_value(report)
}

/// The report as pretty JSON text with a final newline (the contents of report.json).
pub fn to_json_text<T: Serialize>(report: &T) -> Result<String, serde_json::Error> {
    let mut text = serde_json::to_string_pretty(&to_json(report)?)?;
    text.push('\n');
    Ok(text)
}
