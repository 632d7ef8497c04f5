//! The time base of a record and the one check of sample times: finite and increasing.
//!
//! Every place that needs ordered time stamps (the record readers, [`super::Record::validate`],
//! the energy analysis, the model force along a motion, the simulation's sample times) calls
//! [`check_time`] or [`check_sorted`] and turns the typed [`TimeError`] into its own message.

use serde::{Deserialize, Serialize};
use std::sync::Arc;
use thiserror::Error;

/// Fewest samples a time base holds (a step needs two).
pub(crate) const MIN_TIME_SAMPLES: usize = 2;

/// Why a sequence of time stamps is not a valid time base. Indices are 0-based sample indices.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum TimeError {
    /// Fewer samples than needed.
    #[error("{found} samples, at least {needed} needed")]
    TooFew { found: usize, needed: usize },
    /// A time stamp is NaN or infinite.
    #[error("time stamp {index} is {value} (time stamps must be finite)")]
    NonFinite { index: usize, value: f64 },
    /// A time stamp does not follow its predecessor (strictly, or at all for [`check_sorted`]).
    #[error("time is not strictly increasing at sample {index} (t = {previous} then {time})")]
    NotIncreasing {
        index: usize,
        time: f64,
        previous: f64,
    },
}

/// Checks that every time stamp is finite and strictly greater than the one before.
pub fn check_time(time: &[f64]) -> Result<(), TimeError> {
    check_order(time, true)
}

/// Checks that every time stamp is finite and not smaller than the one before (sample times
/// of a simulation may repeat).
pub fn check_sorted(time: &[f64]) -> Result<(), TimeError> {
    check_order(time, false)
}

fn check_order(time: &[f64], strict: bool) -> Result<(), TimeError> {
    if let Some((index, &value)) = time.iter().enumerate().find(|(_, t)| !t.is_finite()) {
        return Err(TimeError::NonFinite { index, value });
    }
    let out_of_order = |w: &[f64]| if strict { w[1] <= w[0] } else { w[1] < w[0] };
    match time.windows(2).position(out_of_order) {
        Some(i) => Err(TimeError::NotIncreasing {
            index: i + 1,
            time: time[i + 1],
            previous: time[i],
        }),
        None => Ok(()),
    }
}

/// Checks [`check_time`] and that there are at least `min_samples` samples.
pub(crate) fn check_time_base(time: &[f64], min_samples: usize) -> Result<(), TimeError> {
    check_count(time, min_samples)?;
    check_time(time)
}

/// Checks that there are at least `min_samples` time stamps.
pub(crate) fn check_count(time: &[f64], min_samples: usize) -> Result<(), TimeError> {
    if time.len() < min_samples {
        return Err(TimeError::TooFew {
            found: time.len(),
            needed: min_samples,
        });
    }
    Ok(())
}

/// The time stamps of a record \[s\]: finite and strictly increasing (see [`TimeBase::new`]).
/// Clones share the stamps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct TimeBase {
    samples: Arc<Vec<f64>>,
}

impl TimeBase {
    /// A checked time base: at least [`MIN_TIME_SAMPLES`] finite, strictly increasing stamps.
    pub fn new(samples: Vec<f64>) -> Result<Self, TimeError> {
        check_time_base(&samples, MIN_TIME_SAMPLES)?;
        Ok(Self {
            samples: Arc::new(samples),
        })
    }

    /// Time stamps taken as they are; [`super::Record::validate`] checks them before any
    /// analysis (this keeps [`super::Record::new`] infallible).
    pub(crate) fn unchecked(samples: Vec<f64>) -> Self {
        Self {
            samples: Arc::new(samples),
        }
    }

    /// The time stamps.
    pub fn as_slice(&self) -> &[f64] {
        &self.samples
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// Checks the stamps and that there are at least `min_samples` of them.
    pub fn check(&self, min_samples: usize) -> Result<(), TimeError> {
        check_time_base(&self.samples, min_samples)
    }

    /// Checks only that there are at least `min_samples` stamps (see [`check_count`]).
    pub fn check_count(&self, min_samples: usize) -> Result<(), TimeError> {
        check_count(&self.samples, min_samples)
    }

    /// The first `len` samples (all of them if there are fewer).
    pub(crate) fn head(&self, len: usize) -> Self {
        Self {
            samples: Arc::new(self.samples[..len.min(self.samples.len())].to_vec()),
        }
    }

    /// The samples from index `first` on (none if `first` is past the end).
    pub(crate) fn tail(&self, first: usize) -> Self {
        Self {
            samples: Arc::new(self.samples.get(first..).unwrap_or_default().to_vec()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_increasing_finite_stamps() {
        let t = TimeBase::new(vec![0.0, 0.5, 1.0]).unwrap();
        assert_eq!(t.as_slice(), &[0.0, 0.5, 1.0]);
        assert_eq!(t.len(), 3);
    }

    #[test]
    fn names_the_first_offending_sample() {
        assert_eq!(
            check_time(&[0.0, 1.0, 1.0, 0.5]),
            Err(TimeError::NotIncreasing {
                index: 2,
                time: 1.0,
                previous: 1.0
            })
        );
        assert_eq!(check_sorted(&[0.0, 1.0, 1.0]), Ok(()));
        assert!(matches!(
            check_sorted(&[0.0, 1.0, 0.9]),
            Err(TimeError::NotIncreasing { index: 2, .. })
        ));
        assert!(matches!(
            check_time(&[0.0, f64::NAN, 2.0]),
            Err(TimeError::NonFinite { index: 1, .. })
        ));
        assert!(matches!(
            TimeBase::new(vec![1.0]),
            Err(TimeError::TooFew {
                found: 1,
                needed: 2
            })
        ));
    }

    #[test]
    fn tail() {
        let t = TimeBase::new(vec![0.0, 1.0, 2.0, 3.0]).unwrap();
        assert_eq!(t.tail(2).as_slice(), &[2.0, 3.0]);
        assert!(t.tail(9).is_empty());
    }
}
