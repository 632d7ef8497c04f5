//! Closed-form state Jacobians of the dynamic models (dahl, lugre, gms) against the
//! finite-difference default (`finite_difference_jacobian`), at many pseudo-random states,
//! velocities and normal forces; GMS's and LuGre's closed-form force gradients and velocity
//! derivatives of the rates against theirs.

use frictionid_models::linearisation::CBRT_EPSILON;
use frictionid_models::model::{
    finite_difference_force_gradient, finite_difference_jacobian,
    finite_difference_velocity_derivative,
};
use frictionid_models::*;

/// xorshift64*: a reproducible stream of uniform numbers in [0, 1).
struct Uniform(u64);

impl Uniform {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [lo, hi).
    fn between(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
    /// Log-uniform magnitude in [1e-6, 1] m/s with a random sign.
    fn velocity(&mut self) -> f64 {
        let v = 10f64.powf(self.between(-6.0, 0.0));
        if self.next() < 0.5 {
            -v
        } else {
            v
        }
    }
}

fn derivative(m: &dyn InternalStates, v: f64, z: &[f64], normal: f64) -> Vec<f64> {
    let mut d = vec![0.0; z.len()];
    m.state_derivative(v, z, normal, &mut d);
    d
}

/// Compares the model's Jacobian with central differences at (v, z, N). The tolerance is
/// the finite-difference error: 1e-6 relative (truncation) plus the rounding of the rates
/// divided by the step.
fn assert_jacobian_matches(m: &dyn InternalStates, v: f64, z: &[f64], normal: f64) {
    let n = z.len();
    let (mut exact, mut numeric) = (vec![f64::NAN; n * n], vec![f64::NAN; n * n]);
    Derivatives::of(m).state_jacobian(v, z, normal, &mut exact);
    finite_difference_jacobian(m, v, z, normal, &mut numeric);
    let rates = derivative(m, v, z, normal);
    let rate_scale = rates.iter().fold(v.abs(), |a, d| a.max(d.abs()));
    for j in 0..n {
        let step = f64::EPSILON.cbrt() * z[j].abs().max(1e-6);
        let rounding = 1e3 * f64::EPSILON * rate_scale / step;
        for i in 0..n {
            let (a, b) = (exact[i * n + j], numeric[i * n + j]);
            assert!(
                a.is_finite() && (a - b).abs() <= 1e-6 * a.abs().max(b.abs()) + rounding,
                "{}: d(dz_{i})/dz_{j} = {a} vs finite differences {b} at v = {v:e}, z = {z:?}, N = {normal}",
                m.name()
            );
        }
    }
}

#[test]
fn lugre_jacobian_matches_finite_differences() {
    let mut rng = Uniform(0x1234_5678_9abc_def1);
    for m in [
        LuGre::default(),
        LuGre {
            sigma0: 1e7,
            sigma1: 4000.0,
            mu_c: 0.18,
            mu_s: 0.26,
            v_s: 0.005,
            ..LuGre::default()
        },
    ] {
        for _ in 0..2000 {
            let (v, normal) = (rng.velocity(), rng.between(1.0, 30.0));
            let z = rng.between(-2.0, 2.0) * m.g(v, normal) / m.sigma0;
            assert_jacobian_matches(&m, v, &[z], normal);
        }
        // No normal load, or at rest: nothing moves.
        let mut j = [1.0];
        m.state_jacobian(0.01, &[1e-6], 0.0, &mut j);
        assert_eq!(j[0], 0.0);
        m.state_jacobian(0.0, &[1e-6], 14.5, &mut j);
        assert_eq!(j[0], 0.0);
    }
}

#[test]
fn dahl_jacobian_matches_finite_differences() {
    let mut rng = Uniform(0x0fed_cba9_8765_4321);
    for alpha in [1.0, 1.5, 2.0, 3.0, 0.7] {
        let m = Dahl {
            sigma0: 2e4,
            mu_c: 0.21,
            alpha,
        };
        for _ in 0..2000 {
            let (v, normal) = (rng.velocity(), rng.between(1.0, 30.0));
            let fc = m.mu_c * normal;
            let f = rng.between(-2.0, 2.0) * fc;
            // |r|^alpha is not smooth at r = 0 (singular slope for alpha < 1): central
            // differences are a fair oracle only where the step is small against |r| (their
            // truncation error grows as (step / r)^2).
            let r = 1.0 - f * v.signum() / fc;
            let step = f64::EPSILON.cbrt() * f.abs().max(1e-6) / fc;
            let near_kink = if alpha < 1.0 { 0.05 } else { 1e3 * step };
            if alpha != 1.0 && r.abs() < near_kink {
                continue;
            }
            assert_jacobian_matches(&m, v, &[f], normal);
        }
    }
}

/// Three GMS elements, two damped, with this sharpness and Stribeck exponent.
fn three_element_gms(sharpness: f64, delta: f64) -> Gms {
    let element = |stiffness, weight, damping| GmsElement {
        stiffness,
        weight,
        damping,
    };
    Gms {
        elements: vec![
            element(4e5, 0.5, 2.0),
            element(1e5, 0.3, 0.0),
            element(2.5e4, 0.2, 0.7),
        ],
        sharpness,
        delta,
        ..Gms::default()
    }
}

/// A random (v, z, N) for `m`: each element loaded to within 1.5 times its sliding force.
fn gms_probe(m: &Gms, rng: &mut Uniform) -> (f64, Vec<f64>, f64) {
    let (v, normal) = (rng.velocity(), rng.between(1.0, 30.0));
    let s = m.s(v, normal);
    let z = m
        .elements
        .iter()
        .map(|e| rng.between(-1.5, 1.5) * e.weight * s / e.stiffness)
        .collect();
    (v, z, normal)
}

#[test]
fn gms_jacobian_matches_finite_differences() {
    let mut rng = Uniform(0x5555_aaaa_3333_cccc);
    for sharpness in [1.0, 2.0, 3.5, 20.0] {
        let m = three_element_gms(sharpness, 2.0);
        for _ in 0..2000 {
            let (v, z, normal) = gms_probe(&m, &mut rng);
            assert_jacobian_matches(&m, v, &z, normal);
        }
    }
}

/// `a` within the central-difference error of `b`: 1e-6 relative (truncation) plus the
/// rounding of values of size `scale` over the step.
fn close_to_differences(a: f64, b: f64, scale: f64, step: f64) -> bool {
    a.is_finite()
        && (a - b).abs() <= 1e-6 * a.abs().max(b.abs()) + 1e3 * f64::EPSILON * scale / step
}

/// dF/dv, dF/dz and d(dz/dt)/dv against central differences at (v, z, N).
fn assert_gradients_match(m: &dyn InternalStates, v: f64, z: &[f64], normal: f64) {
    let n = z.len();
    let (mut dfdz, mut dfdz_fd) = (vec![f64::NAN; n], vec![f64::NAN; n]);
    let df_dv = Derivatives::of(m).force_gradient(v, z, normal, &mut dfdz);
    let df_dv_fd = finite_difference_force_gradient(m, v, z, normal, &mut dfdz_fd);
    let force = m.force(v, z, normal).abs().max(normal);
    let v_step = CBRT_EPSILON * v.abs().max(1e-6);
    let at = format!("{} at v = {v:e}, z = {z:?}, N = {normal}", m.name());
    assert!(
        close_to_differences(df_dv, df_dv_fd, force, v_step),
        "dF/dv {df_dv} vs {df_dv_fd}: {at}"
    );
    for j in 0..n {
        let step = CBRT_EPSILON * z[j].abs().max(1e-6);
        let (a, b) = (dfdz[j], dfdz_fd[j]);
        assert!(
            close_to_differences(a, b, force, step),
            "dF/dz_{j} {a} vs {b}: {at}"
        );
    }
    let (mut dv, mut dv_fd) = (vec![f64::NAN; n], vec![f64::NAN; n]);
    Derivatives::of(m).state_velocity_derivative(v, z, normal, &mut dv);
    finite_difference_velocity_derivative(m, v, z, normal, &mut dv_fd);
    let rates = derivative(m, v, z, normal);
    let rate_scale = rates.iter().fold(v.abs(), |a, d| a.max(d.abs()));
    for i in 0..n {
        let (a, b) = (dv[i], dv_fd[i]);
        assert!(
            close_to_differences(a, b, rate_scale, v_step),
            "d(dz_{i})/dv {a} vs {b}: {at}"
        );
    }
}

/// GMS's closed-form gradients (damped and undamped elements, every sharpness, Stribeck
/// exponents below, at and above 2) and LuGre's agree with finite differences.
#[test]
fn closed_form_force_gradients_match_finite_differences() {
    let mut rng = Uniform(0x1234_5678_9abc_def0);
    for (sharpness, delta) in [(1.0, 2.0), (2.0, 0.7), (3.5, 2.0), (20.0, 3.0)] {
        let m = three_element_gms(sharpness, delta);
        for _ in 0..2000 {
            let (v, z, normal) = gms_probe(&m, &mut rng);
            assert_gradients_match(&m, v, &z, normal);
        }
    }
    let lugre = LuGre::default();
    for _ in 0..2000 {
        let (v, normal) = (rng.velocity(), rng.between(1.0, 30.0));
        let z = [rng.between(-1.5, 1.5) * lugre.g(v, normal) / lugre.sigma0];
        assert_gradients_match(&lugre, v, &z, normal);
    }
}

/// The default Jacobian is the finite-difference one; the closed forms agree with it at the
/// harness's probe points too, including the default models.
#[test]
fn every_registered_dynamic_model_agrees_at_its_defaults() {
    for name in names() {
        let model = default_model(&name).unwrap();
        let Some(m) = model.states() else {
            continue;
        };
        let n = m.n_states();
        for v in [1e-4, -0.003, 0.05, -0.4] {
            let z: Vec<f64> = (0..n).map(|i| 1e-6 * (1.0 + i as f64)).collect();
            assert_jacobian_matches(m, v, &z, 14.5);
        }
    }
}
