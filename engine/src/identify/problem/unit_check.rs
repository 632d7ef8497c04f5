//! Units checked from a record's motion before any fit, whatever the fit varies.
//!
//! A free pendulum turns back only within a turn of its hanging equilibrium: two consecutive
//! reversals farther apart than 2 pi are an angle in the wrong unit ([`check_swing`]).
//!
//! A driven record's balance ([`check_driven_balance`]): along a driven axis the measured input u
//! balances J a + c v + F_c sgn(v) + F_0 (+ R(q)). Integrated over consecutive chunks of the
//! record (no derivative of a noisy motion is needed),
//!
//!   int u dt = J (v_1 - v_0) + c (q_1 - q_0) + F_c int sgn(v) dt + F_0 (t_1 - t_0) + k int R(q) dt,
//!
//! a linear least-squares problem whose J is the inertia the record's motion implies. A motion
//! read in the wrong unit scales a and v, not u: positions in millimetres read as metres make
//! J 1000 times smaller, an angle in degrees read as radians 57.3 times smaller. Against the
//! configured inertia (fixed, [`MassReference::Fixed`]) a ratio near a unit's factor either way
//! is a unit error; against a start value the fit will vary ([`MassReference::Start`]) only a
//! ratio near a factor that makes the motion too large is, since a start may be rough. A
//! ratio the record does not determine (J below [`MIN_T_RATIO`] standard errors, or a
//! balance explaining less than [`MIN_EXPLAINED`] of the input) decides nothing.

use crate::axis::Restoring;
use crate::energy::{record_motion, SeriesSource};
use crate::oscillator::Oscillator;
use crate::record::sanity::robust_peak;
use crate::record::{Channel, Record, ScaleError};
use nalgebra::{DMatrix, DVector};

/// The fewest chunks the balance is integrated over.
const MIN_CHUNKS: usize = 20;

/// The number of chunks aimed at (fewer on short records: at least two samples each).
const CHUNKS: usize = 200;

/// The fewest standard errors the implied inertia must lie above zero to be judged.
pub const MIN_T_RATIO: f64 = 10.0;

/// The least share of the input's variance the balance must explain to be judged.
pub const MIN_EXPLAINED: f64 = 0.5;

/// How far (as a factor either way) the ratio may lie from a unit's factor and still be named.
pub const FACTOR_TOLERANCE: f64 = 3.0;

/// What the implied inertia is compared with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MassReference {
    /// The configured mass (inertia), not fitted.
    Fixed(f64),
    /// The configured start of a fitted mass (inertia).
    Start(f64),
}

/// A unit error the balance names.
#[derive(Debug, Clone, PartialEq)]
pub struct BalanceScale {
    /// The channel whose scale is wrong: `displacement`, `velocity` or `acceleration`.
    pub channel: &'static str,
    /// The inertia the record implies.
    pub implied: f64,
    /// The configured inertia (fixed or start).
    pub configured: f64,
    /// The scale to set.
    pub scale: f64,
    /// What was read as what (`millimetres read as metres`).
    pub words: &'static str,
}

