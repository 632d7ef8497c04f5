//! The run specification: what a front end (the CLI's TOML config, a Python dict) asks the
//! engine to do, as one serializable value, and every rule that turns it into engine options.
//!
//! A front end parses its own syntax into a [`Spec`] (serde does the work: unknown keys are
//! errors, defaults are filled in here, values are checked by `try_from` conversions), then
//! asks the spec for engine options ([`Spec::fit_options`], [`SimulationSpec::sim_options`],
//! [`EnergySpec::options`]). Run-time hooks (progress, parallelism) are not part of the spec:
//! they travel apart in [`Hooks`].
//!
//! The measured records are not part of this value yet: front ends read them and hand them
//! to the jobs in [`crate::jobs`].

use crate::axis::{Axis, Restoring};
use crate::data::{RecordSource, RecordUse, MAX_SAMPLES};
use crate::energy::{Differentiator, EnergyOptions};
use crate::identify::{
    check_min_speed, non_model_bound_keys, FitDomain, FitOptions, ForceTarget, OscillatorParam,
    ProgressFn, PropertyUncertainty, Search,
};
use crate::oscillator::{Oscillator, OscillatorProperty, PartialOscillator};
use crate::simulate::{Integrator, SimOptions};
use frictionid_models::suggest::did_you_mean;
use frictionid_models::{default_model, names, FrictionModel, ModelError};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use thiserror::Error;

/// Why a spec cannot be built or used.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SpecError {
    /// A command needs a `[model]` the spec does not have.
    #[error("{purpose} needs a [model] table (e.g. type = \"coulomb\")")]
    MissingModel {
        /// The command.
        purpose: String,
    },
    /// A command needs a `[simulation]` the spec does not have.
    #[error("{purpose} needs a [simulation] table (x0, duration, sample_rate)")]
    MissingSimulation {
        /// The command.
        purpose: String,
    },
    /// `[fit] free` or `bounds` names a parameter the model does not have.
    #[error(
        "[fit] {key}: model `{model}` has no parameter `{name}`{hint}; its parameters: {known}"
    )]
    UnknownParameter {
        /// `free` or `bounds`.
        key: String,
        /// The model.
        model: String,
        /// The name as written.
        name: String,
        /// " (did you mean `x`?)" or empty.
        hint: String,
        /// The model's parameters, comma-separated.
        known: String,
    },
    /// A bound that is not an ordered interval.
    #[error("[fit] bounds: `{name}` = [{lower}, {upper}] is not an interval with lower < upper")]
    BadBounds {
        /// The parameter.
        name: String,
        /// Lower bound as written.
        lower: f64,
        /// Upper bound as written.
        upper: f64,
    },
    /// A `[fit.options]` value that cannot be used.
    #[error("{0}")]
    FitOption(String),
    /// A value out of range or a key missing in `[simulation]`.
    #[error("[simulation]: {0}")]
    Simulation(String),
    /// An empty list of models to compare.
    #[error("no models to compare")]
    NoModels,
    /// A model name that is not registered.
    #[error("unknown model `{name}` in the models to compare{hint}; registered models: {known}")]
    UnknownModel {
        /// The name as written.
        name: String,
        /// " (did you mean `x`?)" or empty.
        hint: String,
        /// Every registered name, comma-separated.
        known: String,
    },
    /// An oscillator property or its standard deviation out of range.
    #[error("[oscillator]: {0}")]
    Oscillator(String),
    /// A model error.
    #[error(transparent)]
    Model(#[from] ModelError),
}

/// Run-time hooks of a job, kept apart from the (serializable) [`Spec`].
#[derive(Clone)]
pub struct Hooks {
    /// Called after every solver iteration (from worker threads).
    pub progress: Option<ProgressFn>,
    /// Use several cores (records, Jacobian columns, starts, models).
    pub parallel: bool,
}

impl Default for Hooks {
    fn default() -> Self {
        Self {
            progress: None,
            parallel: true,
        }
    }
}

