//! Gaussian Stribeck friction with a power-law viscous term: the `stribeck_power` model.
//!
//! F = sgn(v) [ N (mu_c + (mu_s - mu_c) exp(-(v / v_s)^2)) + viscous v_ref |v / v_ref|^alpha ]
//!
//! | parameter | unit | default | bounds | fit | meaning |
//! |---|---|---|---|---|---|
//! | `mu_c` | 1 | 0.2 | [0, 10] | free | Coulomb (kinetic) friction coefficient |
//! | `mu_s` | 1 | 0.3 | [0, 10] | free | static (breakaway) friction coefficient |
//! | `v_s` | m/s | 0.01 | (0, 100] | free | Stribeck velocity |
//! | `viscous` | N s/m | 0.5 | [0, inf) | free | viscous slope at the reference speed |
//! | `alpha` | 1 | 1 | (0, 5] | free | velocity exponent of the viscous term |
//! | `v_ref` | m/s | 0.1 | (0, 100] | fixed | reference speed of the viscous term (redundant with viscous: fixed) |
//!
//! `v_s` is the Stribeck velocity of the Gaussian dip. The table above is rendered from the
//! declarations in `declare_params!` below (a test checks it).
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
    mu_s_warning, sgn, FrictionModel, GuessHint, ModelError, Staging, StribeckLevels, SwitchedLaw,
};

/// The registry name of the model.
pub const NAME: &str = "stribeck_power";

frictionid_models::declare_params! {
    /// Gaussian Stribeck friction plus a power-law viscous force.
    pub struct StribeckPower {
        mu_c: new("1", 0.2, (0.0, 10.0), "Coulomb (kinetic) friction coefficient"),
        mu_s: new("1", 0.3, (0.0, 10.0), "static (breakaway) friction coefficient"),
        v_s: positive("m/s", 0.01, 100.0, "Stribeck velocity"),
        viscous: non_negative("N s/m", 0.5, "viscous slope at the reference speed"),
        alpha: positive("1", 1.0, 5.0, "velocity exponent of the viscous term"),
        v_ref: positive(
            "m/s",
            0.1,
            100.0,
            "reference speed of the viscous term (redundant with viscous: fixed)"
        )
        .fixed(),
    }
}

impl StribeckPower {
    /// The parameters the committed fixtures (`fixtures/sim-*.toml`) were simulated with.
    pub fn fixture_truth() -> Self {
        Self {
            mu_c: 0.2,
            mu_s: 0.3,
            v_s: 0.02,
            viscous: 4.0,
            alpha: 1.6,
            v_ref: 0.1,
        }
    }

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
    frictionid_models::declared_param_methods!(
        name: NAME,
        equation: "F = sgn(v) (N (mu_c + (mu_s - mu_c) exp(-(v/v_s)^2)) + viscous v_ref |v/v_ref|^alpha)",
    );
    fn force(&self, v: f64, _z: &[f64], normal: f64) -> f64 {
        sgn(v) * (normal * self.coefficient(v) + self.viscous_force(v))
    }
    frictionid_models::law_groups!(switching, staging);
    // The bounds are checked before this, from the declarations: only the law's own rule.
    fn validate(&self) -> Result<Vec<String>, ModelError> {
        Ok(mu_s_warning(NAME, self.mu_s, self.mu_c))
    }
}

impl SwitchedLaw for StribeckPower {
    fn static_limit(&self, normal: f64) -> Option<f64> {
        Some(self.mu_s * normal)
    }
    fn slip_force(&self, v: f64, direction: f64, normal: f64) -> f64 {
        // The dry part takes its sign from the slip mode; the viscous part vanishes at v = 0
        // and is continuous there, so sgn(v) is safe for it.
        direction * normal * self.coefficient(v) + sgn(v) * self.viscous_force(v)
    }
}

impl Staging for StribeckPower {
    fn apply_guess(&mut self, hint: &GuessHint) {
        let levels = StribeckLevels::guess(hint);
        self.mu_c = levels.mu_c;
        self.mu_s = levels.mu_s;
        self.v_s = levels.v_s.unwrap_or(self.v_s);
        self.viscous = levels.viscous;
    }
}
