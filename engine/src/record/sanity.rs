//! Unit sanity of a free-vibration record against its oscillator, before any fit: a record
//! exported in mm/s, or with time stamps in milliseconds, is an error that names the key to set.
//!
//! - Speed: a passive oscillator released at x0 with speed v0 never moves faster than
//!   sqrt((x0 w)^2 + v0^2), w = sqrt(k/m). A peak speed more than [`MAX_SPEED_RATIO`] times that
//!   is a unit error. Friction lowers the peak legitimately (Coulomb: (x0 - F/k) w), so the low
//!   side allows a wider margin, [`MIN_SPEED_RATIO`] (a factor 1000 off is what unit mistakes
//!   produce, such as x0 in mm).
//! - Time: friction and light damping barely change the period of the oscillation, 2 pi / w.
//!   A measured period [`MAX_PERIOD_RATIO`] times longer or shorter is a unit error.
//! - Angles: on a rotary axis whose restoring law is not linear (the pendulum), no passive
//!   motion within the record's swing |q| <= A moves faster than sqrt(2 (max V - min V) / J +
//!   v0^2) over [-A, A]. An angular speed (measured, else differentiated from the angle)
//!   [`MAX_SPEED_RATIO`] times that is an angle read in the wrong unit: degrees read as
//!   radians make it 57.3 times the truth while the potential stays bounded. A linear spring
//!   scales with the angle, so its records cannot tell.
//! - Swings: a free pendulum turns back only within a turn of its hanging equilibrium, so two
//!   consecutive reversals of its motion lie less than 2 pi apart, whatever its inertia and
//!   gravity moment (fitted or not). Swings wider than that are an angle in the wrong unit:
//!   degrees read as radians widen every swing 57.3 times
//!   ([`crate::identify::problem::unit_check::check_swing`], which reads the motion as the
//!   energy analysis does).
//! - Balance: a driven record's input balances J a + c v + ...; the inertia that balance
//!   implies, against the configured one, names a motion read in the wrong unit
//!   ([`crate::identify::problem::unit_check::check_driven_balance`]).

use super::{Channel, Record};
use crate::oscillator::Oscillator;
use thiserror::Error;

/// Largest accepted ratio of the peak speed to what x0, v0 and k/m allow.
pub(crate) const MAX_SPEED_RATIO: f64 = 3.0;

/// Smallest accepted ratio of the peak speed to what x0, v0 and k/m allow.
pub(crate) const MIN_SPEED_RATIO: f64 = 0.1;

/// Largest accepted ratio (either way) of the measured oscillation period to 2 pi sqrt(m/k).
pub(crate) const MAX_PERIOD_RATIO: f64 = 3.0;

/// A record whose units disagree with its oscillator.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ScaleError {
    /// The peak speed is far above or below what x0, v0 and k/m allow.
    #[error(
        "{record}: peak speed {peak:.4e} m/s is {} than x0 = {x0} m and k/m allow ({expected:.4e} m/s): {advice}",
        ratio_words(*ratio)
    )]
    Speed {
        record: String,
        peak: f64,
        expected: f64,
        x0: f64,
        ratio: f64,
        advice: String,
    },
    /// The oscillation period is far from 2 pi sqrt(m/k).
    #[error(
        "{record}: the oscillation period {period:.4e} s is {} than 2 pi sqrt(m/k) = {natural:.4e} s: {advice}",
        ratio_words(*ratio)
    )]
    Period {
        record: String,
        period: f64,
        natural: f64,
        ratio: f64,
        advice: String,
    },
    /// The angular speed is far above what the restoring law allows over the swing.
    #[error(
        "{record}: peak angular speed {peak:.4e} rad/s is {} than the restoring law and the inertia allow over the record's swing of +-{swing:.4e} rad ({expected:.4e} rad/s): is the angle in degrees? set displacement_scale = 0.0174533 (pi/180)",
        ratio_words(*ratio)
    )]
    Angle {
        record: String,
        peak: f64,
        expected: f64,
        swing: f64,
        ratio: f64,
    },
    /// A free pendulum swings wider than a turn between two reversals.
    #[error(
        "{record}: the angle swings {swing:.4e} rad between the reversals at t = {from:.4} s and t = {to:.4} s, wider than a pendulum can turn back within (2 pi): {advice}"
    )]
    Swing {
        record: String,
        swing: f64,
        from: f64,
        to: f64,
        advice: String,
    },
    /// A driven record's balance implies an inertia a unit's factor away from the configured one.
    #[error(
        "{record}: the {channel} looks like {words}: the input balances J a with J = {implied:.4e} against the configured {configured:.4e} ({}): set {channel}_scale = {scale}",
        ratio_words(*implied / *configured)
    )]
    Balance {
        record: String,
        channel: &'static str,
        words: &'static str,
        implied: f64,
        configured: f64,
        scale: String,
    },
}