impl std::fmt::Debug for Hooks {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Hooks")
            .field("progress", &self.progress.is_some())
            .field("parallel", &self.parallel)
            .finish()
    }
}

/// `[oscillator]`: the oscillator's properties and, optionally, one standard deviation of
/// each (`mass_std`, `damping_std`, `stiffness_std`, `normal_force_std`; SI units, 0 when
/// absent: known exactly), which the uncertainty budget propagates into every fitted
/// parameter. Deserialized through [`OscillatorInput`], which checks every value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "OscillatorInput", into = "OscillatorInput")]
pub struct OscillatorSpec {
    /// The nominal properties (placeholders for the keys in `unknown`).
    pub oscillator: Oscillator,
    /// Their standard deviations.
    pub uncertainty: PropertyUncertainty,
    /// The properties not given: a force-domain fit on a measured force needs only the
    /// normal force; the analyses that need the others name them
    /// ([`crate::identify::require_mechanics`]).
    pub unknown: Vec<OscillatorProperty>,
}

/// `[oscillator]` as written; [`OscillatorSpec`] is built from it.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OscillatorInput {
    /// `linear` (default) or `rotary`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    axis: Option<Axis>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    mass: Option<f64>,
    /// The rotary name of `mass` [kg m^2].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    inertia: Option<f64>,
    /// The restoring law (default: the linear spring of `stiffness`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    restoring: Option<Restoring>,
    /// The input's offset: a constant force (torque) in the balance [N or N m] (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    input_offset: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    damping: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    stiffness: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    normal_force: Option<f64>,
    /// One standard deviation of the mass (`inertia_std` on a rotary axis).
    #[serde(default, alias = "inertia_std")]
    mass_std: f64,
    #[serde(default)]
    damping_std: f64,
    #[serde(default)]
    stiffness_std: f64,
    #[serde(default)]
    normal_force_std: f64,
}

impl TryFrom<OscillatorInput> for OscillatorSpec {
    type Error = SpecError;

    fn try_from(o: OscillatorInput) -> Result<Self, SpecError> {
        let (axis, restoring) = axis_of(&o)?;
        let (mut oscillator, mut unknown) = PartialOscillator {
            mass: o.mass.or(o.inertia),
            damping: o.damping,
            stiffness: o.stiffness,
            normal_force: o.normal_force,
        }
        .resolve();
        oscillator.axis = axis;
        oscillator.restoring = restoring;
        oscillator.input_offset = o.input_offset.unwrap_or(0.0);
        if !restoring.law().reads_stiffness() {
            unknown.retain(|&p| p != OscillatorProperty::Stiffness);
        }
        let spec = Self {
            oscillator,
            uncertainty: PropertyUncertainty {
                mass: o.mass_std,
                damping: o.damping_std,
                stiffness: o.stiffness_std,
                normal_force: o.normal_force_std,
            },
            unknown,
        };
        spec.validate()?;
        Ok(spec)
    }
}

/// The axis and the restoring law of `[oscillator]`: the pendulum turns (a rotary axis
/// unless the axis is given, an error on a linear one); `inertia` belongs to a rotary
/// axis and names the same property as `mass`.
fn axis_of(o: &OscillatorInput) -> Result<(Axis, Restoring), SpecError> {
    let restoring = o.restoring.unwrap_or_default();
    let turns = matches!(restoring, Restoring::Pendulum(_));
    let axis = match (o.axis, turns) {
        (Some(Axis::Linear), true) => {
            return Err(SpecError::Oscillator(
                "`restoring` = pendulum turns about an axis: set `axis = \"rotary\"`".into(),
            ))
        }
        (Some(axis), _) => axis,
        (None, true) => Axis::Rotary,
        (None, false) => Axis::Linear,
    };
    if o.mass.is_some() && o.inertia.is_some() {
        return Err(SpecError::Oscillator(
            "give `inertia` or `mass` (the same property), not both".into(),
        ));
    }
    if o.inertia.is_some() && axis.is_linear() {
        return Err(SpecError::Oscillator(
            "`inertia` is the rotary axis's name of `mass`: set `axis = \"rotary\"` or \
             write `mass`"
                .into(),
        ));
    }
    Ok((axis, restoring))
}

