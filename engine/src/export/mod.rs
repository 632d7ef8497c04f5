//! Fitted laws as source code: a fit's (or a comparison's recommended) friction law written
//! as a self-contained C, Rust or Python file, or tabulated as a compensation table.
//!
//! One [`LawDescription`] is built from a report (report.json's value, or a [`FitResult`]):
//! the law's name, equation and reference, its parameters with units and standard errors,
//! the records it was fitted to, and its code ([`code::LawCode`], written once per law in
//! [`laws`]): the `force` and the exact step of its states. Every emitter ([`c`], [`rust`],
//! [`python`]) prints that one description in its language, so the three share one
//! semantics:
//!
//! - a state, empty for static laws, initialised at rest (every state 0);
//! - `update(state, v, n, dt)` advances the states over `dt` at constant velocity `v` and
//!   normal force `n`, by the law's exact step (Dahl, LuGre, GMS at sharpness 1 and 2: the
//!   engine's own `Propagator` steps, operation for operation);
//! - `force(state, v, n)` is the friction force at velocity `v`.
//!
//! Replaying a record is the engine's convention (`energy::model_force`): init; F\[0\] =
//! force(state, v\[0\], n\[0\]); for each sample i >= 1, update(state, (v\[i-1\] + v\[i\]) / 2,
//! (n\[i-1\] + n\[i\]) / 2, t\[i\] - t\[i-1\]), then F\[i\] = force(state, v\[i\], n\[i\]).
//!
//! A law fitted without a normal force has its levels as forces: the exported code is then
//! called with n = 1 (the engine's convention, `identify::values::levels`), which its header
//! says. [`table`] writes the steady-state force on a velocity grid. Values in, text out.

pub(crate) mod c;
pub(crate) mod code;
mod description;
pub(crate) mod laws;
mod print;
pub(crate) mod python;
pub(crate) mod rust;
pub(crate) mod table;

pub use description::{LawDescription, LawParam};

use crate::identify::FitResult;
use std::fmt;
use std::str::FromStr;
use thiserror::Error;

/// Why a law cannot be exported.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ExportError {
    /// The report lacks a key, or holds a value that cannot be read.
    #[error("`{key}`: {reason}")]
    Report {
        /// The key (dotted path).
        key: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A law without an exporter (a plugin, or an unknown name).
    #[error(
        "model `{0}` cannot be exported: only the built-in laws ({list}) have exporters",
        list = laws::EXPORTABLE.join(", ")
    )]
    NotExportable(String),
    /// A law whose step has no closed form at its fitted parameters.
    #[error("{0}")]
    NoExactStep(String),
    /// A constant's name collides with another in the target language.
    #[error("parameters `{0}` and `{1}` have the same name in {2}")]
    NameClash(String, String, &'static str),
    /// Bad options (the table's normal force).
    #[error("{0}")]
    Options(String),
}

/// A target of `export`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lang {
    /// C99, math.h only.
    C,
    /// Rust, `no_std` with the `libm` crate.
    Rust,
    /// Python, `math` only.
    Python,
    /// The steady-state compensation table (CSV).
    Table,
}

impl Lang {
    /// Every target, as the command line spells them.
    pub const NAMES: [&'static str; 4] = ["c", "rust", "python", "table"];
}

impl FromStr for Lang {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "c" => Ok(Lang::C),
            "rust" | "rs" => Ok(Lang::Rust),
            "python" | "py" => Ok(Lang::Python),
            "table" | "csv" => Ok(Lang::Table),
            _ => Err(format!(
                "unknown language `{s}` (expected one of {})",
                Lang::NAMES.join(", ")
            )),
        }
    }
}

impl fmt::Display for Lang {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = match self {
            Lang::C => "c",
            Lang::Rust => "rust",
            Lang::Python => "python",
            Lang::Table => "table",
        };
        f.write_str(name)
    }
}

/// How to write an export.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportOptions {
    /// The target.
    pub lang: Lang,
    /// The C identifiers' prefix (`fid_`; its upper case prefixes the constants).
    pub prefix: String,
    /// The table's normal force \[N\] (default: the report's, 1 without one).
    pub normal_force: Option<f64>,
}

