//! The direction-dependent Coulomb laws: forces by hand, the harness at asymmetric levels
//! (every check but odd symmetry, which they break on purpose), the stick band, the
//! documentation tables and the starts from the symmetric laws they hold.

use frictionid_models::testing::{self, check_odd_symmetry};
use frictionid_models::*;

fn asymmetric() -> ViscousCoulombAsymmetric {
    ViscousCoulombAsymmetric {
        mu_pos: 0.3,
        mu_neg: 0.1,
        viscous: 2.0,
    }
}

#[test]
fn forces_take_the_level_of_the_sliding_direction() {
    let c = CoulombAsymmetric {
        mu_pos: 0.3,
        mu_neg: 0.1,
    };
    assert_eq!(c.force(0.2, &[], 10.0), 3.0);
    assert_eq!(c.force(-0.2, &[], 10.0), -1.0);
    assert_eq!(c.force(0.0, &[], 10.0), 0.0);
    assert_eq!(c.force(-1e-300, &[], 10.0), -1.0);
    let v = asymmetric();
    assert_eq!(v.force(0.5, &[], 10.0), 3.0 + 1.0);
    assert_eq!(v.force(-0.5, &[], 10.0), -1.0 - 1.0);
    // The stick band [-mu_neg N, mu_pos N] = [-1, 3]: centre 1, half-width 2.
    let law = v.switching().expect("a switched law");
    assert_eq!(law.static_limit(10.0), Some(2.0));
    assert!((law.static_offset(10.0) - 1.0).abs() < 1e-15);
    assert_eq!(law.slip_force(0.0, 1.0, 10.0), 3.0);
    assert_eq!(law.slip_force(0.0, -1.0, 10.0), -1.0);
}

#[test]
fn asymmetric_levels_pass_every_check_but_odd_symmetry() {
    let laws: [Box<dyn FrictionModel>; 2] = [
        Box::new(CoulombAsymmetric {
            mu_pos: 0.3,
            mu_neg: 0.1,
        }),
        Box::new(asymmetric()),
    ];
    for m in laws {
        let m = m.as_ref();
        let outcome = testing::check_registered(m)
            .and_then(|()| testing::check_declarations(m))
            .and_then(|()| testing::check_param_vector(m))
            .and_then(|()| testing::check_bounds(m))
            .and_then(|()| testing::check_serde(m))
            .and_then(|()| testing::check_finite(m))
            .and_then(|()| testing::check_dissipative(m))
            .and_then(|()| testing::check_slip_direction(m))
            .and_then(|()| testing::check_param_gradients(m));
        assert!(outcome.is_ok(), "{outcome:?}");
        assert!(check_odd_symmetry(m).is_err(), "{} is not odd", m.name());
    }
}

/// Each starts exactly at the symmetric law it holds, and refuses a law it does not hold
/// (so `compare` never holds it to a law it cannot reach).
#[test]
fn starts_reproduce_the_laws_they_hold() {
    let ctx = StartContext::new(14.5, 10.0);
    let mut c = CoulombAsymmetric::default();
    let staging = |m: &mut dyn FrictionModel, from: &dyn FrictionModel| {
        m.staging().is_some_and(|s| s.start_from(from, &ctx))
    };
    assert!(staging(&mut c, &Coulomb { mu: 0.27 }));
    assert_eq!((c.mu_pos, c.mu_neg), (0.27, 0.27));
    let vc = ViscousCoulomb {
        mu: 0.25,
        viscous: 0.5,
    };
    assert!(!staging(&mut c, &vc), "no viscous term to hold");
    assert_eq!((c.mu_pos, c.mu_neg), (0.27, 0.27));

    let mut v = ViscousCoulombAsymmetric::default();
    assert!(staging(&mut v, &vc));
    assert_eq!((v.mu_pos, v.mu_neg, v.viscous), (0.25, 0.25, 0.5));
    assert!(staging(&mut v, &Coulomb { mu: 0.3 }));
    assert_eq!((v.mu_pos, v.mu_neg, v.viscous), (0.3, 0.3, 0.0));
    let ca = CoulombAsymmetric {
        mu_pos: 0.3,
        mu_neg: 0.1,
    };
    assert!(staging(&mut v, &ca));
    assert_eq!((v.mu_pos, v.mu_neg, v.viscous), (0.3, 0.1, 0.0));
    assert!(!staging(&mut v, &Stribeck::default()), "a Stribeck dip");
}
