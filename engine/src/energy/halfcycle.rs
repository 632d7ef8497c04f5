//! Turning points of a sampled velocity and the differentiation-free half-cycle estimate.
//!
//! # Robust turning points
//! A noisy velocity crosses zero many times near each turning point (where |v| is comparable
//! to the noise) and keeps crossing after the mass has stopped. Crossings are therefore found
//! with hysteresis: the record is split into *excursions*, runs of at least [`MIN_RUN`]
//! consecutive samples with |v| above a level
//!
//!   L = max(velocity_threshold, 5 sigma_n),
//!
//! where sigma_n is a robust estimate of the white-noise level (the median absolute second
//! difference of v divided by 0.6745 sqrt(6); the second difference of a smooth 1 kHz velocity
//! is far below the noise). A Gaussian sample exceeds 5 sigma with probability 6e-7, three in
//! a row essentially never, so noise alone cannot open an excursion. Successive excursions of
//! the same sign are merged (a dip below L is not a reversal). Between excursions of opposite
//! sign there is exactly one turning point: if the velocity crosses zero several times in that
//! gap, the median crossing is taken (each crossing is located by linear interpolation between
//! the two samples around it). After the last excursion, the first time the velocity reaches
//! zero is the final turning point: the mass is at rest from there (or the record ends).
//!
//! # Half-cycle estimate
//! Between successive turning points the velocity is zero at both ends, so the mechanical
//! energy there is the potential energy k x^2 / 2 alone. Its drop, less the viscous loss
//! c int v^2 dt, is the work of friction; divided by the distance travelled int |v| dt it is
//! the mean friction force of that half-cycle. No acceleration is needed.

use crate::error::EngineError;
use crate::oscillator::Oscillator;
use serde::{Deserialize, Serialize};

/// The fewest consecutive samples above the hysteresis level that make an excursion.
pub const MIN_RUN: usize = 3;

/// Noise-level multiple in the hysteresis level.
const NOISE_FACTOR: f64 = 5.0;

/// The mean friction force of one half-cycle, from the energy balance between two turning
/// points.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HalfCycle {
    /// Time of the turning point that starts the half-cycle \[s\].
    pub t_start: f64,
    /// Time of the turning point that ends it \[s\].
    pub t_end: f64,
    /// Distance travelled, int |v| dt \[m\].
    pub distance: f64,
    /// Mechanical energy at the start minus at the end \[J\].
    pub energy_lost: f64,
    /// Viscous loss c int v^2 dt \[J\].
    pub viscous_loss: f64,
    /// Mean friction force (energy_lost - viscous_loss) / distance \[N\].
    pub force: f64,
}

/// How the signal is reconstructed between samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Interp {
    /// Measured velocity: linear between samples, displacement its exact integral (the
    /// trapezoidal rule). Uses no acceleration.
    Linear,
    /// Exact states: cubic Hermite velocity from (v, a) at both ends of an interval; at a
    /// turning point (where a may jump) a Taylor expansion from the nearer sample on the
    /// same side.
    Hermite,
}

/// Samples of a motion.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Samples<'a> {
    pub time: &'a [f64],
    pub x: &'a [f64],
    pub v: &'a [f64],
    pub a: &'a [f64],
    pub interp: Interp,
}

/// A turning point (velocity zero) or the release.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Turning {
    /// Time \[s\].
    pub time: f64,
    /// Index i of the sample interval [t_i, t_i+1] that holds it.
    pub interval: usize,
    /// Displacement there \[m\].
    pub x: f64,
    /// Velocity there [m/s] (0 except at a release with a velocity).
    pub v: f64,
}

/// The turning points of a record.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Motion {
    /// Turning points in time order: the release (if from rest), every reversal, and the
    /// final stop (if reached).
    pub turning: Vec<Turning>,
    /// Reversals and the final stop: the points where the acceleration may jump.
    pub breaks: Vec<Turning>,
    /// End of the oscillating interval: the final stop, or the last sample.
    pub end_time: f64,
}

impl Motion {
    /// The first sample index at or after each break (segment starts for differentiation).
    pub(crate) fn break_indices(&self, time: &[f64]) -> Vec<usize> {
        self.breaks
            .iter()
            .map(|b| {
                if time.get(b.interval).is_some_and(|&t| b.time > t) {
                    b.interval + 1
                } else {
                    b.interval
                }
            })
            .collect()
    }
}