/// A unit's factor: the scale that corrects it, whether it makes the motion too large, and
/// its words per channel (displacement, velocity, acceleration).
struct Factor {
    scale: f64,
    too_large: bool,
    words: [&'static str; 3],
}

const LINEAR: [Factor; 3] = [
    Factor {
        scale: 1e-3,
        too_large: true,
        words: [
            "millimetres read as metres",
            "mm/s read as m/s",
            "mm/s^2 read as m/s^2",
        ],
    },
    Factor {
        scale: 1e-6,
        too_large: true,
        words: [
            "micrometres read as metres",
            "um/s read as m/s",
            "um/s^2 read as m/s^2",
        ],
    },
    Factor {
        scale: 1e3,
        too_large: false,
        words: [
            "metres read as millimetres",
            "m/s read as mm/s",
            "m/s^2 read as mm/s^2",
        ],
    },
];

const ROTARY: [Factor; 2] = [
    Factor {
        scale: std::f64::consts::PI / 180.0,
        too_large: true,
        words: [
            "degrees read as radians",
            "deg/s read as rad/s",
            "deg/s^2 read as rad/s^2",
        ],
    },
    Factor {
        scale: 180.0 / std::f64::consts::PI,
        too_large: false,
        words: [
            "radians read as degrees",
            "rad/s read as deg/s",
            "rad/s^2 read as deg/s^2",
        ],
    },
];

/// The unit error `record`'s balance shows against `reference`, if any (see the module docs).
/// `None` for a record without an input or a motion, or one whose balance decides nothing.
pub fn balance_scale(
    record: &Record,
    osc: &Oscillator,
    reference: MassReference,
) -> Option<BalanceScale> {
    let implied = implied_inertia(record, osc)?;
    let (configured, fixed) = match reference {
        MassReference::Fixed(m) => (m, true),
        MassReference::Start(m) => (m, false),
    };
    if !(configured > 0.0 && configured.is_finite()) {
        return None;
    }
    let ratio = implied / configured;
    let factors: &[Factor] = if osc.axis.is_linear() {
        &LINEAR
    } else {
        &ROTARY
    };
    let factor = factors
        .iter()
        .find(|f| (fixed || f.too_large) && (ratio / f.scale).ln().abs() < FACTOR_TOLERANCE.ln())?;
    let (channel, words) = if record.channel(Channel::Acceleration).is_some() {
        ("acceleration", factor.words[2])
    } else if record.channel(Channel::Velocity).is_some() {
        ("velocity", factor.words[1])
    } else {
        ("displacement", factor.words[0])
    };
    Some(BalanceScale {
        channel,
        implied,
        configured,
        scale: factor.scale,
        words,
    })
}

/// The inertia J of the chunked balance (module docs), when the record determines it.
pub fn implied_inertia(record: &Record, osc: &Oscillator) -> Option<f64> {
    let u = record.channel(Channel::InputForce)?;
    let motion = record_motion(record)?;
    let time = record.time();
    let n = time
        .len()
        .min(u.len())
        .min(motion.v.len())
        .min(motion.x.len());
    let chunk = (n / CHUNKS).max(2);
    if n / chunk < MIN_CHUNKS {
        return None;
    }
    let accel = record.channel(Channel::Acceleration);
    let restoring: Vec<f64> = motion
        .x
        .iter()
        .map(|&q| osc.restoring.law().force(q, osc.stiffness))
        .collect();
    let has_restoring = restoring.iter().any(|r| *r != 0.0 && r.is_finite());
    let sign: Vec<f64> = motion.v.iter().map(|v| v.signum()).collect();
    let bounds: Vec<usize> = (0..=n / chunk).map(|j| (j * chunk).min(n - 1)).collect();
    let rows: Vec<[f64; 6]> = bounds
        .windows(2)
        .filter(|w| w[1] > w[0])
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            let dv = match accel {
                Some(acc) => integral(time, acc, a, b),
                None => motion.v[b] - motion.v[a],
            };
            [
                dv,
                motion.x[b] - motion.x[a],
                integral(time, &sign, a, b),
                time[b] - time[a],
                integral(time, &restoring, a, b),
                integral(time, u, a, b),
            ]
        })
        .collect();
    let columns = if has_restoring { 5 } else { 4 };
    solve_inertia(&rows, columns)
}

/// Trapezoidal integral of `y` over samples `a..=b`.
fn integral(time: &[f64], y: &[f64], a: usize, b: usize) -> f64 {
    (a..b)
        .map(|i| 0.5 * (y[i] + y[i + 1]) * (time[i + 1] - time[i]))
        .sum()
}

