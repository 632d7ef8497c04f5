//! Where a free-vibration record starts: the release instant, given or found.
//!
//! Instruments often record before the mass is let go (a pre-trigger rest). With
//! `release = "auto"` the rest is found from the velocity itself: the rest level and noise are
//! estimated on the samples well before the motion, the release is the first *sustained*
//! departure from that noise band (every sample from there to the large-amplitude motion lies
//! outside it), refined by following a cubic fitted to the early rise of the speed back to the
//! rest level, to a fraction of a sample. The record then keeps its samples from the last one
//! at or before that instant, and a velocity fit simulates from the instant itself.

use serde::de::{self, Deserializer, Visitor};
use serde::{Deserialize, Serialize, Serializer};
use std::fmt;

/// The `release` key of a record: where the free vibration starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Release {
    /// Found from the velocity (`"auto"`).
    Auto,
    /// At this time stamp \[s\] (a number).
    At(f64),
}

impl Serialize for Release {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Release::Auto => s.serialize_str("auto"),
            Release::At(t) => s.serialize_f64(*t),
        }
    }
}

impl<'de> Deserialize<'de> for Release {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct ReleaseVisitor;
        impl Visitor<'_> for ReleaseVisitor {
            type Value = Release;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("\"auto\" or the release time in seconds")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Release, E> {
                if v == "auto" {
                    Ok(Release::Auto)
                } else {
                    Err(E::invalid_value(de::Unexpected::Str(v), &self))
                }
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Release, E> {
                Ok(Release::At(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Release, E> {
                Ok(Release::At(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Release, E> {
                Ok(Release::At(v as f64))
            }
        }
        d.deserialize_any(ReleaseVisitor)
    }
}

/// Samples in a row that must exceed the motion level for the motion to count as begun.
const SUSTAINED_SAMPLES: usize = 5;

/// Fewest rest samples for a noise estimate; with fewer the record starts at release.
const MIN_REST_SAMPLES: usize = 20;

/// The motion level: this fraction of the peak speed.
const MOTION_FRACTION: f64 = 0.2;

/// Rest noise band: this many robust standard deviations around the rest level.
const NOISE_BAND_SIGMAS: f64 = 5.0;

/// The release instant found in a velocity record (see the module docs), or `None` when there
/// is no measurable rest (the motion starts within the first [`MIN_REST_SAMPLES`] samples, or
/// the samples before it are not quiet: the record starts at release) or no motion at all.
pub fn detect_release(time: &[f64], velocity: &[f64]) -> Option<f64> {
    let n = time.len().min(velocity.len());
    let peak = velocity.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if n == 0 || !(peak > 0.0 && peak.is_finite()) {
        return None;
    }
    let anchor = first_sustained(velocity, |v| v.abs() > MOTION_FRACTION * peak)?;
    if anchor < MIN_REST_SAMPLES {
        return None;
    }
    // The first half of the samples before the motion: rest, away from the rise.
    let (level, sigma) = robust_level(velocity.get(..anchor / 2)?);
    let band = (NOISE_BAND_SIGMAS * sigma).max(1e-9 * peak);
    if band > 0.5 * MOTION_FRACTION * peak {
        // The samples before the motion are not quiet: no rest to cut.
        return None;
    }
    let outside = |i: usize| (velocity[i] - level).abs() > band;
    let mut departure = anchor;
    while departure > 0 && outside(departure - 1) {
        departure -= 1;
    }
    let t_rise = extrapolate_rise(
        &time[departure..anchor],
        &velocity[departure..anchor],
        level,
    );
    // The rise starts before it leaves the noise band, but not before the rest began.
    let (t_departure, t_anchor) = (time[departure], time[anchor]);
    let lower = time[0].max(t_departure - (t_anchor - t_departure));
    Some(t_rise.unwrap_or(t_departure).clamp(lower, t_departure))
}

/// The first index from which `hit` holds for [`SUSTAINED_SAMPLES`] samples in a row.
fn first_sustained(values: &[f64], hit: impl Fn(f64) -> bool) -> Option<usize> {
    let mut run = 0;
    for (i, &v) in values.iter().enumerate() {
        run = if hit(v) { run + 1 } else { 0 };
        if run == SUSTAINED_SAMPLES {
            return Some(i + 1 - SUSTAINED_SAMPLES);
        }
    }
    None
}

/// Median and robust standard deviation (1.4826 times the median absolute deviation).
fn robust_level(values: &[f64]) -> (f64, f64) {
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(0.0)
    };
    let level = median(&mut values.to_vec());
    let sigma = 1.4826 * median(&mut values.iter().map(|v| (v - level).abs()).collect());
    (level, sigma)
}

/// Where the rise (`v` against `t`) crosses the rest `level`: a cubic fitted to the rise
/// (a straight line with fewer than [`CUBIC_SAMPLES`] samples) and followed back from the
/// first sample to its crossing, to a fraction of a sample. A straight line through a rise
/// that bends (the sine of a free vibration bends over towards its peak; a Stribeck law's
/// falling force bends it up at first) misses the crossing by a part of a sample.
fn extrapolate_rise(t: &[f64], v: &[f64], level: f64) -> Option<f64> {
    if t.len() < 2 {
        return None;
    }
    let line = crossing_of_line(t, v, level);
    if t.len() < CUBIC_SAMPLES {
        return line;
    }
    crossing_of_cubic(t, v, level).or(line)
}

/// Fewest samples of the rise fitted by a cubic.
const CUBIC_SAMPLES: usize = 8;

/// Where the least-squares line through (`t`, `v`) crosses `level`.
fn crossing_of_line(t: &[f64], v: &[f64], level: f64) -> Option<f64> {
    let n = t.len() as f64;
    let (mt, mv) = (t.iter().sum::<f64>() / n, v.iter().sum::<f64>() / n);
    let sxy: f64 = t.iter().zip(v).map(|(a, b)| (a - mt) * (b - mv)).sum();
    let sxx: f64 = t.iter().map(|a| (a - mt).powi(2)).sum();
    let slope = sxy / sxx;
    let crossing = mt + (level - mv) / slope;
    crossing.is_finite().then_some(crossing)
}

/// Where the least-squares cubic through (`t`, `v`) first crosses `level` going back from
/// `t[0]`, searched over one span of the rise before it.
fn crossing_of_cubic(t: &[f64], v: &[f64], level: f64) -> Option<f64> {
    let (t0, span) = (t[0], t[t.len() - 1] - t[0]);
    if span.is_nan() || span <= 0.0 {
        return None;
    }
    let s: Vec<f64> = t.iter().map(|&x| (x - t0) / span).collect();
    let a = nalgebra::DMatrix::from_fn(s.len(), 4, |i, j| s[i].powi(j as i32));
    let b = nalgebra::DVector::from_iterator(v.len(), v.iter().map(|&x| x - level));
    let c = a.svd(true, true).solve(&b, 1e-14).ok()?;
    let p = |x: f64| c[0] + x * (c[1] + x * (c[2] + x * c[3]));
    let sign = p(0.0).signum();
    const STEPS: usize = 400;
    let mut hi = 0.0;
    for k in 1..=STEPS {
        let lo = -(k as f64) / STEPS as f64;
        if p(lo).signum() != sign {
            let (mut lo, mut hi) = (lo, hi);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if p(mid).signum() == sign {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            let crossing = t0 + 0.5 * (lo + hi) * span;
            return crossing.is_finite().then_some(crossing);
        }
        hi = lo;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_record_that_moves_at_once_has_no_rest() {
        let t: Vec<f64> = (0..1000).map(|i| i as f64 * 1e-3).collect();
        for omega in [10.0, 30.0, 100.0] {
            let v: Vec<f64> = t.iter().map(|t| -(omega * t).sin()).collect();
            let found = detect_release(&t, &v).unwrap_or(0.0);
            assert!(found <= 1e-3, "omega {omega}: {found}");
        }
        assert_eq!(detect_release(&t, &vec![0.0; 1000]), None);
    }

    #[test]
    fn a_noise_free_ramp_is_found_exactly() {
        // Rest until 0.3 s, then v = -2 (t - 0.3) (sampled every 1 ms).
        let t: Vec<f64> = (0..600).map(|i| i as f64 * 1e-3).collect();
        let v: Vec<f64> = t.iter().map(|&t| -2.0 * (t - 0.3).max(0.0)).collect();
        let found = detect_release(&t, &v).unwrap();
        assert!((found - 0.3).abs() < 1e-9, "{found}");
    }

    /// A free vibration's sine released between samples (5 kHz, rest before): the instant
    /// found to a small fraction of a sample, where the straight line through the rise
    /// lands a tenth of a sample off (early: the sine bends over).
    #[test]
    fn a_sine_released_between_samples_is_found_to_a_fraction_of_a_sample() {
        let (rate, omega, t0) = (5000.0, 13.8, 0.200_07);
        let t: Vec<f64> = (0..3000).map(|i| i as f64 / rate).collect();
        let v: Vec<f64> = t
            .iter()
            .map(|&t| {
                if t > t0 {
                    -0.19 * (omega * (t - t0)).sin()
                } else {
                    0.0
                }
            })
            .collect();
        let found = detect_release(&t, &v).unwrap();
        assert!((found - t0).abs() < 0.01 / rate, "{found}");
        let anchor = first_sustained(&v, |x| x.abs() > MOTION_FRACTION * 0.19).unwrap();
        let departure = t.partition_point(|&x| x <= t0);
        let line = crossing_of_line(&t[departure..anchor], &v[departure..anchor], 0.0).unwrap();
        assert!((line - t0).abs() > 0.05 / rate, "the straight line: {line}");
    }

    #[test]
    fn release_key_reads_auto_or_seconds() {
        let r: Release = serde_json::from_str("\"auto\"").unwrap();
        assert_eq!(r, Release::Auto);
        let r: Release = serde_json::from_str("0.25").unwrap();
        assert_eq!(r, Release::At(0.25));
        let r: Release = serde_json::from_str("1").unwrap();
        assert_eq!(r, Release::At(1.0));
        let e = serde_json::from_str::<Release>("\"late\"").unwrap_err();
        assert!(
            e.to_string().contains("\"auto\" or the release time"),
            "{e}"
        );
    }
}
