//! The LuGre model.
//!
//! dz/dt = v - sigma0 |v| z / g(v),  g(v) = N (mu_c + (mu_s - mu_c) exp(-(v/v_s)^2)),
//! F = sigma0 z + sigma1 dz/dt + sigma2 v
//!
//! | parameter | unit | default | bounds | fit | meaning |
//! |---|---|---|---|---|---|
//! | `sigma0` | N/m | 1e5 | (0, 1e12] | free | bristle stiffness |
//! | `sigma1` | N s/m | 300 | [0, inf) | free | bristle damping |
//! | `sigma2` | N s/m | 0.5 | [0, inf) | free | viscous friction coefficient |
//! | `mu_c` | 1 | 0.2 | (0, 10] | free | Coulomb friction coefficient |
//! | `mu_s` | 1 | 0.3 | (0, 10] | free | static friction coefficient |
//! | `v_s` | m/s | 0.01 | (0, 100] | free | Stribeck velocity |
//!
//! Stored energy: sigma0 z^2 / 2. mu_s < mu_c is admissible but reported as a warning.
//!
//! Exact steps (`Propagator`): at constant v and N the bristle equation is linear in z,
//! z' = v - lambda z with lambda = sigma0 |v| / g(v), so z relaxes exponentially towards
//! z_ss = g(v) sgn(v) / sigma0 over the distance travelled: z(t) = z_ss + (z0 - z_ss)
//! exp(-sigma0 |v| t / g(v)). Without normal load (g = 0) or motion the bristles stay.
//!
//! Reference: C. Canudas de Wit, H. Olsson, K. J. Åström, P. Lischinsky, "A new model for
//! control of systems with friction", IEEE Trans. Automatic Control 40(3), 419-425, 1995.

use crate::builtin::stribeck::{mu_s_warning, Stribeck};
use crate::error::ModelError;
use crate::hints::GuessHint;
use crate::interval::Interval;
use crate::linearisation::Linearisation;
use crate::model::{
    decay, sgn, FrictionModel, InternalStates, Jacobians, ParamGradients, Propagator, RigidLimit,
    Staging,
};
use crate::start::{StartContext, StribeckLevels, TYPICAL_PRESLIDING_DISPLACEMENT};

crate::declare_params! {
    /// The LuGre bristle model with the Stribeck curve of Canudas de Wit et al. (1995).
    pub struct LuGre {
        sigma0: positive("N/m", 1e5, 1e12, "bristle stiffness"),
        sigma1: non_negative("N s/m", 300.0, "bristle damping"),
        sigma2: non_negative("N s/m", 0.5, "viscous friction coefficient"),
        mu_c: positive("1", 0.2, 10.0, "Coulomb friction coefficient"),
        mu_s: positive("1", 0.3, 10.0, "static friction coefficient"),
        v_s: positive("m/s", 0.01, 100.0, "Stribeck velocity"),
    }
}

impl LuGre {
    /// The Stribeck level g(v) \[N\].
    pub fn g(&self, v: f64, normal: f64) -> f64 {
        let r = v / self.v_s;
        normal * (self.mu_c + (self.mu_s - self.mu_c) * decay(r * r))
    }

    /// The partial derivatives (d/dz, d/dv) of dz/dt, from one Stribeck exponential; (0, 0)
    /// without normal load. d/dz does not depend on z.
    fn z_dot_partials(&self, v: f64, z: f64, normal: f64) -> (f64, f64) {
        let r = v / self.v_s;
        let stribeck = decay(r * r);
        let g = normal * (self.mu_c + (self.mu_s - self.mu_c) * stribeck);
        if g <= 0.0 {
            return (0.0, 0.0);
        }
        let dg = normal * (self.mu_s - self.mu_c) * stribeck * (-2.0 * r / self.v_s);
        let d_ratio = (sgn(v) * g - v.abs() * dg) / (g * g);
        (-self.sigma0 * v.abs() / g, 1.0 - self.sigma0 * z * d_ratio)
    }