impl Default for ExportOptions {
    fn default() -> Self {
        Self {
            lang: Lang::C,
            prefix: "fid_".into(),
            normal_force: None,
        }
    }
}

/// The source text (or table) of the law a report holds (report.json's value: a `fit`
/// report, or a `compare` report's recommended law). `source` names the report in the header.
pub fn export_report(
    report: &serde_json::Value,
    source: &str,
    opts: &ExportOptions,
) -> Result<String, ExportError> {
    emit(&LawDescription::from_report(report, source)?, opts)
}

/// The source text (or table) of a fitted law.
pub fn export_fit(fit: &FitResult, opts: &ExportOptions) -> Result<String, ExportError> {
    emit(&LawDescription::from_fit(fit)?, opts)
}

/// The description written in `opts.lang`.
pub fn emit(desc: &LawDescription, opts: &ExportOptions) -> Result<String, ExportError> {
    match opts.lang {
        Lang::C => c::emit(desc, &opts.prefix),
        Lang::Rust => rust::emit(desc),
        Lang::Python => python::emit(desc),
        Lang::Table => table::emit(desc, opts.normal_force),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn fit(model: serde_json::Value) -> serde_json::Value {
        json!({
            "command": "fit",
            "model": model["type"],
            "model_parameters": model,
            "parameters": [],
            "records": [{ "file": "a.csv", "max_speed": 0.1 }],
            "oscillator": { "normal_force": 14.5 },
            "compared": "velocity",
        })
    }

    /// A comparison exports the verdict's simplest law, not the best-ranked one.
    #[test]
    fn a_comparison_exports_its_recommended_law() {
        let report = json!({
            "command": "compare",
            "ranking": [
                fit(json!({ "type": "stribeck" })),
                fit(json!({ "type": "coulomb", "mu": 0.25 })),
            ],
            "verdict": { "simplest": "coulomb" },
        });
        let desc = LawDescription::from_report(&report, "r.json").unwrap();
        assert_eq!(desc.model, "coulomb");
        assert!(desc.source.contains("recommended"));
        let opts = ExportOptions {
            lang: Lang::Python,
            ..ExportOptions::default()
        };
        let text = emit(&desc, &opts).unwrap();
        assert!(text.contains("MU = 0.25  # [1]"), "{text}");
    }

    /// Levels given in N mark a law fitted without a normal force; its header says n = 1.
    #[test]
    fn levels_in_newtons_ask_for_a_unit_normal_force() {
        let mut report = fit(json!({ "type": "coulomb", "mu": 2.5 }));
        report["parameters"] =
            json!([{ "name": "mu", "value": 2.5, "unit": "N", "free": true, "std_error": 0.1 }]);
        let desc = LawDescription::from_report(&report, "r.json").unwrap();
        assert!(desc.levels_as_forces);
        let text = emit(&desc, &ExportOptions::default()).unwrap();
        assert!(text.contains("n = 1"), "{text}");
        assert!(
            text.contains("#define FID_MU 2.5 /* [N] std error 1.000e-1, fitted"),
            "{text}"
        );
    }

    /// Literals read back to the same double in every target.
    #[test]
    fn literals_round_trip() {
        for x in [0.2, 1e5, 1e-7, 1e16, 123456.789, 5e-324, 0.0] {
            let text = description::literal(x);
            assert_eq!(text.parse::<f64>(), Ok(x), "{text}");
            assert!(text.contains(['.', 'e']), "{text}");
        }
    }

    #[test]
    fn unknown_languages_and_laws_are_refused() {
        assert!("fortran".parse::<Lang>().is_err());
        assert_eq!("PY".parse::<Lang>(), Ok(Lang::Python));
        let err = LawDescription::from_report(&fit(json!({ "type": "mine" })), "r").unwrap_err();
        assert_eq!(err, ExportError::NotExportable("mine".into()));
        let bad_prefix = ExportOptions {
            prefix: "9x".into(),
            ..ExportOptions::default()
        };
        let desc = LawDescription::from_report(&fit(json!({ "type": "none" })), "r").unwrap();
        assert!(emit(&desc, &bad_prefix).is_err());
    }
}
