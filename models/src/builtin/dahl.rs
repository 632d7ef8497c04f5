//! The Dahl model.
//!
//! dF/dt = sigma0 v |1 - F sgn(v) / (mu_c N)|^alpha sgn(1 - F sgn(v) / (mu_c N)); the friction
//! force is the internal state F.
//!
//! | parameter | unit | default | bounds | fit | meaning |
//! |---|---|---|---|---|---|
//! | `sigma0` | N/m | 1e5 | (0, 1e12] | free | rest stiffness of the contact |
//! | `mu_c` | 1 | 0.2 | (0, 10] | free | Coulomb friction coefficient |
//! | `alpha` | 1 | 1 | (0, 10] | free | shape exponent of the hysteresis |
//!
//! The rest stiffness sigma0 is the slope of F against the displacement at F = 0.
//!
//! The integrators hold F to sigma0 times their absolute tolerance (in metres): an error in the
//! force weighs as the deflection of the contact spring that makes it
//! (`state_tolerance_scales`).
//!
//! Stored energy: F^2 / (2 sigma0) (exact for alpha = 1: the model then dissipates
//! F^2 |v| / (mu_c N) >= 0).
//!
//! Reference: P. R. Dahl, "A solid friction model", Technical Report TOR-0158(3107-18)-1,
//! The Aerospace Corporation, 1968.

use crate::builtin::coulomb::Coulomb;
use crate::hints::GuessHint;
use crate::model::{sgn, FrictionModel, InternalStates, Jacobians, RigidLimit, Staging};
use crate::start::{StartContext, StribeckLevels, TYPICAL_PRESLIDING_DISPLACEMENT};

crate::declare_params! {
    /// Dahl's dynamic friction model with the friction force as internal state.
    pub struct Dahl {
        sigma0: positive("N/m", 1e5, 1e12, "rest stiffness of the contact"),
        mu_c: positive("1", 0.2, 10.0, "Coulomb friction coefficient"),
        alpha: positive("1", 1.0, 10.0, "shape exponent of the hysteresis"),
    }
}

impl Dahl {
    /// |r|^alpha for |r| = `a` >= 0: exactly `a` for the linear hysteresis (alpha = 1, the
    /// default), else exp(alpha ln a), which costs about half of libm's correctly rounded
    /// `powf` (it was a fifth of the five-model FMM `compare`) and differs from it by a few
    /// units in the last place.
    fn shape(&self, a: f64) -> f64 {
        if self.alpha == 1.0 {
            a
        } else if a == 0.0 {
            0.0
        } else {
            (self.alpha * a.ln()).exp()
        }
    }
}

#[typetag::serde(name = "dahl")]
impl FrictionModel for Dahl {
    crate::declared_param_methods!(
        name: "dahl",
        equation: "dF/dt = sigma0 v |1 - F sgn(v)/(mu_c N)|^alpha sgn(1 - F sgn(v)/(mu_c N)), friction = F",
    );
    fn force(&self, _v: f64, z: &[f64], _normal: f64) -> f64 {
        z.first().copied().unwrap_or(0.0)
    }
    fn steady_state(&self, v: f64, normal: f64) -> f64 {
        self.mu_c * normal * sgn(v)
    }
    crate::law_groups!(states, staging);
}

