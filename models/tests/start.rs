//! Starts from simpler models (`Staging::start_from`): the started model slides at
//! exactly the steady-state curve of the fitted simpler one, and its presliding scales are
//! the physical ones (stiffness from the presliding displacement, critical bristle damping).

use frictionid_models::*;

const N: f64 = 14.5;
const MASS: f64 = 10.391;

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

fn fitted_stribeck() -> Stribeck {
    Stribeck {
        mu_c: 0.22,
        mu_s: 0.30,
        v_s: 0.01,
        delta: 2.0,
        viscous: 1.0,
    }
}

const SPEEDS: [f64; 9] = [1e-9, 1e-5, 0.002, 0.01, 0.02, 0.05, 0.2, 1.0, -0.013];

fn same_steady_state(a: &dyn FrictionModel, b: &dyn FrictionModel) {
    for v in SPEEDS {
        let (fa, fb) = (a.steady_state(v, N), b.steady_state(v, N));
        assert!(
            close(fa, fb, 1e-14),
            "{} vs {} at v = {v}: {fa} vs {fb}",
            a.name(),
            b.name()
        );
    }
}

#[test]
fn lugre_from_a_stribeck_fit() {
    let fitted = fitted_stribeck();
    let ctx = StartContext::new(N, MASS);
    let mut m = LuGre::default();
    assert!(m.start_from(&fitted, &ctx));
    same_steady_state(&m, &fitted);
    assert_eq!((m.mu_c, m.mu_s, m.v_s, m.sigma2), (0.22, 0.30, 0.01, 1.0));
    // sigma0 = mu_c N / 20 um = 3.19 N / 2e-5 m; sigma1 = 2 sqrt(sigma0 m).
    assert!(close(m.sigma0, 0.22 * 14.5 / 2e-5, 1e-14));
    assert!(close(m.sigma1, 2.0 * (m.sigma0 * MASS).sqrt(), 1e-14));
    // The bristle mode of the mass on the bristles is critically damped: zeta = 1.
    let zeta = m.sigma1 / (2.0 * (m.sigma0 * MASS).sqrt());
    assert!(close(zeta, 1.0, 1e-14));
    testing::assert_model(&m);
}

#[test]
fn presliding_displacement_sets_the_stiffness() {
    let ctx = StartContext {
        presliding_displacement: 1e-6,
        ..StartContext::new(N, MASS)
    };
    let mut m = LuGre::default();
    assert!(m.start_from(&fitted_stribeck(), &ctx));
    // At the steady bristle deflection of the Coulomb level the spring carries mu_c N.
    assert!(close(m.sigma0 * 1e-6, 0.22 * N, 1e-14));
    let mut d = Dahl::default();
    assert!(d.start_from(&Coulomb { mu: 0.24 }, &ctx));
    assert!(close(d.sigma0 * 1e-6, 0.24 * N, 1e-14));
    assert_eq!(d.mu_c, 0.24);
    same_steady_state(&d, &Coulomb { mu: 0.24 });
}

#[test]
fn gms_from_a_stribeck_fit_slides_at_its_curve() {
    let fitted = Stribeck {
        delta: 1.5,
        ..fitted_stribeck()
    };
    let ctx = StartContext::new(N, MASS);
    let mut m = Gms::default();
    m.elements[0].weight = 0.5; // weights summing to 7/6: rescaled to 1
    assert!(m.start_from(&fitted, &ctx));
    same_steady_state(&m, &fitted);
    let total_weight: f64 = m.elements.iter().map(|e| e.weight).sum();
    assert!(close(total_weight, 1.0, 1e-15));
    // Stiffness ratios kept (1 : 1/3 : 1/9), total from the presliding displacement.
    let k: Vec<f64> = m.elements.iter().map(|e| e.stiffness).collect();
    assert!(close(k[0] / k[1], 3.0, 1e-14) && close(k[1] / k[2], 3.0, 1e-14));
    assert!(close(k.iter().sum::<f64>(), 0.22 * N / 2e-5, 1e-14));
    testing::assert_model(&m);
}

