//! Segments integrated by ode_solvers' Dormand-Prince 5(4), with event location on its dense
//! output.

use super::root::illinois;
use super::{Driver, Dynamics, Recorder, SimOptions};
use crate::error::EngineError;
use nalgebra::allocator::Allocator;
use nalgebra::{Const, DefaultAllocator, Dim, Dyn, OVector, U1};
use ode_solvers::continuous_output_model::ContinuousOutputModel;
use ode_solvers::dop_shared::IntegrationError;
use ode_solvers::{Dopri5, OutputType, System};

/// Width of the final bracket of the event time [s].
const EVENT_TOL: f64 = 1e-13;
/// Largest step, as a fraction of the undamped period (keeps one velocity zero per step).
const H_MAX_PERIODS: f64 = 1.0 / 8.0;

/// Why a segment stopped before the end time.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Stop {
    /// Reached the end time.
    None,
    /// The event function changed sign in (lo, hi].
    Event { lo: f64, hi: f64 },
    /// The state at the end of the step at `t` is not finite.
    NonFinite { t: f64 },
}

/// Watches the event function after each accepted step.
struct Watch {
    dir: f64,
    t_last: f64,
    stop: Stop,
}

/// The right-hand side handed to ode_solvers, with the event watch in `solout`.
struct Rhs<'w, 'm> {
    dynamics: Dynamics<'m>,
    dir: f64,
    watch: &'w mut Watch,
}

impl<D: Dim> System<f64, OVector<f64, D>> for Rhs<'_, '_>
where
    DefaultAllocator: Allocator<D>,
{
    #[inline]
    fn system(&self, _t: f64, y: &OVector<f64, D>, dy: &mut OVector<f64, D>) {
        self.dynamics.rhs(y.as_slice(), dy.as_mut_slice(), self.dir);
    }

    fn solout(&mut self, t: f64, y: &OVector<f64, D>, _dy: &OVector<f64, D>) -> bool {
        if y.iter().any(|v| !v.is_finite()) {
            self.watch.stop = Stop::NonFinite { t };
            return true;
        }
        let v = y.as_slice().get(1).copied().unwrap_or(0.0);
        if self.watch.dir * v <= 0.0 {
            self.watch.stop = Stop::Event {
                lo: self.watch.t_last,
                hi: t,
            };
            return true;
        }
        self.watch.t_last = t;
        false
    }
}

/// Runs the whole simulation with Dopri5, monomorphised for 0, 1 and 2 internal states.
pub(super) fn run<R: Recorder>(
    drv: &mut Driver<'_, R>,
    y0: &[f64],
    t_end: f64,
    opts: &SimOptions,
    period: f64,
) -> Result<(), EngineError> {
    match y0.len() {
        2 => run_dim(drv, y0, t_end, opts, period, Const::<2>),
        3 => run_dim(drv, y0, t_end, opts, period, Const::<3>),
        4 => run_dim(drv, y0, t_end, opts, period, Const::<4>),
        n => run_dim(drv, y0, t_end, opts, period, Dyn(n)),
    }
}

