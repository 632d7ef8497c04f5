//! Stribeck friction with viscous term.
//!
//! F = N (mu_c + (mu_s - mu_c) exp(-|v / v_s|^delta)) sgn(v) + viscous v
//!
//! | parameter | unit | default | bounds | fit | meaning |
//! |---|---|---|---|---|---|
//! | `mu_c` | 1 | 0.2 | [0, 10] | free | Coulomb (kinetic) friction coefficient |
//! | `mu_s` | 1 | 0.3 | [0, 10] | free | static (breakaway) friction coefficient |
//! | `v_s` | m/s | 0.01 | (0, 100] | free | Stribeck velocity |
//! | `delta` | 1 | 2 | (0, 10] | fixed | Stribeck shape exponent (usually fixed) |
//! | `viscous` | N s/m | 0.5 | [0, inf) | free | viscous friction coefficient |
//!
//! The breakaway limit used to decide sticking is mu_s N. mu_s < mu_c is admissible but
//! reported as a warning.
//!
//! Reference: R. Stribeck, "Die wesentlichen Eigenschaften der Gleit- und Rollenlager",
//! Z. VDI 46, 1902; the exponential form as in Armstrong-Hélouvry et al., Automatica 30(7), 1994.

use crate::error::ModelError;
use crate::hints::GuessHint;
use crate::model::{decay, sgn, FrictionModel, ParamGradients, Staging, SwitchedLaw};
use crate::start::{StartContext, StribeckLevels};

crate::declare_params! {
    /// Static friction law with a Stribeck dip between static and Coulomb levels.
    pub struct Stribeck {
        mu_c: new("1", 0.2, (0.0, 10.0), "Coulomb (kinetic) friction coefficient"),
        mu_s: new("1", 0.3, (0.0, 10.0), "static (breakaway) friction coefficient"),
        v_s: positive("m/s", 0.01, 100.0, "Stribeck velocity"),
        delta: positive("1", 2.0, 10.0, "Stribeck shape exponent (usually fixed)").fixed(),
        viscous: non_negative("N s/m", 0.5, "viscous friction coefficient"),
    }
}

crate::start::stribeck_levels_setter!(Stribeck);

impl Stribeck {
    /// The velocity-dependent coefficient mu_c + (mu_s - mu_c) exp(-|v/v_s|^delta).
    pub fn coefficient(&self, v: f64) -> f64 {
        self.mu_c + (self.mu_s - self.mu_c) * decay(self.shape((v / self.v_s).abs()))
    }

    /// a^delta for a = |v/v_s|: a product for the default (and usually fixed) delta = 2, a
    /// copy for delta = 1, else libm's `powf` (which was 37 % of a force-domain Stribeck fit
    /// at delta = 2).
    fn shape(&self, a: f64) -> f64 {
        if self.delta == 2.0 {
            a * a
        } else if self.delta == 1.0 {
            a
        } else {
            a.powf(self.delta)
        }
    }
}

#[typetag::serde(name = "stribeck")]
impl FrictionModel for Stribeck {
    crate::declared_param_methods!(
        name: "stribeck",
        equation: "F = N (mu_c + (mu_s - mu_c) exp(-|v/v_s|^delta)) sgn(v) + viscous v",
    );
    fn force(&self, v: f64, _z: &[f64], normal: f64) -> f64 {
        normal * self.coefficient(v) * sgn(v) + self.viscous * v
    }
    crate::law_groups!(switching, staging, param_gradients);
    fn validate(&self) -> Result<Vec<String>, ModelError> {
        Ok(mu_s_warning(self.name(), self.mu_s, self.mu_c))
    }
}

impl ParamGradients for Stribeck {
    /// With a = |v / v_s|, e = exp(-a^delta) and the dip D = N (mu_s - mu_c) e sgn(v):
    /// dF/dmu_c = N (1 - e) sgn(v), dF/dmu_s = N e sgn(v), dF/dv_s = D delta a^delta / v_s,
    /// dF/ddelta = -D a^delta ln(a), dF/dviscous = v.
    fn force_param_gradient(&self, v: f64, _z: &[f64], normal: f64, out: &mut [f64]) {
        let a = (v / self.v_s).abs();
        let power = self.shape(a);
        let e = decay(power);
        let sign = sgn(v);
        let dip = normal * (self.mu_s - self.mu_c) * e * sign;
        let (d_vs, d_delta) = if power > 0.0 {
            (dip * self.delta * power / self.v_s, -dip * power * a.ln())
        } else {
            (0.0, 0.0)
        };
        let gradient = [
            normal * (1.0 - e) * sign,
            normal * e * sign,
            d_vs,
            d_delta,
            v,
        ];
        for (o, d) in out.iter_mut().zip(gradient) {
            *o = d;
        }
    }
}

impl SwitchedLaw for Stribeck {
    fn static_limit(&self, normal: f64) -> Option<f64> {
        Some(self.mu_s * normal)
    }
    fn slip_force(&self, v: f64, direction: f64, normal: f64) -> f64 {
        normal * self.coefficient(v) * direction + self.viscous * v
    }
}

impl Staging for Stribeck {
    fn apply_guess(&mut self, hint: &GuessHint) {
        self.set_levels(&StribeckLevels::guess(hint));
    }
    fn start_from(&mut self, fitted: &dyn FrictionModel, _ctx: &StartContext) -> bool {
        let Some(levels) = StribeckLevels::from_model(fitted) else {
            return false;
        };
        self.set_levels(&levels);
        true
    }
}

/// The warning of `validate` for a static coefficient below the kinetic one (none when
/// mu_s >= mu_c), for every model with both levels.
pub fn mu_s_warning(model: &str, mu_s: f64, mu_c: f64) -> Vec<String> {
    if mu_s < mu_c {
        vec![format!(
            "model `{model}`: mu_s = {mu_s} is below mu_c = {mu_c} (friction rises with speed near zero)"
        )]
    } else {
        Vec::new()
    }
}
