//! The resolution of a spec into the values a run takes: the fit's options, handed out in
//! parts, and the models to compare.

use super::{Spec, SpecError};
use crate::identify::{FitOptions, Hooks, ParamOptions, TargetOptions};
use frictionid_models::suggest::did_you_mean;
use frictionid_models::{default_model, names, FrictionModel};

#[cfg(doc)]
use super::ModelSpec;

impl Spec {
    /// The options of a fit: the parts `[fit]` and `[fit.options]` give, with the parameters
    /// `keep_initial` names starting at their current values (see [`ModelSpec::given`]), the
    /// keys `[oscillator]` left unknown, the fit's simulation options, `[energy]`, the
    /// oscillator's standard deviations and `hooks`. Every default is its part's own.
    pub fn fit_options(&self, keep_initial: &[String], hooks: &Hooks) -> FitOptions {
        FitOptions {
            params: ParamOptions {
                keep_initial: keep_initial.to_vec(),
                ..self.fit.params.clone()
            },
            target: TargetOptions {
                unknown_oscillator: self.unknown_oscillator.clone(),
                ..self.fit.target.clone()
            },
            search: self.fit.search.clone(),
            sim: self.fit.sim_options(),
            energy: self.energy.options(),
            uncertainty: self.uncertainty,
            hooks: hooks.clone(),
        }
    }

    /// The models to compare: `requested`, else `[fit.options] models`, else every registered
    /// model. A model named in `[model]` starts from the values given there.
    pub fn models_to_compare(
        &self,
        requested: Option<&[String]>,
    ) -> Result<Vec<Box<dyn FrictionModel>>, SpecError> {
        let registered = names();
        let list: Vec<String> = match (requested, &self.fit.run.models) {
            (Some(r), _) => r.to_vec(),
            (None, Some(c)) => c.clone(),
            (None, None) => registered.clone(),
        };
        if list.is_empty() {
            return Err(SpecError::NoModels);
        }
        list.iter()
            .map(|name| self.model_to_compare(name.trim(), &registered))
            .collect()
    }

    fn model_to_compare(
        &self,
        name: &str,
        registered: &[String],
    ) -> Result<Box<dyn FrictionModel>, SpecError> {
        if !registered.iter().any(|n| n == name) {
            return Err(SpecError::UnknownModel {
                name: name.into(),
                hint: did_you_mean(name, registered.iter().map(String::as_str)),
                known: registered.join(", "),
            });
        }
        Ok(match &self.model {
            Some(m) if m.model.name() == name => m.model.clone(),
            _ => default_model(name)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::*;
    use crate::identify::FitOptions;
    use crate::oscillator::Oscillator;
    use frictionid_models::names;

    #[test]
    fn fit_options_take_the_spec_and_keep_hooks_apart() {
        let model =
            ModelSpec::from_json(&serde_json::json!({"type": "coulomb", "mu": 0.3})).unwrap();
        assert_eq!(model.given, vec!["mu".to_string()]);
        let fit: FitSpec = serde_json::from_value(serde_json::json!({
            "free": ["mu"], "bounds": {"mu": [0.0, 1.0]}, "max_iterations": 7,
            "options": {"velocity_offset": true, "guess": false}
        }))
        .unwrap();
        let spec = Spec::new(
            Oscillator::fmm(),
            Some(model),
            fit,
            None,
            EnergySpec::default(),
        )
        .unwrap();
        let hooks = Hooks {
            parallel: false,
            ..Hooks::default()
        };
        let o = spec.fit_options(&["mu".to_string()], &hooks);
        assert_eq!(o.params.free, Some(vec!["mu".to_string()]));
        assert_eq!(o.params.bounds.get("mu"), Some(&(0.0, 1.0)));
        assert_eq!(o.search.max_iterations, 7);
        assert!(o.params.velocity_offset && !o.params.guess && !o.hooks.parallel);
        assert_eq!(o.params.keep_initial, vec!["mu".to_string()]);
        assert_eq!(o.sim, FitOptions::default().sim);
    }

    #[test]
    fn models_to_compare_prefer_the_request_and_suggest_names() {
        let spec = Spec::new(
            Oscillator::fmm(),
            None,
            FitSpec::default(),
            None,
            EnergySpec::default(),
        )
        .unwrap();
        let request = vec!["coulomb".to_string()];
        let models = spec.models_to_compare(Some(&request)).unwrap();
        assert_eq!(models[0].name(), "coulomb");
        assert_eq!(
            spec.models_to_compare(Some(&[])).unwrap_err(),
            SpecError::NoModels
        );
        let e = spec
            .models_to_compare(Some(&["colomb".to_string()]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("(did you mean `coulomb`?)"), "{e}");
        assert_eq!(spec.models_to_compare(None).unwrap().len(), names().len());
    }
}
