//! The metadata of one model parameter and the checks of a parameter vector against it.
//! Plain values: this module imports only the crate's error type.

use crate::error::ModelError;
use serde::Serialize;

/// Metadata of one model parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParamInfo {
    /// Parameter name, as used in config files.
    pub name: String,
    /// SI unit ("1" for dimensionless coefficients).
    pub unit: String,
    /// Default value.
    pub default: f64,
    /// Physical lower bound.
    pub lower: f64,
    /// Physical upper bound.
    pub upper: f64,
    /// When true the lower bound itself is excluded (the value must be strictly greater).
    pub lower_exclusive: bool,
    /// One-line meaning.
    pub description: String,
    /// Whether the identifier keeps this parameter fixed unless the user frees it by name
    /// (e.g. the Stribeck shape exponent).
    pub fixed_by_default: bool,
}

impl ParamInfo {
    /// Metadata with an inclusive lower bound.
    pub fn new(
        name: &str,
        unit: &str,
        default: f64,
        (lower, upper): (f64, f64),
        description: &str,
    ) -> Self {
        Self {
            name: name.to_string(),
            unit: unit.to_string(),
            default,
            lower,
            upper,
            lower_exclusive: false,
            description: description.to_string(),
            fixed_by_default: false,
        }
    }

    /// Metadata for a strictly positive parameter (lower bound 0, excluded).
    pub fn positive(name: &str, unit: &str, default: f64, upper: f64, description: &str) -> Self {
        Self {
            lower_exclusive: true,
            ..Self::new(name, unit, default, (0.0, upper), description)
        }
    }

    /// The same metadata, marked as fixed unless freed by name.
    pub fn fixed(self) -> Self {
        Self {
            fixed_by_default: true,
            ..self
        }
    }

    /// Whether `value` lies inside the physical bounds.
    pub fn admits(&self, value: f64) -> bool {
        let above = if self.lower_exclusive {
            value > self.lower
        } else {
            value >= self.lower
        };
        value.is_finite() && above && value <= self.upper
    }

    /// The bounds as text, e.g. `(0, inf]` or `[0, 10]`.
    pub fn bounds_text(&self) -> String {
        format!(
            "{}{}, {}]",
            if self.lower_exclusive { "(" } else { "[" },
            fmt_bound(self.lower),
            fmt_bound(self.upper)
        )
    }
}

fn fmt_bound(x: f64) -> String {
    if x == f64::INFINITY {
        "inf".into()
    } else if x == f64::NEG_INFINITY {
        "-inf".into()
    } else {
        format!("{x}")
    }
}

/// Checks `values` against the bounds in `info`; the error names the model and parameter.
pub fn check_bounds(model: &str, info: &[ParamInfo], values: &[f64]) -> Result<(), ModelError> {
    for (p, &v) in info.iter().zip(values) {
        if !p.admits(v) {
            return Err(ModelError::OutOfBounds {
                model: model.to_string(),
                param: p.name.clone(),
                value: v,
                bounds: p.bounds_text(),
            });
        }
    }
    Ok(())
}

/// Checks the length of a parameter vector passed to `set_params`.
pub fn check_len(model: &str, expected: usize, got: usize) -> Result<(), ModelError> {
    if expected == got {
        Ok(())
    } else {
        Err(ModelError::ParamCount {
            model: model.to_string(),
            expected,
            got,
        })
    }
}
