//! `[fit]` and its `[fit.options]` as a config gives them: the parts of the fit options
//! themselves ([`ParamOptions`], [`SearchOptions`], [`TargetOptions`], each with its own
//! defaults) and the choices of the run ([`RunChoices`]). Each key of the two tables is
//! declared once, by the part that reads it (`OptionKeys`); the tables route every key to
//! its part, and an unknown key is serde's "unknown field" error listing every key of its
//! table, as the config's messages (with their "did you mean") expect.

use super::error::SpecError;
use super::model::parameter_names;
use super::simulation::IntegratorMethod;
use crate::identify::values::option_keys::option_keys;
use crate::identify::{
    fit_sim_options, non_model_bound_keys, OptionKeys, ParamOptions, SearchOptions, TargetOptions,
};
use crate::simulate::SimOptions;
use frictionid_models::suggest::did_you_mean;
use frictionid_models::FrictionModel;
use serde::de::{DeserializeSeed, Error as _, MapAccess, Visitor};
use serde::{Deserialize, Deserializer};
use std::sync::OnceLock;

/// `[fit]` with its `[fit.options]`: which parameters to fit and how, what to compare, how
/// to search, and the choices of the run. Absent keys take their part's defaults.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FitSpec {
    /// `[fit] free`, `bounds`; `[fit.options] oscillator`, `velocity_offset`, `time_shift`,
    /// `x0`, `guess`.
    pub params: ParamOptions,
    /// `[fit] max_iterations`, `tolerance`; `[fit.options] multistart`, `search`, `prefit`.
    pub search: SearchOptions,
    /// `[fit.options] domain`, `force_target`, `force_offset`, `min_speed`.
    pub target: TargetOptions,
    /// `[fit.options] models`, `integrator`.
    pub run: RunChoices,
}

/// `[fit.options]` keys that choose the run rather than the fit's parameters, target or
/// search.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunChoices {
    /// Models compared by `compare` when none are requested.
    pub models: Option<Vec<String>>,
    /// The integrator of the fit's simulations (default `auto`: exact, rodas or dopri5 by the
    /// law and its stiffness, which stiff bristle records, sigma0 >= 1e6 N/m, need).
    pub integrator: Option<IntegratorMethod>,
}

option_keys!(RunChoices {
    fit: [],
    options: ["models" => models, "integrator" => integrator],
});

/// The `[fit]` key of the `[fit.options]` table.
const OPTIONS_KEY: &str = "options";

/// Every key of `[fit]`, part by part.
fn fit_keys() -> &'static [&'static str] {
    static KEYS: OnceLock<Vec<&'static str>> = OnceLock::new();
    KEYS.get_or_init(|| {
        [
            ParamOptions::FIT_KEYS,
            SearchOptions::FIT_KEYS,
            TargetOptions::FIT_KEYS,
            RunChoices::FIT_KEYS,
            &[OPTIONS_KEY],
        ]
        .concat()
    })
}

/// Every key of `[fit.options]`, part by part.
fn options_keys() -> &'static [&'static str] {
    static KEYS: OnceLock<Vec<&'static str>> = OnceLock::new();
    KEYS.get_or_init(|| {
        [
            ParamOptions::OPTIONS_KEYS,
            SearchOptions::OPTIONS_KEYS,
            TargetOptions::OPTIONS_KEYS,
            RunChoices::OPTIONS_KEYS,
        ]
        .concat()
    })
}

/// A key of a table whose keys are `0`: an unknown one is an error while the key is read (so
/// that the config's message points at the key).
struct KnownKey(&'static [&'static str]);

impl<'de> DeserializeSeed<'de> for KnownKey {
    type Value = String;

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<String, D::Error> {
        deserializer.deserialize_identifier(self)
    }
}

impl Visitor<'_> for KnownKey {
    type Value = String;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("field identifier")
    }

    fn visit_str<E: serde::de::Error>(self, key: &str) -> Result<String, E> {
        if self.0.contains(&key) {
            Ok(key.to_string())
        } else {
            Err(E::unknown_field(key, self.0))
        }
    }
}

impl<'de> Deserialize<'de> for FitSpec {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_struct("FitSpec", fit_keys(), FitTable)
    }
}

/// The `[fit]` table.
struct FitTable;