    /// dF/dz into `dfdz` and dF/dv returned, from the partials (d/dz, d/dv) of dz/dt:
    /// dF/dz = sigma0 + sigma1 d(dz/dt)/dz, dF/dv = sigma1 d(dz/dt)/dv + sigma2.
    fn force_partials(&self, (dz_dz, dz_dv): (f64, f64), dfdz: &mut [f64]) -> f64 {
        if let Some(d) = dfdz.first_mut() {
            *d = self.sigma0 + self.sigma1 * dz_dz;
        }
        self.sigma1 * dz_dv + self.sigma2
    }

    /// F = sigma0 z + sigma1 dz/dt + sigma2 v.
    fn force_at(&self, v: f64, z: f64, z_dot: f64) -> f64 {
        self.sigma0 * z + self.sigma1 * z_dot + self.sigma2 * v
    }

    /// The Stribeck level g(v) and its derivatives with respect to mu_c, mu_s and v_s.
    fn g_and_slopes(&self, v: f64, normal: f64) -> (f64, [f64; 3]) {
        let r = v / self.v_s;
        let e = decay(r * r);
        let g = normal * (self.mu_c + (self.mu_s - self.mu_c) * e);
        let d_vs = normal * (self.mu_s - self.mu_c) * e * 2.0 * r * r / self.v_s;
        (g, [normal * (1.0 - e), normal * e, d_vs])
    }

    /// The step's relaxation: (z_ss, exp(-x), -expm1(-x), x) with x = sigma0 |v| dt / g, or
    /// `None` where the bristles do not move (no load, no motion).
    fn relaxation(&self, interval: Interval, g: f64) -> Option<(f64, f64, f64, f64)> {
        if g.is_nan() || g <= 0.0 || interval.v == 0.0 || interval.dt <= 0.0 {
            return None;
        }
        let x = self.sigma0 * interval.travel() / g;
        let settled = -(-x).exp_m1();
        Some((sgn(interval.v) * g / self.sigma0, 1.0 - settled, settled, x))
    }

    fn z_dot(&self, v: f64, z: f64, normal: f64) -> f64 {
        let g = self.g(v, normal);
        if g > 0.0 {
            v - self.sigma0 * v.abs() * z / g
        } else {
            // No normal load: the bristles carry no force.
            0.0
        }
    }
}

#[typetag::serde(name = "lugre")]
impl FrictionModel for LuGre {
    crate::declared_param_methods!(
        name: "lugre",
        equation: "dz/dt = v - sigma0 |v| z / g(v), g(v) = N (mu_c + (mu_s - mu_c) exp(-(v/v_s)^2)), F = sigma0 z + sigma1 dz/dt + sigma2 v",
    );
    fn force(&self, v: f64, z: &[f64], normal: f64) -> f64 {
        let z0 = z.first().copied().unwrap_or(0.0);
        self.force_at(v, z0, self.z_dot(v, z0, normal))
    }
    fn steady_state(&self, v: f64, normal: f64) -> f64 {
        self.g(v, normal) * sgn(v) + self.sigma2 * v
    }
    crate::law_groups!(states, staging, param_gradients);
    fn validate(&self) -> Result<Vec<String>, ModelError> {
        Ok(mu_s_warning(self.name(), self.mu_s, self.mu_c))
    }
}

