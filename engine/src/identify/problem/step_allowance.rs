//! The step allowance of a fit's simulations: a trial point may cost at most a multiple of what
//! the start point cost, so runaway trial points (a law that chatters, bristles stiffening
//! without bound on records that cannot tell) are cut off by cost, not by stiffness. A
//! physically valid stiff point is integrated by the stiff stepper in about as many steps as
//! a soft one and stays well inside the allowance.
//!
//! Work is counted in integrator steps (accepted and rejected) per sample; the first
//! simulation a problem runs (its start point) sets the baseline. A simulation over its cap
//! fails, which the solver takes as a rejected trial.

use crate::simulate::SimStats;
use std::sync::atomic::{AtomicU64, Ordering};

/// A trial simulation may take this many times the start point's steps per sample.
pub(crate) const WORK_FACTOR: f64 = 8.0;

/// Steps per sample every simulation may take whatever the baseline (the exact propagator's
/// baseline is a few steps per record).
pub(crate) const MIN_STEPS_PER_SAMPLE: f64 = 1.0;

/// Below this many integrator steps over all records at the start point, a problem's records
/// and Jacobian columns are simulated on one thread: handing them to other threads costs
/// more than it saves (the exact propagator takes a few steps per record; Dopri5 on a 2 s
/// FMM record about 400).
pub(crate) const PARALLEL_MIN_STEPS: f64 = 2000.0;

/// Baseline steps per sample, in millionths (0: not measured yet).
const SCALE: f64 = 1e6;

/// The step allowance of one fit problem: per record, the start point's steps per sample, once
/// measured (per record, so that the caps do not depend on which simulation ends first).
#[derive(Debug, Default)]
pub struct StepAllowance {
    baseline: Vec<AtomicU64>,
}

impl StepAllowance {
    /// An allowance for `records` records whose baselines their first simulations set.
    pub fn new(records: usize) -> Self {
        Self {
            baseline: (0..records).map(|_| AtomicU64::new(0)).collect(),
        }
    }

    /// The step cap of a simulation of record `record` with `samples` samples (`None` before
    /// its baseline).
    pub fn cap(&self, record: usize, samples: usize) -> Option<u64> {
        let base = self.baseline.get(record)?.load(Ordering::Relaxed);
        (base > 0).then(|| {
            let per_sample = (WORK_FACTOR * base as f64 / SCALE).max(MIN_STEPS_PER_SAMPLE);
            (per_sample * samples.max(1) as f64).ceil() as u64
        })
    }

    /// Whether every record's baseline is known and together they take fewer than
    /// [`PARALLEL_MIN_STEPS`] steps, for records of `samples` samples each.
    pub fn is_light(&self, samples: impl Iterator<Item = usize>) -> bool {
        let mut steps = 0.0;
        for (slot, n) in self.baseline.iter().zip(samples) {
            let base = slot.load(Ordering::Relaxed);
            if base == 0 {
                return false;
            }
            steps += base as f64 / SCALE * n as f64;
        }
        steps < PARALLEL_MIN_STEPS
    }

    /// Records the work of a finished simulation of record `record` with `samples` samples:
    /// the record's first one sets its baseline.
    pub fn record(&self, record: usize, stats: &SimStats, samples: usize) {
        let Some(slot) = self.baseline.get(record) else {
            return;
        };
        let steps = (stats.steps + stats.rejected_steps).max(1);
        let per_sample = (steps as f64 / samples.max(1) as f64 * SCALE).ceil() as u64;
        let _ = slot.compare_exchange(0, per_sample.max(1), Ordering::Relaxed, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_simulation_sets_a_cap_of_a_multiple_of_its_steps_per_sample() {
        let allowance = StepAllowance::new(2);
        assert_eq!(allowance.cap(0, 1000), None);
        let start = SimStats {
            steps: 3000,
            rejected_steps: 1000,
            ..SimStats::default()
        };
        allowance.record(0, &start, 2000);
        // 2 steps per sample at the start: 16 per sample allowed.
        assert_eq!(allowance.cap(0, 1000), Some(16_000));
        assert_eq!(allowance.cap(1, 1000), None);
        let later = SimStats {
            steps: 1,
            ..SimStats::default()
        };
        allowance.record(0, &later, 2000);
        assert_eq!(allowance.cap(0, 1000), Some(16_000));
        allowance.record(1, &later, 2000);
        assert_eq!(allowance.cap(1, 500), Some(500));
        assert_eq!(allowance.cap(2, 500), None);
    }

    #[test]
    fn records_are_light_once_measured_below_the_parallel_threshold() {
        let allowance = StepAllowance::new(2);
        let few = SimStats {
            steps: 10,
            ..SimStats::default()
        };
        assert!(!allowance.is_light([2000, 2000].into_iter()));
        allowance.record(0, &few, 2000);
        assert!(
            !allowance.is_light([2000, 2000].into_iter()),
            "record 1 unmeasured"
        );
        allowance.record(1, &few, 2000);
        assert!(allowance.is_light([2000, 2000].into_iter()));
        let many = StepAllowance::new(1);
        let dopri = SimStats {
            steps: 2500,
            ..SimStats::default()
        };
        many.record(0, &dopri, 2000);
        assert!(!many.is_light([2000].into_iter()));
    }
}