fn run_dim<R: Recorder, D: Dim>(
    drv: &mut Driver<'_, R>,
    y0: &[f64],
    t_end: f64,
    opts: &SimOptions,
    period: f64,
    dim: D,
) -> Result<(), EngineError>
where
    DefaultAllocator: Allocator<D>,
    OVector<f64, D>: std::ops::Mul<f64, Output = OVector<f64, D>>,
{
    let mut t = 0.0;
    let mut y = OVector::<f64, D>::from_column_slice_generic(dim, U1, y0);
    let h_max = period * H_MAX_PERIODS;
    // Below this remaining time a segment is not started (Dopri5 would underflow).
    let tiny = 1e-13 * (1.0 + t_end);
    loop {
        let Some(dir) = drv.decide(t, y.as_slice())? else {
            return Ok(());
        };
        if t_end - t <= tiny {
            drv.fill_end(y.as_slice(), dir);
            return Ok(());
        }
        let used = drv.stats.steps + drv.stats.rejected_steps;
        let remaining = drv.max_steps.saturating_sub(used);
        if remaining == 0 {
            return Err(too_many_steps(t, drv.max_steps));
        }
        let n_max = u32::try_from(remaining).unwrap_or(u32::MAX);
        let mut watch = Watch {
            dir,
            t_last: t,
            stop: Stop::None,
        };
        let mut com = ContinuousOutputModel::<f64, OVector<f64, D>>::new();
        let result = {
            let rhs = Rhs {
                dynamics: drv.dynamics,
                dir,
                watch: &mut watch,
            };
            let mut solver = Dopri5::from_param(
                rhs,
                t,
                t_end,
                t_end - t,
                y.clone(),
                opts.rtol,
                opts.atol,
                0.9,
                0.04,
                0.2,
                10.0,
                h_max,
                0.0,
                n_max,
                // Disable the stiffness abort: stiff bristle models must run to the end.
                u32::MAX,
                OutputType::Continuous,
            );
            solver.integrate_with_continuous_output_model(&mut com)
        };
        let stats = result.map_err(|e| integration_error(e, drv.max_steps))?;
        drv.stats.rhs_evaluations += u64::from(stats.num_eval);
        drv.stats.steps += u64::from(stats.accepted_steps);
        drv.stats.rejected_steps += u64::from(stats.rejected_steps);

        let eval = |tt: f64| com.evaluate(tt);
        match watch.stop {
            Stop::NonFinite { t: tf } => {
                let yf = eval(tf).map(|v| v.as_slice().to_vec()).unwrap_or_default();
                return Err(Driver::<R>::non_finite(tf, &yf));
            }
            Stop::None => {
                let t_top = watch.t_last;
                write_samples(drv, &eval, t, t_end, t_top, dir)?;
                return Ok(());
            }
            Stop::Event { lo, hi } => {
                let g = |tt: f64| eval(tt).and_then(|yy| yy.as_slice().get(1).map(|&v| dir * v));
                let t_e = locate(&g, lo, hi).ok_or_else(|| EngineError::Integration {
                    time: lo,
                    reason: "the velocity could not be evaluated while locating a turning point"
                        .into(),
                })?;
                write_samples(drv, &eval, t, t_e, hi, dir)?;
                let mut y_e = eval(t_e).ok_or_else(|| EngineError::Integration {
                    time: t_e,
                    reason: "no dense output at the turning point".into(),
                })?;
                if let Some(v) = y_e.as_mut_slice().get_mut(1) {
                    *v = 0.0;
                }
                let x_e = y_e.as_slice().first().copied().unwrap_or(0.0);
                drv.turning_point(t_e, x_e)?;
                t = t_e;
                y = y_e;
            }
        }
    }
}

/// Writes the samples with time <= `until` from the dense output (times clamped to `t_top`,
/// the last accepted step, against round-off at the end time).
fn write_samples<R: Recorder, D: Dim>(
    drv: &mut Driver<'_, R>,
    eval: &impl Fn(f64) -> Option<OVector<f64, D>>,
    t_start: f64,
    until: f64,
    t_top: f64,
    dir: f64,
) -> Result<(), EngineError>
where
    DefaultAllocator: Allocator<D>,
{
    let n = drv.pending_until(until);
    for _ in 0..n {
        let Some(&ts) = drv.samples.get(drv.next) else {
            break;
        };
        let tt = ts.clamp(t_start, t_top.max(t_start));
        let ys = eval(tt).ok_or_else(|| EngineError::Integration {
            time: ts,
            reason: "no dense output at this sample time".into(),
        })?;
        drv.write_moving(ts, ys.as_slice(), dir);
    }
    Ok(())
}

/// Locates the zero of `g` in (lo, hi] where g(hi) <= 0. At the start of a segment g(lo) may
/// be 0; a point with g > 0 is then searched on a geometric grid towards `lo`.
fn locate(g: &impl Fn(f64) -> Option<f64>, lo: f64, hi: f64) -> Option<f64> {
    let g_hi = g(hi)?;
    if g_hi == 0.0 {
        return Some(hi);
    }
    let mut a = lo;
    let mut g_a = g(lo)?;
    if g_a <= 0.0 {
        let mut s = hi - lo;
        let mut found = false;
        for _ in 0..60 {
            s *= 0.5;
            let tt = lo + s;
            let gt = g(tt)?;
            if gt > 0.0 {
                a = tt;
                g_a = gt;
                found = true;
                break;
            }
        }
        if !found {
            return Some(lo);
        }
    }
    illinois(g, a, g_a, hi, g_hi, EVENT_TOL)
}

fn too_many_steps(time: f64, max_steps: u64) -> EngineError {
    EngineError::Integration {
        time,
        reason: format!("more than max_steps = {max_steps} steps"),
    }
}

fn integration_error(e: IntegrationError, max_steps: u64) -> EngineError {
    match e {
        IntegrationError::MaxNumStepReached { x, .. } => too_many_steps(x, max_steps),
        IntegrationError::StepSizeUnderflow { x } => EngineError::Integration {
            time: x,
            reason: "step-size underflow (the right-hand side is not finite or varies too \
                     fast to resolve)"
                .into(),
        },
        IntegrationError::StiffnessDetected { x } => EngineError::Integration {
            time: x,
            reason: "the problem became stiff".into(),
        },
    }
}