impl<'de> Visitor<'de> for FitTable {
    type Value = FitSpec;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("struct FitSpec")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<FitSpec, A::Error> {
        let mut spec = FitSpec::default();
        while let Some(key) = map.next_key_seed(KnownKey(fit_keys()))? {
            if key == OPTIONS_KEY {
                map.next_value_seed(OptionsTable(&mut spec))?;
            } else {
                spec.read_key(&key, &mut map)?;
            }
        }
        Ok(spec)
    }
}

/// The `[fit.options]` table, read into the parts of a [`FitSpec`].
struct OptionsTable<'a>(&'a mut FitSpec);

impl<'de> DeserializeSeed<'de> for OptionsTable<'_> {
    type Value = ();

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<(), D::Error> {
        deserializer.deserialize_struct("FitOptionsSpec", options_keys(), self)
    }
}

impl<'de> Visitor<'de> for OptionsTable<'_> {
    type Value = ();

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("struct FitOptionsSpec")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        while let Some(key) = map.next_key_seed(KnownKey(options_keys()))? {
            self.0.read_key(&key, &mut map)?;
        }
        Ok(())
    }
}

impl FitSpec {
    /// Checks that `free` names parameters of `model`, `bounds` parameters of `model` or the
    /// oscillator and nuisance keys (`mass`, `shift`, `x0`, `offset`, ...), and that each
    /// bound is an ordered pair. The error names the key and suggests the nearest name.
    pub fn check_against(&self, model: &dyn FrictionModel) -> Result<(), SpecError> {
        let known = parameter_names(model);
        let check = |name: &str, key: &str| -> Result<(), SpecError> {
            if known.iter().any(|n| n == name) {
                return Ok(());
            }
            Err(SpecError::UnknownParameter {
                key: key.into(),
                model: model.name().into(),
                name: name.into(),
                hint: did_you_mean(name, known.iter().map(String::as_str)),
                known: known.join(", "),
            })
        };
        for name in self.params.free.iter().flatten() {
            check(name, "free")?;
        }
        let other = non_model_bound_keys();
        for (name, (lower, upper)) in &self.params.bounds {
            if !other.contains(&name.as_str()) {
                check(name, "bounds")?;
            }
            if lower.is_nan() || upper.is_nan() || lower >= upper {
                return Err(SpecError::BadBounds {
                    name: name.clone(),
                    lower: *lower,
                    upper: *upper,
                });
            }
        }
        Ok(())
    }

    /// Checks that the search can run: `[fit] max_iterations` allows at least one iteration
    /// (0 would report the start as the fit) and `tolerance` is a finite number >= 0.
    pub fn check_search(&self) -> Result<(), SpecError> {
        if self.search.max_iterations == 0 {
            return Err(SpecError::FitOption(
                "[fit] max_iterations = 0 allows no iteration: give at least 1 (default 200)"
                    .into(),
            ));
        }
        match self.search.tolerance {
            Some(t) if !(t.is_finite() && t >= 0.0) => Err(SpecError::FitOption(format!(
                "[fit] tolerance must be a finite number >= 0, got {t}"
            ))),
            _ => Ok(()),
        }
    }

    /// The free parameter names for `model`: `free` as written, or else every parameter not
    /// marked fixed by default (such as the Stribeck shape exponent).
    pub fn free_names(&self, model: &dyn FrictionModel) -> Vec<String> {
        match &self.params.free {
            Some(list) => list.clone(),
            None => model
                .param_info()
                .into_iter()
                .filter(|p| !p.fixed_by_default)
                .map(|p| p.name)
                .collect(),
        }
    }

    /// The fit's simulation options: the integrator `[fit.options] integrator` asks for, the
    /// fit's defaults ([`fit_sim_options`]) otherwise.
    pub fn sim_options(&self) -> SimOptions {
        let defaults = fit_sim_options();
        SimOptions {
            integrator: self
                .run
                .integrator
                .map_or(defaults.integrator, IntegratorMethod::engine_integrator),
            ..defaults
        }
    }

