//! Where a free-vibration record starts: the release instant, given or found.
//!
//! Instruments often record before the mass is let go (a pre-trigger rest). With
//! `release = "auto"` the rest is found from the velocity itself: the rest level and noise are
//! estimated on the samples well before the motion, the release is the first *sustained*
//! departure from that noise band (every sample from there to the large-amplitude motion lies
//! outside it), refined by extrapolating the early, nearly linear rise of the speed back to the
//! rest level. The record then keeps its samples from the last one at or before that instant.

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

/// Where the straight line fitted to the rise (`v` against `t`) crosses the rest `level`.
fn extrapolate_rise(t: &[f64], v: &[f64], level: f64) -> Option<f64> {
    let n = t.len() as f64;
    if t.len() < 2 {
        return None;
    }
    let (mt, mv) = (t.iter().sum::<f64>() / n, v.iter().sum::<f64>() / n);
    let sxy: f64 = t.iter().zip(v).map(|(a, b)| (a - mt) * (b - mv)).sum();
    let sxx: f64 = t.iter().map(|a| (a - mt).powi(2)).sum();
    let slope = sxy / sxx;
    let crossing = mt + (level - mv) / slope;
    crossing.is_finite().then_some(crossing)
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