#[test]
fn static_laws_from_simpler_static_laws() {
    let ctx = StartContext::new(N, MASS);
    let vc = ViscousCoulomb {
        mu: 0.21,
        viscous: 2.0,
    };
    let mut s = Stribeck::default();
    assert!(s.start_from(&vc, &ctx));
    same_steady_state(&s, &vc);
    assert!(s.start_from(&fitted_stribeck(), &ctx));
    assert_eq!(s, fitted_stribeck());
    // Coulomb takes the Coulomb level (the Stribeck curve far from its dip).
    let mut c = Coulomb::default();
    assert!(c.start_from(&fitted_stribeck(), &ctx));
    assert_eq!(c.mu, fitted_stribeck().mu_c);
    // Models without a start mapping, and fits without a Coulomb level, change nothing.
    let mut m = Makkar::default();
    assert!(!m.start_from(&fitted_stribeck(), &ctx));
    assert_eq!(m, Makkar::default());
    let mut l = LuGre::default();
    assert!(!l.start_from(&NoFriction {}, &ctx));
    assert_eq!(l, LuGre::default());
}

/// A fit that ended with mu_s < mu_c is available as levels; the caller decides, and
/// `mu_s_at_least_mu_c` gives the flat curve.
#[test]
fn levels_keep_what_was_fitted() {
    let odd = Stribeck {
        mu_s: 0.1,
        ..fitted_stribeck()
    };
    let levels = StribeckLevels::from_model(&odd).unwrap();
    assert_eq!(levels.mu_s, 0.1);
    assert_eq!(levels.mu_s_at_least_mu_c(), 0.22);
}

/// The rigid-contact limit of each model that declares one: the limit law, started from a
/// fitted instance of the model, has the model's steady-state curve (the curve the model
/// slides at once its bristles are rigid), the declared stiffness is a stiffness, and the
/// parameters it frees are the law's.
#[test]
fn rigid_limits_slide_at_the_models_steady_state_curve() {
    let lugre = LuGre {
        sigma0: 3e6,
        sigma1: 900.0,
        sigma2: 1.3,
        mu_c: 0.21,
        mu_s: 0.29,
        v_s: 0.007,
    };
    let dahl = Dahl {
        sigma0: 4e5,
        mu_c: 0.23,
        alpha: 1.4,
    };
    let mut gms = Gms::with_elements(2);
    gms.delta = 1.3;
    gms.viscous = 0.7;
    let ctx = StartContext::new(N, MASS);
    for model in [&lugre as &dyn InternalStates, &dahl, &gms] {
        let limit = model
            .rigid_limit()
            .expect("a bristle model has a rigid limit");
        let mut law = limit.law;
        assert_eq!(
            law.n_states(),
            0,
            "{}: the limit is a static law",
            model.name()
        );
        assert!(law.staging().is_some_and(|s| s.start_from(model, &ctx)));
        same_steady_state(law.as_ref(), model);
        let info = model.param_info();
        assert!(!limit.stiffnesses.is_empty());
        assert!(limit.stiffnesses.iter().all(|&i| info[i].unit == "N/m"));
        // The presliding-only parameters are not among the limit law's own.
        let law_names: Vec<String> = law.param_info().into_iter().map(|p| p.name).collect();
        for &i in &limit.presliding {
            assert!(!law_names.contains(&info[i].name), "{}", info[i].name);
            assert!(!limit.stiffnesses.contains(&i));
        }
        let names: Vec<String> = law.param_info().into_iter().map(|p| p.name).collect();
        assert!(limit.also_free.iter().all(|n| names.iter().any(|m| m == n)));
    }
    for model in [
        &fitted_stribeck() as &dyn FrictionModel,
        &Coulomb { mu: 0.2 },
    ] {
        let limit = model.states().and_then(|s| s.rigid_limit());
        assert!(limit.is_none(), "{}", model.name());
    }
}