impl Samples<'_> {
    fn n(&self) -> usize {
        self.time.len()
    }

    /// Whether the velocity reaches or crosses zero in interval i (coming from non-zero).
    fn crosses(&self, i: usize) -> bool {
        match (self.v.get(i), self.v.get(i + 1)) {
            (Some(&a), Some(&b)) => a != 0.0 && (b == 0.0 || a.signum() != b.signum()),
            _ => false,
        }
    }

    /// The zero of the velocity in interval i.
    fn crossing_time(&self, i: usize) -> f64 {
        let (t0, t1, v0, v1) = (self.time[i], self.time[i + 1], self.v[i], self.v[i + 1]);
        let h = t1 - t0;
        let linear = t0 + h * v0 / (v0 - v1);
        if self.interp == Interp::Hermite {
            let a0 = self.a[i];
            if a0 != 0.0 {
                let tau = -v0 / a0;
                if (0.0..=h).contains(&tau) {
                    return t0 + tau;
                }
            }
        }
        linear
    }

    /// Velocity at `t` in interval i, reconstructed from the left sample only (Hermite) or
    /// linearly.
    fn v_lin(&self, i: usize, t: f64) -> f64 {
        let (t0, t1) = (self.time[i], self.time[i + 1]);
        self.v[i] + (self.v[i + 1] - self.v[i]) * (t - t0) / (t1 - t0)
    }

    /// Displacement at `t` in interval i.
    fn x_at(&self, i: usize, t: f64) -> f64 {
        let tau = t - self.time[i];
        match self.interp {
            Interp::Linear => self.x[i] + tau * (self.v[i] + self.v_lin(i, t)) / 2.0,
            Interp::Hermite => self.x[i] + self.v[i] * tau + self.a[i] * tau * tau / 2.0,
        }
    }

    fn turning_at(&self, i: usize) -> Turning {
        let time = self.crossing_time(i);
        Turning {
            time,
            interval: i,
            x: self.x_at(i, time),
            v: 0.0,
        }
    }

    /// (int |v| dt, int v^2 dt) over [lo, hi] inside interval i.
    fn integrals(&self, i: usize, lo: f64, hi: f64) -> (f64, f64) {
        let (t0, t1) = (self.time[i], self.time[i + 1]);
        let len = hi - lo;
        if len <= 0.0 {
            return (0.0, 0.0);
        }
        match self.interp {
            Interp::Linear => {
                let (va, vb) = (self.v_lin(i, lo), self.v_lin(i, hi));
                let sq = len * (va * va + va * vb + vb * vb) / 3.0;
                let abs = if va * vb >= 0.0 {
                    len * (va + vb).abs() / 2.0
                } else {
                    len * (va * va + vb * vb) / (2.0 * (va.abs() + vb.abs()))
                };
                (abs, sq)
            }
            Interp::Hermite => {
                let (v0, v1, a0, a1) = (self.v[i], self.v[i + 1], self.a[i], self.a[i + 1]);
                let h = t1 - t0;
                let full = lo <= t0 && hi >= t1;
                let vel = |t: f64| -> f64 {
                    if full {
                        let s = (t - t0) / h;
                        let (s2, s3) = (s * s, s * s * s);
                        (2.0 * s3 - 3.0 * s2 + 1.0) * v0
                            + (s3 - 2.0 * s2 + s) * h * a0
                            + (-2.0 * s3 + 3.0 * s2) * v1
                            + (s3 - s2) * h * a1
                    } else if lo <= t0 {
                        v0 + a0 * (t - t0)
                    } else {
                        v1 + a1 * (t - t1)
                    }
                };
                gauss3(lo, hi, |t| {
                    let u = vel(t);
                    (u.abs(), u * u)
                })
            }
        }
    }

    /// (int |v| dt, int v^2 dt) from turning point `a` to turning point `b`.
    fn integrals_between(&self, a: &Turning, b: &Turning) -> (f64, f64) {
        let mut acc = (0.0, 0.0);
        for i in a.interval..=b.interval.min(self.n().saturating_sub(2)) {
            let lo = self.time[i].max(a.time);
            let hi = self.time[i + 1].min(b.time);
            let (p, q) = self.integrals(i, lo, hi);
            acc.0 += p;
            acc.1 += q;
        }
        acc
    }
}

/// Three-point Gauss-Legendre quadrature of a pair of integrands.
fn gauss3(lo: f64, hi: f64, f: impl Fn(f64) -> (f64, f64)) -> (f64, f64) {
    let (c, r) = ((lo + hi) / 2.0, (hi - lo) / 2.0);
    let g = (0.6_f64).sqrt();
    let mut acc = (0.0, 0.0);
    for (node, w) in [(-g, 5.0 / 9.0), (0.0, 8.0 / 9.0), (g, 5.0 / 9.0)] {
        let (p, q) = f(c + r * node);
        acc.0 += w * p;
        acc.1 += w * q;
    }
    (acc.0 * r, acc.1 * r)
}