impl From<OscillatorSpec> for OscillatorInput {
    fn from(o: OscillatorSpec) -> Self {
        let (p, u) = (o.oscillator, o.uncertainty);
        let given = |property: OscillatorProperty, value: f64| {
            (!o.unknown.contains(&property)).then_some(value)
        };
        let rotary = !p.axis.is_linear();
        Self {
            axis: rotary.then_some(p.axis),
            inertia: given(OscillatorProperty::Mass, p.mass).filter(|_| rotary),
            restoring: (!p.restoring.is_linear_spring()).then_some(p.restoring),
            input_offset: (p.input_offset != 0.0).then_some(p.input_offset),
            mass: given(OscillatorProperty::Mass, p.mass).filter(|_| !rotary),
            damping: given(OscillatorProperty::Damping, p.damping),
            stiffness: given(OscillatorProperty::Stiffness, p.stiffness)
                .filter(|_| p.restoring.law().reads_stiffness()),
            normal_force: given(OscillatorProperty::NormalForce, p.normal_force),
            mass_std: u.mass,
            damping_std: u.damping,
            stiffness_std: u.stiffness,
            normal_force_std: u.normal_force,
        }
    }
}

impl From<Oscillator> for OscillatorSpec {
    /// Properties known exactly.
    fn from(oscillator: Oscillator) -> Self {
        Self {
            oscillator,
            uncertainty: PropertyUncertainty::default(),
            unknown: Vec::new(),
        }
    }
}

impl OscillatorSpec {
    /// Checks the properties and their standard deviations.
    pub fn validate(&self) -> Result<(), SpecError> {
        self.oscillator
            .validate()
            .and_then(|()| self.uncertainty.validate())
            .map_err(|e| SpecError::Oscillator(e.to_string()))
    }
}

/// Everything but the records: oscillator, model, fit, simulation and energy settings.
#[derive(Debug, Clone, Serialize)]
pub struct Spec {
    /// The oscillator.
    pub oscillator: Oscillator,
    /// One standard deviation of each oscillator property (the uncertainty budget).
    pub uncertainty: PropertyUncertainty,
    /// The friction model, if given.
    pub model: Option<ModelSpec>,
    /// Fit settings (defaults when absent).
    pub fit: FitSpec,
    /// Simulation settings, if given.
    pub simulation: Option<SimulationSpec>,
    /// Energy-analysis settings (defaults when absent).
    pub energy: EnergySpec,
    /// `[oscillator]` properties not given (their values in `oscillator` are placeholders):
    /// a force-domain fit on a measured force needs only the normal force.
    pub unknown_oscillator: Vec<OscillatorProperty>,
}

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

fn parameter_names(model: &dyn FrictionModel) -> Vec<String> {
    model.param_info().into_iter().map(|p| p.name).collect()
}

impl Spec {
    /// A spec with `oscillator`, `model` and the other settings, checked against each other.
    pub fn new(
        oscillator: impl Into<OscillatorSpec>,
        model: Option<ModelSpec>,
        fit: FitSpec,
        simulation: Option<SimulationSpec>,
        energy: EnergySpec,
    ) -> Result<Self, SpecError> {
        let oscillator: OscillatorSpec = oscillator.into();
        oscillator.validate()?;
        if let Some(m) = &model {
            fit.check_against(m.model.as_ref())?;
        }
        check_min_speed(fit.options.min_speed, fit.options.domain).map_err(SpecError::FitOption)?;
        Ok(Self {
            oscillator: oscillator.oscillator,
            uncertainty: oscillator.uncertainty,
            model,
            fit,
            simulation,
            energy,
            unknown_oscillator: oscillator.unknown,
        })
    }

    /// How the fit uses its records: simulated (velocity domain) or replayed as measured
    /// (force domain), which decides whether a `[[records]]` entry needs `x0`.
    pub fn record_use(&self) -> RecordUse {
        match self.fit.options.domain {
            FitDomain::Velocity => RecordUse::Simulated,
            FitDomain::Force => RecordUse::Replayed,
        }
    }

