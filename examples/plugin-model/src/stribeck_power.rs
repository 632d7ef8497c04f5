//! Gaussian Stribeck friction with a power-law viscous term: the `stribeck_power` model.
//!
//! F = sgn(v) [ N (mu_c + (mu_s - mu_c) exp(-(v / v_s)^2)) + viscous v_ref |v / v_ref|^alpha ]
//!
//! | parameter | unit | default | bounds | fit | meaning |
//! |---|---|---|---|---|---|
//! | `mu_c` | 1 | 0.2 | [0, 10] | free | Coulomb (kinetic) friction coefficient |
//! | `mu_s` | 1 | 0.3 | [0, 10] | free | static (breakaway) friction coefficient |
//! | `v_s` | m/s | 0.01 | (0, 100] | free | Stribeck velocity of the Gaussian dip |
//! | `viscous` | N s/m | 0.5 | [0, inf] | free | viscous slope at the reference speed |
//! | `alpha` | 1 | 1 | (0, 5] | free | velocity exponent of the viscous term |
//! | `v_ref` | m/s | 0.1 | (0, 100] | fixed | reference speed of the viscous term |
//!
//! The viscous term is written about a reference speed so that `viscous` keeps the unit
//! N s/m for every exponent: at |v| = v_ref it is `viscous * v_ref`, and with alpha = 1 it is
//! the ordinary `viscous * v` (the model is then the built-in `stribeck` with delta = 2).
//! alpha > 1 describes drag that grows faster than linearly with speed (squeeze films,
//! churning, air drag with alpha = 2); alpha < 1 the shear thinning of a lubricant or a fluid
//! damper. `v_ref` is redundant with `viscous` in a fit and is therefore fixed by default.
//!
//! The law is set-valued at v = 0: the mass sticks at a turning point when the spring force
//! does not exceed mu_s N (`static_limit`), and the direction of the Coulomb part while
//! slipping comes from the engine's slip mode (`slip_force`), never from the sign of a
//! velocity that is zero or of the wrong sign by round-off.
//!
//! References: the Gaussian Stribeck curve as in B. Armstrong-Hélouvry, P. Dupont,
//! C. Canudas de Wit, "A survey of models, analysis tools and compensation methods for the
//! control of machines with friction", Automatica 30(7), 1083-1138, 1994; the power-law
//! (velocity-exponent) viscous force F = C |v|^alpha sgn(v) as used for fluid viscous dampers,
//! e.g. M. C. Constantinou, M. D. Symans, "Experimental study of seismic response of buildings
//! with supplemental fluid dampers", The Structural Design of Tall Buildings 2(2), 93-132, 1993.

use frictionid_models::{
    check_bounds, check_len, sgn, FrictionModel, GuessHint, ModelError, ParamInfo,
};
use serde::{Deserialize, Serialize};

/// The registry name of the model.
pub const NAME: &str = "stribeck_power";

/// Gaussian Stribeck friction plus a power-law viscous force.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StribeckPower {
    /// Coulomb coefficient.
    pub mu_c: f64,
    /// Static coefficient.
    pub mu_s: f64,
    /// Stribeck velocity [m/s].
    pub v_s: f64,
    /// Viscous slope at the reference speed [N s/m].
    pub viscous: f64,
    /// Velocity exponent of the viscous term.
    pub alpha: f64,
    /// Reference speed of the viscous term [m/s].
    pub v_ref: f64,
}

impl Default for StribeckPower {
    fn default() -> Self {
        Self {
            mu_c: 0.2,
            mu_s: 0.3,
            v_s: 0.01,
            viscous: 0.5,
            alpha: 1.0,
            v_ref: 0.1,
        }
    }
}

impl StribeckPower {
    /// The dry coefficient mu_c + (mu_s - mu_c) exp(-(v / v_s)^2).
    pub fn coefficient(&self, v: f64) -> f64 {
        let r = v / self.v_s;
        self.mu_c + (self.mu_s - self.mu_c) * (-r * r).exp()
    }

