//! The uncertainty of the oscillator's known properties (m, c, k, N; one standard deviation
//! each) and the parts of a fitted parameter's standard error it adds (see
//! [`crate::identify::assessment::property_refits`]).

use crate::error::EngineError;
use crate::oscillator::OscillatorProperty;
use serde::{Deserialize, Serialize};

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

    /// Every property with its standard deviation.
    pub(crate) fn properties(&self) -> [(OscillatorProperty, f64); 4] {
        [
            (OscillatorProperty::Mass, self.mass),
            (OscillatorProperty::Damping, self.damping),
            (OscillatorProperty::Stiffness, self.stiffness),
            (OscillatorProperty::NormalForce, self.normal_force),
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
                p.key()
            ))),
            None => Ok(()),
        }
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
    /// Sets the component of `p` (none for a property without an uncertainty).
    pub(crate) fn set(&mut self, p: OscillatorProperty, value: f64) {
        match p {
            OscillatorProperty::Mass => self.mass = value,
            OscillatorProperty::Damping => self.damping = value,
            OscillatorProperty::Stiffness => self.stiffness = value,
            OscillatorProperty::NormalForce => self.normal_force = value,
            _ => {}
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
