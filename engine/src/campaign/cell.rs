//! The value of a manifest cell carried into the results as a condition.

use serde::{Deserialize, Serialize};

/// A condition's value: a number when every value of its column reads as one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum CellValue {
    /// A number.
    Number(f64),
    /// Text.
    Text(String),
}

impl CellValue {
    /// `cell` as a number when `numeric` and it reads as one, else as text.
    pub fn parse(cell: &str, numeric: bool) -> Self {
        match cell.parse::<f64>() {
            Ok(x) if numeric => Self::Number(x),
            _ => Self::Text(cell.to_string()),
        }
    }

    /// The number, for a numeric condition.
    pub fn number(&self) -> Option<f64> {
        match self {
            Self::Number(x) => Some(*x),
            Self::Text(_) => None,
        }
    }

    /// The value as a CSV cell or label.
    pub fn text(&self) -> String {
        match self {
            Self::Number(x) => x.to_string(),
            Self::Text(t) => t.clone(),
        }
    }
}

/// The value of condition `name` in `conditions` (`None`: absent, or no single value).
pub(crate) fn condition_value<'a>(
    conditions: &'a [(String, Option<CellValue>)],
    name: &str,
) -> Option<&'a CellValue> {
    conditions
        .iter()
        .find(|(n, _)| n == name)
        .and_then(|(_, v)| v.as_ref())
}