    /// The magnitude of the viscous force, viscous v_ref |v / v_ref|^alpha \[N\].
    pub fn viscous_force(&self, v: f64) -> f64 {
        self.viscous * self.v_ref * (v / self.v_ref).abs().powf(self.alpha)
    }
}

#[typetag::serde(name = "stribeck_power")]
impl FrictionModel for StribeckPower {
    fn name(&self) -> &'static str {
        NAME
    }

    fn equation(&self) -> String {
        "F = sgn(v) (N (mu_c + (mu_s - mu_c) exp(-(v/v_s)^2)) + viscous v_ref |v/v_ref|^alpha)"
            .into()
    }

    fn param_info(&self) -> Vec<ParamInfo> {
        vec![
            ParamInfo::new(
                "mu_c",
                "1",
                0.2,
                (0.0, 10.0),
                "Coulomb (kinetic) friction coefficient",
            ),
            ParamInfo::new(
                "mu_s",
                "1",
                0.3,
                (0.0, 10.0),
                "static (breakaway) friction coefficient",
            ),
            ParamInfo::positive("v_s", "m/s", 0.01, 100.0, "Stribeck velocity"),
            ParamInfo::new(
                "viscous",
                "N s/m",
                0.5,
                (0.0, f64::INFINITY),
                "viscous slope at the reference speed",
            ),
            ParamInfo::positive(
                "alpha",
                "1",
                1.0,
                5.0,
                "velocity exponent of the viscous term",
            ),
            ParamInfo::positive(
                "v_ref",
                "m/s",
                0.1,
                100.0,
                "reference speed of the viscous term (redundant with viscous: fixed)",
            )
            .fixed(),
        ]
    }

    fn params(&self) -> Vec<f64> {
        vec![
            self.mu_c,
            self.mu_s,
            self.v_s,
            self.viscous,
            self.alpha,
            self.v_ref,
        ]
    }

    fn set_params(&mut self, values: &[f64]) -> Result<(), ModelError> {
        check_len(NAME, 6, values.len())?;
        if let [mu_c, mu_s, v_s, viscous, alpha, v_ref] = *values {
            *self = Self {
                mu_c,
                mu_s,
                v_s,
                viscous,
                alpha,
                v_ref,
            };
        }
        Ok(())
    }

    fn force(&self, v: f64, _z: &[f64], normal: f64) -> f64 {
        sgn(v) * (normal * self.coefficient(v) + self.viscous_force(v))
    }

    fn static_limit(&self, normal: f64) -> Option<f64> {
        Some(self.mu_s * normal)
    }

    fn slip_force(&self, v: f64, direction: f64, normal: f64) -> f64 {
        // The dry part takes its sign from the slip mode; the viscous part vanishes at v = 0
        // and is continuous there, so sgn(v) is safe for it.
        direction * normal * self.coefficient(v) + sgn(v) * self.viscous_force(v)
    }

    fn steady_state(&self, v: f64, normal: f64) -> f64 {
        self.force(v, &[], normal)
    }

    fn apply_guess(&mut self, hint: &GuessHint) {
        let v = hint.typical_velocity.max(1e-6);
        self.mu_c = 0.9 * hint.mu;
        self.mu_s = 1.2 * hint.mu;
        self.v_s = 0.2 * v;
        self.viscous = 0.05 * hint.mu * hint.normal_force / v;
    }

    fn validate(&self) -> Result<Vec<String>, ModelError> {
        check_bounds(NAME, &self.param_info(), &self.params())?;
        let mut warnings = Vec::new();
        if self.mu_s < self.mu_c {
            warnings.push(format!(
                "model `{NAME}`: mu_s = {} is below mu_c = {} (friction rises with speed near zero)",
                self.mu_s, self.mu_c
            ));
        }
        Ok(warnings)
    }
}
