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
//! Exact steps (`Propagator`): at constant v and N, r = 1 - F sgn(v) / (mu_c N) obeys
//! dr/dkappa = -|r|^alpha sgn(r) in the dimensionless travel kappa = sigma0 |v| t / (mu_c N).
//! For alpha = 1 the force relaxes exponentially in the distance travelled, r = r0 exp(-kappa);
//! for any other alpha |r|^(1 - alpha) moves linearly, |r|^(1 - alpha) = |r0|^(1 - alpha) -
//! (1 - alpha) kappa, so that with alpha > 1 r decays as a power of the travel and with
//! alpha < 1 it reaches 0 (the force at its Coulomb level) after the finite travel
//! |r0|^(1 - alpha) / (1 - alpha) and stays there. The sensitivities to sigma0, mu_c and alpha
//! are the derivatives of that step.
//!
//! Reference: P. R. Dahl, "A solid friction model", Technical Report TOR-0158(3107-18)-1,
//! The Aerospace Corporation, 1968.

use crate::builtin::coulomb::Coulomb;
use crate::hints::GuessHint;
use crate::interval::Interval;
use crate::model::{
    sgn, FrictionModel, InternalStates, Jacobians, ParamGradients, Propagator, RigidLimit, Staging,
};
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

    /// The exact step of r = 1 - F sgn(v) / (mu_c N) over the dimensionless travel `kappa`
    /// (see the module docs).
    fn relax(&self, r0: f64, kappa: f64) -> Relaxation {
        let delta = 1.0 - self.alpha;
        let log_ratio = if r0 == 0.0 {
            0.0
        } else if delta == 0.0 {
            -kappa
        } else {
            // |r1|^delta = |r0|^delta (1 - w): w >= 1 means r reached 0 within the step.
            let w = delta * kappa * (-delta * r0.abs().ln()).exp();
            if w >= 1.0 {
                f64::NEG_INFINITY
            } else {
                (-w).ln_1p() / delta
            }
        };
        let change = r0 * log_ratio.exp_m1();
        Relaxation {
            r0,
            r1: r0 + change,
            change,
            log_ratio,
        }
    }

    /// The derivatives of a step `step` over the travel `kappa`: (dr1/dr0, dr1/dkappa,
    /// dr1/dalpha).
    fn relax_derivatives(&self, step: &Relaxation, kappa: f64) -> (f64, f64, f64) {
        let (alpha, r0, r1) = (self.alpha, step.r0, step.r1);
        if r1 == 0.0 {
            // r stays at 0 from r0 = 0, or reached it within the step (alpha < 1).
            let gain = if r0 != 0.0 || (alpha < 1.0 && kappa > 0.0) {
                0.0
            } else if alpha == 1.0 {
                (-kappa).exp()
            } else {
                1.0
            };
            return (gain, 0.0, 0.0);
        }
        let gain = (alpha * step.log_ratio).exp();
        let l0 = r0.abs().ln();
        if alpha == 1.0 {
            return (gain, -r1, -r1 * (kappa * l0 - 0.5 * kappa * kappa));
        }
        let delta = 1.0 - alpha;
        // |r1|^(-delta), with ln|r1| = l0 + log_ratio.
        let shrink = (-delta * (l0 + step.log_ratio)).exp();
        let d_log_d_delta = if delta.abs() * (l0.abs() + kappa) < 1e-5 {
            // The series about alpha = 1, where the closed form below cancels.
            kappa * l0 - 0.5 * kappa * kappa
                + 2.0 * delta * (kappa * kappa * l0 - 0.5 * kappa * l0 * l0 - kappa.powi(3) / 3.0)
        } else {
            (-step.log_ratio - kappa * shrink * (1.0 - delta * l0)) / delta
        };
        (gain, -r1 * shrink, -r1 * d_log_d_delta)
    }

    /// The step's frame: the Coulomb level mu_c N, the direction and the travel kappa, or
    /// `None` where the force does not move (no normal load, no motion).
    fn frame(&self, interval: Interval) -> Option<(f64, f64, f64)> {
        let fc = self.mu_c * interval.normal;
        let moves = fc > 0.0 && interval.v != 0.0 && interval.dt > 0.0;
        moves.then(|| (fc, sgn(interval.v), self.sigma0 * interval.travel() / fc))
    }
}

/// One exact step of Dahl's r (see [`Dahl::relax`]).
struct Relaxation {
    r0: f64,
    r1: f64,
    /// r1 - r0, without cancellation.
    change: f64,
    /// ln(|r1| / |r0|): -infinity when r reached 0, 0 when it stays there.
    log_ratio: f64,
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
    crate::law_groups!(states, staging, param_gradients);
}