/// `1000x larger` / `1000x smaller`.
fn ratio_words(ratio: f64) -> String {
    if ratio >= 1.0 {
        format!("{}x larger", round_ratio(ratio))
    } else {
        format!("{}x smaller", round_ratio(1.0 / ratio))
    }
}

/// Three significant digits, without an exponent for everyday ratios.
fn round_ratio(r: f64) -> String {
    let digits = r.abs().log10().floor() as i32;
    let unit = 10f64.powi(digits - 2);
    let rounded = (r / unit).round() * unit;
    if (1.0..1e7).contains(&rounded) {
        format!("{}", rounded.round())
    } else {
        format!("{rounded:.3}")
    }
}

/// The power of ten nearest to `1 / ratio`, as a key value (`1e-3`).
fn suggested_scale(ratio: f64) -> String {
    format!("1e{}", -(ratio.log10().round() as i32))
}

/// Checks the units of a velocity record against `osc` (see the module docs). Records without
/// velocity, or released at rest from x0 = 0, are not checked.
pub fn check_scales(record: &Record, osc: &Oscillator) -> Result<(), ScaleError> {
    check_angle(record, osc)?;
    if record.channel(Channel::Velocity).is_none() {
        return Ok(());
    }
    check_speed(record, osc)?;
    check_period(record, osc)
}

/// Samples of the potential over the swing in [`check_angle`].
const SWING_SAMPLES: usize = 400;

/// Half-width in samples of the central difference that differentiates an angle (an
/// encoder's steps averaged over 2 x 5 samples).
const ANGLE_SPAN: usize = 5;

fn check_angle(record: &Record, osc: &Oscillator) -> Result<(), ScaleError> {
    if osc.axis.is_linear() || osc.has_linear_spring() {
        return Ok(());
    }
    let Some(q) = record.channel(Channel::Displacement) else {
        return Ok(());
    };
    let swing = robust_peak(q).max(record.x0.abs());
    let potential = (0..=SWING_SAMPLES)
        .map(|i| osc.potential(swing * (2.0 * i as f64 / SWING_SAMPLES as f64 - 1.0)));
    let (low, high) = potential.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    let expected = (2.0 * (high - low) / osc.mass + record.v0 * record.v0).sqrt();
    let peak = match record.channel(Channel::Velocity) {
        Some(v) => robust_peak(v),
        None => robust_peak(&central_difference(record.time(), q, ANGLE_SPAN)),
    };
    if !(expected > 0.0 && expected.is_finite() && peak.is_finite()) {
        return Ok(());
    }
    let ratio = peak / expected;
    if ratio <= MAX_SPEED_RATIO {
        return Ok(());
    }
    Err(ScaleError::Angle {
        record: record.name.clone(),
        peak,
        expected,
        swing,
        ratio,
    })
}

/// (q[i+s] - q[i-s]) / (t[i+s] - t[i-s]) wherever both samples exist.
fn central_difference(time: &[f64], q: &[f64], span: usize) -> Vec<f64> {
    let n = time.len().min(q.len());
    (span..n.saturating_sub(span))
        .map(|i| (q[i + span] - q[i - span]) / (time[i + span] - time[i - span]))
        .collect()
}

fn check_speed(record: &Record, osc: &Oscillator) -> Result<(), ScaleError> {
    let omega = (osc.small_motion_stiffness() / osc.mass).sqrt();
    let expected = (record.x0 * omega).hypot(record.v0);
    let peak = robust_peak(record.velocity());
    if !(expected > 0.0 && expected.is_finite() && peak > 0.0) {
        return Ok(());
    }
    let ratio = peak / expected;
    if (MIN_SPEED_RATIO..=MAX_SPEED_RATIO).contains(&ratio) {
        return Ok(());
    }
    let advice = match ratio.log10().round() as i32 {
        3 => "is the velocity in mm/s? set velocity_scale = 1e-3".to_string(),
        6 => "is the velocity in um/s? set velocity_scale = 1e-6".to_string(),
        -3 => "is x0 in mm? x0 is in metres".to_string(),
        _ => format!(
            "check x0 or set velocity_scale = {}",
            suggested_scale(ratio)
        ),
    };
    Err(ScaleError::Speed {
        record: record.name.clone(),
        peak,
        expected,
        x0: record.x0,
        ratio,
        advice,
    })
}

fn check_period(record: &Record, osc: &Oscillator) -> Result<(), ScaleError> {
    let natural = 2.0 * std::f64::consts::PI * (osc.mass / osc.small_motion_stiffness()).sqrt();
    if !natural.is_finite() {
        // No restoring force: no natural period to compare with.
        return Ok(());
    }
    let Some(period) = oscillation_period(record.time(), record.velocity()) else {
        return Ok(());
    };
    let ratio = period / natural;
    if (1.0 / MAX_PERIOD_RATIO..=MAX_PERIOD_RATIO).contains(&ratio) {
        return Ok(());
    }
    let unit = if (ratio.log10().round() as i32) == 3 {
        "are the time stamps in milliseconds? "
    } else {
        ""
    };
    Err(ScaleError::Period {
        record: record.name.clone(),
        period,
        natural,
        ratio,
        advice: format!("{unit}set time_scale = {}", suggested_scale(ratio)),
    })
}

