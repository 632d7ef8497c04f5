//! The hardening (or softening) Duffing spring.

use super::{BuildRestoring, RestoringLaw};

/// R(q) = k q + k3 q^3, V(q) = k q^2 / 2 + k3 q^4 / 4, with k the oscillator's `stiffness`
/// and k3 the cubic stiffness [N/m^3 or N m/rad^3] (> 0 hardening, < 0 softening).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CubicSpring {
    /// k3 [N/m^3].
    pub cubic_stiffness: f64,
}

impl RestoringLaw for CubicSpring {
    #[inline]
    fn force(&self, q: f64, k: f64) -> f64 {
        k * q + self.cubic_stiffness * q * q * q
    }
    #[inline]
    fn stiffness(&self, q: f64, k: f64) -> f64 {
        k + 3.0 * self.cubic_stiffness * q * q
    }
    #[inline]
    fn potential(&self, q: f64, k: f64) -> f64 {
        let q2 = q * q;
        0.5 * k * q2 + 0.25 * self.cubic_stiffness * q2 * q2
    }
    fn reads_stiffness(&self) -> bool {
        true
    }
    fn check(&self) -> Result<(), String> {
        let k3 = self.cubic_stiffness;
        if k3.is_finite() {
            Ok(())
        } else {
            Err(format!("`cubic_stiffness` must be finite, got {k3}"))
        }
    }
}

impl BuildRestoring for CubicSpring {
    const NAME: &'static str = "cubic_spring";
    const KEYS: &'static [&'static str] = &["cubic_stiffness"];
    fn from_values(values: &[f64]) -> Self {
        Self {
            cubic_stiffness: values.first().copied().unwrap_or(f64::NAN),
        }
    }
    fn values(&self) -> Vec<f64> {
        vec![self.cubic_stiffness]
    }
}
