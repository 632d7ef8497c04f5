//! No restoring force: a free axis (a drive, a slide, a joint without gravity load).

use super::{BuildRestoring, RestoringLaw};

/// R(q) = 0: the axis has no equilibrium position and no natural period.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NoRestoring;

impl RestoringLaw for NoRestoring {
    #[inline]
    fn force(&self, _q: f64, _k: f64) -> f64 {
        0.0
    }
    #[inline]
    fn stiffness(&self, _q: f64, _k: f64) -> f64 {
        0.0
    }
    #[inline]
    fn potential(&self, _q: f64, _k: f64) -> f64 {
        0.0
    }
}

impl BuildRestoring for NoRestoring {
    const NAME: &'static str = "none";
    const KEYS: &'static [&'static str] = &[];
    fn from_values(_values: &[f64]) -> Self {
        Self
    }
    fn values(&self) -> Vec<f64> {
        Vec::new()
    }
}
