//! The engine behind the model harness: [`EngineSimulator`] connects
//! `frictionid_models::testing::motion` (energy never increases, mirror symmetry, integrators
//! agree) to this crate's simulator, so a model crate checks its laws in motion with one line
//! (see docs/writing-a-model.md).

use crate::oscillator::Oscillator;
use crate::simulate::{simulate, Initial, Integrator, SimOptions};
use crate::synthetic::uniform_times;
use frictionid_models::testing::motion::{Integration, Motion, Release, Simulator};
use frictionid_models::testing::Model;

/// Releases of an oscillator simulated by the engine, sampled at 1 kHz.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EngineSimulator(pub Oscillator);

impl EngineSimulator {
    /// The options of one release: the default adaptive method, or the paper's Euler.
    fn options(integration: Integration) -> SimOptions {
        let integrator = match integration {
            Integration::Adaptive => SimOptions::default().integrator,
            Integration::Euler { steps_per_period } => Integrator::Euler { steps_per_period },
        };
        SimOptions {
            integrator,
            ..SimOptions::default()
        }
    }
}

impl Simulator for EngineSimulator {
    fn stiffness(&self) -> f64 {
        self.0.stiffness
    }

    fn normal_force(&self) -> f64 {
        self.0.normal_force
    }

    fn release(&self, model: &Model, release: Release) -> Result<Motion, String> {
        let Release {
            x0,
            t_end,
            integration,
        } = release;
        let times = uniform_times(t_end, 1000.0);
        let opts = Self::options(integration);
        let sim = simulate(&self.0, model, &Initial::at_rest(x0), t_end, &times, &opts)
            .map_err(|e| e.to_string())?;
        Ok(Motion {
            total_energy: sim.total_energy(),
            rest_displacement: sim.rest.map(|r| r.displacement),
            events: sim.events.len(),
            time: sim.time,
            x: sim.x,
            v: sim.v,
            friction: sim.friction,
        })
    }
}
