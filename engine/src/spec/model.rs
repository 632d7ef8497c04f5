//! `[model]`: the friction model of a spec and which of its parameters were given.

use super::error::SpecError;
use crate::energy::record_motion;
use crate::oscillator::Oscillator;
use crate::record::Record;
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

impl ModelSpec {
    /// Checks that a static law's force is finite at its start values along `record`'s
    /// velocities and, unless the law is switched, at rest (every simulated motion starts or
    /// turns there), under the
    /// record's normal force (else `osc`'s): a formula dividing by zero there cannot be
    /// fitted. The error names the model's key and the first velocity where the force stops
    /// being finite. Laws with internal states are not checked (their force needs the states).
    pub fn check_finite_on(&self, record: &Record, osc: &Oscillator) -> Result<(), SpecError> {
        let model = self.model.as_ref();
        if model.n_states() > 0 {
            return Ok(());
        }
        let normal = record.normal_force_with(osc);
        let force = |v: f64, i: usize| model.force(v, &[], normal.at(i));
        // A switched law's force at rest is its static limit, not this formula.
        let switched = model
            .switching()
            .and_then(|s| s.static_limit(normal.at(0)))
            .is_some();
        if !switched && !force(0.0, 0).is_finite() {
            return Err(not_finite(model, force(0.0, 0), "at rest, v = 0".into()));
        }
        let Some(motion) = record_motion(record) else {
            return Ok(());
        };
        let time = record.time();
        match motion
            .v
            .iter()
            .enumerate()
            .find(|&(i, &v)| v.is_finite() && !force(v, i).is_finite())
        {
            None => Ok(()),
            Some((i, &v)) => Err(not_finite(
                model,
                force(v, i),
                format!(
                    "on record `{}` at v = {v:e} (t = {} s)",
                    record.name,
                    time.get(i).copied().unwrap_or(f64::NAN)
                ),
            )),
        }
    }
}

/// The error of a law whose force is `value` `where_`.
fn not_finite(model: &dyn FrictionModel, value: f64, where_: String) -> SpecError {
    let key = if model.name() == "expression" {
        let equation = model.equation();
        format!(
            "[model] force = `{}`",
            equation.strip_prefix("F = ").unwrap_or(&equation)
        )
    } else {
        format!("[model] type = \"{}\"", model.name())
    };
    SpecError::NotFinite {
        key,
        value,
        place: where_,
    }
}

pub(super) fn parameter_names(model: &dyn FrictionModel) -> Vec<String> {
    model.param_info().into_iter().map(|p| p.name).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(table: serde_json::Value) -> ModelSpec {
        ModelSpec::from_json(&table).unwrap()
    }

    /// A record moving at 1 - t m/s: forwards, through rest at t = 1 s, backwards.
    fn record() -> Record {
        let t: Vec<f64> = (0..=20).map(|i| i as f64 * 0.1).collect();
        let v = t.iter().map(|t| 1.0 - t).collect();
        Record::new("run.csv", t, v, 0.0)
    }

    #[test]
    fn a_formula_dividing_by_zero_on_the_data_names_the_key_and_the_place() {
        let osc = Oscillator::fmm();
        for (force, says) in [
            (
                "mu * N * v / abs(v)",
                "[model] force = `mu * N * v / abs(v)`: the force is NaN at rest",
            ),
            (
                "mu * N / (v - 0.5)",
                "[model] force = `mu * N / (v - 0.5)`: the force is inf on record `run.csv` at v = \
                 5e-1 (t = 0.5 s)",
            ),
        ] {
            let table = serde_json::json!({"type": "expression", "force": force, "params": {"mu": 0.2}});
            let e = spec(table)
                .check_finite_on(&record(), &osc)
                .unwrap_err()
                .to_string();
            assert!(e.starts_with(says), "{force}: {e}");
        }
        for fine in [
            serde_json::json!({"type": "expression"}),
            serde_json::json!({"type": "expression", "force": "mu * N * sign(v)", "params": {"mu": 0.2}}),
            serde_json::json!({"type": "stribeck"}),
            serde_json::json!({"type": "lugre"}),
        ] {
            spec(fine).check_finite_on(&record(), &osc).unwrap();
        }
    }
}
