//! Coulomb friction with a level per sliding direction.
//!
//! F = N mu_pos (v > 0), -N mu_neg (v < 0)
//!
//! | parameter | unit | default | bounds | fit | meaning |
//! |---|---|---|---|---|---|
//! | `mu_pos` | 1 | 0.2 | [0, 10] | free | Coulomb friction coefficient sliding in +v |
//! | `mu_neg` | 1 | 0.2 | [0, 10] | free | Coulomb friction coefficient sliding in -v |
//!
//! With `mu_pos = mu_neg` it is `coulomb`. The mass sticks while the force it must hold lies
//! in [-mu_neg N, mu_pos N].
//!
//! Reference: direction-dependent Coulomb levels as identified on robot joints and drives,
//! e.g. B. Armstrong-Hélouvry, *Control of Machines with Friction*, Kluwer (1991), ch. 2; W.
//! Khalil, E. Dombre, *Modeling, Identification and Control of Robots* (2002), section 12.4.

use crate::hints::GuessHint;
use crate::model::{FrictionModel, ParamGradients, Staging, SwitchedLaw};
use crate::start::{StartContext, StribeckLevels};

crate::declare_params! {
    /// Coulomb friction whose level depends on the sliding direction.
    pub struct CoulombAsymmetric {
        mu_pos: new("1", 0.2, (0.0, 10.0), "Coulomb friction coefficient sliding in +v"),
        mu_neg: new("1", 0.2, (0.0, 10.0), "Coulomb friction coefficient sliding in -v"),
    }
}

/// The friction force per unit normal force sliding in `direction` (+1, -1; 0 at rest).
pub(crate) fn directed_level(mu_pos: f64, mu_neg: f64, direction: f64) -> f64 {
    if direction > 0.0 {
        mu_pos
    } else if direction < 0.0 {
        -mu_neg
    } else {
        0.0
    }
}

#[typetag::serde(name = "coulomb_asymmetric")]
impl FrictionModel for CoulombAsymmetric {
    crate::declared_param_methods!(
        name: "coulomb_asymmetric",
        equation: "F = N mu_pos (v > 0), -N mu_neg (v < 0)",
    );
    fn force(&self, v: f64, _z: &[f64], normal: f64) -> f64 {
        normal * directed_level(self.mu_pos, self.mu_neg, v)
    }
    crate::law_groups!(switching, staging, param_gradients);
}

impl ParamGradients for CoulombAsymmetric {
    /// dF/dmu_pos = N (v > 0), dF/dmu_neg = -N (v < 0).
    fn force_param_gradient(&self, v: f64, _z: &[f64], normal: f64, out: &mut [f64]) {
        let pos = if v > 0.0 { normal } else { 0.0 };
        let neg = if v < 0.0 { -normal } else { 0.0 };
        for (o, d) in out.iter_mut().zip([pos, neg]) {
            *o = d;
        }
    }
}

impl SwitchedLaw for CoulombAsymmetric {
    fn static_limit(&self, normal: f64) -> Option<f64> {
        Some(0.5 * (self.mu_pos + self.mu_neg) * normal)
    }
    fn static_offset(&self, normal: f64) -> f64 {
        0.5 * (self.mu_pos - self.mu_neg) * normal
    }
    fn slip_force(&self, _v: f64, direction: f64, normal: f64) -> f64 {
        normal * directed_level(self.mu_pos, self.mu_neg, direction)
    }
    fn affine_slip(&self, direction: f64, normal: f64) -> Option<(f64, f64)> {
        Some((self.slip_force(0.0, direction, normal), 0.0))
    }
}

impl Staging for CoulombAsymmetric {
    fn apply_guess(&mut self, hint: &GuessHint) {
        self.mu_pos = hint.mu;
        self.mu_neg = hint.mu;
    }
    /// Both levels at a fitted symmetric law's level, where that reproduces its curve.
    fn start_from(&mut self, fitted: &dyn FrictionModel, ctx: &StartContext) -> bool {
        let Some(level) = symmetric_level(fitted, ctx.normal_force) else {
            return false;
        };
        let mut trial = self.clone();
        (trial.mu_pos, trial.mu_neg) = (level, level);
        take_if_reproduces(self, trial, fitted, ctx.normal_force)
    }
}

/// The value of `model`'s parameter `name`, when it has a finite one.
pub(crate) fn param_named(model: &dyn FrictionModel, name: &str) -> Option<f64> {
    model
        .param_info()
        .iter()
        .zip(model.params())
        .find(|(p, _)| p.name == name)
        .map(|(_, v)| v)
        .filter(|v| v.is_finite())
}

/// The Coulomb level of a fitted symmetric law (`mu` or `mu_c`).
pub(crate) fn symmetric_level(fitted: &dyn FrictionModel, _normal: f64) -> Option<f64> {
    StribeckLevels::from_model(fitted).map(|l| l.mu_c)
}

/// Sliding speeds at which a start must reproduce the law it starts from [m/s].
const PROBE_SPEEDS: [f64; 5] = [1e-5, 1e-3, 0.03, 0.5, 5.0];

/// Takes `trial` into `model` when its steady-state curve is `fitted`'s at every probe
/// speed, in both directions (to rounding): the start is then exactly the fitted law, which
/// the law holds as a limit. False, leaving `model` as it was, otherwise.
pub(crate) fn take_if_reproduces<M: FrictionModel>(
    model: &mut M,
    trial: M,
    fitted: &dyn FrictionModel,
    normal: f64,
) -> bool {
    let normal = if normal > 0.0 { normal } else { 1.0 };
    let same = PROBE_SPEEDS.iter().flat_map(|&v| [v, -v]).all(|v| {
        let (a, b) = (
            trial.steady_state(v, normal),
            fitted.steady_state(v, normal),
        );
        (a - b).abs() <= 1e-9 * (a.abs() + b.abs()) + f64::MIN_POSITIVE
    });
    if same {
        *model = trial;
    }
    same
}
