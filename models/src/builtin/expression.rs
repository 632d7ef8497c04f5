//! A static friction law written as a formula in the config.
//!
//! F = f(v, N; p_1, ..., p_n), e.g. `mu * N * tanh(v / eps) + b * v`
//!
//! ```toml
//! [model]
//! type = "expression"
//! force = "mu * N * tanh(v / eps) + b * v"
//! params = { mu = 0.2, eps = 1.0e-4, b = 0.5 }
//! bounds = { mu = [0, 1], eps = [1e-9, 1] }      # optional, inclusive; default (-inf, inf)
//! units = { mu = "1", eps = "m/s", b = "N s/m" } # optional, for listings and reports
//! ```
//!
//! | key | meaning |
//! |---|---|
//! | `force` | the friction force [N] as a formula of `v` [m/s], `N` [N] and the parameters |
//! | `params` | every other name in the formula with its value (SI units) |
//! | `bounds` | physical bounds `[lower, upper]` of some parameters |
//! | `units` | units of some parameters (text) |
//! | `channels` | names of record channels the formula reads (`[[records]] channels`) |
//!
//! Besides `v` and `N` a formula may read the conditions of the motion at each instant:
//! `x` (the displacement, m or rad), `a` (the acceleration) and `u` (the input force), unless
//! a parameter has that name, and every record channel named in `channels` (a `load`, a
//! `temperature`), by that name: `F = Fc * (1 + kt * (temperature - 25)) * sign(v) + b * v`
//! with `channels = ["temperature"]`. The engine hands them the record's samples (a
//! force-domain fit, inverse dynamics) and a missing channel is an error naming the record
//! and the channel. Without values (the law's `force`) they read 0.
//!
//! The parameters are the names of `params`, ordered by their first appearance in the
//! formula (stable for a given formula); they are fitted like any model's. A parameter or a
//! channel that the formula does not use, or a name in the formula that is neither `v`, `N`,
//! a parameter, `x`, `a`, `u` nor a channel, is an error naming it. Syntax and functions: see [`crate::formula`] (usual
//! precedence, `^` or `**` for powers, `sign`/`sgn` with sign(0) = 0, `abs`, `exp`, `ln`,
//! `sqrt`, `tanh`, `sin`, `cos`, `atan`, `min`, `max`, ...). The formula is parsed once, when
//! the model is built, into an exmex flat expression; evaluation does not parse.
//!
//! Without `force`, the model is the default law `mu * N * tanh(v / eps)` with mu = 0.2,
//! eps = 1e-4 m/s (a smoothed Coulomb law; `params`, `bounds` and `units` then override its
//! defaults).
//!
//! Switched laws: a formula containing `sign(v)` (or `sgn(v)`, `sign(-v)`) has a set-valued
//! force at rest, like Coulomb's. Then `static_limit` is |F(0+)| (also when that is 0, e.g.
//! mu = 0, exactly as coulomb's mu N) and `slip_force(v, direction, N)` evaluates a second compiled form of the formula
//! in which `sign(v)` is replaced by `direction` itself, while every other occurrence of `v`
//! keeps its (possibly zero or round-off-signed) value. So `mu * N * sign(v)` is exactly
//! `coulomb` in the engine's switched treatment, and no velocity is nudged (which would bias
//! the smooth parts of the law by the nudge). `sign` of any other argument (`sign(v - 1)`) is
//! evaluated as written.

use crate::conditions::Condition;
use crate::error::ModelError;
use crate::formula::{self, Formula, Parsed};
use crate::hints::GuessHint;
use crate::model::{FrictionModel, Staging, SwitchedLaw};
use crate::param_info::{check_len, ParamInfo};
use crate::params::ParamSpec;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

const MODEL: &str = "expression";
/// The variable standing for the slip direction in the switched form (not writable by users).
const DIRECTION: &str = "#direction";
const DEFAULT_FORCE: &str = "mu * N * tanh(v / eps)";

/// The table of the `expression` model as written in a config file.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ExpressionConfig {
    /// The force formula; `None` selects the default law.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub force: Option<String>,
    /// Parameter values.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub params: BTreeMap<String, f64>,
    /// Physical bounds `[lower, upper]` of some parameters.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub bounds: BTreeMap<String, [f64; 2]>,
    /// Units of some parameters.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub units: BTreeMap<String, String>,
    /// Names of the record channels the formula reads.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub channels: Vec<String>,
}

