//! Starts from simpler models, for staged identification: a Coulomb or Stribeck
//! fit gives the levels of the steady-state curve, from which a dynamic model takes its start
//! (`Staging::start_from`), and the data-driven first guess of every Stribeck-type
//! model (`Staging::apply_guess`) is written once, here.
//!
//! The mappings keep the steady-state curve of the simpler fit: LuGre, GMS and a Stribeck
//! model started from a Stribeck fit (delta = 2 for LuGre) slide at exactly its force, and
//! what the simpler fit cannot see (presliding) comes from physical scales:
//! - bristle or element stiffness from the presliding displacement: sigma0 = mu_c N / x_p,
//!   with x_p a few tens of micrometres for dry contacts unless the caller knows better;
//! - LuGre's bristle damping at the critical damping of the bristle mode, 2 sqrt(sigma0 m).

use crate::hints::GuessHint;
pub use crate::hints::{StartContext, TYPICAL_PRESLIDING_DISPLACEMENT};
use crate::model::FrictionModel;

/// The levels of a Stribeck-type steady-state curve,
/// F_ss = N (mu_c + (mu_s - mu_c) exp(-|v / v_s|^delta)) sgn(v) + viscous v.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StribeckLevels {
    /// Coulomb coefficient.
    pub mu_c: f64,
    /// Static coefficient.
    pub mu_s: f64,
    /// Stribeck velocity [m/s]; `None` for a curve without a dip (Coulomb).
    pub v_s: Option<f64>,
    /// Shape exponent; `None` when the fitted model has none.
    pub delta: Option<f64>,
    /// Viscous coefficient [N s/m].
    pub viscous: f64,
}

impl StribeckLevels {
    /// The data-driven first guess of the Stribeck-type models: Coulomb level just below
    /// and static level above the energy estimate, the dip at a fifth of the typical speed,
    /// a viscous term of 5 % of the friction level at that speed.
    pub fn guess(hint: &GuessHint) -> Self {
        let v = hint.typical_velocity.max(1e-6);
        Self {
            mu_c: 0.9 * hint.mu,
            mu_s: 1.2 * hint.mu,
            v_s: Some(0.2 * v),
            delta: None,
            viscous: 0.05 * hint.mu * hint.normal_force / v,
        }
    }

    /// The levels of a fitted model, read from its parameters by their conventional names:
    /// `mu` (coulomb, viscous_coulomb) or `mu_c` and `mu_s` (a missing `mu_s` is `mu_c`),
    /// `v_s`, `delta`, and `viscous` or `sigma2` (0 when absent). `None` for a model with no
    /// Coulomb level or a non-finite one.
    pub fn from_model(model: &dyn FrictionModel) -> Option<Self> {
        let info = model.param_info();
        let values = model.params();
        let get = |name: &str| {
            info.iter()
                .zip(&values)
                .find(|(p, _)| p.name == name)
                .map(|(_, &v)| v)
                .filter(|v| v.is_finite())
        };
        let mu_c = get("mu_c").or_else(|| get("mu"))?;
        Some(Self {
            mu_c,
            mu_s: get("mu_s").unwrap_or(mu_c),
            v_s: get("v_s"),
            delta: get("delta"),
            viscous: get("viscous").or_else(|| get("sigma2")).unwrap_or(0.0),
        })
    }

    /// The Coulomb level and viscous term of a fitted `coulomb` or `viscous_coulomb`: the start
    /// of a law that holds them with its extra terms at zero (`None` for any other law).
    pub fn of_coulomb_law(model: &dyn FrictionModel) -> Option<(f64, f64)> {
        if !matches!(model.name(), "coulomb" | "viscous_coulomb") {
            return None;
        }
        Self::from_model(model).map(|levels| (levels.mu_c, levels.viscous))
    }

    /// Writes the levels into a Stribeck-curve model's `[mu_c, mu_s, v_s, delta, viscous]`,
    /// keeping its own `v_s` and `delta` where the levels have none.
    pub(crate) fn write_into(&self, [mu_c, mu_s, v_s, delta, viscous]: [&mut f64; 5]) {
        *mu_c = self.mu_c;
        *mu_s = self.mu_s;
        *v_s = self.v_s.unwrap_or(*v_s);
        *delta = self.delta.unwrap_or(*delta);
        *viscous = self.viscous;
    }

    /// The static coefficient, never below the Coulomb one (a fit that ended with
    /// mu_s < mu_c starts the next stage at the flat curve instead).
    pub fn mu_s_at_least_mu_c(&self) -> f64 {
        self.mu_s.max(self.mu_c)
    }
}

/// Writes `set_levels(&mut self, &StribeckLevels)` for a model with the Stribeck-curve fields
/// `mu_c`, `mu_s`, `v_s`, `delta` and `viscous`: it takes the levels mu_c, mu_s, v_s and
/// delta (when given) and viscous.
macro_rules! stribeck_levels_setter {
    ($model:ty) => {
        impl $model {
            fn set_levels(&mut self, levels: &$crate::start::StribeckLevels) {
                let Self {
                    mu_c,
                    mu_s,
                    v_s,
                    delta,
                    viscous,
                    ..
                } = self;
                levels.write_into([mu_c, mu_s, v_s, delta, viscous]);
            }
        }
    };
}
pub(crate) use stribeck_levels_setter;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Coulomb, LuGre, Stribeck, ViscousCoulomb};

    #[test]
    fn levels_are_read_by_conventional_names() {
        let c = StribeckLevels::from_model(&Coulomb { mu: 0.24 }).unwrap();
        assert_eq!((c.mu_c, c.mu_s, c.v_s, c.viscous), (0.24, 0.24, None, 0.0));
        let vc = ViscousCoulomb {
            mu: 0.2,
            viscous: 3.0,
        };
        assert_eq!(StribeckLevels::from_model(&vc).unwrap().viscous, 3.0);
        let s = StribeckLevels::from_model(&Stribeck::default()).unwrap();
        assert_eq!(
            (s.mu_c, s.mu_s, s.v_s, s.delta, s.viscous),
            (0.2, 0.3, Some(0.01), Some(2.0), 0.5)
        );
        assert_eq!(
            StribeckLevels::from_model(&LuGre::default())
                .unwrap()
                .viscous,
            0.5
        );
        assert!(StribeckLevels::from_model(&crate::NoFriction {}).is_none());
    }
}
