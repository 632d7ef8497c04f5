//! The linear spring R(q) = k q, the default: k is the oscillator's `stiffness`.

use super::{BuildRestoring, RestoringLaw};

/// R(q) = k q, V(q) = k q^2 / 2, with k the oscillator's `stiffness` [N/m or N m/rad].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LinearSpring;

impl RestoringLaw for LinearSpring {
    #[inline]
    fn force(&self, q: f64, k: f64) -> f64 {
        k * q
    }
    #[inline]
    fn stiffness(&self, _q: f64, k: f64) -> f64 {
        k
    }
    #[inline]
    fn potential(&self, q: f64, k: f64) -> f64 {
        0.5 * k * q * q
    }
    fn is_linear_spring(&self) -> bool {
        true
    }
    fn reads_stiffness(&self) -> bool {
        true
    }
}

impl BuildRestoring for LinearSpring {
    const NAME: &'static str = "linear_spring";
    const KEYS: &'static [&'static str] = &[];
    fn from_values(_values: &[f64]) -> Self {
        Self
    }
    fn values(&self) -> Vec<f64> {
        Vec::new()
    }
}