/// One fittable parameter of a formula.
#[derive(Debug, Clone, PartialEq)]
struct Param {
    name: String,
    value: f64,
    bounds: Option<[f64; 2]>,
    unit: Option<String>,
}

/// A static friction law given as a formula, compiled once when the model is built.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "ExpressionConfig", into = "ExpressionConfig")]
pub struct Expression {
    force: String,
    params: Vec<Param>,
    /// The record channels named in the config (as written, for its round trip).
    channels: Vec<String>,
    /// The conditions the formula reads, in order of first appearance.
    conditions: Vec<Condition>,
    /// F(v, N, params..., conditions...).
    compiled: Formula,
    /// F with sign(v) replaced by the slip direction: (v, N, params..., conditions...,
    /// direction); `None`
    /// when the formula has no sign(v).
    switched: Option<Formula>,
}

impl Expression {
    /// Builds the model from a formula and its parameter values (no bounds, no units).
    pub fn new(force: &str, params: &[(&str, f64)]) -> Result<Self, ModelError> {
        Self::try_from(ExpressionConfig {
            force: Some(force.to_string()),
            params: params.iter().map(|(n, v)| (n.to_string(), *v)).collect(),
            ..ExpressionConfig::default()
        })
    }

    /// The formula as written.
    pub fn formula(&self) -> &str {
        &self.force
    }

    /// The parameter names, in the order of `params`/`set_params`.
    pub fn param_names(&self) -> Vec<&str> {
        self.params.iter().map(|p| p.name.as_str()).collect()
    }

    /// Whether the law is switched (has sign(v)), so that `slip_force` substitutes the
    /// direction.
    pub fn is_switched(&self) -> bool {
        self.switched.is_some()
    }

    fn eval(&self, f: &Formula, v: f64, normal: f64, at: &[f64], direction: Option<f64>) -> f64 {
        // Variables in the order v, N, params..., conditions..., direction (see `compile`).
        let np = self.params.len();
        let nc = self.conditions.len();
        f.eval_by(|i| match i {
            0 => v,
            1 => normal,
            i if i < 2 + np => self.params[i - 2].value,
            i if i < 2 + np + nc => crate::conditions::condition_value(at, i - 2 - np),
            _ => direction.unwrap_or(f64::NAN),
        })
    }

    /// The force at v -> 0+ in the switched form (sign(v) = +1) at the values `at` of the
    /// formula's conditions.
    fn breakaway_in(&self, normal: f64, at: &[f64]) -> Option<f64> {
        let f = self.switched.as_ref()?;
        let f0 = self.eval(f, 0.0, normal, at, Some(1.0));
        f0.is_finite().then_some(f0.abs())
    }
}

/// The parameters of the default law `mu * N * tanh(v / eps)`: values, bounds and units
/// (a config's `params`, `bounds` and `units` override them).
const DEFAULT_PARAMS: [ParamSpec; 2] = [
    ParamSpec::new("mu", "1", 0.2, (0.0, 10.0), "friction coefficient"),
    ParamSpec::new(
        "eps",
        "m/s",
        1e-4,
        (1e-9, 1.0),
        "velocity scale of the tanh",
    ),
];

fn bad_key(key: &str, message: String) -> ModelError {
    ModelError::BadKey {
        model: MODEL.into(),
        key: key.into(),
        message,
    }
}

/// The config with the default law filled in where it gives no formula.
fn with_default_law(mut cfg: ExpressionConfig) -> (String, ExpressionConfig) {
    match cfg.force.take() {
        Some(force) => (force, cfg),
        None => {
            let mut defaults = ExpressionConfig::default();
            for spec in DEFAULT_PARAMS {
                let name = spec.name.to_string();
                defaults.params.insert(name.clone(), spec.default);
                defaults
                    .bounds
                    .insert(name.clone(), [spec.lower, spec.upper]);
                defaults.units.insert(name, spec.unit.to_string());
            }
            defaults.params.extend(cfg.params);
            defaults.bounds.extend(cfg.bounds);
            defaults.units.extend(cfg.units);
            (DEFAULT_FORCE.to_string(), defaults)
        }
    }
}

