//! The pendulum: gravity's torque on a rigid body turning about a horizontal axis.

use super::{BuildRestoring, RestoringLaw};

/// R(q) = M_g sin(q), V(q) = M_g (1 - cos q), q the angle from the hanging equilibrium [rad]
/// and M_g = m g l the gravity moment [N m] (m the mass, l the distance from the axis to the
/// centre of mass). Small swings have the period 2 pi sqrt(J / M_g).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pendulum {
    /// M_g = m g l [N m] (> 0).
    pub gravity_moment: f64,
}

impl RestoringLaw for Pendulum {
    #[inline]
    fn force(&self, q: f64, _k: f64) -> f64 {
        self.gravity_moment * q.sin()
    }
    #[inline]
    fn stiffness(&self, q: f64, _k: f64) -> f64 {
        self.gravity_moment * q.cos()
    }
    #[inline]
    fn potential(&self, q: f64, _k: f64) -> f64 {
        // 1 - cos q = 2 sin^2(q/2), without the cancellation near q = 0.
        let s = (0.5 * q).sin();
        2.0 * self.gravity_moment * s * s
    }
    fn check(&self) -> Result<(), String> {
        let m = self.gravity_moment;
        if m.is_finite() && m > 0.0 {
            Ok(())
        } else {
            Err(format!("`gravity_moment` must be finite and > 0, got {m}"))
        }
    }
}

impl BuildRestoring for Pendulum {
    const NAME: &'static str = "pendulum";
    const KEYS: &'static [&'static str] = &["gravity_moment"];
    fn from_values(values: &[f64]) -> Self {
        Self {
            gravity_moment: values.first().copied().unwrap_or(f64::NAN),
        }
    }
    fn values(&self) -> Vec<f64> {
        vec![self.gravity_moment]
    }
}