/// The peak |v| ignoring the largest 0.1 % of the samples (a spike is not the motion).
pub(crate) fn robust_peak(v: &[f64]) -> f64 {
    let mut abs: Vec<f64> = v
        .iter()
        .map(|x| x.abs())
        .filter(|x| x.is_finite())
        .collect();
    abs.sort_by(f64::total_cmp);
    let skip = abs.len() / 1000;
    abs.len()
        .checked_sub(1 + skip)
        .and_then(|i| abs.get(i))
        .copied()
        .unwrap_or(0.0)
}

/// Twice the median spacing of the velocity's zero crossings. A crossing counts when the
/// velocity goes from beyond a tenth of the peak speed on one side to beyond it on the other
/// (so noise at rest does not count); its time is the last sign change in between,
/// interpolated. The median, because a lobe lost in that band doubles one spacing. `None` with
/// fewer than three crossings.
fn oscillation_period(time: &[f64], v: &[f64]) -> Option<f64> {
    let band = 0.1 * robust_peak(v);
    let mut side = 0.0;
    let mut last_sign_change = None;
    let mut crossings = Vec::new();
    for i in 1..time.len().min(v.len()) {
        let (t0, t1, v0, v1) = (time[i - 1], time[i], v[i - 1], v[i]);
        if v0.signum() != v1.signum() && v1 != v0 {
            last_sign_change = Some(t0 + (t1 - t0) * v0 / (v0 - v1));
        }
        if v1.abs() <= band {
            continue;
        }
        if side != 0.0 && v1.signum() != side {
            crossings.extend(last_sign_change);
        }
        side = v1.signum();
    }
    let mut gaps: Vec<f64> = crossings.windows(2).map(|w| w[1] - w[0]).collect();
    gaps.sort_by(f64::total_cmp);
    (gaps.len() >= 2).then(|| 2.0 * gaps[gaps.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An undamped free vibration of the FMM stage at `x0`, `rate` Hz for 2 s.
    fn record(x0: f64, v_scale: f64, t_scale: f64) -> Record {
        let osc = Oscillator::fmm();
        let w = (osc.stiffness / osc.mass).sqrt();
        let t: Vec<f64> = (0..2000).map(|i| i as f64 * 1e-3).collect();
        let v: Vec<f64> = t
            .iter()
            .map(|t| -x0 * w * (w * t).sin() / v_scale)
            .collect();
        let t: Vec<f64> = t.iter().map(|t| t / t_scale).collect();
        let mut r = Record::new("x14.csv", t, v, x0);
        r.x0 = x0;
        r
    }

    #[test]
    fn a_consistent_record_passes() {
        check_scales(&record(0.014, 1.0, 1.0), &Oscillator::fmm()).unwrap();
    }

    #[test]
    fn velocity_in_mm_per_s_names_the_key() {
        let e = check_scales(&record(0.014, 1e-3, 1.0), &Oscillator::fmm()).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.starts_with("x14.csv: peak speed")
                && msg.contains("1000x larger than x0 = 0.014 m"),
            "{msg}"
        );
        assert!(
            msg.ends_with("is the velocity in mm/s? set velocity_scale = 1e-3"),
            "{msg}"
        );
        let ScaleError::Speed { ratio, .. } = e else {
            panic!("{e:?}")
        };
        assert!((ratio - 1000.0).abs() < 1.0, "{ratio}");
    }

    #[test]
    fn x0_in_mm_is_caught_too() {
        let mut r = record(0.014, 1.0, 1.0);
        r.x0 = 14.0;
        let msg = check_scales(&r, &Oscillator::fmm())
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("1000x smaller") && msg.contains("is x0 in mm?"),
            "{msg}"
        );
    }

    #[test]
    fn millisecond_time_stamps_name_time_scale() {
        let msg = check_scales(&record(0.014, 1.0, 1e-3), &Oscillator::fmm())
            .unwrap_err()
            .to_string();
        assert!(msg.contains("1000x larger than 2 pi sqrt(m/k)"), "{msg}");
        assert!(
            msg.ends_with("are the time stamps in milliseconds? set time_scale = 1e-3"),
            "{msg}"
        );
    }

    #[test]
    fn the_period_of_a_sine_is_measured() {
        let t: Vec<f64> = (0..5000).map(|i| i as f64 * 1e-3).collect();
        let v: Vec<f64> = t
            .iter()
            .map(|t| (2.0 * std::f64::consts::PI * t / 0.4).sin())
            .collect();
        let p = oscillation_period(&t, &v).unwrap();
        assert!((p - 0.4).abs() < 2e-3, "{p}");
    }
}