/// Every name of `channels` is a valid name, neither `v`, `N`, `x`, `a`, `u`, a function nor
/// a parameter, that the formula uses.
fn check_channel_names(
    cfg: &ExpressionConfig,
    parsed: &Parsed,
    force: &str,
) -> Result<(), ModelError> {
    for name in &cfg.channels {
        if ["v", "N", "x", "a", "u"].contains(&name.as_str()) || formula::is_reserved(name) {
            return Err(bad_key(
                "channels",
                format!(
                    "`{name}` is reserved (v, N, x, a, u and function names cannot be channels)"
                ),
            ));
        }
        if !formula::is_identifier(name) {
            return Err(bad_key(
                "channels",
                format!(
                    "`{name}` is not a valid name (a letter or `_`, then letters, digits or `_`)"
                ),
            ));
        }
        if cfg.params.contains_key(name) {
            return Err(bad_key(
                "channels",
                format!("`{name}` is both a parameter and a channel"),
            ));
        }
        if !parsed.variables().iter().any(|(n, _)| n == name) {
            return Err(bad_key(
                "channels",
                format!("channel `{name}` does not appear in the formula `{force}`"),
            ));
        }
    }
    Ok(())
}

/// The conditions the formula reads, in order of first appearance: `x`, `a`, `u` where no
/// parameter has the name, and the channels named in `channels`.
fn ordered_conditions(parsed: &Parsed, cfg: &ExpressionConfig) -> Vec<Condition> {
    parsed
        .variables()
        .iter()
        .map(|(name, _)| name.as_str())
        .filter(|name| !cfg.params.contains_key(*name))
        .filter(|name| ["x", "a", "u"].contains(name) || cfg.channels.iter().any(|c| c == name))
        .map(Condition::from_name)
        .collect()
}

/// Every name of `params` is a valid, unreserved name that the formula uses.
fn check_param_names(
    cfg: &ExpressionConfig,
    parsed: &Parsed,
    force: &str,
) -> Result<(), ModelError> {
    for name in cfg.params.keys() {
        if name == "v" || name == "N" || formula::is_reserved(name) {
            return Err(bad_key(
                "params",
                format!("`{name}` is reserved (v, N and function names cannot be parameters)"),
            ));
        }
        if !formula::is_identifier(name) {
            return Err(bad_key(
                "params",
                format!(
                    "`{name}` is not a valid name (a letter or `_`, then letters, digits or `_`)"
                ),
            ));
        }
        if !parsed.variables().iter().any(|(n, _)| n == name) {
            return Err(bad_key(
                "params",
                format!("parameter `{name}` does not appear in the formula `{force}`"),
            ));
        }
    }
    Ok(())
}

/// `bounds` and `units` name only parameters, and every bound is ordered.
fn check_bounds_and_units(cfg: &ExpressionConfig) -> Result<(), ModelError> {
    for (key, names) in [
        ("bounds", cfg.bounds.keys().collect::<Vec<_>>()),
        ("units", cfg.units.keys().collect::<Vec<_>>()),
    ] {
        if let Some(name) = names.into_iter().find(|n| !cfg.params.contains_key(*n)) {
            return Err(bad_key(
                key,
                format!("`{name}` is not a parameter of the formula"),
            ));
        }
    }
    for (name, [lo, hi]) in &cfg.bounds {
        if lo.is_nan() || hi.is_nan() || lo > hi {
            return Err(bad_key(
                "bounds",
                format!("bounds of `{name}` must be [lower, upper] with lower <= upper, got [{lo}, {hi}]"),
            ));
        }
    }
    Ok(())
}

/// The parameters in order of first appearance in the formula.
fn ordered_params(parsed: &Parsed, mut cfg: ExpressionConfig) -> Vec<Param> {
    let mut params = Vec::new();
    for (name, _) in parsed.variables() {
        if name == "v" || name == "N" {
            continue;
        }
        if let Some(value) = cfg.params.remove(name) {
            params.push(Param {
                name: name.clone(),
                value,
                bounds: cfg.bounds.remove(name),
                unit: cfg.units.remove(name),
            });
        }
    }
    params
}

