//! The run specification: what a front end (the CLI's TOML config, a Python dict) asks the
//! engine to do, as one value, and every rule that turns it into engine options.
//!
//! A front end parses its own syntax into a [`Spec`] (serde does the work: unknown keys are
//! errors, defaults are the parts' own, values are checked by `try_from` conversions), then
//! asks the spec for engine options ([`Spec::fit_options`], [`SimulationSpec::sim_options`],
//! [`EnergySpec::options`]). Run-time hooks (progress, parallelism) are not part of the spec:
//! they travel apart in [`Hooks`].
//!
//! One file per table: [`oscillator`], [`model`], [`fit`] (`[fit]` and `[fit.options]`, made
//! of the fit options' parts), [`simulation`], [`energy`]; [`resolve`] turns a spec into the
//! run's values; [`error`] says why a spec cannot be built.
//!
//! The measured records are not part of this value yet: front ends read them and hand them
//! to the jobs in [`crate::jobs`].

pub(crate) mod energy;
pub(crate) mod error;
pub(crate) mod fit;
pub(crate) mod model;
pub(crate) mod oscillator;
pub(crate) mod plan;
pub(crate) mod resolve;
pub(crate) mod simulation;

pub use self::energy::{DifferentiatorMethod, EnergySpec};
pub use self::error::SpecError;
pub use self::fit::{FitSpec, RunChoices};
pub use self::model::ModelSpec;
pub use self::oscillator::{OscillatorSpec, OscillatorTable};
pub use self::plan::{prior_model, CandidateSpec, PlanSpec};
pub use self::simulation::{
    IntegratorMethod, IntegratorSpec, SimulationInput, SimulationSpec, DEFAULT_SAMPLE_RATE,
    EULER_STEPS_PER_PERIOD,
};
pub use crate::identify::Hooks;

use crate::data::RecordUse;
use crate::identify::problem::unit_check::{check_driven_balance, check_swing, MassReference};
use crate::identify::{check_min_speed, FitDomain, PropertyUncertainty};
use crate::oscillator::{Oscillator, OscillatorProperty};
use crate::record::{check_scales, Record, ScaleError};

/// Everything but the records: oscillator, model, fit, simulation and energy settings.
#[derive(Debug, Clone)]
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
    /// `[oscillator]` keys not given (their values in `oscillator` are placeholders): a
    /// force-domain fit on a measured force needs only the normal force.
    pub unknown_oscillator: Vec<OscillatorProperty>,
    /// `[oscillator]` keys not given whose values were assumed (damping: 0).
    pub assumed_oscillator: Vec<OscillatorProperty>,
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
        fit.check_search()?;
        check_min_speed(fit.target.min_speed, fit.target.domain).map_err(SpecError::FitOption)?;
        Ok(Self {
            oscillator: oscillator.oscillator,
            uncertainty: oscillator.uncertainty,
            model,
            fit,
            simulation,
            energy,
            unknown_oscillator: oscillator.unknown,
            assumed_oscillator: oscillator.assumed,
        })
    }

    /// How the fit uses its records: simulated (velocity domain) or replayed as measured
    /// (force domain), which decides whether a `[[records]]` entry needs `x0`.
    pub fn record_use(&self) -> RecordUse {
        match self.fit.target.domain {
            FitDomain::Velocity if self.oscillator.has_restoring_force() => RecordUse::Simulated,
            FitDomain::Velocity => RecordUse::Unpositioned,
            FitDomain::Force => RecordUse::Replayed,
        }
    }

    /// What was assumed for the `[oscillator]` keys not given, one sentence each (for the
    /// reports and the terminal), where the run's equation reads them: a simulation, a
    /// velocity fit, the energy analysis (a force-domain fit reads damping only through Eq. 7
    /// or inverse dynamics), once the keys those need are given.
    pub fn assumptions(&self) -> Vec<String> {
        let incomplete = [OscillatorProperty::Mass, OscillatorProperty::Stiffness]
            .iter()
            .any(|p| self.unknown_oscillator.contains(p));
        if self.fit.target.domain == FitDomain::Force || incomplete {
            // Nothing to say yet: the run is refused, naming the keys it needs first.
            return Vec::new();
        }
        self.assumed_oscillator
            .iter()
            .map(|p| {
                format!(
                    "[oscillator]: `{}` not given: assumed 0 (no viscous damping); give it, or \
                     fit it with `[fit.options] oscillator = [\"{}\"]`",
                    p.name_on(self.oscillator.axis),
                    p.name_on(self.oscillator.axis)
                )
            })
            .collect()
    }

    /// Checks the units of a read record against the oscillator: the speed, period and angle
    /// checks where every property is given ([`check_scales`]), a free pendulum's swings
    /// ([`check_swing`]) and a driven record's balance against the mass, given or the start
    /// of a fitted one ([`check_driven_balance`]; not judged when the mass is not given).
    pub fn check_units(&self, record: &Record) -> Result<(), ScaleError> {
        if self.unknown_oscillator.is_empty() {
            check_scales(record, &self.oscillator)?;
        }
        check_swing(record, &self.oscillator)?;
        match self.mass_reference() {
            Some(reference) => check_driven_balance(record, &self.oscillator, reference),
            None => Ok(()),
        }
    }

    /// Checks that the `[model]`'s force is finite along `record` at its start values
    /// ([`ModelSpec::check_finite_on`]); nothing to check without a model.
    pub fn check_law_on(&self, record: &Record) -> Result<(), SpecError> {
        match &self.model {
            Some(m) => m.check_finite_on(record, &self.oscillator),
            None => Ok(()),
        }
    }

    /// The configured mass (inertia) as a fit uses it: fixed, the start of a fitted one, or
    /// `None` when it is not given.
    fn mass_reference(&self) -> Option<MassReference> {
        let mass = OscillatorProperty::Mass;
        if self.unknown_oscillator.contains(&mass) {
            None
        } else if self.fit.params.oscillator.contains(&mass) {
            Some(MassReference::Start(self.oscillator.mass))
        } else {
            Some(MassReference::Fixed(self.oscillator.mass))
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::OscillatorParam;

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
        assert_eq!(f.params.oscillator, vec![OscillatorParam::Mass]);
    }
}
