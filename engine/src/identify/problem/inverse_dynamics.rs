//! The balance of an inverse-dynamics fit: along the measured motion of a driven axis,
//!
//!   J a + c v + R(q) + F(v, z, N) + offset = u,
//!
//! with u the record's `input_force` channel. The fit compares the measured u with the left
//! side at the trial values of the friction law, of the oscillator properties it varies
//! (`[fit.options] oscillator`: mass or inertia J, damping c, stiffness k) and of the offset:
//! each of them enters the prediction, so the residual u - J a - c v - R(q) - F - offset
//! depends on all of them and the fit's Jacobian carries their columns like any other (the
//! inverse-dynamics identification, IDIM, of drives and robot joints).
//!
//! # Acceleration
//! The record's `acceleration` channel where it has one. Otherwise the velocity (measured, or
//! the centred difference of the displacement) is differentiated by a Savitzky-Golay
//! derivative: a quartic fitted by least squares over a window of [`ACCELERATION_SPAN`]
//! seconds (21 samples at 1 kHz, 201 at 10 kHz; at least [`MIN_WINDOW`]), its slope taken at
//! the window's centre. A centred fit is zero-phase: it neither lags nor leads the motion.
//! Windows never reach across a change of the motion's direction (a sample's class: moving
//! forwards, backwards, or within the `[energy] velocity_threshold` of rest), where a
//! Coulomb level makes the acceleration jump by 2 F_c / J; near the end of a run the window
//! slides inwards (a one-sided fit of the same size). On a smooth motion its error is that of
//! a quartic over 20 ms, as SciPy's Savitzky-Golay filter computes it
//! (`the_derivative_of_a_smooth_motion_is_exact_to_the_window_order`).
//!
//! # Compared samples
//! The samples moving faster than the `[energy] velocity_threshold` (1 mm/s by default):
//! at rest the friction force is static, anywhere within the breakaway level, and no sliding
//! law predicts it.

use crate::energy::{savitzky_golay_derivative, SeriesSource};
use crate::error::EngineError;
use crate::oscillator::{Oscillator, OscillatorProperty};
use crate::record::{Channel, Record};
use nalgebra::{DMatrix, DVector};

/// The duration of the Savitzky-Golay window that differentiates a velocity \[s\].
pub const ACCELERATION_SPAN: f64 = 0.02;

/// The fewest samples of that window.
pub const MIN_WINDOW: usize = 7;

/// The degree of its polynomial.
pub const ACCELERATION_ORDER: usize = 4;

/// The restoring force R(q) of the axis at position `q`, from its restoring law (the linear
/// spring: k q).
pub fn restoring_force(osc: &Oscillator, q: f64) -> f64 {
    osc.restoring.law().force(q, osc.stiffness)
}

/// The oscillator's terms of one record's balance: the acceleration along it and which
/// terms the axis has.
#[derive(Debug, Clone, PartialEq)]
pub struct Balance {
    /// The acceleration at every sample.
    pub acceleration: Vec<f64>,
    /// Where it came from: measured, or differentiated.
    pub acceleration_source: SeriesSource,
    /// Whether the axis has a restoring force (a stiffness given or fitted).
    pub restoring: bool,
}

impl Balance {
    /// The balance of `record` moving with velocity `v`: its acceleration channel, else the
    /// derivative of `v` (see the module docs); `restoring` says whether R(q) is in it.
    pub fn new(
        record: &Record,
        v: &[f64],
        threshold: f64,
        restoring: bool,
    ) -> Result<Self, EngineError> {
        let (acceleration, acceleration_source) = match record.channel(Channel::Acceleration) {
            Some(a) => (a.to_vec(), SeriesSource::Measured),
            None => (
                differentiate(record.time(), v, threshold)?,
                SeriesSource::Differentiated,
            ),
        };
        Ok(Self {
            acceleration,
            acceleration_source,
            restoring,
        })
    }

    /// The axis's terms J a + c v + R(q) + F_0 at sample `i`, of velocity `v` and position
    /// `q` (F_0 the constant force of the balance, [`Oscillator::input_offset`]).
    pub fn axis_force(&self, osc: &Oscillator, i: usize, v: f64, q: f64) -> f64 {
        osc.mass * self.acceleration[i]
            + osc.damping * v
            + self.restoring_at(osc, q)
            + osc.input_offset
    }

    /// The restoring force at position `q` (0 for an axis without one).
    pub fn restoring_at(&self, osc: &Oscillator, q: f64) -> f64 {
        if self.restoring {
            restoring_force(osc, q)
        } else {
            0.0
        }
    }
}