    /// The model, or an error naming the command that needs it.
    pub fn require_model(&self, purpose: &str) -> Result<&ModelSpec, SpecError> {
        self.model.as_ref().ok_or_else(|| SpecError::MissingModel {
            purpose: purpose.into(),
        })
    }

    /// The simulation settings, or an error naming the command that needs them.
    pub fn require_simulation(&self, purpose: &str) -> Result<&SimulationSpec, SpecError> {
        self.simulation
            .as_ref()
            .ok_or_else(|| SpecError::MissingSimulation {
                purpose: purpose.into(),
            })
    }

    /// The identifier options: `[fit]`, `[fit.options]` and `[energy]`, with `hooks`.
    /// `keep_initial` names parameters whose current values start the fit (see
    /// [`ModelSpec::given`]).
    pub fn fit_options(&self, keep_initial: &[String], hooks: &Hooks) -> FitOptions {
        let given = &self.fit.options;
        let defaults = FitOptions::default();
        FitOptions {
            free: self.fit.free.clone(),
            bounds: self
                .fit
                .bounds
                .iter()
                .map(|(k, [lo, hi])| (k.clone(), (*lo, *hi)))
                .collect(),
            guess: given.guess.unwrap_or(true),
            keep_initial: keep_initial.to_vec(),
            oscillator: given.oscillator.clone(),
            velocity_offset: given.velocity_offset,
            time_shift: given.time_shift,
            x0: given.x0,
            uncertainty: self.uncertainty,
            domain: given.domain,
            force_target: given.force_target,
            force_offset: given.force_offset,
            min_speed: given.min_speed,
            prefit: given.prefit.unwrap_or(defaults.prefit),
            unknown_oscillator: self.unknown_oscillator.clone(),
            multistart: given.multistart,
            search: given.search,
            max_iterations: self.fit.max_iterations.unwrap_or(defaults.max_iterations),
            tolerance: self.fit.tolerance.or(defaults.tolerance),
            energy: self.energy.options(),
            parallel: hooks.parallel,
            progress: hooks.progress.clone(),
            sim: SimOptions {
                integrator: given
                    .integrator
                    .map_or(defaults.sim.integrator, IntegratorMethod::engine_integrator),
                ..defaults.sim
            },
        }
    }

