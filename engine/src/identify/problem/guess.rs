//! The data-driven guess that starts a fit: the friction level from the half-cycle energy
//! estimate (else the mean |F| of Eq. 7) and a typical speed of each record; and the bound a
//! velocity fit without a normal force puts on the levels it reads as forces.

use crate::energy::differentiate::central_difference;
use crate::energy::{
    analyze_record, half_cycle_force, record_motion, EnergyAnalysis, EnergyOptions,
};
use crate::identify::values::levels::FrictionLevels;
use crate::oscillator::Oscillator;
use crate::record::{Channel, Record};
use frictionid_models::GuessHint;
use std::borrow::Borrow;

/// Data-driven hints: the friction level from the half-cycle energy estimate, a typical speed.
pub fn guess_hint(osc: &Oscillator, records: &[Record], energy: &EnergyOptions) -> GuessHint {
    let level = |_, rec: &Record| friction_level(rec, osc, energy);
    guess_hint_with(osc, records, FrictionLevels::Coefficients, level)
}

/// [`guess_hint`] with each record's friction level from `level` (of its index and itself),
/// the start clipped to where `levels` lets it lie.
pub(crate) fn guess_hint_with<B: Borrow<Record>>(
    osc: &Oscillator,
    records: &[B],
    levels: FrictionLevels,
    level: impl Fn(usize, &Record) -> Option<f64>,
) -> GuessHint {
    let mut found = Vec::new();
    let mut speeds = Vec::new();
    for (index, rec) in records.iter().map(Borrow::borrow).enumerate() {
        if let Some(level) = level(index, rec) {
            found.push(level);
        }
        let peak = rec.velocity().iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if peak > 0.0 {
            speeds.push(peak / 2.0);
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let n = osc.normal_force;
    let mu = if found.is_empty() || n <= 0.0 {
        0.2
    } else {
        levels.clamp_guess(mean(&found) / n)
    };
    GuessHint {
        mu,
        typical_velocity: if speeds.is_empty() {
            0.05
        } else {
            mean(&speeds)
        },
        normal_force: n,
        stiffness: osc.stiffness,
        mass: osc.mass,
    }
}

/// A record's friction level: its half-cycle energy estimate, else (no complete half-cycle
/// with a positive loss) the mean |F| of Eq. 7 along it.
pub(crate) fn friction_level(
    record: &Record,
    osc: &Oscillator,
    energy: &EnergyOptions,
) -> Option<f64> {
    let half_cycles = half_cycle_force(record, osc, energy).ok()?;
    half_cycles.and_then(usable_level).or_else(|| {
        let analysis = analyze_record(record, osc, energy).ok()?;
        usable_level(analysis.mean_abs_force)
    })
}

/// [`friction_level`] read off a record's energy analysis: the mean of its half-cycle
/// forces, else the mean |F| of Eq. 7.
pub(crate) fn level_of_analysis(analysis: &EnergyAnalysis) -> Option<f64> {
    usable_level(analysis.half_cycle_mean).or_else(|| usable_level(analysis.mean_abs_force))
}

/// The largest friction force `records` can hold \[N\], read off their balance
/// J a + c v + R(q) + F + F_0 = u at each sample, |F| <= |u - F_0 - R(q)| + J |a| + c |v|
/// (a from the acceleration channel, else the differentiated velocity; u = 0 in free
/// vibration): a law's level above it would hold the axis where the records show it moving.
/// The bound of a velocity fit's levels read as forces (no normal force given); 0 when no
/// record has a motion.
pub(crate) fn largest_friction_bound(records: &[Record], osc: &Oscillator) -> f64 {
    records
        .iter()
        .filter_map(|record| {
            let motion = record_motion(record)?;
            let a = match record.channel(Channel::Acceleration) {
                Some(a) => a.to_vec(),
                None => central_difference(record.time(), &motion.v),
            };
            let u = record.channel(Channel::InputForce);
            let bound = (0..motion.v.len()).map(|i| {
                let drive = u.and_then(|u| u.get(i)).copied().unwrap_or(0.0);
                (drive - osc.input_offset - osc.restoring_force(motion.x[i])).abs()
                    + osc.mass * a.get(i).copied().unwrap_or(0.0).abs()
                    + osc.damping * motion.v[i].abs()
            });
            Some(bound.fold(0.0, f64::max))
        })
        .filter(|b| b.is_finite())
        .fold(0.0, f64::max)
}

/// A friction level that can start a fit: finite and positive.
fn usable_level(f: f64) -> Option<f64> {
    (f.is_finite() && f > 0.0).then_some(f)
}