/// The samples an inverse-dynamics fit compares: those moving faster than `threshold`.
pub fn sliding_samples(v: &[f64], threshold: f64) -> Vec<usize> {
    (0..v.len()).filter(|&i| v[i].abs() > threshold).collect()
}

/// The Savitzky-Golay window for samples `time`: [`ACCELERATION_SPAN`] seconds, odd, at
/// least [`MIN_WINDOW`] samples.
pub fn differentiation_window(time: &[f64]) -> usize {
    let span = match (time.first(), time.last()) {
        (Some(a), Some(b)) if time.len() > 1 => (b - a) / (time.len() - 1) as f64,
        _ => return MIN_WINDOW,
    };
    let half = (0.5 * ACCELERATION_SPAN / span).round();
    let half = if half.is_finite() { half as usize } else { 0 };
    (2 * half + 1).max(MIN_WINDOW)
}

/// The first sample of every run of one direction of motion (forwards, backwards, within
/// `threshold` of rest), after the first run.
pub fn direction_breaks(v: &[f64], threshold: f64) -> Vec<usize> {
    let class = |x: f64| {
        if x > threshold {
            1
        } else if x < -threshold {
            -1
        } else {
            0
        }
    };
    (1..v.len())
        .filter(|&i| class(v[i]) != class(v[i - 1]))
        .collect()
}

/// The zero-phase derivative of `v` (see the module docs).
pub fn differentiate(time: &[f64], v: &[f64], threshold: f64) -> Result<Vec<f64>, EngineError> {
    let window = differentiation_window(time);
    let breaks = direction_breaks(v, threshold);
    savitzky_golay_derivative(time, v, window, ACCELERATION_ORDER, &breaks)
}

/// One record's series for the linear start: the compared samples, u there, and the whole
/// acceleration, velocity and position.
pub struct BalanceSamples<'a> {
    /// Indices of the compared samples.
    pub used: &'a [usize],
    /// The input force at them.
    pub input: &'a [f64],
    /// Acceleration, velocity and position at every sample.
    pub motion: [&'a [f64]; 3],
    /// Whether the axis has a restoring force.
    pub restoring: bool,
}

/// The linear least-squares estimate of the balance with a viscous+Coulomb friction and an
/// offset per record: the classical inverse-dynamics solution, where a fit starts.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearStart {
    /// The oscillator with the fitted properties at their estimates (positive ones kept).
    pub oscillator: Oscillator,
    /// The Coulomb level F_c \[N\].
    pub coulomb: f64,
}

/// The linear start from `records` for the properties in `fitted`, the others held at
/// `osc`'s values; `None` when the samples do not determine it.
pub fn linear_start(
    records: &[BalanceSamples<'_>],
    osc: &Oscillator,
    fitted: &[OscillatorProperty],
) -> Option<LinearStart> {
    let columns = regressor_columns(fitted);
    let width = columns.len() + records.len();
    let mut normal = DMatrix::<f64>::zeros(width, width);
    let mut rhs = DVector::<f64>::zeros(width);
    let mut row = vec![0.0; width];
    for (r, rec) in records.iter().enumerate() {
        let [a, v, q] = rec.motion;
        for (k, &i) in rec.used.iter().enumerate() {
            let known = known_terms(osc, fitted, rec.restoring, (a[i], v[i], q[i]));
            for (slot, c) in columns.iter().enumerate() {
                row[slot] = c.value(a[i], v[i], q[i]);
            }
            row[columns.len()..].iter_mut().for_each(|x| *x = 0.0);
            row[columns.len() + r] = 1.0;
            let y = rec.input[k] - known;
            for (p, &xp) in row.iter().enumerate() {
                rhs[p] += xp * y;
                for (q, &xq) in row.iter().enumerate() {
                    normal[(p, q)] += xp * xq;
                }
            }
        }
    }
    let solution = normal.svd(true, true).solve(&rhs, 1e-12).ok()?;
    let mut oscillator = *osc;
    for (c, value) in columns.iter().zip(solution.iter()) {
        c.assign(&mut oscillator, *value);
    }
    let coulomb = columns
        .iter()
        .position(|c| matches!(c, Regressor::Coulomb))
        .map(|slot| solution[slot].abs())?;
    Some(LinearStart {
        oscillator,
        coulomb,
    })
}

/// A column of the linear start's regression.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Regressor {
    Property(OscillatorProperty),
    Coulomb,
    Viscous,
}

impl Regressor {
    fn value(self, a: f64, v: f64, q: f64) -> f64 {
        match self {
            Self::Property(p) => p.balance_column(a, v, q),
            Self::Viscous => v,
            Self::Coulomb => v.signum(),
        }
    }