    /// The models to compare: `requested`, else `[fit.options] models`, else every registered
    /// model. A model named in `[model]` starts from the values given there.
    pub fn models_to_compare(
        &self,
        requested: Option<&[String]>,
    ) -> Result<Vec<Box<dyn FrictionModel>>, SpecError> {
        let registered = names();
        let list: Vec<String> = match (requested, &self.fit.options.models) {
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

/// `[fit]`: which parameters to fit, their bounds and the solver's limits.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FitSpec {
    /// Names of the parameters to fit; `None` means every parameter of the model that is not
    /// fixed by default.
    pub free: Option<Vec<String>>,
    /// Search bounds [lower, upper] per parameter (default: the model's physical bounds).
    pub bounds: BTreeMap<String, [f64; 2]>,
    /// Largest number of solver iterations.
    pub max_iterations: Option<u64>,
    /// Convergence tolerance of the solver (relative change of the cost).
    pub tolerance: Option<f64>,
    /// Further identifier options (`[fit.options]`).
    pub options: FitOptionsSpec,
}

/// `[fit.options]`: identifier options beyond `free` and `bounds`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FitOptionsSpec {
    /// Oscillator properties to fit with the model: any of "mass", "damping", "stiffness"
    /// (velocity fits, and force fits with `force_target = "inverse_dynamics"`).
    pub oscillator: Vec<OscillatorParam>,
    /// Fit a velocity offset per record.
    pub velocity_offset: bool,
    /// Fit a release-time shift per record.
    pub time_shift: bool,
    /// Fit the release displacement x0 of each record, starting from its given value.
    pub x0: bool,
    /// Number of starts (default: 1, or 4 when more than two model parameters are free).
    pub multistart: Option<usize>,
    /// Search strategy: "local", "staged" or "global" (default: staged for models with
    /// internal states or more than two free parameters, local otherwise).
    pub search: Option<Search>,
    /// Data-driven initial values for parameters the model table does not give (default true).
    pub guess: Option<bool>,
    /// Models compared by `compare` when none are requested.
    pub models: Option<Vec<String>>,
    /// What the fit compares: "velocity" (default) or "force".
    pub domain: FitDomain,
    /// Force domain: "auto" (default: the force channel, else Eq. 7), "measured", "energy" or
    /// "inverse_dynamics" (the input force against J a + c v + R(q) + F).
    pub force_target: ForceTarget,
    /// Force domain: fit a constant force offset per record (a load cell's zero, a drive's
    /// force offset).
    pub force_offset: bool,
    /// Force domain: compare only the samples with |v| >= min_speed \[m/s\] (the sliding
    /// ones; default: every sample).
    pub min_speed: Option<f64>,
    /// Velocity fits of dynamic models start also from a force-domain prefit (default false).
    pub prefit: Option<bool>,
    /// The integrator of the fit's simulations (default `auto`: exact, rodas or dopri5 by the
    /// law and its stiffness, which stiff bristle records, sigma0 >= 1e6 N/m, need).
    pub integrator: Option<IntegratorMethod>,
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
        for name in self.free.iter().flatten() {
            check(name, "free")?;
        }
        let other = non_model_bound_keys();
        for (name, [lower, upper]) in &self.bounds {
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

    /// The free parameter names for `model`: `free` as written, or else every parameter not
    /// marked fixed by default (such as the Stribeck shape exponent).
    pub fn free_names(&self, model: &dyn FrictionModel) -> Vec<String> {
        match &self.free {
            Some(list) => list.clone(),
            None => model
                .param_info()
                .into_iter()
                .filter(|p| !p.fixed_by_default)
                .map(|p| p.name)
                .collect(),
        }
    }
}

/// The ODE integrator chosen in `[simulation.integrator]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum IntegratorMethod {
    /// Adaptive Dormand-Prince 5(4) with dense output and event location.
    Dopri5,
    /// Fixed-step explicit Euler (for comparison only).
    Euler,
    /// The fits' choice, and `simulate`'s default: the exact propagator for laws affine in v,
    /// Rodas4 where the motion is stiff (bristle contacts of sigma0 >= 1e6 N/m), Dopri5
    /// otherwise.
    #[default]
    Auto,
    /// The exact closed-form propagator (coulomb, viscous_coulomb, none).
    Exact,
    /// The stiff Rosenbrock method Rodas4 (bristle and element models with stiff contacts).
    Rodas,
}

/// `[simulation.integrator]`: integrator choice (default `auto`, as the fits) and tolerances
/// (the engine's defaults when absent).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IntegratorSpec {
    /// The integration method.
    pub method: IntegratorMethod,
    /// Euler only: steps per natural period.
    pub steps_per_period: Option<f64>,
    /// Relative tolerance.
    pub rtol: Option<f64>,
    /// Absolute tolerance.
    pub atol: Option<f64>,
    /// Largest number of steps.
    pub max_steps: Option<u64>,
    /// Largest number of events (turning points, sticks).
    pub max_events: Option<usize>,
}

/// Steps per natural period of the Euler integrator when neither the spec nor the engine's
/// default options name a number.
pub const EULER_STEPS_PER_PERIOD: f64 = 10_000.0;

impl IntegratorMethod {
    /// The engine's integrator (Euler with [`EULER_STEPS_PER_PERIOD`]).
    pub fn engine_integrator(self) -> Integrator {
        match self {
            IntegratorMethod::Dopri5 => Integrator::Dopri5,
            IntegratorMethod::Auto => Integrator::Auto,
            IntegratorMethod::Exact => Integrator::Exact,
            IntegratorMethod::Rodas => Integrator::Rodas,
            IntegratorMethod::Euler => Integrator::Euler {
                steps_per_period: EULER_STEPS_PER_PERIOD,
            },
        }
    }
}

