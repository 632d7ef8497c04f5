//! `[model]`: the friction model of a spec and which of its parameters were given.

use super::error::SpecError;
use frictionid_models::FrictionModel;
use serde::Serialize;

/// The friction model of a spec and which of its parameters were given explicitly.
#[derive(Debug, Clone, Serialize)]
pub struct ModelSpec {
    /// The model with the given parameter values (defaults for the others).
    pub model: Box<dyn FrictionModel>,
    /// Parameters whose values were written out: a fit starts from these values instead of a
    /// data-driven guess.
    pub given: Vec<String>,
    /// Admissible but unusual values (front ends show them as warnings).
    #[serde(skip)]
    pub warnings: Vec<String>,
}

impl ModelSpec {
    /// A model spec; `written` are the keys of the table the model was built from (those that
    /// name parameters become [`ModelSpec::given`]).
    pub fn new(
        model: Box<dyn FrictionModel>,
        warnings: Vec<String>,
        written: impl IntoIterator<Item = String>,
    ) -> Self {
        let names = parameter_names(model.as_ref());
        let given = written.into_iter().filter(|k| names.contains(k)).collect();
        Self {
            model,
            given,
            warnings,
        }
    }

    /// Builds the model from a JSON table (`{"type": "coulomb", "mu": 0.2}`).
    pub fn from_json(table: &serde_json::Value) -> Result<Self, SpecError> {
        let built = frictionid_models::build_json(table)?;
        let written = table
            .as_object()
            .map(|o| o.keys().cloned().collect::<Vec<_>>())
            .unwrap_or_default();
        Ok(Self::new(built.model, built.warnings, written))
    }
}

pub(super) fn parameter_names(model: &dyn FrictionModel) -> Vec<String> {
    model.param_info().into_iter().map(|p| p.name).collect()
}