    /// Sets the property this column estimates, where the estimate lies in its domain
    /// ([`OscillatorProperty::admissible`]).
    fn assign(self, osc: &mut Oscillator, value: f64) {
        if let Self::Property(p) = self {
            if let Some(value) = p.admissible(value) {
                p.set(osc, value);
            }
        }
    }
}

/// The fitted properties' columns, the Coulomb level's and a viscous one (unless the damping
/// is fitted: the two would be the same column).
fn regressor_columns(fitted: &[OscillatorProperty]) -> Vec<Regressor> {
    let mut columns: Vec<Regressor> = fitted.iter().map(|&p| Regressor::Property(p)).collect();
    columns.push(Regressor::Coulomb);
    if !fitted.contains(&OscillatorProperty::Damping) {
        columns.push(Regressor::Viscous);
    }
    columns
}

/// The terms of the balance that are not fitted, at `osc`'s values.
fn known_terms(
    osc: &Oscillator,
    fitted: &[OscillatorProperty],
    restoring: bool,
    (a, v, q): (f64, f64, f64),
) -> f64 {
    let held = |p: OscillatorProperty| !fitted.contains(&p);
    let mut sum = 0.0;
    if held(OscillatorProperty::Mass) {
        sum += osc.mass * a;
    }
    if held(OscillatorProperty::Damping) {
        sum += osc.damping * v;
    }
    if restoring && !fitted.iter().any(|p| p.is_restoring()) {
        sum += restoring_force(osc, q);
    }
    if held(OscillatorProperty::InputOffset) {
        sum += osc.input_offset;
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The worst |a - exact| over `v(t) = offset + sin(2 pi 1.3 t) + 0.4 cos(2 pi 3.1 t)`,
    /// 2 s at 1 kHz, against its analytic derivative, relative to the acceleration's
    /// amplitude (2 pi 1.3 + 0.4 2 pi 3.1): over every sample, and over those at least half
    /// a window from the record's ends.
    fn derivative_error(offset: f64) -> (f64, f64) {
        let w1 = 2.0 * std::f64::consts::PI * 1.3;
        let w2 = 2.0 * std::f64::consts::PI * 3.1;
        let time: Vec<f64> = (0..2000).map(|i| i as f64 * 1e-3).collect();
        let v: Vec<f64> = time
            .iter()
            .map(|t| offset + (w1 * t).sin() + 0.4 * (w2 * t).cos())
            .collect();
        let a = differentiate(&time, &v, 0.0).unwrap();
        let errors: Vec<f64> = time
            .iter()
            .zip(&a)
            .map(|(t, a)| (a - (w1 * (w1 * t).cos() - 0.4 * w2 * (w2 * t).sin())).abs())
            .map(|e| e / (w1 + 0.4 * w2))
            .collect();
        let worst = |e: &[f64]| e.iter().copied().fold(0.0, f64::max);
        (worst(&errors), worst(&errors[10..1990]))
    }

    /// Oracle: the analytic derivative, and SciPy's Savitzky-Golay filter. Moving one way
    /// throughout (no break), the quartic over 21 samples leaves 1.69e-6 of the amplitude
    /// where it is centred and 8.77e-6 at the record's last sample (one-sided): SciPy's
    /// `savgol_coeffs(21, 4, deriv=1, pos=...)` on the same samples gives 1.6869e-6 and
    /// 8.7737e-6. With reversals, whose runs end in one-sided fits of shorter runs, within
    /// 2e-5. A lag of one sample would leave 1.4e-2.
    #[test]
    fn the_derivative_of_a_smooth_motion_is_exact_to_the_window_order() {
        assert_eq!(
            differentiation_window(&(0..3).map(|i| i as f64 * 1e-3).collect::<Vec<_>>()),
            21
        );
        let (all, centred) = derivative_error(2.0);
        assert!((all / 8.7737e-6 - 1.0).abs() < 1e-3, "{all}");
        assert!((centred / 1.6869e-6 - 1.0).abs() < 1e-3, "{centred}");
        let (reversing, _) = derivative_error(0.0);
        assert!(reversing < 2e-5, "{reversing}");
    }

    /// The window follows the sample rate: 21 samples at 1 kHz, 201 at 10 kHz, 7 at 100 Hz.
    #[test]
    fn the_window_spans_twenty_milliseconds() {
        let at = |dt: f64| differentiation_window(&[0.0, dt, 2.0 * dt]);
        assert_eq!((at(1e-3), at(1e-4), at(1e-2)), (21, 201, 7));
    }

    /// Runs break where the direction of motion changes, the band of rest being a direction.
    #[test]
    fn runs_break_at_every_change_of_direction() {
        let v = [0.5, 0.2, 0.0005, -0.3, -0.1, 0.2];
        assert_eq!(direction_breaks(&v, 1e-3), vec![2, 3, 5]);
    }
}
