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
//! forwards, backwards, or at rest), where a Coulomb level makes the acceleration jump by
//! 2 F_c / J; near the end of a run the window slides inwards (a one-sided fit of the same
//! size). On a smooth motion its error is that of a quartic over 20 ms, as SciPy's
//! Savitzky-Golay filter computes it
//! (`the_derivative_of_a_smooth_motion_is_exact_to_the_window_order`).
//!
//! The band of rest that classes the samples is the record's own: [`REST_BAND`] times the
//! velocity's noise (its resolution, for a velocity differenced from a quantised position),
//! estimated from its second differences ([`velocity_noise`]), never a speed in m/s: the
//! acceleration is the same whatever unit the record is written in (the record scaled by
//! 1000 gives an acceleration scaled by 1000, sample for sample). Where the velocity chatters
//! across that band at a reversal (a quantised position's velocity steps by a whole
//! resolution), runs shorter than [`MIN_WINDOW`] samples follow one another: the samples
//! from the first break of such a cluster to its last form one run, whose acceleration, a
//! fit of a few quantised samples, is marked unreliable ([`Acceleration::unreliable`]) and
//! not compared.
//!
//! # Compared samples
//! The samples moving faster than the `[energy] velocity_threshold` (1 mm/s by default):
//! at rest the friction force is static, anywhere within the breakaway level, and no sliding
//! law predicts it.

use crate::energy::{savitzky_golay_derivative, savitzky_golay_noise_gains, SeriesSource};
use crate::error::EngineError;
use crate::identify::values::{Check, Finding, Status, UnreliableSamples};
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
    /// The samples whose differentiated acceleration is unreliable (ascending): fits of a
    /// few samples where the velocity chatters across its band of rest at a reversal.
    pub unreliable: Vec<usize>,
    /// Whether the axis has a restoring force (a stiffness given or fitted).
    pub restoring: bool,
}

impl Balance {
    /// The balance of `record` moving with velocity `v`: its acceleration channel, else the
    /// derivative of `v` (see the module docs); `restoring` says whether R(q) is in it.
    pub fn new(record: &Record, v: &[f64], restoring: bool) -> Result<Self, EngineError> {
        let (acceleration, acceleration_source) = match record.channel(Channel::Acceleration) {
            Some(a) => (
                Acceleration {
                    values: a.to_vec(),
                    unreliable: Vec::new(),
                },
                SeriesSource::Measured,
            ),
            None => (
                differentiate_marked(record.time(), v)?,
                SeriesSource::Differentiated,
            ),
        };
        Ok(Self {
            acceleration: acceleration.values,
            acceleration_source,
            unreliable: acceleration.unreliable,
            restoring,
        })
    }

    /// The samples of `sliding` (ascending) whose acceleration is unreliable, with their
    /// time ranges along `time`; `None` when there are none.
    pub fn left_out(&self, sliding: &[usize], time: &[f64]) -> Option<UnreliableSamples> {
        let out: Vec<usize> = sliding
            .iter()
            .copied()
            .filter(|i| self.unreliable.binary_search(i).is_ok())
            .collect();
        if out.is_empty() {
            return None;
        }
        let mut ranges: Vec<[f64; 2]> = Vec::new();
        let mut times = Vec::with_capacity(out.len());
        let mut previous: Option<usize> = None;
        for &i in &out {
            let t = time.get(i).copied().unwrap_or(f64::NAN);
            times.push(t);
            match (previous, ranges.last_mut()) {
                (Some(p), Some(last)) if i == p + 1 => last[1] = t,
                _ => ranges.push([t, t]),
            }
            previous = Some(i);
        }
        Some(UnreliableSamples {
            count: out.len(),
            of: sliding.len(),
            ranges,
            times,
        })
    }