impl ParamGradients for LuGre {
    /// F = sigma0 z + sigma1 z' + sigma2 v with z' = v - sigma0 |v| z / g(v): sigma0 enters
    /// the spring and the rate, the levels and v_s the rate through g.
    fn force_param_gradient(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]) {
        let z0 = z.first().copied().unwrap_or(0.0);
        let (g, slopes) = self.g_and_slopes(v, normal);
        let (z_dot, d_sigma0, level) = if g > 0.0 {
            let relax = v.abs() * z0 / g;
            (
                v - self.sigma0 * relax,
                -relax,
                self.sigma1 * self.sigma0 * relax / g,
            )
        } else {
            (0.0, 0.0, 0.0)
        };
        let gradient = [
            z0 + self.sigma1 * d_sigma0,
            z_dot,
            v,
            level * slopes[0],
            level * slopes[1],
            level * slopes[2],
        ];
        for (o, d) in out.iter_mut().zip(gradient) {
            *o = d;
        }
    }

    /// z' = v - sigma0 |v| z / g(v): d/dsigma0 = -|v| z / g, d/dp = sigma0 |v| z (dg/dp) / g^2
    /// for the levels and v_s; sigma1 and sigma2 do not enter.
    fn state_param_gradient(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]) -> bool {
        let z0 = z.first().copied().unwrap_or(0.0);
        let (g, slopes) = self.g_and_slopes(v, normal);
        let relax = if g > 0.0 { v.abs() * z0 / g } else { 0.0 };
        let level = if g > 0.0 {
            self.sigma0 * relax / g
        } else {
            0.0
        };
        let gradient = [
            -relax,
            0.0,
            0.0,
            level * slopes[0],
            level * slopes[1],
            level * slopes[2],
        ];
        for (o, d) in out.iter_mut().zip(gradient) {
            *o = d;
        }
        true
    }
}

impl Propagator for LuGre {
    fn propagate(&self, interval: Interval, z: &mut [f64]) {
        let g = self.g(interval.v, interval.normal);
        let (Some(z0), Some((z_ss, _, settled, _))) = (z.first_mut(), self.relaxation(interval, g))
        else {
            return;
        };
        *z0 += (z_ss - *z0) * settled;
    }

    /// With Q = (1 - E) z_ss + (z0 - z_ss) E x (E = exp(-x)): dz1/dsigma0 = E S0 - Q / sigma0
    /// and dz1/dp = E S0 + Q (dg/dp) / g for the levels and v_s (z_ss and x hold sigma0 / g).
    fn propagate_with_sensitivities(&self, interval: Interval, z: &mut [f64], sens: &mut [f64]) {
        let (g, slopes) = self.g_and_slopes(interval.v, interval.normal);
        let (Some(z0), Some((z_ss, kept, settled, x))) =
            (z.first_mut(), self.relaxation(interval, g))
        else {
            return;
        };
        let q = settled * z_ss + (*z0 - z_ss) * kept * x;
        let level = q / g;
        let direct = [
            -q / self.sigma0,
            0.0,
            0.0,
            level * slopes[0],
            level * slopes[1],
            level * slopes[2],
        ];
        for (s, d) in sens.iter_mut().zip(direct) {
            *s = kept * *s + d;
        }
        *z0 += (z_ss - *z0) * settled;
    }
}

impl InternalStates for LuGre {
    fn n_states(&self) -> usize {
        1
    }
    fn state_derivative(&self, v: f64, z: &[f64], normal: f64, dz: &mut [f64]) {
        if let (Some(&z0), Some(d)) = (z.first(), dz.first_mut()) {
            *d = self.z_dot(v, z0, normal);
        }
    }
    /// sigma1 and sigma2 (the bristles' damping and the viscous term).
    fn force_only_params(&self) -> Vec<usize> {
        vec![1, 2]
    }
    /// dz/dt once for both (it holds the Stribeck level's exponential).
    fn state_derivative_and_force(&self, v: f64, z: &[f64], normal: f64, dz: &mut [f64]) -> f64 {
        let z0 = z.first().copied().unwrap_or(0.0);
        let z_dot = self.z_dot(v, z0, normal);
        if let Some(d) = dz.first_mut() {
            *d = z_dot;
        }
        self.force_at(v, z0, z_dot)
    }
    fn stored_energy(&self, z: &[f64], _normal: f64) -> f64 {
        let z0 = z.first().copied().unwrap_or(0.0);
        0.5 * self.sigma0 * z0 * z0
    }
    /// Rigid, critically damped bristles: the force follows the steady-state curve, a
    /// Stribeck law with delta = 2 and sigma2 as its viscous term.
    fn rigid_limit(&self) -> Option<RigidLimit> {
        Some(RigidLimit {
            law: Box::new(Stribeck::default()),
            stiffnesses: vec![0],
            presliding: Vec::new(),
            also_free: Vec::new(),
        })
    }
    crate::law_groups!(jacobians, propagator);
}