/// The first coefficient of the least-squares fit of the last entry of each row on its first
/// `columns`, when it lies [`MIN_T_RATIO`] standard errors above zero and the fit explains
/// [`MIN_EXPLAINED`] of the target.
fn solve_inertia(rows: &[[f64; 6]], columns: usize) -> Option<f64> {
    let m = rows.len();
    if m <= columns + 2 || rows.iter().flatten().any(|x| !x.is_finite()) {
        return None;
    }
    let rms: Vec<f64> = (0..columns)
        .map(|c| (rows.iter().map(|r| r[c] * r[c]).sum::<f64>() / m as f64).sqrt())
        .collect();
    if rms.iter().any(|s| *s <= 0.0) {
        return None;
    }
    let a = DMatrix::from_fn(m, columns, |i, c| rows[i][c] / rms[c]);
    let y = DVector::from_iterator(m, rows.iter().map(|r| r[5]));
    let normal = a.transpose() * &a;
    let inverse = normal.clone().try_inverse()?;
    let beta = &inverse * (a.transpose() * &y);
    let residual = &y - &a * &beta;
    let rss = residual.norm_squared();
    let mean = y.mean();
    let tss: f64 = y.iter().map(|v| (v - mean).powi(2)).sum();
    if tss <= 0.0 || tss.is_nan() || 1.0 - rss / tss < MIN_EXPLAINED {
        return None;
    }
    let variance = rss / (m - columns) as f64;
    let se = (variance * inverse[(0, 0)]).sqrt();
    let j = beta[0];
    (j > MIN_T_RATIO * se && j.is_finite()).then(|| j / rms[0])
}

/// How much wider than 2 pi two consecutive reversals of a free pendulum may lie (the
/// angle's noise at the reversals).
const SWING_MARGIN: f64 = 1.1;

/// Checks that a free pendulum's consecutive reversals lie within a turn of each other (see
/// the module docs): the second-widest swing decides, so one spike does not. Records of other
/// axes, driven records and records with fewer than two swings are not checked.
pub fn check_swing(record: &Record, osc: &Oscillator) -> Result<(), ScaleError> {
    if !matches!(osc.restoring, Restoring::Pendulum(_))
        || record.channel(Channel::InputForce).is_some()
    {
        return Ok(());
    }
    let Some(motion) = record_motion(record) else {
        return Ok(());
    };
    let time = record.time();
    let turns = reversals(time, &motion.v);
    let mut swings: Vec<(f64, usize, usize)> = turns
        .windows(2)
        .map(|w| ((motion.x[w[1]] - motion.x[w[0]]).abs(), w[0], w[1]))
        .filter(|s| s.0.is_finite())
        .collect();
    swings.sort_by(|a, b| b.0.total_cmp(&a.0));
    let Some(&(swing, a, b)) = swings.get(1) else {
        return Ok(());
    };
    let turn = 2.0 * std::f64::consts::PI;
    if swing <= SWING_MARGIN * turn {
        return Ok(());
    }
    let channel = if motion.displacement == SeriesSource::Measured {
        "displacement"
    } else {
        "velocity"
    };
    let advice = if swing.to_radians() <= SWING_MARGIN * turn {
        format!("is the angle in degrees? set {channel}_scale = 0.0174533 (pi/180)")
    } else {
        format!("the angle is not in radians: set {channel}_scale to the radians of one unit")
    };
    Err(ScaleError::Swing {
        record: record.name.clone(),
        swing,
        from: time[a],
        to: time[b],
        advice,
    })
}

/// The samples where the motion turns back: the start when it is at rest there, and the last
/// sign change of the velocity between its leaving a tenth of the peak speed on one side and
/// reaching it on the other (as the period check of [`crate::record::sanity`] counts crossings).
fn reversals(time: &[f64], v: &[f64]) -> Vec<usize> {
    let band = 0.1 * robust_peak(v);
    let n = time.len().min(v.len());
    let mut turns = Vec::new();
    if v.first().is_some_and(|v0| v0.abs() <= band) {
        turns.push(0);
    }
    let mut side = 0.0;
    let mut last_change = None;
    for i in 1..n {
        if v[i - 1].signum() != v[i].signum() {
            last_change = Some(i);
        }
        if v[i].abs() <= band {
            continue;
        }
        if side != 0.0 && v[i].signum() != side {
            turns.extend(last_change);
        }
        side = v[i].signum();
    }
    turns
}

/// Checks a driven record's balance against the configured inertia (see the module docs): a
/// ratio near a unit's factor names the channel and the scale to set.
pub fn check_driven_balance(
    record: &Record,
    osc: &Oscillator,
    reference: MassReference,
) -> Result<(), ScaleError> {
    match balance_scale(record, osc, reference) {
        None => Ok(()),
        Some(found) => Err(ScaleError::Balance {
            record: record.name.clone(),
            channel: found.channel,
            words: found.words,
            implied: found.implied,
            configured: found.configured,
            scale: scale_text(found.scale),
        }),
    }
}

