//! The mechanical energy of the oscillator along a motion (Eqs. 2-3 of the paper): the one
//! place where kinetic and potential energy are computed, for simulated trajectories and for
//! the energy analysis of records alike.

use crate::oscillator::Oscillator;
use serde::{Deserialize, Serialize};

/// Kinetic, potential and mechanical energy, one value per sample.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MechanicalEnergy {
    /// Kinetic energy m v^2 / 2 \[J\] (Eq. 3).
    pub kinetic: Vec<f64>,
    /// Potential energy V(x) of the restoring law \[J\] (Eq. 2: k x^2 / 2 for the spring).
    pub potential: Vec<f64>,
    /// Mechanical energy E = KE + PE \[J\] (the paper's E; without energy stored in a
    /// friction model's states).
    pub energy: Vec<f64>,
}

impl MechanicalEnergy {
    /// The energies of `osc` (its inertia and restoring law) at displacements `x` and
    /// velocities `v` (same length).
    pub fn of(osc: &Oscillator, x: &[f64], v: &[f64]) -> Self {
        let mass = osc.mass;
        let kinetic: Vec<f64> = v.iter().map(|&v| 0.5 * mass * v * v).collect();
        let potential: Vec<f64> = x.iter().map(|&x| osc.potential(x)).collect();
        let energy = kinetic
            .iter()
            .zip(&potential)
            .map(|(ke, pe)| ke + pe)
            .collect();
        Self {
            kinetic,
            potential,
            energy,
        }
    }

    /// The three series under the names the outputs use (`kinetic`, `potential`, `energy`).
    pub fn named_series(&self) -> [(&'static str, &[f64]); 3] {
        [
            ("kinetic", &self.kinetic),
            ("potential", &self.potential),
            ("energy", &self.energy),
        ]
    }
}