impl Jacobians for LuGre {
    /// d(dz/dt)/dz = -sigma0 |v| / g(v) (0 without normal load).
    fn state_jacobian(&self, v: f64, _z: &[f64], normal: f64, jac: &mut [f64]) {
        if let Some(j) = jac.first_mut() {
            *j = self.z_dot_partials(v, 0.0, normal).0;
        }
    }
    /// dF/dz = sigma0 + sigma1 d(dz/dt)/dz, dF/dv = sigma1 d(dz/dt)/dv + sigma2.
    fn force_gradient(&self, v: f64, z: &[f64], normal: f64, dfdz: &mut [f64]) -> f64 {
        let z0 = z.first().copied().unwrap_or(0.0);
        self.force_partials(self.z_dot_partials(v, z0, normal), dfdz)
    }
    /// d(dz/dt)/dv = 1 - sigma0 z (sgn(v) g - |v| g') / g^2 (0 without normal load).
    fn state_velocity_derivative(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]) {
        if let (Some(&z0), Some(o)) = (z.first(), out.first_mut()) {
            *o = self.z_dot_partials(v, z0, normal).1;
        }
    }
    /// The Stribeck exponential once for the three derivatives (the three calls take it three
    /// times).
    fn linearisation(&self, v: f64, z: &[f64], normal: f64, out: Linearisation<'_>) -> f64 {
        let z0 = z.first().copied().unwrap_or(0.0);
        let partials = self.z_dot_partials(v, z0, normal);
        if let Some(j) = out.dz_dz.first_mut() {
            *j = partials.0;
        }
        if let Some(o) = out.dz_dv.first_mut() {
            *o = partials.1;
        }
        self.force_partials(partials, out.df_dz)
    }
}

impl Staging for LuGre {
    fn apply_guess(&mut self, hint: &GuessHint) {
        let levels = StribeckLevels::guess(hint);
        self.mu_c = levels.mu_c;
        self.mu_s = levels.mu_s;
        self.sigma2 = levels.viscous;
        // Stribeck velocities are typically a few percent of the sliding speeds of a free
        // vibration; bristle damping a fraction of the critical damping of the bristle mode.
        self.v_s = 0.05 * hint.typical_velocity.max(1e-6);
        self.sigma0 = (hint.mu * hint.normal_force / TYPICAL_PRESLIDING_DISPLACEMENT).max(1.0);
        self.sigma1 = 0.25 * (self.sigma0 * hint.mass).sqrt();
    }
    /// The Stribeck levels (sliding at the fitted curve, which LuGre's Gaussian dip
    /// reproduces exactly for delta = 2), the bristle stiffness from the presliding
    /// displacement at the Coulomb level, the bristle damping at its critical value.
    fn start_from(&mut self, fitted: &dyn FrictionModel, ctx: &StartContext) -> bool {
        let Some(levels) = StribeckLevels::from_model(fitted) else {
            return false;
        };
        self.mu_c = levels.mu_c;
        self.mu_s = levels.mu_s;
        self.v_s = levels.v_s.unwrap_or(self.v_s);
        self.sigma2 = levels.viscous;
        self.sigma0 = ctx.stiffness_for(levels.mu_c * ctx.normal_force);
        self.sigma1 = ctx.critical_damping(self.sigma0);
        true
    }
}