/// A scale as a key value: `0.001`, `1e-6`, `1000`, `0.0174533`.
fn scale_text(scale: f64) -> String {
    let rounded = format!("{scale:.6e}").parse::<f64>().unwrap_or(scale);
    if (1e-4..1e5).contains(&rounded) {
        format!("{}", (rounded * 1e7).round() / 1e7)
    } else {
        format!("{rounded:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::axis::{NoRestoring, Restoring};
    use crate::record::TimeBase;

    /// A driven slide (M 12 kg, c 30 N s/m, Coulomb 8 N, offset 0.5 N) moving along
    /// x = 0.05 sin(2 pi 1.3 t) + 0.02 sin(2 pi 3.7 t), its input from the balance; positions
    /// multiplied by `unit` (1000: millimetres).
    fn slide(unit: f64) -> Record {
        let w = [
            2.0 * std::f64::consts::PI * 1.3,
            2.0 * std::f64::consts::PI * 3.7,
        ];
        let t: Vec<f64> = (0..4000).map(|i| i as f64 * 1e-3).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|t| 0.05 * (w[0] * t).sin() + 0.02 * (w[1] * t).sin())
            .collect();
        let v: Vec<f64> = t
            .iter()
            .map(|t| 0.05 * w[0] * (w[0] * t).cos() + 0.02 * w[1] * (w[1] * t).cos())
            .collect();
        let a: Vec<f64> = t
            .iter()
            .map(|t| -0.05 * w[0] * w[0] * (w[0] * t).sin() - 0.02 * w[1] * w[1] * (w[1] * t).sin())
            .collect();
        let u: Vec<f64> = (0..t.len())
            .map(|i| 12.0 * a[i] + 30.0 * v[i] + 8.0 * v[i].signum() + 0.5)
            .collect();
        let x: Vec<f64> = x.iter().map(|x| x * unit).collect();
        Record::from_time_base("drive.csv", TimeBase::unchecked(t))
            .with_channel(Channel::Displacement, x)
            .with_channel(Channel::InputForce, u)
    }

    fn axis() -> Oscillator {
        Oscillator {
            mass: 12.0,
            stiffness: 0.0,
            restoring: Restoring::None(NoRestoring),
            ..Oscillator::fmm()
        }
    }

    #[test]
    fn the_balance_implies_the_inertia_and_names_millimetres() {
        let j = implied_inertia(&slide(1.0), &axis()).unwrap();
        assert!((j / 12.0 - 1.0).abs() < 0.02, "{j}");
        for reference in [MassReference::Fixed(12.0), MassReference::Start(10.0)] {
            assert_eq!(balance_scale(&slide(1.0), &axis(), reference), None);
            let found = balance_scale(&slide(1000.0), &axis(), reference).unwrap();
            assert_eq!(
                (found.channel, found.scale, found.words),
                ("displacement", 1e-3, "millimetres read as metres")
            );
        }
        // Metres read as millimetres: only a fixed mass tells.
        let small = slide(1e-3);
        assert_eq!(
            balance_scale(&small, &axis(), MassReference::Fixed(12.0)).map(|b| b.scale),
            Some(1e3)
        );
        assert_eq!(
            balance_scale(&small, &axis(), MassReference::Start(12.0)),
            None
        );
    }

    #[test]
    fn a_record_without_acceleration_decides_nothing() {
        let t: Vec<f64> = (0..2000).map(|i| i as f64 * 1e-3).collect();
        let x: Vec<f64> = t.iter().map(|t| 0.1 * t).collect();
        let u = vec![3.0 + 8.0 + 0.5; t.len()];
        let r = Record::new("run.csv", t.clone(), vec![0.1; t.len()], 0.0)
            .with_channel(Channel::Displacement, x)
            .with_channel(Channel::InputForce, u);
        assert_eq!(implied_inertia(&r, &axis()), None);
    }
}
