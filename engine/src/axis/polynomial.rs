//! The polynomial spring: a linear, a quadratic (asymmetric) and a cubic term, as a flat
//! torsion spring read by an encoder shows them.

use super::{BuildRestoring, RestoringLaw};

/// R(q) = k1 q + k2 q^2 + k3 q^3, V(q) = k1 q^2 / 2 + k2 q^3 / 3 + k3 q^4 / 4: k1 the
/// oscillator's `stiffness` [N/m or N m/rad] (written in the restoring table or in
/// `[oscillator]`), k2 the quadratic stiffness [N/m^2 or N m/rad^2] (its sign says which
/// side is stiffer), k3 the cubic stiffness [N/m^3 or N m/rad^3] (> 0 hardening, < 0
/// softening). With k2 = 0 it is the cubic spring.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Polynomial {
    /// k2 [N/m^2].
    pub quadratic_stiffness: f64,
    /// k3 [N/m^3].
    pub cubic_stiffness: f64,
}

impl RestoringLaw for Polynomial {
    #[inline]
    fn force(&self, q: f64, k: f64) -> f64 {
        q * (k + q * (self.quadratic_stiffness + q * self.cubic_stiffness))
    }
    #[inline]
    fn stiffness(&self, q: f64, k: f64) -> f64 {
        k + q * (2.0 * self.quadratic_stiffness + 3.0 * self.cubic_stiffness * q)
    }
    #[inline]
    fn potential(&self, q: f64, k: f64) -> f64 {
        let (k2, k3) = (self.quadratic_stiffness, self.cubic_stiffness);
        q * q * (0.5 * k + q * (k2 / 3.0 + 0.25 * k3 * q))
    }
    fn reads_stiffness(&self) -> bool {
        true
    }
    fn check(&self) -> Result<(), String> {
        for (key, value) in Self::KEYS.iter().zip(self.values()) {
            if !value.is_finite() {
                return Err(format!("`{key}` must be finite, got {value}"));
            }
        }
        Ok(())
    }
}

impl BuildRestoring for Polynomial {
    const NAME: &'static str = "polynomial";
    const KEYS: &'static [&'static str] = &["quadratic_stiffness", "cubic_stiffness"];
    const OPTIONAL: &'static [&'static str] = &["quadratic_stiffness", "cubic_stiffness"];
    fn from_values(values: &[f64]) -> Self {
        Self {
            quadratic_stiffness: values.first().copied().unwrap_or(f64::NAN),
            cubic_stiffness: values.get(1).copied().unwrap_or(f64::NAN),
        }
    }
    fn values(&self) -> Vec<f64> {
        vec![self.quadratic_stiffness, self.cubic_stiffness]
    }
}