impl InternalStates for Dahl {
    fn state_derivative(&self, v: f64, z: &[f64], normal: f64, dz: &mut [f64]) {
        let (Some(&f), Some(d)) = (z.first(), dz.first_mut()) else {
            return;
        };
        let fc = self.mu_c * normal;
        *d = if fc > 0.0 {
            let r = 1.0 - f * sgn(v) / fc;
            self.sigma0 * v * self.shape(r.abs()) * sgn(r)
        } else {
            // No normal load: no friction can build up.
            0.0
        };
    }
    fn n_states(&self) -> usize {
        1
    }
    /// The state is the force of the contact spring, sigma0 N per metre of deflection.
    fn state_tolerance_scales(&self) -> Vec<f64> {
        vec![self.sigma0]
    }
    /// Steady sliding: the force at its Coulomb level, F = mu_c N sgn(v) (r = 0). For alpha < 1
    /// the rate's slope is unbounded there and the force reaches the level in finite time: an
    /// explicit method chatters about it (Dopri5 took 26 000 steps for the FMM release at
    /// sigma0 1e5, alpha 0.8, against Rodas4's 1 000), so the stiffness estimate looks here.
    fn sliding_states(&self, v: f64, normal: f64, out: &mut [f64]) -> bool {
        let Some(f) = out.first_mut() else {
            return false;
        };
        *f = self.mu_c * normal * sgn(v);
        true
    }
    fn stored_energy(&self, z: &[f64], _normal: f64) -> f64 {
        let f = z.first().copied().unwrap_or(0.0);
        f * f / (2.0 * self.sigma0)
    }
    /// Rigid bristles: the force jumps between +-mu_c N at each reversal, Coulomb's law.
    fn rigid_limit(&self) -> Option<RigidLimit> {
        Some(RigidLimit {
            law: Box::new(Coulomb::default()),
            stiffnesses: vec![0],
            presliding: vec![2],
            also_free: Vec::new(),
        })
    }
    crate::law_groups!(jacobians);
}

impl Jacobians for Dahl {
    /// d(dF/dt)/dF = -sigma0 |v| alpha |r|^(alpha - 1) / (mu_c N), r = 1 - F sgn(v) / (mu_c N);
    /// 0 without normal load. At r = 0 with alpha < 1 the derivative is unbounded: there
    /// the finite-difference default gives a finite slope instead.
    fn state_jacobian(&self, v: f64, z: &[f64], normal: f64, jac: &mut [f64]) {
        let (Some(&f), Some(j)) = (z.first(), jac.first_mut()) else {
            return;
        };
        let fc = self.mu_c * normal;
        if fc <= 0.0 || v == 0.0 {
            *j = 0.0;
            return;
        }
        let r = 1.0 - f * sgn(v) / fc;
        if r == 0.0 && self.alpha < 1.0 {
            crate::model::finite_difference_jacobian(self, v, z, normal, jac);
            return;
        }
        let slope = if self.alpha == 1.0 {
            1.0
        } else {
            self.alpha * r.abs().powf(self.alpha - 1.0)
        };
        *j = -self.sigma0 * v.abs() * slope / fc;
    }
    /// The force is the state: dF/dz = 1, dF/dv = 0.
    fn force_gradient(&self, _v: f64, _z: &[f64], _normal: f64, dfdz: &mut [f64]) -> f64 {
        if let Some(d) = dfdz.first_mut() {
            *d = 1.0;
        }
        0.0
    }
    /// d(dF/dt)/dv = sigma0 |r|^alpha sgn(r) within a sliding direction (r depends on v only
    /// through sgn(v)); 0 without normal load.
    fn state_velocity_derivative(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]) {
        let (Some(&f), Some(o)) = (z.first(), out.first_mut()) else {
            return;
        };
        let fc = self.mu_c * normal;
        *o = if fc > 0.0 {
            let r = 1.0 - f * sgn(v) / fc;
            self.sigma0 * self.shape(r.abs()) * sgn(r)
        } else {
            0.0
        };
    }
}

impl Staging for Dahl {
    fn apply_guess(&mut self, hint: &GuessHint) {
        self.mu_c = hint.mu;
        // Presliding displacements of dry contacts are typically a few tens of micrometres.
        self.sigma0 = (hint.mu * hint.normal_force / TYPICAL_PRESLIDING_DISPLACEMENT).max(1.0);
    }
    /// The Coulomb level of the fitted model and the rest stiffness that reaches it at the
    /// presliding displacement.
    fn start_from(&mut self, fitted: &dyn FrictionModel, ctx: &StartContext) -> bool {
        let Some(levels) = StribeckLevels::from_model(fitted) else {
            return false;
        };
        self.mu_c = levels.mu_c;
        self.sigma0 = ctx.stiffness_for(levels.mu_c * ctx.normal_force);
        true
    }
}
