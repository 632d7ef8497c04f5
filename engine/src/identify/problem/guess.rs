//! The data-driven guess that starts a fit: the friction level from the half-cycle energy
//! estimate (else the mean |F| of Eq. 7) and a typical speed of each record.

use crate::energy::{analyze_record, half_cycle_force, EnergyAnalysis};
use crate::identify::values::options::FitOptions;
use crate::oscillator::Oscillator;
use crate::record::Record;
use frictionid_models::GuessHint;
use std::borrow::Borrow;

/// Data-driven hints: the friction level from the half-cycle energy estimate, a typical speed.
pub fn guess_hint(osc: &Oscillator, records: &[Record], opts: &FitOptions) -> GuessHint {
    guess_hint_with(osc, records, |_, rec| friction_level(rec, osc, opts))
}

/// [`guess_hint`] with each record's friction level from `level` (of its index and itself).
pub fn guess_hint_with<B: Borrow<Record>>(
    osc: &Oscillator,
    records: &[B],
    level: impl Fn(usize, &Record) -> Option<f64>,
) -> GuessHint {
    let mut levels = Vec::new();
    let mut speeds = Vec::new();
    for (index, rec) in records.iter().map(Borrow::borrow).enumerate() {
        if let Some(level) = level(index, rec) {
            levels.push(level);
        }
        let peak = rec.velocity().iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if peak > 0.0 {
            speeds.push(peak / 2.0);
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let n = osc.normal_force;
    let mu = if levels.is_empty() || n <= 0.0 {
        0.2
    } else {
        (mean(&levels) / n).clamp(1e-4, 5.0)
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
pub(crate) fn friction_level(record: &Record, osc: &Oscillator, opts: &FitOptions) -> Option<f64> {
    let half_cycles = half_cycle_force(record, osc, &opts.energy).ok()?;
    half_cycles.and_then(usable_level).or_else(|| {
        let analysis = analyze_record(record, osc, &opts.energy).ok()?;
        usable_level(analysis.mean_abs_force)
    })
}

/// [`friction_level`] read off a record's energy analysis: the mean of its half-cycle
/// forces, else the mean |F| of Eq. 7.
pub(crate) fn level_of_analysis(analysis: &EnergyAnalysis) -> Option<f64> {
    usable_level(analysis.half_cycle_mean).or_else(|| usable_level(analysis.mean_abs_force))
}

/// A friction level that can start a fit: finite and positive.
fn usable_level(f: f64) -> Option<f64> {
    (f.is_finite() && f > 0.0).then_some(f)
}