impl IntegratorSpec {
    /// The engine's simulation options (engine defaults where not given).
    pub fn sim_options(&self) -> SimOptions {
        let defaults = SimOptions::default();
        let integrator = match self.method {
            IntegratorMethod::Euler => Integrator::Euler {
                steps_per_period: match (self.steps_per_period, &defaults.integrator) {
                    (Some(n), _) => n,
                    (None, Integrator::Euler { steps_per_period }) => *steps_per_period,
                    (None, _) => EULER_STEPS_PER_PERIOD,
                },
            },
            method => method.engine_integrator(),
        };
        SimOptions {
            integrator,
            rtol: self.rtol.unwrap_or(defaults.rtol),
            atol: self.atol.unwrap_or(defaults.atol),
            max_steps: self.max_steps.unwrap_or(defaults.max_steps),
            max_events: self.max_events.unwrap_or(defaults.max_events),
        }
    }
}

/// Sample rate of a simulation that does not name one \[Hz\].
pub const DEFAULT_SAMPLE_RATE: f64 = 1000.0;

/// `[simulation]`: the release state, the time grid and optional synthetic noise. Deserialized
/// through [`SimulationInput`], which fills the defaults and checks every value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "SimulationInput")]
pub struct SimulationSpec {
    /// Release displacement \[m\].
    pub x0: f64,
    /// Release velocity \[m/s\].
    pub v0: f64,
    /// Initial internal states of the model (default: the model's own).
    pub z0: Option<Vec<f64>>,
    /// Simulated time \[s\].
    pub duration: f64,
    /// Output sample rate \[Hz\].
    pub sample_rate: f64,
    /// Standard deviation of the Gaussian velocity noise of a synthetic record \[m/s\];
    /// `None`: no record.
    pub noise: Option<f64>,
    /// Seed of the noise generator.
    pub seed: u64,
    /// Integrator options.
    pub integrator: IntegratorSpec,
    /// The measured input u(t) that drives the axis: a file read as a `[[records]]` entry
    /// is (`file`, `time_column`, `input_force_column`, `input_force_scale`, `format`, ...),
    /// its `input_force` channel taken linear between samples. `None`: free vibration.
    pub input: Option<RecordSource>,
}

/// `[simulation]` as written: every key optional; [`SimulationSpec`] is built from it.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationInput {
    x0: Option<f64>,
    #[serde(default)]
    v0: f64,
    z0: Option<Vec<f64>>,
    duration: Option<f64>,
    sample_rate: Option<f64>,
    noise: Option<f64>,
    #[serde(default)]
    seed: u64,
    #[serde(default)]
    integrator: IntegratorSpec,
    input: Option<RecordSource>,
}

fn positive(what: &str, value: f64) -> Result<f64, SpecError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(SpecError::Simulation(format!(
            "`{what}` must be a positive number, got {value}"
        )))
    }
}

fn finite(what: &str, value: f64) -> Result<f64, SpecError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(SpecError::Simulation(format!(
            "`{what}` must be finite, got {value}"
        )))
    }
}

fn required(what: &str, meaning: &str, value: Option<f64>) -> Result<f64, SpecError> {
    value.ok_or_else(|| SpecError::Simulation(format!("missing `{what}` ({meaning})")))
}

impl TryFrom<SimulationInput> for SimulationSpec {
    type Error = SpecError;

    fn try_from(s: SimulationInput) -> Result<Self, SpecError> {
        let x0 = required("x0", "the release displacement, m", s.x0)?;
        let duration = required("duration", "the simulated time, s", s.duration)?;
        if let Some(n) = s.noise.filter(|n| !(n.is_finite() && *n >= 0.0)) {
            return Err(SpecError::Simulation(format!(
                "`noise` must be >= 0, got {n}"
            )));
        }
        let duration = positive("duration", duration)?;
        let sample_rate = positive("sample_rate", s.sample_rate.unwrap_or(DEFAULT_SAMPLE_RATE))?;
        // The output holds duration * sample_rate + 1 samples: bound it before allocating.
        let samples = duration * sample_rate;
        if samples >= MAX_SAMPLES as f64 {
            return Err(SpecError::Simulation(format!(
                "duration * sample_rate = {samples:e} samples; at most {MAX_SAMPLES} are written"
            )));
        }
        Ok(Self {
            x0: finite("x0", x0)?,
            v0: finite("v0", s.v0)?,
            z0: s.z0,
            duration,
            sample_rate,
            noise: s.noise,
            seed: s.seed,
            integrator: s.integrator,
            input: s.input,
        })
    }
}