/// The white-noise level of a velocity that the turning-point detector's hysteresis scales
/// with: [`crate::record::noise::difference_noise`] of its second differences.
pub(crate) const VELOCITY_NOISE_ORDER: usize = 2;

/// Finds the turning points. `release` is the release velocity: when |release| <= the
/// hysteresis level the first sample is the first turning point. `velocity_noise` is the
/// velocity's noise from its differences of [`VELOCITY_NOISE_ORDER`]. `record` names the data
/// in errors.
pub(crate) fn detect_motion(
    s: &Samples,
    velocity_threshold: f64,
    velocity_noise: f64,
    release: f64,
    record: &str,
) -> Result<Motion, EngineError> {
    let n = s.n();
    let level = velocity_threshold.max(NOISE_FACTOR * velocity_noise);
    // Excursions: (first, last, sign) runs of |v| > level, at least MIN_RUN long.
    let mut runs: Vec<(usize, usize, f64)> = Vec::new();
    let mut i = 0;
    while i < n {
        if s.v[i].abs() > level {
            let sign = s.v[i].signum();
            let mut j = i;
            while j + 1 < n && s.v[j + 1].abs() > level && s.v[j + 1].signum() == sign {
                j += 1;
            }
            if j + 1 - i >= MIN_RUN {
                match runs.last_mut() {
                    Some(last) if last.2 == sign => last.1 = j,
                    _ => runs.push((i, j, sign)),
                }
            }
            i = j + 1;
        } else {
            i += 1;
        }
    }
    if runs.is_empty() {
        return Err(EngineError::Record {
            record: record.to_string(),
            reason: format!(
                "no motion: |v| never exceeds {level:.3e} m/s for {MIN_RUN} samples in a row \
                 (velocity_threshold or 5x the noise level)"
            ),
        });
    }
    let mut turning = Vec::new();
    let mut breaks = Vec::new();
    let t0 = s.time[0];
    if release.abs() <= level {
        turning.push(Turning {
            time: t0,
            interval: 0,
            x: s.x[0],
            v: release,
        });
    }
    for pair in runs.windows(2) {
        let (end, start) = (pair[0].1, pair[1].0);
        let candidates: Vec<usize> = (end..start).filter(|&k| s.crosses(k)).collect();
        if let Some(&k) = candidates.get(candidates.len() / 2) {
            let tp = s.turning_at(k);
            turning.push(tp);
            breaks.push(tp);
        }
    }
    let mut end_time = s.time[n - 1];
    if let Some(&(_, last, _)) = runs.last() {
        if let Some(k) = (last..n.saturating_sub(1)).find(|&k| s.crosses(k)) {
            let tp = s.turning_at(k);
            end_time = tp.time;
            turning.push(tp);
            breaks.push(tp);
        }
    }
    Ok(Motion {
        turning,
        breaks,
        end_time,
    })
}

/// The half-cycles between successive turning points, with their mean and sample standard
/// deviation (NaN when there are none; std 0 for a single one).
pub(crate) fn half_cycles(
    s: &Samples,
    motion: &Motion,
    osc: &Oscillator,
) -> (Vec<HalfCycle>, f64, f64) {
    let energy = |tp: &Turning| osc.potential(tp.x) + 0.5 * osc.mass * tp.v * tp.v;
    let cycles: Vec<HalfCycle> = motion
        .turning
        .windows(2)
        .filter_map(|w| {
            let (a, b) = (&w[0], &w[1]);
            let (distance, v2) = s.integrals_between(a, b);
            if distance <= 0.0 {
                return None;
            }
            let energy_lost = energy(a) - energy(b);
            let viscous_loss = osc.damping * v2;
            Some(HalfCycle {
                t_start: a.time,
                t_end: b.time,
                distance,
                energy_lost,
                viscous_loss,
                force: (energy_lost - viscous_loss) / distance,
            })
        })
        .collect();
    let k = cycles.len();
    if k == 0 {
        return (cycles, f64::NAN, f64::NAN);
    }
    let mean = cycles.iter().map(|c| c.force).sum::<f64>() / k as f64;
    let std = if k > 1 {
        (cycles.iter().map(|c| (c.force - mean).powi(2)).sum::<f64>() / (k - 1) as f64).sqrt()
    } else {
        0.0
    };
    (cycles, mean, std)
}