/// The formula compiled over (v, N, params..., conditions...), and its switched form with
/// sign(v) replaced by the slip direction (an extra last variable) when it has sign(v).
fn compile(
    parsed: &Parsed,
    params: &[Param],
    conditions: &[Condition],
) -> Result<(Formula, Option<Formula>), ModelError> {
    let mut variables = vec!["v", "N"];
    variables.extend(params.iter().map(|p| p.name.as_str()));
    variables.extend(conditions.iter().map(Condition::name));
    let compiled = parsed.compile(&variables)?;
    if !parsed.has_sign_of("v") {
        return Ok((compiled, None));
    }
    variables.push(DIRECTION);
    let switched = parsed
        .with_sign_of_replaced("v", DIRECTION)
        .compile(&variables)?;
    Ok((compiled, Some(switched)))
}

impl TryFrom<ExpressionConfig> for Expression {
    type Error = ModelError;

    fn try_from(cfg: ExpressionConfig) -> Result<Self, ModelError> {
        let (force, cfg) = with_default_law(cfg);
        let parsed: Parsed = formula::parse(&force)?;
        check_param_names(&cfg, &parsed, &force)?;
        check_channel_names(&cfg, &parsed, &force)?;
        check_bounds_and_units(&cfg)?;
        let conditions = ordered_conditions(&parsed, &cfg);
        let channels = cfg.channels.clone();
        let params = ordered_params(&parsed, cfg);
        let (compiled, switched) = compile(&parsed, &params, &conditions)?;
        Ok(Self {
            force,
            params,
            channels,
            conditions,
            compiled,
            switched,
        })
    }
}

impl From<Expression> for ExpressionConfig {
    fn from(m: Expression) -> Self {
        let mut cfg = ExpressionConfig {
            force: Some(m.force),
            channels: m.channels,
            ..ExpressionConfig::default()
        };
        for p in m.params {
            if let Some(b) = p.bounds {
                cfg.bounds.insert(p.name.clone(), b);
            }
            if let Some(u) = p.unit {
                cfg.units.insert(p.name.clone(), u);
            }
            cfg.params.insert(p.name, p.value);
        }
        cfg
    }
}

#[typetag::serde(name = "expression")]
impl FrictionModel for Expression {
    fn name(&self) -> &'static str {
        MODEL
    }
    fn equation(&self) -> String {
        format!("F = {}", self.force)
    }
    fn param_info(&self) -> Vec<ParamInfo> {
        self.params
            .iter()
            .map(|p| {
                let [lo, hi] = p.bounds.unwrap_or([f64::NEG_INFINITY, f64::INFINITY]);
                ParamInfo::new(
                    &p.name,
                    p.unit.as_deref().unwrap_or("?"),
                    p.value,
                    (lo, hi),
                    "parameter of the formula",
                )
            })
            .collect()
    }
    fn params(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.value).collect()
    }
    fn set_params(&mut self, values: &[f64]) -> Result<(), ModelError> {
        check_len(self.name(), self.params.len(), values.len())?;
        for (p, &v) in self.params.iter_mut().zip(values) {
            p.value = v;
        }
        Ok(())
    }
    fn force(&self, v: f64, _z: &[f64], normal: f64) -> f64 {
        self.eval(&self.compiled, v, normal, &[], None)
    }
    fn conditions(&self) -> Vec<Condition> {
        self.conditions.clone()
    }
    fn force_in(&self, v: f64, _z: &[f64], normal: f64, at: &[f64]) -> f64 {
        self.eval(&self.compiled, v, normal, at, None)
    }
    crate::law_groups!(switching, staging);
}

impl SwitchedLaw for Expression {
    crate::at_no_conditions!(switching);
    fn static_limit_in(&self, normal: f64, at: &[f64]) -> Option<f64> {
        self.breakaway_in(normal, at)
    }
    fn slip_force_in(&self, v: f64, direction: f64, normal: f64, at: &[f64]) -> f64 {
        match &self.switched {
            Some(f) => self.eval(f, v, normal, at, Some(direction)),
            None => self.force_in(v, &[], normal, at),
        }
    }
}

impl Staging for Expression {
    fn apply_guess(&mut self, hint: &GuessHint) {
        // Only the conventional name is guessed: a parameter `mu` is the mean coefficient.
        for p in &mut self.params {
            if p.name == "mu" && hint.mu.is_finite() {
                let [lo, hi] = p.bounds.unwrap_or([f64::NEG_INFINITY, f64::INFINITY]);
                p.value = hint.mu.clamp(lo, hi);
            }
        }
    }
}
