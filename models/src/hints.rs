//! What the identifier tells a model when it stages a fit: the data-driven first guess
//! ([`GuessHint`]) and what a start mapping knows beyond the fitted simpler model
//! ([`StartContext`]). Plain values: this module imports nothing of the crate.

/// A typical presliding displacement of a dry contact \[m\]: the bristle or element
/// deflection at which the friction force reaches its sliding level.
pub const TYPICAL_PRESLIDING_DISPLACEMENT: f64 = 2e-5;

/// Data-driven hints for initial parameter values, computed by the identifier from the
/// measured records (see `Staging::apply_guess`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GuessHint {
    /// Mean friction force divided by the normal force (from the half-cycle energy estimate).
    pub mu: f64,
    /// A typical sliding speed of the records [m/s] (e.g. the RMS velocity).
    pub typical_velocity: f64,
    /// The normal force \[N\].
    pub normal_force: f64,
    /// The oscillator stiffness [N/m]; bristle and element stiffnesses are guessed relative to it.
    pub stiffness: f64,
    /// The oscillator mass \[kg\] (for damping-like parameters such as LuGre's sigma1).
    pub mass: f64,
}

/// What a start mapping (`Staging::start_from`) knows beyond the fitted model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StartContext {
    /// The normal force \[N\].
    pub normal_force: f64,
    /// The oscillator mass \[kg\] (for damping at the critical damping of a bristle mode).
    pub mass: f64,
    /// The displacement at which the contact reaches its sliding force \[m\].
    pub presliding_displacement: f64,
}

impl StartContext {
    /// A context with the typical presliding displacement.
    pub fn new(normal_force: f64, mass: f64) -> Self {
        Self {
            normal_force,
            mass,
            presliding_displacement: TYPICAL_PRESLIDING_DISPLACEMENT,
        }
    }

    /// The contact stiffness that reaches the force `level` \[N\] at the presliding
    /// displacement (at least 1 N/m).
    pub fn stiffness_for(&self, level: f64) -> f64 {
        (level / self.presliding_displacement).max(1.0)
    }

    /// The critical damping 2 sqrt(k m) of a contact of stiffness `k` carrying the mass.
    pub fn critical_damping(&self, k: f64) -> f64 {
        2.0 * (k * self.mass).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scales_by_hand() {
        let ctx = StartContext::new(14.5, 10.391);
        // mu_c N = 2.9 N at 20 micrometres: 1.45e5 N/m.
        assert!((ctx.stiffness_for(2.9) - 1.45e5).abs() < 1e-9);
        // 2 sqrt(1e5 * 10.391) = 2 * 1019.362...
        assert!((ctx.critical_damping(1e5) - 2.0 * 1_039_100f64.sqrt()).abs() < 1e-9);
        assert_eq!(ctx.stiffness_for(0.0), 1.0);
    }
}