    /// `used` without the samples whose acceleration is unreliable.
    pub fn reliable(&self, used: Vec<usize>) -> Vec<usize> {
        if self.unreliable.is_empty() {
            return used;
        }
        used.into_iter()
            .filter(|i| self.unreliable.binary_search(i).is_err())
            .collect()
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

/// The band of rest in the velocity's noise: a sample moves when its speed exceeds this many
/// times the noise ([`velocity_noise`]).
pub const REST_BAND: f64 = 3.0;

/// The noise of the velocity `v` (its resolution for a quantised one), in its own unit: the
/// median absolute second difference over 0.6745 sqrt(6) (a white noise's standard deviation;
/// the motion's own second difference, of order a' dt^2, is negligible at the sampling rates
/// a derivative needs), or the mean absolute second difference where more than half of them
/// vanish (a quantised velocity standing still between its steps). Scales with `v`.
pub fn velocity_noise(v: &[f64]) -> f64 {
    let mut second: Vec<f64> = v
        .windows(3)
        .map(|w| (w[2] - 2.0 * w[1] + w[0]).abs())
        .filter(|d| d.is_finite())
        .collect();
    if second.is_empty() {
        return 0.0;
    }
    let mean = second.iter().sum::<f64>() / second.len() as f64;
    let mid = second.len() / 2;
    let (_, median, _) = second.select_nth_unstable_by(mid, f64::total_cmp);
    let scale = if *median > 0.0 {
        *median / 0.6745
    } else {
        mean
    };
    scale / 6.0_f64.sqrt()
}

/// The most a sample's acceleration may amplify the velocity's noise against a centred
/// window's: beyond it (the last few samples of a run, fitted one-sided) the acceleration is
/// unreliable.
pub const MAX_NOISE_GAIN: f64 = 2.0;

/// An acceleration differentiated from a velocity, with the samples where it is unreliable.
#[derive(Debug, Clone, PartialEq)]
pub struct Acceleration {
    /// The acceleration at every sample.
    pub values: Vec<f64>,
    /// The samples of runs shorter than [`MIN_WINDOW`] (ascending).
    pub unreliable: Vec<usize>,
}

/// The zero-phase derivative of `v` (see the module docs).
pub fn differentiate(time: &[f64], v: &[f64]) -> Result<Vec<f64>, EngineError> {
    Ok(differentiate_marked(time, v)?.values)
}

/// The zero-phase derivative of `v` with its unreliable samples (see the module docs).
pub fn differentiate_marked(time: &[f64], v: &[f64]) -> Result<Acceleration, EngineError> {
    let window = differentiation_window(time);
    let band = REST_BAND * velocity_noise(v);
    let (breaks, short) = merge_short_runs(&direction_breaks(v, band), v.len());
    let values = savitzky_golay_derivative(time, v, window, ACCELERATION_ORDER, &breaks)?;
    let gains = savitzky_golay_noise_gains(v.len(), window, ACCELERATION_ORDER, &breaks)?;
    let mut unreliable: Vec<usize> = (0..v.len())
        .filter(|&i| gains[i] > MAX_NOISE_GAIN)
        .chain(short)
        .collect();
    unreliable.sort_unstable();
    unreliable.dedup();
    Ok(Acceleration { values, unreliable })
}

/// The breaks of runs at least [`MIN_WINDOW`] samples long: each cluster of `breaks` closer
/// than that to one another becomes its first and last break (the run between them spans the
/// cluster), and the samples of runs still shorter than [`MIN_WINDOW`] (clusters, and the
/// record's ends) are unreliable. Returns the breaks and those samples, for `n` samples.
pub fn merge_short_runs(breaks: &[usize], n: usize) -> (Vec<usize>, Vec<usize>) {
    let mut merged: Vec<usize> = Vec::with_capacity(breaks.len());
    let mut cluster_start: Option<usize> = None;
    for (k, &b) in breaks.iter().enumerate() {
        let near_next = breaks.get(k + 1).is_some_and(|&c| c - b < MIN_WINDOW);
        match (cluster_start, near_next) {
            (None, true) => cluster_start = Some(b),
            (None, false) => merged.push(b),
            (Some(_), true) => {}
            (Some(first), false) => {
                merged.push(first);
                merged.push(b);
                cluster_start = None;
            }
        }
    }
    let mut bounds = Vec::with_capacity(merged.len() + 2);
    bounds.push(0);
    bounds.extend(merged.iter().copied().filter(|&b| b > 0 && b < n));
    bounds.push(n);
    let unreliable = bounds
        .windows(2)
        .filter(|r| r[1] - r[0] < MIN_WINDOW)
        .flat_map(|r| r[0]..r[1])
        .collect();
    (merged, unreliable)
}

/// The share of a record's sliding samples left out beyond which the finding warns: the fit
/// then judges a small part of the motion.
pub const UNRELIABLE_WARN_SHARE: f64 = 0.25;

/// Time ranges a finding's message lists at most.
const LISTED_RANGES: usize = 5;

/// The finding of `record`'s samples left out (`None` when none are): a pass stating how
/// many and where, a warning when more than [`UNRELIABLE_WARN_SHARE`] of the sliding samples
/// are.
pub fn unreliable_target_finding(record: &str, u: &UnreliableSamples) -> Option<Finding> {
    if u.count == 0 {
        return None;
    }
    let share = u.count as f64 / u.of.max(1) as f64;
    let listed: Vec<String> = u
        .ranges
        .iter()
        .take(LISTED_RANGES)
        .map(|[a, b]| format!("{a:.4}-{b:.4} s"))
        .collect();
    let more = match u.ranges.len().saturating_sub(LISTED_RANGES) {
        0 => String::new(),
        n => format!(" and {n} more"),
    };
    let status = if share > UNRELIABLE_WARN_SHARE {
        Status::Warn
    } else {
        Status::Pass
    };
    Some(Finding::new(
        Check::UnreliableTarget,
        status,
        Some(100.0 * share),
        format!(
            "record `{record}`: {} of {} sliding samples ({:.1} %) left out, their acceleration \
             differentiated one-sided at a run's end or across a reversal (in {} ranges: {}{more})",
            u.count,
            u.of,
            100.0 * share,
            u.ranges.len(),
            listed.join(", "),
        ),
    ))
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
        let a = differentiate(&time, &v).unwrap();
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

    /// Breaks closer than the fewest window samples to one another merge into one run from
    /// the first to the last; that run, and a record's end shorter than it, are unreliable.
    #[test]
    fn chattering_breaks_merge_into_one_unreliable_run() {
        let (breaks, unreliable) = merge_short_runs(&[20, 22, 23, 26, 60, 95], 100);
        assert_eq!(breaks, vec![20, 26, 60, 95]);
        assert_eq!(unreliable, vec![20, 21, 22, 23, 24, 25, 95, 96, 97, 98, 99]);
    }

    /// The velocity's noise scales with the velocity, and a quantised velocity chattering
    /// across zero at a reversal leaves one unreliable run there, whatever the unit.
    #[test]
    fn the_band_of_rest_follows_the_velocity_in_its_own_unit() {
        let time: Vec<f64> = (0..4000).map(|i| i as f64 * 5e-4).collect();
        let quantum = 1e-3;
        let v: Vec<f64> = time
            .iter()
            .map(|t| ((0.05 * (2.0 * std::f64::consts::PI * t).cos()) / quantum).round() * quantum)
            .map(|v: f64| {
                v + if (v / quantum) as i64 % 3 == 0 {
                    quantum
                } else {
                    0.0
                }
            })
            .collect();
        let scaled: Vec<f64> = v.iter().map(|v| v * 1000.0).collect();
        let noise = velocity_noise(&v);
        assert!(noise > 0.0);
        assert!((velocity_noise(&scaled) / noise / 1000.0 - 1.0).abs() < 1e-9);
        let a = differentiate_marked(&time, &v).unwrap();
        let b = differentiate_marked(&time, &scaled).unwrap();
        assert_eq!(a.unreliable, b.unreliable);
        assert!(
            a.unreliable.iter().any(|i| (480..520).contains(i)),
            "{:?}",
            a.unreliable
        );
        for (x, y) in a.values.iter().zip(&b.values) {
            assert!((x * 1000.0 - y).abs() <= 1e-9 * y.abs().max(1.0), "{x} {y}");
        }
    }

    /// The last samples of a run, fitted one-sided, amplify the noise more than twice a
    /// centred window: they are unreliable; the centre of a long run is not.
    #[test]
    fn a_runs_one_sided_ends_are_unreliable() {
        let time: Vec<f64> = (0..300).map(|i| i as f64 * 1e-3).collect();
        let v: Vec<f64> = time.iter().map(|t| 1.0 + t).collect();
        let a = differentiate_marked(&time, &v).unwrap();
        assert!(a.unreliable.contains(&0) && a.unreliable.contains(&299));
        assert!(!a.unreliable.contains(&150));
        assert!(a.unreliable.len() < 20, "{:?}", a.unreliable);
    }

    /// Runs break where the direction of motion changes, the band of rest being a direction.
    #[test]
    fn runs_break_at_every_change_of_direction() {
        let v = [0.5, 0.2, 0.0005, -0.3, -0.1, 0.2];
        assert_eq!(direction_breaks(&v, 1e-3), vec![2, 3, 5]);
    }
}
