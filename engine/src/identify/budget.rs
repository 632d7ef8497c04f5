//! The uncertainty budget: how the uncertainty of the oscillator's known properties (m, c,
//! k, N; one standard deviation each) propagates into the fitted parameters, beside the
//! data's own standard error.
//!
//! The sensitivity of the optimum to a property q is taken by refits at q + sigma and
//! q - sigma (central difference, started from the optimum): the component of parameter
//! theta is |theta(q + sigma) - theta(q - sigma)| / 2. The total standard error is the root
//! sum of squares of the data component and every property component; the 95 % interval
//! follows from the total.

use super::options::FitOptions;
use super::residuals::Residuals;
use super::result::{FitResult, FittedParam};
use super::stats::t_quantile_975;
use crate::error::EngineError;
use crate::oscillator::Oscillator;
use frictionid_models::FrictionModel;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// One standard deviation of each oscillator property (0: known exactly).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PropertyUncertainty {
    /// Of the mass [kg].
    pub mass: f64,
    /// Of the damping [N s/m].
    pub damping: f64,
    /// Of the stiffness [N/m].
    pub stiffness: f64,
    /// Of the normal force [N].
    pub normal_force: f64,
}

impl PropertyUncertainty {
    /// Whether any property is uncertain.
    pub fn any(&self) -> bool {
        self.properties().iter().any(|(_, s)| *s > 0.0)
    }

    fn properties(&self) -> [(Property, f64); 4] {
        [
            (Property::Mass, self.mass),
            (Property::Damping, self.damping),
            (Property::Stiffness, self.stiffness),
            (Property::NormalForce, self.normal_force),
        ]
    }

    /// Checks that every standard deviation is finite and >= 0.
    pub fn validate(&self) -> Result<(), EngineError> {
        match self
            .properties()
            .iter()
            .find(|(_, s)| !(s.is_finite() && *s >= 0.0))
        {
            Some((p, s)) => Err(EngineError::InvalidOscillator(format!(
                "`{}_std` must be finite and >= 0, got {s}",
                p.name()
            ))),
            None => Ok(()),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Property {
    Mass,
    Damping,
    Stiffness,
    NormalForce,
}

impl Property {
    fn name(self) -> &'static str {
        match self {
            Self::Mass => "mass",
            Self::Damping => "damping",
            Self::Stiffness => "stiffness",
            Self::NormalForce => "normal_force",
        }
    }

    fn shifted(self, osc: &Oscillator, by: f64) -> Oscillator {
        let mut o = *osc;
        match self {
            Self::Mass => o.mass += by,
            Self::Damping => o.damping += by,
            Self::Stiffness => o.stiffness += by,
            Self::NormalForce => o.normal_force += by,
        }
        o
    }
}

/// The parts of a parameter's standard error.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct StdErrorComponents {
    /// From the data (the least-squares standard error); `None` when it cannot be computed.
    pub data: Option<f64>,
    /// From the mass's uncertainty.
    pub mass: f64,
    /// From the damping's uncertainty.
    pub damping: f64,
    /// From the stiffness's uncertainty.
    pub stiffness: f64,
    /// From the normal force's uncertainty.
    pub normal_force: f64,
}

impl StdErrorComponents {
    fn set(&mut self, p: Property, value: f64) {
        match p {
            Property::Mass => self.mass = value,
            Property::Damping => self.damping = value,
            Property::Stiffness => self.stiffness = value,
            Property::NormalForce => self.normal_force = value,
        }
    }

    /// Root sum of squares of every component (`None` without a data component).
    pub fn total(&self) -> Option<f64> {
        let props = self.mass.powi(2)
            + self.damping.powi(2)
            + self.stiffness.powi(2)
            + self.normal_force.powi(2);
        self.data.map(|d| (d * d + props).sqrt())
    }

    /// The source with the largest component.
    pub fn dominant(&self) -> &'static str {
        [
            ("data", self.data.unwrap_or(0.0)),
            ("mass", self.mass),
            ("damping", self.damping),
            ("stiffness", self.stiffness),
            ("normal_force", self.normal_force),
        ]
        .into_iter()
        .fold(
            ("data", -1.0),
            |best, c| if c.1 > best.1 { c } else { best },
        )
        .0
    }
}

/// Everything a refit needs.
pub(crate) struct Refit<'a, R: Residuals> {
    pub residuals: Arc<R>,
    pub osc: &'a Oscillator,
    pub opts: &'a FitOptions,
}

/// Adds the property components to every free parameter of `result` and makes its standard
/// error and interval the totals. Properties that the fit itself varies are skipped.
pub(crate) fn apply_budget<R: Residuals + 'static>(
    result: &mut FitResult,
    refit: &Refit<'_, R>,
    fit_with: impl Fn(
        Arc<R>,
        &Oscillator,
        &(dyn FrictionModel + 'static),
        &FitOptions,
    ) -> FitResultOrError,
) -> Result<(), EngineError> {
    let sigma = refit.opts.uncertainty;
    sigma.validate()?;
    let mut opts = refit.opts.clone();
    opts.uncertainty = PropertyUncertainty::default();
    opts.guess = false;
    opts.multistart = Some(1);
    opts.progress = None;
    let fitted: Vec<&str> = refit.opts.oscillator.iter().map(|q| q.name()).collect();
    let mut components: Vec<StdErrorComponents> = result
        .parameters
        .iter()
        .map(|p| StdErrorComponents {
            data: p.std_error,
            ..StdErrorComponents::default()
        })
        .collect();
    for (property, s) in sigma.properties() {
        if s <= 0.0 || fitted.contains(&property.name()) {
            continue;
        }
        let at = |by: f64| {
            fit_with(
                refit.residuals.clone(),
                &property.shifted(refit.osc, by),
                result.fitted_model.as_ref(),
                &opts,
            )
        };
        let (up, down) = (at(s)?, at(-s)?);
        for (c, p) in components.iter_mut().zip(&result.parameters) {
            if let (Some(a), Some(b)) = (up.value(&p.name), down.value(&p.name)) {
                c.set(property, ((a - b) / 2.0).abs());
            }
        }
    }
    let tq = t_quantile_975(result.samples.saturating_sub(result.free_parameters));
    for (p, c) in result.parameters.iter_mut().zip(components) {
        if p.free {
            set_total(p, c, tq);
        }
    }
    Ok(())
}

/// What a refit returns.
pub(crate) type FitResultOrError = Result<FitResult, EngineError>;

fn set_total(p: &mut FittedParam, c: StdErrorComponents, tq: f64) {
    p.std_error = c.total();
    p.ci95 = p.std_error.map(|s| [p.value - tq * s, p.value + tq * s]);
    p.std_error_components = Some(c);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn components_add_in_quadrature_and_name_the_dominant_source() {
        let c = StdErrorComponents {
            data: Some(3.0),
            normal_force: 4.0,
            ..StdErrorComponents::default()
        };
        assert_eq!(c.total(), Some(5.0));
        assert_eq!(c.dominant(), "normal_force");
        let none = StdErrorComponents::default();
        assert_eq!(none.total(), None);
        let bad = PropertyUncertainty {
            mass: -1.0,
            ..PropertyUncertainty::default()
        };
        assert!(bad.validate().unwrap_err().to_string().contains("mass_std"));
    }
}
