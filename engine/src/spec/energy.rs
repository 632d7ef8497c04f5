//! `[energy]`: the options of the energy analysis.

use crate::energy::{Differentiator, EnergyOptions};
use serde::{Deserialize, Serialize};

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
}
