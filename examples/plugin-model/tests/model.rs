//! The plugin model as a library: hand-computed forces, the reduction to the built-in
//! `stribeck` model at alpha = 1, odd symmetry, the set-valued static part, and its
//! registration in the typetag registry of a binary that links this crate.

use frictionid_models::{
    build_json, names, testing, FrictionModel, ModelError, Stribeck, SwitchedLaw,
};
use frictionid_plugin_example::{StribeckPower, NAME};

const N: f64 = 14.5;
const EXP_M1: f64 = 0.367_879_441_171_442_33; // e^-1
const EXP_M4: f64 = 0.018_315_638_888_734_18; // e^-4

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

fn model() -> StribeckPower {
    StribeckPower::fixture_truth()
}

#[test]
fn forces_match_hand_computed_values() {
    let m = model();
    // v = v_s: dip factor e^-1; viscous 4 * 0.1 * 0.2^1.6 with 0.2^1.6 = e^(1.6 ln 0.2).
    let visc = 0.4 * (1.6 * 0.2f64.ln()).exp();
    let f = N * (0.2 + 0.1 * EXP_M1) + visc;
    assert!(
        close(m.force(0.02, &[], N), f, 1e-14),
        "{}",
        m.force(0.02, &[], N)
    );
    // v = 2 v_s = 0.04: dip factor e^-4.
    let visc = 0.4 * (1.6 * 0.4f64.ln()).exp();
    assert!(close(
        m.force(0.04, &[], N),
        N * (0.2 + 0.1 * EXP_M4) + visc,
        1e-14
    ));
    // v = v_ref = 0.1: the dip has vanished (e^-25) and the viscous force is viscous * v_ref.
    assert!(close(m.force(0.1, &[], N), N * 0.2 + 0.4, 1e-9));
    // alpha = 2 at v = 3 v_ref: viscous v_ref 9.
    let m2 = StribeckPower {
        alpha: 2.0,
        ..m.clone()
    };
    assert!(close(m2.viscous_force(0.3), 4.0 * 0.1 * 9.0, 1e-14));
    // sgn(0) = 0 and no dependence on states.
    assert_eq!(m.force(0.0, &[], N), 0.0);
    assert!(m.states().is_none(), "no internal states");
    assert_eq!(m.steady_state(0.05, N), m.force(0.05, &[], N));
}

#[test]
fn alpha_one_is_the_builtin_gaussian_stribeck() {
    let builtin = Stribeck {
        mu_c: 0.2,
        mu_s: 0.3,
        v_s: 0.02,
        delta: 2.0,
        viscous: 4.0,
    };
    let m = StribeckPower {
        alpha: 1.0,
        v_ref: 0.37,
        ..model()
    };
    for v in [1e-9, 1e-5, 0.003, 0.02, 0.05, 0.2, 1.0, 3.0] {
        for v in [v, -v] {
            let (a, b) = (m.force(v, &[], N), builtin.force(v, &[], N));
            assert!(close(a, b, 1e-13), "v = {v}: {a} vs {b}");
            for dir in [1.0, -1.0] {
                let (a, b) = (m.slip_force(v, dir, N), builtin.slip_force(v, dir, N));
                assert!(close(a, b, 1e-13), "v = {v}, dir {dir}: {a} vs {b}");
            }
        }
    }
    assert_eq!(m.static_limit(N), builtin.static_limit(N));
}

#[test]
fn force_is_odd_and_dissipative() {
    let m = model();
    for v in [1e-300, 1e-12, 1e-6, 0.001, 0.02, 0.1, 0.7, 10.0] {
        assert_eq!(m.force(-v, &[], N), -m.force(v, &[], N), "v = {v}");
        assert!(m.force(v, &[], N) * v > 0.0, "v = {v}");
    }
}

#[test]
fn static_part_takes_its_sign_from_the_slip_direction() {
    let m = model();
    assert_eq!(m.static_limit(N), Some(0.3 * N));
    // At v = 0 (a mode boundary) the slip force is the breakaway force in the slip direction.
    assert!(close(m.slip_force(0.0, 1.0, N), 0.3 * N, 1e-15));
    assert!(close(m.slip_force(0.0, -1.0, N), -0.3 * N, 1e-15));
    // A round-off velocity of the wrong sign does not flip the dry part.
    assert!(m.slip_force(-1e-15, 1.0, N) > 0.29 * N);
}

#[test]
fn the_linked_plugin_is_in_the_registry() {
    assert!(names().iter().any(|n| n == NAME), "{:?}", names());
    // Built from a table by name, missing parameters take their defaults.
    let b = build_json(&serde_json::json!({ "type": "stribeck_power", "alpha": 2.0 })).unwrap();
    assert_eq!(b.model.name(), NAME);
    assert_eq!(b.model.params(), [0.2, 0.3, 0.01, 0.5, 2.0, 0.1]);
    assert!(b.warnings.is_empty());
    // Unknown keys are rejected by name, with a hint.
    let e = build_json(&serde_json::json!({ "type": "stribeck_power", "alpah": 2.0 })).unwrap_err();
    assert!(
        matches!(e, ModelError::UnknownParameter { ref key, ref hint, .. }
            if key == "alpah" && hint.contains("alpha")),
        "{e}"
    );
    // Bounds are checked by name: alpha must be > 0.
    let e = build_json(&serde_json::json!({ "type": "stribeck_power", "alpha": 0.0 })).unwrap_err();
    assert!(
        matches!(e, ModelError::OutOfBounds { ref param, .. } if param == "alpha"),
        "{e}"
    );
    // mu_s < mu_c is admissible but warned about.
    let b = build_json(&serde_json::json!({ "type": "stribeck_power", "mu_s": 0.1 })).unwrap();
    assert_eq!(b.warnings.len(), 1);
}

#[test]
fn params_declarations() {
    let mut m = StribeckPower::default();
    let names: Vec<String> = m.param_info().into_iter().map(|p| p.name).collect();
    assert_eq!(names, ["mu_c", "mu_s", "v_s", "viscous", "alpha", "v_ref"]);
    let fixed: Vec<bool> = m.param_info().iter().map(|p| p.fixed_by_default).collect();
    assert_eq!(fixed, [false, false, false, false, false, true]);
    m.set_params(&[0.1, 0.2, 0.03, 1.5, 0.7, 0.2]).unwrap();
    assert_eq!(m.params(), [0.1, 0.2, 0.03, 1.5, 0.7, 0.2]);
    assert!(matches!(
        m.set_params(&[1.0]),
        Err(ModelError::ParamCount {
            expected: 6,
            got: 1,
            ..
        })
    ));
}

/// The invariants every model satisfies (`frictionid_models::testing`): registration, the
/// parameter vector and its bounds, JSON/TOML round trips, finite and exactly odd forces, a
/// dissipative law, the slip direction of the set-valued part.
#[test]
fn passes_the_model_harness() {
    for m in [
        StribeckPower::default(),
        model(),
        StribeckPower {
            alpha: 0.3,
            ..model()
        },
    ] {
        testing::assert_model(&m);
    }
}

/// The parameter table in the module documentation is rendered from the declarations.
#[test]
fn documentation_table_matches_the_declarations() {
    let source = include_str!("../src/stribeck_power.rs");
    if let Some(table) = testing::doc_table_mismatch(source, &model().param_info()) {
        panic!("the documentation should contain\n{table}");
    }
}
