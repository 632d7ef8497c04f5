//! The model test harness (`frictionid_models::testing`) over every built-in model, at its
//! defaults and at other admissible parameter sets, and the documentation tables against the
//! parameter declarations.

use frictionid_models::testing::{assert_model, check_model, doc_table_mismatch, Check};
use frictionid_models::*;

#[test]
fn every_registered_model_passes_the_harness() {
    for name in names() {
        let m = default_model(&name).unwrap();
        assert_model(m.as_ref());
    }
}

#[test]
fn other_parameter_sets_pass_the_harness() {
    let models: Vec<Box<dyn FrictionModel>> = vec![
        Box::new(Coulomb { mu: 0.0 }),
        Box::new(Stribeck {
            mu_s: 0.1,
            delta: 1.0,
            ..Stribeck::default()
        }),
        Box::new(Dahl {
            alpha: 2.5,
            ..Dahl::default()
        }),
        Box::new(Gms {
            sharpness: 1.0,
            elements: vec![
                GmsElement {
                    stiffness: 2e5,
                    weight: 0.7,
                    damping: 3.0,
                },
                GmsElement {
                    stiffness: 4e4,
                    weight: 0.3,
                    damping: 0.0,
                },
            ],
            ..Gms::default()
        }),
        Box::new(LuGre {
            sigma1: 0.0,
            ..LuGre::default()
        }),
        Box::new(Gms {
            elements: vec![
                GmsElement {
                    stiffness: 3e5,
                    weight: 0.6,
                    damping: 5.0,
                },
                GmsElement {
                    stiffness: 2e4,
                    weight: 0.4,
                    damping: 0.0,
                },
            ],
            sharpness: 3.0,
            ..Gms::default()
        }),
        Box::new(Gms::with_elements(7)),
        Box::new(
            Expression::new("mu * N * sign(v) + b * v^3", &[("mu", 0.2), ("b", 2.0)]).unwrap(),
        ),
        Box::new(
            Expression::new(
                "N * (mu_c + (mu_s - mu_c) * exp(-(v / v_s)^2)) * sign(v) + b * v",
                &[("mu_c", 0.2), ("mu_s", 0.3), ("v_s", 0.01), ("b", 0.5)],
            )
            .unwrap(),
        ),
    ];
    for m in models {
        assert_model(m.as_ref());
    }
}

#[test]
fn the_harness_finds_broken_laws() {
    // A law that pushes (F v < 0) is caught as not dissipative.
    let pushing =
        Expression::new("-mu * N * tanh(v / eps)", &[("mu", 0.2), ("eps", 1e-3)]).unwrap();
    let v = check_model(&pushing).unwrap_err();
    assert_eq!(v.check, Check::Dissipative, "{v}");
    // A law that is not odd.
    let skewed = Expression::new(
        "mu * N * tanh(v / eps) + b",
        &[("mu", 0.2), ("eps", 1e-3), ("b", 1e-3)],
    )
    .unwrap();
    let v = check_model(&skewed).unwrap_err();
    assert_eq!(v.check, Check::OddSymmetry, "{v}");
    // A law that overflows at high speed.
    let blowing = Expression::new(
        "mu * N * sign(v) * exp(v^2 * b)",
        &[("mu", 0.2), ("b", 1e3)],
    )
    .unwrap();
    let v = check_model(&blowing).unwrap_err();
    assert_eq!(v.check, Check::Finite, "{v}");
}

/// The parameter tables in the module docs are the ones rendered from the declarations.
#[test]
fn documentation_tables_match_the_declarations() {
    let sources: [(&str, &str); 11] = [
        ("coulomb", include_str!("../src/builtin/coulomb.rs")),
        (
            "viscous_coulomb",
            include_str!("../src/builtin/viscous_coulomb.rs"),
        ),
        ("stribeck", include_str!("../src/builtin/stribeck.rs")),
        ("dahl", include_str!("../src/builtin/dahl.rs")),
        ("lugre", include_str!("../src/builtin/lugre.rs")),
        ("makkar", include_str!("../src/builtin/makkar.rs")),
        ("gms", include_str!("../src/builtin/gms.rs")),
        (
            "coulomb_asymmetric",
            include_str!("../src/builtin/coulomb_asymmetric.rs"),
        ),
        (
            "viscous_coulomb_asymmetric",
            include_str!("../src/builtin/viscous_coulomb_asymmetric.rs"),
        ),
        (
            "coulomb_load",
            include_str!("../src/builtin/coulomb_load.rs"),
        ),
        (
            "position_ripple",
            include_str!("../src/builtin/position_ripple.rs"),
        ),
    ];
    for (name, source) in sources {
        let info = if name == "gms" {
            Gms::shared_param_info()
        } else {
            default_model(name).unwrap().param_info()
        };
        if let Some(table) = doc_table_mismatch(source, &info) {
            panic!("the documentation of `{name}` should contain\n{table}");
        }
    }
}
