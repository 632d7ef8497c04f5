//! The entry points of a simulation: a whole [`Trajectory`] ([`simulate`],
//! [`simulate_driven`]) or only the velocity at the sample times for a fit
//! ([`simulate_velocity`], [`simulate_velocity_watched`]).

use super::recorders::{FullRecorder, VelocityRecorder};
use super::run::run;
use super::values::{Initial, RunInputs, SampleGrid, SimOptions, SimStats, Trajectory};
use crate::error::EngineError;
use crate::oscillator::Oscillator;
use frictionid_models::FrictionModel;

/// Simulates the free vibration of `osc` with friction `model` from `init` up to `t_end`,
/// returning the states at `sample_times` (sorted, within [0, t_end]) from the dense output.
pub fn simulate(
    osc: &Oscillator,
    model: &dyn FrictionModel,
    init: &Initial,
    t_end: f64,
    sample_times: &[f64],
    opts: &SimOptions,
) -> Result<Trajectory, EngineError> {
    simulate_driven(RunInputs {
        osc,
        model,
        init,
        input: None,
        channels: None,
        grid: SampleGrid {
            t_end,
            sample_times,
        },
        opts,
    })
}

/// [`simulate`] of any [`RunInputs`], under the measured input when it has one: the axis
/// sticks while |u - R(q)| stays within the static friction and breaks away, at the time
/// located exactly on the piecewise-linear input, when it leaves it.
pub fn simulate_driven(inputs: RunInputs<'_>) -> Result<Trajectory, EngineError> {
    let n_samples = inputs.grid.sample_times.len();
    let mut rec = FullRecorder::new(inputs.osc, inputs.model, n_samples, inputs.model.n_states());
    let out = run(inputs, &mut rec)?;
    rec.finish_energies();
    Ok(Trajectory {
        events: out.events,
        rest: out.rest,
        stats: out.stats,
        ..rec.series
    })
}

/// The cheap variant for fitting: only the velocity at the sample times, written into
/// `v_out` (cleared first, so a buffer can be reused across calls). Same method and errors
/// as [`simulate`]; returns the statistics.
pub fn simulate_velocity(
    inputs: RunInputs<'_>,
    v_out: &mut Vec<f64>,
) -> Result<SimStats, EngineError> {
    let mut no_watch = |_: usize| false;
    let velocity = VelocityRun {
        v_out,
        watch: &mut no_watch,
    };
    simulate_velocity_watched(inputs, velocity)
}

/// Where [`simulate_velocity_watched`] writes, and who watches.
pub struct VelocityRun<'a> {
    /// The velocities at the sample times (cleared first).
    pub v_out: &'a mut Vec<f64>,
    /// Called after each step with the number of samples written so far; `true` stops the
    /// run with [`IntegrationFailure::Halted`](crate::error::IntegrationFailure::Halted).
    pub watch: &'a mut dyn FnMut(usize) -> bool,
}

/// [`simulate_velocity`] with a watch asked after every step: a fit stops the simulation of a
/// record once another record of the same evaluation has failed.
pub fn simulate_velocity_watched(
    inputs: RunInputs<'_>,
    run_to: VelocityRun<'_>,
) -> Result<SimStats, EngineError> {
    let VelocityRun { v_out, watch } = run_to;
    v_out.clear();
    v_out.reserve(inputs.grid.sample_times.len());
    let mut rec = VelocityRecorder { v: v_out, watch };
    Ok(run(inputs, &mut rec)?.stats)
}