    /// Reads `key`'s value into the part that declares it.
    fn read_key<'de, A: MapAccess<'de>>(&mut self, key: &str, map: &mut A) -> Result<(), A::Error> {
        let read = self.params.read_key(key, map)?
            || self.search.read_key(key, map)?
            || self.target.read_key(key, map)?
            || self.run.read_key(key, map)?;
        if read {
            Ok(())
        } else {
            Err(A::Error::unknown_field(key, options_keys()))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with_bounds<const N: usize>(bounds: [(&str, (f64, f64)); N]) -> FitSpec {
        let mut fit = FitSpec::default();
        fit.params.bounds = bounds.map(|(k, b)| (k.to_string(), b)).into();
        fit
    }

    #[test]
    fn fit_spec_names_unknown_parameters_and_bad_bounds() {
        let coulomb = frictionid_models::Coulomb::default();
        let mut fit = FitSpec::default();
        fit.params.free = Some(vec!["mu_".into()]);
        let e = fit.check_against(&coulomb).unwrap_err().to_string();
        assert!(e.contains("no parameter `mu_` (did you mean `mu`?)"), "{e}");
        let fit = with_bounds([("mu", (1.0, 0.5))]);
        let e = fit.check_against(&coulomb).unwrap_err().to_string();
        assert!(e.contains("not an interval"), "{e}");
        // Bounds of the nuisance parameters and the oscillator are not model parameters.
        let fit = with_bounds([
            ("shift", (-0.5, 0.5)),
            ("x0", (0.009, 0.011)),
            ("offset", (-1e-3, 1e-3)),
        ]);
        fit.check_against(&coulomb).unwrap();
        let fit = with_bounds([("x0", (0.011, 0.009))]);
        let e = fit.check_against(&coulomb).unwrap_err().to_string();
        assert!(
            e.contains("`x0` = [0.011, 0.009] is not an interval"),
            "{e}"
        );
    }

    #[test]
    fn no_iteration_and_a_bad_tolerance_are_refused_naming_the_key() {
        let mut fit = FitSpec::default();
        fit.check_search().unwrap();
        fit.search.max_iterations = 0;
        let e = fit.check_search().unwrap_err().to_string();
        assert!(e.starts_with("[fit] max_iterations = 0"), "{e}");
        fit.search.max_iterations = 1;
        fit.search.tolerance = Some(f64::NAN);
        let e = fit.check_search().unwrap_err().to_string();
        assert!(e.starts_with("[fit] tolerance"), "{e}");
    }

    /// Each key of `[fit]` and `[fit.options]` is read by one part, and the tables list every
    /// key once.
    #[test]
    fn every_key_is_read_by_one_part() {
        for keys in [fit_keys(), options_keys()] {
            for (i, key) in keys.iter().enumerate() {
                assert!(!keys[..i].contains(key), "`{key}` listed twice");
            }
        }
        let fit: FitSpec = serde_json::from_value(serde_json::json!({
            "free": ["mu"], "bounds": {"mu": [0.0, 1.0]}, "max_iterations": 7, "tolerance": 1e-6,
            "options": {
                "oscillator": ["mass"], "velocity_offset": true, "time_shift": true, "x0": true,
                "guess": false, "multistart": 3, "search": "global", "prefit": true,
                "domain": "force", "force_target": "measured", "force_offset": true,
                "min_speed": 0.01, "models": ["coulomb"], "integrator": "rodas"
            }
        }))
        .unwrap();
        let p = &fit.params;
        assert_eq!(p.free, Some(vec!["mu".to_string()]));
        assert_eq!(p.bounds.get("mu"), Some(&(0.0, 1.0)));
        assert!(p.velocity_offset && p.time_shift && p.x0 && !p.guess);
        assert_eq!(p.oscillator.len(), 1);
        let s = &fit.search;
        assert_eq!(
            (s.max_iterations, s.tolerance, s.multistart),
            (7, Some(1e-6), Some(3))
        );
        assert!(s.prefit && s.strategy == Some(crate::identify::Search::Global));
        let t = &fit.target;
        assert_eq!(t.domain, crate::identify::FitDomain::Force);
        assert_eq!(t.force_target, crate::identify::ForceTarget::Measured);
        assert!(t.force_offset && t.min_speed == Some(0.01));
        assert_eq!(fit.run.models, Some(vec!["coulomb".to_string()]));
        assert_eq!(fit.run.integrator, Some(IntegratorMethod::Rodas));
        // A key of one table is unknown in the other.
        let e = serde_json::from_value::<FitSpec>(serde_json::json!({"options": {"free": []}}))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("unknown field `free`, expected one of `oscillator`"),
            "{e}"
        );
        let e = serde_json::from_value::<FitSpec>(serde_json::json!({"guess": false}))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("unknown field `guess`, expected one of `free`, `bounds`"),
            "{e}"
        );
    }
}
