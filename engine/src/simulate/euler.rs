//! The paper's fixed-step explicit Euler: x += h v, v += h a (both from the old state), with the
//! same modes and events as the adaptive engine. Turning points are located by linear
//! interpolation of the velocity within the step; samples are interpolated linearly.

use super::{Driver, Recorder};
use crate::error::EngineError;

/// Runs the whole simulation with fixed steps of `h` seconds.
pub(super) fn run<R: Recorder>(
    drv: &mut Driver<'_, R>,
    mut y: Vec<f64>,
    t_end: f64,
    h: f64,
) -> Result<(), EngineError> {
    let n = y.len();
    let mut y_new = vec![0.0; n];
    let mut dy = vec![0.0; n];
    let mut y_s = vec![0.0; n];
    let mut t = 0.0;
    let tiny = 1e-13 * (1.0 + t_end);
    'segments: loop {
        let Some(dir) = drv.decide(t, &y)? else {
            return Ok(());
        };
        if t_end - t <= tiny {
            drv.fill_end(&y, dir);
            return Ok(());
        }
        let t_seg = t;
        let mut i: u64 = 0;
        let mut g_old = dir * y.get(1).copied().unwrap_or(0.0);
        loop {
            if drv.stats.steps >= drv.max_steps {
                return Err(EngineError::Integration {
                    time: t,
                    reason: format!("more than max_steps = {} steps", drv.max_steps),
                });
            }
            i += 1;
            let t_next = (t_seg + i as f64 * h).min(t_end);
            let hs = t_next - t;
            drv.dynamics.rhs(&y, &mut dy, dir);
            for ((yn, &yo), &d) in y_new.iter_mut().zip(&y).zip(&dy) {
                *yn = yo + hs * d;
            }
            drv.stats.steps += 1;
            drv.stats.rhs_evaluations += 1;
            if y_new.iter().any(|v| !v.is_finite()) {
                return Err(Driver::<R>::non_finite(t_next, &y_new));
            }
            let g_new = dir * y_new.get(1).copied().unwrap_or(0.0);
            if g_new <= 0.0 {
                // Turning point inside (t, t_next]: linear in v.
                let frac = if g_old > 0.0 {
                    g_old / (g_old - g_new)
                } else {
                    1.0
                };
                let t_e = t + frac * hs;
                write_samples(drv, t, &y, t_next, &y_new, t_e, dir, &mut y_s);
                for ((ys, &yo), &yn) in y_s.iter_mut().zip(&y).zip(&y_new) {
                    *ys = yo + frac * (yn - yo);
                }
                if let Some(v) = y_s.get_mut(1) {
                    *v = 0.0;
                }
                y.copy_from_slice(&y_s);
                t = t_e;
                drv.turning_point(t, y.first().copied().unwrap_or(0.0))?;
                continue 'segments;
            }
            write_samples(drv, t, &y, t_next, &y_new, t_next, dir, &mut y_s);
            std::mem::swap(&mut y, &mut y_new);
            t = t_next;
            g_old = g_new;
            if t >= t_end {
                drv.fill_end(&y, dir);
                return Ok(());
            }
        }
    }
}

/// Writes the samples with time <= `until` by linear interpolation between (t0, y0) and
/// (t1, y1).
#[allow(clippy::too_many_arguments)]
fn write_samples<R: Recorder>(
    drv: &mut Driver<'_, R>,
    t0: f64,
    y0: &[f64],
    t1: f64,
    y1: &[f64],
    until: f64,
    dir: f64,
    buf: &mut [f64],
) {
    let n = drv.pending_until(until);
    for _ in 0..n {
        let Some(&ts) = drv.samples.get(drv.next) else {
            break;
        };
        let frac = if t1 > t0 {
            ((ts - t0) / (t1 - t0)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        for ((b, &a0), &a1) in buf.iter_mut().zip(y0).zip(y1) {
            *b = a0 + frac * (a1 - a0);
        }
        drv.write_moving(ts, buf, dir);
    }
}