impl SimulationSpec {
    /// The engine's simulation options.
    pub fn sim_options(&self) -> SimOptions {
        self.integrator.sim_options()
    }
}

/// The differentiator of the energy analysis (`[energy] method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DifferentiatorMethod {
    /// Savitzky-Golay with a window chosen from the record (the default; see
    /// [`Differentiator::Auto`]).
    Auto,
    /// The paper's differentiation (central differences and a moving average).
    Paper,
    /// Savitzky-Golay smoothing differentiator.
    SavitzkyGolay,
}

/// `[energy]`: energy-analysis options; `None` fields take the engine's defaults.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EnergySpec {
    /// Differentiator.
    pub method: Option<DifferentiatorMethod>,
    /// Savitzky-Golay window length (odd number of samples).
    pub window: Option<usize>,
    /// Savitzky-Golay polynomial order.
    pub order: Option<usize>,
    /// Speeds below this are masked in the friction-force estimate \[m/s\].
    pub velocity_threshold: Option<f64>,
    /// Reference friction force for the comparison \[N\] (default: from the model).
    pub reference_force: Option<f64>,
}

/// Savitzky-Golay window and order used when the engine's default differentiator is the
/// paper's and a window or an order is given.
const FALLBACK_SAVITZKY_GOLAY: (usize, usize) = (21, 3);
/// ... and when it is the automatic one: its choice on the FMM rig at 1 kHz.
const AUTO_SAVITZKY_GOLAY: (usize, usize) = (31, crate::energy::AUTO_ORDER);

impl EnergySpec {
    /// The engine's energy-analysis options (engine defaults where not given).
    pub fn options(&self) -> EnergyOptions {
        let defaults = EnergyOptions::default();
        EnergyOptions {
            differentiator: self.differentiator(defaults.differentiator),
            velocity_threshold: self
                .velocity_threshold
                .unwrap_or(defaults.velocity_threshold),
        }
    }

