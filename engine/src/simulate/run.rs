//! One run: the inputs checked, the driver built over the chosen stepper, and its tolerances
//! and largest step.

use super::auto::resolve_method;
use super::block::BlockBuffer;
use super::conditions::BoundConditions;
use super::driver::Driver;
use super::dynamics::Dynamics;
use super::recorders::{Recorder, RunOutput};
use super::values::{Initial, Integrator, RunInputs, SampleGrid, SimOptions, SimStats};
use super::{ClosedForm, Dopri5, Euler, Rodas4};
use crate::error::EngineError;
use crate::oscillator::Oscillator;
use frictionid_models::FrictionModel;

/// A motion whose swing between consecutive turning points is below this many absolute
/// tolerances is declared at rest (smooth and dynamic models only).
pub const REST_SWING_ATOLS: f64 = 10.0;

/// Largest Dormand-Prince step, as a fraction of the undamped period (keeps one velocity zero
/// per step).
const H_MAX_PERIODS: f64 = 1.0 / 8.0;

/// Rodas4's relative tolerance as a multiple of the options' `rtol`. Its embedded error
/// estimate is of third order and overestimates the error of its fourth-order solution: at the
/// same nominal tolerance it is about 100 times more accurate than Dopri5 on the FMM cases
/// (LuGre, sigma0 = 1e7: 3e-11 m at rtol 2e-9, 2e-9 m at 2e-7). The scaling gives both
/// methods about the same accuracy for the same options.
pub const RODAS_TOL_SCALE: f64 = 100.0;

/// Rodas4's absolute tolerance as a multiple of the options' `atol` (see
/// [`RODAS_TOL_SCALE`]); the rest threshold of the driver keeps the options' `atol`.
pub const RODAS_ATOL_SCALE: f64 = 100.0;

/// Checks a run's oscillator and friction law.
pub(super) fn check_system(osc: &Oscillator, model: &dyn FrictionModel) -> Result<(), EngineError> {
    osc.validate()?;
    model.check()?;
    Ok(())
}

/// Validates the inputs, builds the driver and runs it over the chosen stepper.
pub(crate) fn run<R: Recorder>(
    inputs: RunInputs<'_>,
    rec: &mut R,
) -> Result<RunOutput, EngineError> {
    let RunInputs {
        osc,
        model,
        init,
        input,
        channels,
        grid: SampleGrid {
            t_end,
            sample_times,
        },
        opts,
    } = inputs;
    check_system(osc, model)?;
    let conditions = BoundConditions::bind(model, input, channels)?;
    let y0 = initial_state(model, init)?;
    check_times(t_end, sample_times)?;
    check_options(opts)?;
    let dynamics = Dynamics::new(osc, model)?
        .driven_by(input)
        .reading(conditions.as_ref());
    let mut driver = Driver {
        dynamics,
        samples: sample_times,
        next: 0,
        rec,
        events: Vec::new(),
        rest: None,
        stats: SimStats::default(),
        max_events: opts.max_events,
        max_steps: opts.max_steps,
        last_turn: None,
        rest_swing: REST_SWING_ATOLS * opts.atol,
        block: BlockBuffer::new(),
    };
    let period = time_scale(osc, t_end);
    let atol_scales = component_tolerance_scales(model, y0.len());
    match resolve_method(opts.integrator, &dynamics, &y0, period)? {
        Integrator::Exact => driver.run(&mut ClosedForm::new(), &y0, t_end)?,
        Integrator::Euler { steps_per_period } => {
            let Some(period) = osc.period() else {
                return Err(EngineError::InvalidInput(
                    "the Euler integrator's step is a fraction of the natural period, and \
                     an axis without a restoring force has none: use dopri5 or auto"
                        .into(),
                ));
            };
            let mut stepper = Euler::new(y0.len(), period / steps_per_period);
            driver.run(&mut stepper, &y0, t_end)?;
        }
        Integrator::Rodas => {
            let h_max = period * H_MAX_PERIODS;
            let (rtol, atol) = (RODAS_TOL_SCALE * opts.rtol, RODAS_ATOL_SCALE * opts.atol);
            let mut stepper =
                Rodas4::new(y0.len(), rtol, atol, h_max).with_atol_scales(&atol_scales);
            driver.run(&mut stepper, &y0, t_end)?;
        }
        Integrator::Dopri5 | Integrator::Auto => {
            let h_max = period * H_MAX_PERIODS;
            // One absolute tolerance for all components (see `component_tolerance_scales`).
            let mut stepper = Dopri5::new(y0.len(), opts.rtol, opts.atol, h_max);
            driver.run(&mut stepper, &y0, t_end)?;
        }
    }
    Ok(RunOutput {
        events: driver.events,
        rest: driver.rest,
        stats: driver.stats,
    })
}

/// The time scale of a run: the natural period of small motions, or, on an axis without
/// one (no restoring force), the run's length. The largest step and `auto`'s stiffness
/// estimate are fractions of it.
fn time_scale(osc: &Oscillator, t_end: f64) -> f64 {
    osc.period()
        .unwrap_or(if t_end > 0.0 { t_end } else { 1.0 })
}