impl ParamGradients for Dahl {
    /// The force is the state: it depends on no parameter at fixed states.
    fn force_param_gradient(&self, _v: f64, _z: &[f64], _normal: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|o| *o = 0.0);
    }

    /// F' = sigma0 v |r|^alpha sgn(r), r = 1 - F sgn(v) / (mu_c N): d/dsigma0 = F' / sigma0,
    /// d/dmu_c = sigma0 v alpha |r|^(alpha - 1) (1 - r) / mu_c, d/dalpha = F' ln|r|.
    fn state_param_gradient(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]) -> bool {
        let f = z.first().copied().unwrap_or(0.0);
        let fc = self.mu_c * normal;
        let gradient = if fc > 0.0 {
            let r = 1.0 - f * sgn(v) / fc;
            let rate = self.sigma0 * v * self.shape(r.abs()) * sgn(r);
            let slope = if self.alpha == 1.0 {
                self.sigma0 * v
            } else if r == 0.0 {
                0.0
            } else {
                self.sigma0 * v * self.alpha * self.shape(r.abs()) / r.abs()
            };
            let log = if r == 0.0 { 0.0 } else { rate * r.abs().ln() };
            [rate / self.sigma0, slope * (1.0 - r) / self.mu_c, log]
        } else {
            [0.0; 3]
        };
        for (o, d) in out.iter_mut().zip(gradient) {
            *o = d;
        }
        true
    }
}

impl Propagator for Dahl {
    fn propagate(&self, interval: Interval, z: &mut [f64]) {
        let (Some(f), Some((fc, u, kappa))) = (z.first_mut(), self.frame(interval)) else {
            return;
        };
        let step = self.relax(1.0 - *f * u / fc, kappa);
        *f -= u * fc * step.change;
    }

    /// The parameters in order sigma0, mu_c, alpha: kappa depends on sigma0 and mu_c, r0 and
    /// the force on mu_c through the Coulomb level, the step on alpha.
    fn propagate_with_sensitivities(&self, interval: Interval, z: &mut [f64], sens: &mut [f64]) {
        let (Some(f), Some((fc, u, kappa))) = (z.first_mut(), self.frame(interval)) else {
            return;
        };
        let step = self.relax(1.0 - *f * u / fc, kappa);
        let (gain, d_kappa, d_alpha) = self.relax_derivatives(&step, kappa);
        let kappa_slopes = [kappa / self.sigma0, -kappa / self.mu_c, 0.0];
        for (j, s) in sens.iter_mut().enumerate().take(3) {
            let d_fc = if j == 1 { interval.normal } else { 0.0 };
            let d_r0 = (-u * *s + (1.0 - step.r0) * d_fc) / fc;
            let d_shape = if j == 2 { d_alpha } else { 0.0 };
            let d_r1 = gain * d_r0 + d_kappa * kappa_slopes[j] + d_shape;
            *s = u * (d_fc * (1.0 - step.r1) - fc * d_r1);
        }
        *f -= u * fc * step.change;
    }
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
    crate::law_groups!(jacobians, propagator);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::check_step;

    /// With alpha < 1 the force reaches its Coulomb level after the finite travel
    /// kappa* = |r0|^(1 - alpha) / (1 - alpha). Short of it the step is the power law
    /// r = (|r0|^(1 - alpha) - (1 - alpha) kappa)^(1 / (1 - alpha)) and passes the harness's
    /// check (reference integration, sensitivities); beyond it the force sits at mu_c N sgn(v)
    /// exactly, and only mu_c moves it.
    #[test]
    fn below_alpha_one_the_force_reaches_its_level_in_a_finite_travel() {
        let dahl = Dahl {
            sigma0: 1e5,
            mu_c: 0.2,
            alpha: 0.6,
        };
        let (normal, v) = (14.5, 0.05);
        let fc = dahl.mu_c * normal;
        // From rest (r0 = 1): kappa* = 2.5, reached after 2.5 fc / sigma0 of travel.
        let reach = 2.5 * fc / dahl.sigma0;
        for share in [0.01, 0.3, 0.9, 0.999] {
            let interval = Interval {
                v,
                normal,
                dt: share * reach / v,
            };
            let mut z = [0.0];
            dahl.propagate(interval, &mut z);
            let kappa = 2.5 * share;
            let r1 = (1.0 - 0.4 * kappa).powf(2.5);
            assert!(
                (z[0] - fc * (1.0 - r1)).abs() <= 1e-12 * fc,
                "{share}: {z:?}"
            );
            assert_eq!(check_step(&dahl, interval, &[0.0]), Ok(()));
            assert_eq!(check_step(&dahl, interval, &[-0.5 * fc]), Ok(()));
        }
        for share in [1.0 + 1e-9, 1.5, 40.0] {
            let interval = Interval {
                v: -v,
                normal,
                dt: share * reach / v,
            };
            let (mut z, mut sens) = ([0.0], [0.7, -0.3, 2.0]);
            dahl.propagate_with_sensitivities(interval, &mut z, &mut sens);
            assert_eq!(z, [-fc], "{share}");
            assert_eq!(sens, [0.0, -normal, 0.0], "{share}");
        }
    }

    /// Without normal load or motion the force stays, and so do its sensitivities.
    #[test]
    fn without_load_or_motion_nothing_moves() {
        let dahl = Dahl::default();
        for interval in [
            Interval {
                v: 0.1,
                normal: 0.0,
                dt: 1e-3,
            },
            Interval {
                v: 0.0,
                normal: 14.5,
                dt: 1e-3,
            },
        ] {
            let (mut z, mut sens) = ([1.3], [0.1, 0.2, 0.3]);
            dahl.propagate_with_sensitivities(interval, &mut z, &mut sens);
            assert_eq!((z, sens), ([1.3], [0.1, 0.2, 0.3]));
        }
    }
}