    fn differentiator(&self, default: Differentiator) -> Differentiator {
        match self.method {
            Some(DifferentiatorMethod::Paper) => return Differentiator::Paper,
            Some(DifferentiatorMethod::Auto) => return Differentiator::Auto,
            _ => {}
        }
        if self.method.is_none() && self.window.is_none() && self.order.is_none() {
            return default;
        }
        let (window, order) = match default {
            Differentiator::SavitzkyGolay { window, order } => (window, order),
            Differentiator::Paper => FALLBACK_SAVITZKY_GOLAY,
            Differentiator::Auto => AUTO_SAVITZKY_GOLAY,
        };
        Differentiator::SavitzkyGolay {
            window: self.window.unwrap_or(window),
            order: self.order.unwrap_or(order),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn energy_spec_maps_onto_engine_options() {
        let d = EnergyOptions::default();
        assert_eq!(EnergySpec::default().options(), d);
        let o = EnergySpec {
            method: Some(DifferentiatorMethod::Paper),
            velocity_threshold: Some(2e-3),
            ..EnergySpec::default()
        }
        .options();
        assert_eq!(o.differentiator, Differentiator::Paper);
        assert_eq!(o.velocity_threshold, 2e-3);
        let o = EnergySpec {
            window: Some(41),
            ..EnergySpec::default()
        }
        .options();
        // A window without a method is Savitzky-Golay with the automatic choice's degree.
        assert_eq!(d.differentiator, Differentiator::Auto);
        assert_eq!(
            o.differentiator,
            Differentiator::SavitzkyGolay {
                window: 41,
                order: crate::energy::AUTO_ORDER
            }
        );
    }

    #[test]
    fn integrator_spec_maps_onto_engine_options() {
        let d = SimOptions::default();
        // `simulate` integrates as the fits do by default: `auto`, with the engine's
        // tolerances and limits.
        let auto = SimOptions {
            integrator: Integrator::Auto,
            ..d
        };
        assert_eq!(IntegratorSpec::default().sim_options(), auto);
        let o = IntegratorSpec {
            method: IntegratorMethod::Euler,
            steps_per_period: Some(1e5),
            rtol: Some(1e-6),
            max_events: Some(7),
            ..IntegratorSpec::default()
        }
        .sim_options();
        assert_eq!(
            o.integrator,
            Integrator::Euler {
                steps_per_period: 1e5
            }
        );
        assert_eq!((o.rtol, o.atol, o.max_events), (1e-6, d.atol, 7));
    }

    /// A Python front end builds the same spec from JSON dicts: defaults filled, values checked.
    #[test]
    fn simulation_and_fit_specs_deserialize_from_json_with_defaults() {
        let s: SimulationSpec =
            serde_json::from_value(serde_json::json!({"x0": 0.01, "duration": 1.0})).unwrap();
        assert_eq!(
            (s.v0, s.sample_rate, s.noise, s.seed),
            (0.0, DEFAULT_SAMPLE_RATE, None, 0)
        );
        let e = serde_json::from_value::<SimulationSpec>(serde_json::json!({"duration": 1.0}))
            .unwrap_err()
            .to_string();
        assert!(e.contains("[simulation]: missing `x0`"), "{e}");
        let e = serde_json::from_value::<FitSpec>(
            serde_json::json!({"options": {"velocity_ofset": true}}),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("unknown field `velocity_ofset`"), "{e}");
        let f: FitSpec = serde_json::from_value(
            serde_json::json!({"options": {"oscillator": ["mass"], "multistart": 3}}),
        )
        .unwrap();
        assert_eq!(f.options.oscillator, vec![OscillatorParam::Mass]);
    }

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
        assert_eq!(o.free, Some(vec!["mu".to_string()]));
        assert_eq!(o.bounds.get("mu"), Some(&(0.0, 1.0)));
        assert_eq!(o.max_iterations, 7);
        assert!(o.velocity_offset && !o.guess && !o.parallel);
        assert_eq!(o.keep_initial, vec!["mu".to_string()]);
        assert_eq!(o.sim, FitOptions::default().sim);
    }

    #[test]
    fn fit_spec_names_unknown_parameters_and_bad_bounds() {
        let coulomb = frictionid_models::Coulomb::default();
        let fit = FitSpec {
            free: Some(vec!["mu_".into()]),
            ..FitSpec::default()
        };
        let e = fit.check_against(&coulomb).unwrap_err().to_string();
        assert!(e.contains("no parameter `mu_` (did you mean `mu`?)"), "{e}");
        let fit = FitSpec {
            bounds: [("mu".to_string(), [1.0, 0.5])].into(),
            ..FitSpec::default()
        };
        let e = fit.check_against(&coulomb).unwrap_err().to_string();
        assert!(e.contains("not an interval"), "{e}");
        // Bounds of the nuisance parameters and the oscillator are not model parameters.
        let fit = FitSpec {
            bounds: [
                ("shift".to_string(), [-0.5, 0.5]),
                ("x0".to_string(), [0.009, 0.011]),
                ("offset".to_string(), [-1e-3, 1e-3]),
            ]
            .into(),
            ..FitSpec::default()
        };
        fit.check_against(&coulomb).unwrap();
        let fit = FitSpec {
            bounds: [("x0".to_string(), [0.011, 0.009])].into(),
            ..FitSpec::default()
        };
        let e = fit.check_against(&coulomb).unwrap_err().to_string();
        assert!(
            e.contains("`x0` = [0.011, 0.009] is not an interval"),
            "{e}"
        );
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