/// The multipliers of Rodas4's absolute tolerance for the `dim` components [x, v, z...]: 1
/// for x and v, the model's [`InternalStates::state_tolerance_scales`] for its states (1 in
/// place of a declared scale that is not finite and > 0). Dahl at sigma0 = 1e7 N/m: 17 394 ->
/// 10 056 RHS evaluations with them alone, 1e-8 m of x kept.
///
/// Dopri5 keeps one absolute tolerance for every component: its steps on bristle models are
/// bounded by stability, not accuracy (Dahl at 1e7: 1 032 676 and 1 026 016 RHS without and
/// with the scales), and the default options' trajectories, which the identification tests
/// pin down, stay as they were (with the scales Dahl at the default 1e5 took 16 % fewer RHS
/// evaluations, but its force no longer matched a three-element Dahl held in newtons to the
/// 1e-5 N of `simulate_custom`'s test).
///
/// [`InternalStates::state_tolerance_scales`]: frictionid_models::InternalStates
pub(super) fn component_tolerance_scales(model: &dyn FrictionModel, dim: usize) -> Vec<f64> {
    let mut scales = vec![1.0, 1.0];
    if let Some(states) = model.states().filter(|s| s.n_states() > 0) {
        let usable = |s: f64| if s.is_finite() && s > 0.0 { s } else { 1.0 };
        scales.extend(states.state_tolerance_scales().into_iter().map(usable));
    }
    scales.resize(dim, 1.0);
    scales
}

fn initial_state(model: &dyn FrictionModel, init: &Initial) -> Result<Vec<f64>, EngineError> {
    if !init.x0.is_finite() || !init.v0.is_finite() {
        return Err(EngineError::InvalidInput(format!(
            "initial conditions must be finite (x0 = {}, v0 = {})",
            init.x0, init.v0
        )));
    }
    let n = model.n_states();
    let mut y = Vec::with_capacity(2 + n);
    y.push(init.x0);
    y.push(init.v0);
    match &init.z0 {
        None => y.resize(2 + n, 0.0),
        Some(z0) => {
            if z0.len() != n {
                return Err(EngineError::InvalidInput(format!(
                    "model `{}` has {n} internal states, z0 has {}",
                    model.name(),
                    z0.len()
                )));
            }
            if let Some(bad) = z0.iter().find(|z| !z.is_finite()) {
                return Err(EngineError::InvalidInput(format!(
                    "initial internal states must be finite, got {bad}"
                )));
            }
            y.extend_from_slice(z0);
        }
    }
    Ok(y)
}

fn check_times(t_end: f64, times: &[f64]) -> Result<(), EngineError> {
    if !(t_end.is_finite() && t_end >= 0.0) {
        return Err(EngineError::InvalidInput(format!(
            "the end time must be finite and >= 0, got {t_end}"
        )));
    }
    // One branch-free pass for the common case (NaN fails every comparison, and ascending
    // times between a first >= 0 and a last <= t_end all lie in [0, t_end]); the diagnosis
    // below names the first bad sample.
    let in_order = times.first().is_none_or(|&t| t >= 0.0)
        && times.last().is_none_or(|&t| t <= t_end)
        && times.windows(2).fold(true, |ok, w| ok & (w[0] <= w[1]));
    if in_order {
        return Ok(());
    }
    for (i, &t) in times.iter().enumerate() {
        if !(t.is_finite() && (0.0..=t_end).contains(&t)) {
            return Err(EngineError::InvalidInput(format!(
                "sample time {i} (t = {t} s) lies outside [0, {t_end}] s"
            )));
        }
    }
    if let Err(crate::record::TimeError::NotIncreasing {
        index,
        time,
        previous,
    }) = crate::record::check_sorted(times)
    {
        return Err(EngineError::InvalidInput(format!(
            "sample times are not sorted at index {index} ({time} s after {previous} s)"
        )));
    }
    Ok(())
}

fn check_options(opts: &SimOptions) -> Result<(), EngineError> {
    let bad = |what: String| Err(EngineError::InvalidInput(what));
    if !(opts.rtol.is_finite() && opts.rtol >= 1e-14 && opts.rtol < 1.0) {
        return bad(format!("rtol must lie in [1e-14, 1), got {}", opts.rtol));
    }
    if !(opts.atol.is_finite() && opts.atol > 0.0) {
        return bad(format!("atol must be finite and > 0, got {}", opts.atol));
    }
    if opts.max_steps == 0 {
        return bad("max_steps must be >= 1".into());
    }
    if let Integrator::Euler { steps_per_period } = opts.integrator {
        if !(steps_per_period.is_finite() && steps_per_period >= 1.0) {
            return bad(format!(
                "Euler steps_per_period must be finite and >= 1, got {steps_per_period}"
            ));
        }
    }
    Ok(())
}
