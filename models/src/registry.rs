//! The model registry: every type registered through `#[typetag::serde(name = "...")]`.
//!
//! typetag keeps its registry private; the list of registered names is read from the error
//! it raises for an unknown tag (serde's `unknown variant ..., expected one of ...`), so a model
//! defined in any linked crate appears here with no second registration step.

use crate::error::ModelError;
use crate::model::FrictionModel;
use crate::param_info::ParamInfo;
use serde::Serialize;

/// A registered model with its metadata, for listings (`frictionid models`).
#[derive(Debug, Clone, Serialize)]
pub struct ModelListing {
    /// Registry name.
    pub name: String,
    /// One-line equation.
    pub equation: String,
    /// Number of internal states.
    pub states: usize,
    /// Parameter metadata.
    pub parameters: Vec<ParamInfo>,
}

/// A model built from a table, with the validation warnings it raised.
#[derive(Debug, Clone)]
pub struct Built {
    /// The model.
    pub model: Box<dyn FrictionModel>,
    /// Warnings (admissible but unusual values).
    pub warnings: Vec<String>,
}

const PROBE: &str = "__frictionid_registry_probe__";

/// Every registered model name, sorted.
pub fn names() -> Vec<String> {
    let probe = serde_json::json!({ "type": PROBE });
    let msg = match serde_json::from_value::<Box<dyn FrictionModel>>(probe) {
        Ok(_) => return Vec::new(),
        Err(e) => e.to_string(),
    };
    let mut names = parse_expected(&msg);
    names.sort();
    names.dedup();
    names
}

/// Parses serde's "expected one of `a`, `b`" / "expected `a`" list.
fn parse_expected(msg: &str) -> Vec<String> {
    let Some(pos) = msg.find("expected") else {
        return Vec::new();
    };
    // `pos` comes from `find` on the same string: a char boundary within it.
    msg[pos..]
        .split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// The default instance of a registered model.
pub fn default_model(name: &str) -> Result<Box<dyn FrictionModel>, ModelError> {
    Ok(build_json(&serde_json::json!({ "type": name }))?.model)
}

/// Every registered model with its metadata.
pub fn listings() -> Vec<ModelListing> {
    names()
        .into_iter()
        .filter_map(|n| default_model(&n).ok())
        .map(|m| ModelListing {
            name: m.name().to_string(),
            equation: m.equation(),
            states: m.n_states(),
            parameters: m.param_info(),
        })
        .collect()
}

pub use crate::suggest::nearest;

fn hint(name: &str, candidates: &[String]) -> String {
    crate::suggest::did_you_mean(name, candidates.iter().map(String::as_str))
}

/// Builds a model from a TOML table (`type` plus parameter values; missing ones default).
pub fn build_toml(table: &toml::Value) -> Result<Built, ModelError> {
    let json = serde_json::to_value(table).map_err(|e| ModelError::Invalid(e.to_string()))?;
    build_json(&json)
}

/// Builds a model from a JSON object (`type` plus parameter values; missing ones default).
pub fn build_json(value: &serde_json::Value) -> Result<Built, ModelError> {
    let obj = value
        .as_object()
        .ok_or_else(|| ModelError::Invalid("the model must be a table".into()))?;
    let registered = names();
    let Some(ty) = obj.get("type") else {
        return Err(ModelError::MissingType {
            registered: registered.join(", "),
        });
    };
    let Some(ty) = ty.as_str() else {
        return Err(ModelError::Invalid("`type` must be a string".into()));
    };
    if !registered.iter().any(|n| n == ty) {
        return Err(ModelError::UnknownModel {
            name: ty.to_string(),
            hint: hint(ty, &registered),
            registered: registered.join(", "),
        });
    }
    let model: Box<dyn FrictionModel> =
        serde_json::from_value(value.clone()).map_err(|e| translate(ty, &e.to_string()))?;
    let warnings = model.check()?;
    Ok(Built { model, warnings })
}

/// Turns serde's messages into the registry's typed errors.
fn translate(model: &str, msg: &str) -> ModelError {
    if let Some(rest) = msg.strip_prefix("unknown field `") {
        let key = rest.split('`').next().unwrap_or_default().to_string();
        let params = parse_expected(rest);
        return ModelError::UnknownParameter {
            model: model.to_string(),
            hint: hint(&key, &params),
            key,
            params: if params.is_empty() {
                "none".into()
            } else {
                params.join(", ")
            },
        };
    }
    // A model's own checks run while deserialising (serde `try_from`); their messages already
    // name the model.
    if msg.starts_with(&format!("model `{model}`")) || msg.starts_with(&format!("{model} model:")) {
        return ModelError::Invalid(msg.to_string());
    }
    ModelError::Invalid(format!("model `{model}`: {msg}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_serde_expected_lists() {
        let msg = "unknown variant `x`, expected one of `a`, `b_c`, `d`";
        assert_eq!(parse_expected(msg), vec!["a", "b_c", "d"]);
        assert_eq!(
            parse_expected("unknown field `q`, expected `mu`"),
            vec!["mu"]
        );
        assert!(parse_expected("unknown field `q`, there are no fields").is_empty());
    }

    #[test]
    fn nearest_names_only_close_matches() {
        let c = ["coulomb", "lugre", "stribeck"];
        assert_eq!(nearest("colomb", c), Some("coulomb"));
        assert_eq!(nearest("lugree", c), Some("lugre"));
        assert_eq!(nearest("xyzzy", c), None);
    }
}
