//! One sample interval of a replayed motion ([`Interval`]): the constant velocity and normal
//! force a [`crate::Propagator`] steps the states over. A plain value: this module imports
//! nothing of the crate.

/// A stretch of motion at constant velocity and constant normal force.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// The sliding velocity [m/s].
    pub v: f64,
    /// The normal force \[N\].
    pub normal: f64,
    /// The duration \[s\], >= 0.
    pub dt: f64,
}

impl Interval {
    /// The distance travelled, |v| dt \[m\].
    pub fn travel(&self) -> f64 {
        self.v.abs() * self.dt
    }
}
