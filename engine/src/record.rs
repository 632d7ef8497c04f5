//! A measured velocity record.

use crate::error::EngineError;
use serde::{Deserialize, Serialize};

/// One free-vibration velocity record: time stamps, velocities and the known release state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// A name for messages and reports (usually the file name).
    pub name: String,
    /// Time stamps [s], strictly increasing.
    pub time: Vec<f64>,
    /// Measured velocity [m/s].
    pub velocity: Vec<f64>,
    /// Displacement at the first time stamp (release) [m].
    pub x0: f64,
    /// Velocity at release [m/s] (0 for a release from rest).
    pub v0: f64,
    /// Weight of this record in a joint fit.
    pub weight: f64,
}

impl Record {
    /// A record released from rest with unit weight.
    pub fn new(name: impl Into<String>, time: Vec<f64>, velocity: Vec<f64>, x0: f64) -> Self {
        Self {
            name: name.into(),
            time,
            velocity,
            x0,
            v0: 0.0,
            weight: 1.0,
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// Whether the record has no samples.
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// Checks lengths, finiteness, strictly increasing time and at least `min_samples` samples.
    pub fn validate(&self, min_samples: usize) -> Result<(), EngineError> {
        let err = |reason: String| EngineError::Record {
            record: self.name.clone(),
            reason,
        };
        if self.time.len() != self.velocity.len() {
            return Err(err(format!(
                "{} time stamps but {} velocities",
                self.time.len(),
                self.velocity.len()
            )));
        }
        if self.time.len() < min_samples {
            return Err(err(format!(
                "{} samples, at least {min_samples} needed",
                self.time.len()
            )));
        }
        for (i, (&t, &v)) in self.time.iter().zip(&self.velocity).enumerate() {
            if !t.is_finite() || !v.is_finite() {
                return Err(err(format!("sample {i} is not finite (t = {t}, v = {v})")));
            }
        }
        if let Some(i) = self.time.windows(2).position(|w| w[1] <= w[0]) {
            return Err(err(format!(
                "time is not strictly increasing at sample {} (t = {} then {})",
                i + 1,
                self.time[i],
                self.time[i + 1]
            )));
        }
        if !self.x0.is_finite() || !self.v0.is_finite() {
            return Err(err("x0 and v0 must be finite".into()));
        }
        if !(self.weight.is_finite() && self.weight > 0.0) {
            return Err(err(format!("weight must be > 0, got {}", self.weight)));
        }
        Ok(())
    }
}
