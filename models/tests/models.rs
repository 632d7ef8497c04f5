//! Built-in models against hand-computed values, odd symmetry, serde round trips and the
//! registry's error messages.

use frictionid_models::*;

const N: f64 = 14.5;

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

/// Runs `check` on the default instance of every registered model.
fn check_every_model(check: fn(&testing::Model) -> Result<(), testing::Violation>) {
    for name in names() {
        let m = default_model(&name).unwrap();
        check(m.as_ref()).unwrap();
    }
}

#[test]
fn registry_lists_the_built_in_models() {
    assert_eq!(
        names(),
        vec![
            "coulomb",
            "coulomb_asymmetric",
            "coulomb_load",
            "dahl",
            "expression",
            "gms",
            "lugre",
            "makkar",
            "none",
            "position_ripple",
            "stribeck",
            "viscous_coulomb",
            "viscous_coulomb_asymmetric"
        ]
    );
    for l in listings() {
        let m = default_model(&l.name).unwrap();
        assert_eq!(m.name(), l.name);
        assert_eq!(l.parameters, m.param_info());
        // Defaults in the metadata are the defaults of the built instance, inside the bounds.
        testing::check_declarations(m.as_ref()).unwrap();
    }
}

#[test]
fn coulomb_forces_by_hand() {
    let m = Coulomb { mu: 0.24 };
    assert_eq!(m.force(0.3, &[], N), 0.24 * 14.5);
    assert_eq!(m.force(-1e-300, &[], N), -3.48);
    assert_eq!(m.force(0.0, &[], N), 0.0);
    assert_eq!(m.static_limit(N), Some(3.48));
    // In a slip phase the direction comes from the mode, not from sgn(v).
    assert_eq!(m.slip_force(0.0, -1.0, N), -3.48);
    assert_eq!(m.slip_force(1e-18, -1.0, N), -3.48);
}

#[test]
fn viscous_coulomb_forces_by_hand() {
    let m = ViscousCoulomb {
        mu: 0.2,
        viscous: 3.0,
    };
    assert!(close(m.force(0.1, &[], N), 2.9 + 0.3, 1e-15));
    assert!(close(m.force(-0.02, &[], N), -2.9 - 0.06, 1e-15));
    assert_eq!(m.force(0.0, &[], N), 0.0);
    assert!(close(m.force(1e-12, &[], N), 2.9 + 3e-12, 1e-15));
    assert_eq!(m.static_limit(N), Some(0.2 * 14.5));
    assert!(close(m.slip_force(0.0, 1.0, N), 2.9, 1e-15));
}

#[test]
fn stribeck_forces_by_hand() {
    let m = Stribeck {
        mu_c: 0.2,
        mu_s: 0.28,
        v_s: 0.02,
        delta: 2.0,
        viscous: 3.0,
    };
    // v = v_s: N (0.2 + 0.08 e^-1) + 3 * 0.02
    let f = 14.5 * (0.2 + 0.08 * (-1.0f64).exp()) + 0.06;
    assert!(close(m.force(0.02, &[], N), f, 1e-14));
    // v = 2 v_s: e^-4
    let f2 = 14.5 * (0.2 + 0.08 * (-4.0f64).exp()) + 0.12;
    assert!(close(m.force(0.04, &[], N), f2, 1e-14));
    // tiny |v|: the static level mu_s N
    assert!(close(m.force(-1e-9, &[], N), -0.28 * 14.5 - 3e-9, 1e-12));
    assert_eq!(m.force(0.0, &[], N), 0.0);
    assert_eq!(m.static_limit(N), Some(0.28 * 14.5));
    // high speed: Coulomb level plus viscous
    assert!(close(m.force(1.0, &[], N), 2.9 + 3.0, 1e-14));
    // delta = 1: exp(-|v/v_s|)
    let m1 = Stribeck { delta: 1.0, ..m };
    let f3 = 14.5 * (0.2 + 0.08 * (-0.5f64).exp()) + 0.03;
    assert!(close(m1.force(0.01, &[], N), f3, 1e-14));
}

#[test]
fn dahl_state_derivative_by_hand() {
    let m = Dahl {
        sigma0: 1e5,
        mu_c: 0.2,
        alpha: 1.0,
    };
    let fc = 0.2 * 14.5;
    let mut dz = [0.0];
    // F = 0: dF/dt = sigma0 v
    m.state_derivative(0.01, &[0.0], N, &mut dz);
    assert!(close(dz[0], 1e3, 1e-15));
    // F = Fc/2, v > 0: sigma0 v (1 - 1/2)
    m.state_derivative(0.01, &[fc / 2.0], N, &mut dz);
    assert!(close(dz[0], 500.0, 1e-14));
    // F = Fc/2, v < 0: sigma0 v (1 + 1/2)
    m.state_derivative(-0.01, &[fc / 2.0], N, &mut dz);
    assert!(close(dz[0], -1500.0, 1e-14));
    // saturated: no change
    m.state_derivative(0.5, &[fc], N, &mut dz);
    assert_eq!(dz[0], 0.0);
    // v = 0: no change
    m.state_derivative(0.0, &[1.0], N, &mut dz);
    assert_eq!(dz[0], 0.0);
    // alpha = 2, beyond saturation: r = 1 - 1.5 = -0.5 -> sigma0 v 0.25 * (-1)
    let m2 = Dahl { alpha: 2.0, ..m };
    m2.state_derivative(0.01, &[1.5 * fc], N, &mut dz);
    assert!(close(dz[0], -250.0, 1e-14));
    assert_eq!(m.force(0.3, &[1.25], N), 1.25);
    assert!(close(m.stored_energy(&[2.0], N), 4.0 / 2e5, 1e-15));
}

#[test]
fn lugre_by_hand() {
    let m = LuGre::default();
    // g(0) = mu_s N, g(v_s) = N (mu_c + (mu_s - mu_c)/e)
    assert!(close(m.g(0.0, N), 0.3 * 14.5, 1e-15));
    let gvs = 14.5 * (0.2 + 0.1 * (-1.0f64).exp());
    assert!(close(m.g(0.01, N), gvs, 1e-15));
    let z = 1e-5;
    let v = 0.01;
    let zd = v - 1e5 * v * z / gvs;
    let mut dz = [0.0];
    m.state_derivative(v, &[z], N, &mut dz);
    assert!(close(dz[0], zd, 1e-14));
    assert!(close(
        m.force(v, &[z], N),
        1e5 * z + 300.0 * zd + 0.5 * v,
        1e-14
    ));
    // v = 0: dz/dt = 0, F = sigma0 z
    m.state_derivative(0.0, &[z], N, &mut dz);
    assert_eq!(dz[0], 0.0);
    assert!(close(m.force(0.0, &[z], N), 1.0, 1e-14));
    // tiny v: dz/dt ~ v
    m.state_derivative(1e-12, &[0.0], N, &mut dz);
    assert_eq!(dz[0], 1e-12);
    // steady state: z = g/sigma0 sgn(v), F = g sgn(v) + sigma2 v
    let zss = gvs / 1e5;
    m.state_derivative(v, &[zss], N, &mut dz);
    assert!(dz[0].abs() < 1e-15);
    assert!(close(m.force(v, &[zss], N), m.steady_state(v, N), 1e-12));
    assert!(close(m.stored_energy(&[z], N), 0.5 * 1e5 * z * z, 1e-15));
}

#[test]
fn none_is_zero() {
    let m = NoFriction {};
    assert_eq!(m.force(1.0, &[], N), 0.0);
    assert_eq!(m.steady_state(-1.0, N), 0.0);
    assert!(m.params().is_empty());
}

/// F(-v, -z) = -F(v, z) and dz(-v, -z) = -dz(v, z) for every registered model (exactly, at
/// the harness's velocities, states and normal forces).
#[test]
fn every_model_is_odd() {
    check_every_model(testing::check_odd_symmetry);
}

/// The steady state of a dynamic model equals its force at the state where dz/dt = 0.
#[test]
fn dynamic_steady_state_matches_the_fixed_point() {
    let m = Dahl::default();
    let v = 0.05;
    let fc = 0.2 * N;
    assert!(close(m.force(v, &[fc], N), m.steady_state(v, N), 1e-15));
}

/// JSON and TOML round trips with every parameter perturbed, so that the defaults cannot
/// hide a lost field.
#[test]
fn every_model_round_trips_through_json_and_toml() {
    check_every_model(testing::check_serde);
}

/// A model built from the TOML table `text`.
fn build_from(text: &str) -> Result<Built, ModelError> {
    build_toml(&toml::from_str(text).unwrap())
}

#[test]
fn missing_parameters_take_their_defaults() {
    let b = build_from("type = \"lugre\"\nsigma0 = 2.0e5\nmu_c = 0.22\n").unwrap();
    let d = LuGre::default();
    assert_eq!(
        b.model.params(),
        vec![2.0e5, d.sigma1, d.sigma2, 0.22, d.mu_s, d.v_s]
    );
    assert!(b.warnings.is_empty());
}

#[test]
fn unknown_type_lists_the_registered_names() {
    let e = build_from("type = \"lugra\"").unwrap_err().to_string();
    assert!(e.contains("unknown friction model `lugra`"), "{e}");
    assert!(e.contains("did you mean `lugre`"), "{e}");
    for n in names() {
        assert!(e.contains(&n), "{e} lacks {n}");
    }
    let e = build_json(&serde_json::json!({"mu": 1.0}))
        .unwrap_err()
        .to_string();
    assert!(e.contains("no `type`"), "{e}");
}

#[test]
fn unknown_parameter_is_named_with_the_models_parameters() {
    let e = build_from("type = \"stribeck\"\nmu_k = 0.2")
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown parameter `mu_k`"), "{e}");
    assert!(e.contains("stribeck"), "{e}");
    for p in ["mu_c", "mu_s", "v_s", "delta", "viscous"] {
        assert!(e.contains(p), "{e}");
    }
}

#[test]
fn out_of_bounds_values_are_errors() {
    for (text, param) in [
        ("type = \"coulomb\"\nmu = -0.1", "mu"),
        ("type = \"lugre\"\nsigma0 = 0.0", "sigma0"),
        ("type = \"dahl\"\nsigma0 = -5.0", "sigma0"),
        ("type = \"stribeck\"\nv_s = 0.0", "v_s"),
        ("type = \"viscous_coulomb\"\nviscous = -1.0", "viscous"),
    ] {
        let e = build_from(text).unwrap_err();
        assert!(
            matches!(&e, ModelError::OutOfBounds { param: p, .. } if p == param),
            "{text}: {e}"
        );
        assert!(e.to_string().contains("outside its physical bounds"));
    }
    let e = build_json(&serde_json::json!({"type": "coulomb", "mu": "high"}))
        .unwrap_err()
        .to_string();
    assert!(e.contains("coulomb"), "{e}");
}

#[test]
fn mu_s_below_mu_c_is_a_warning_not_an_error() {
    for ty in ["stribeck", "lugre"] {
        let b = build_from(&format!("type = \"{ty}\"\nmu_c = 0.3\nmu_s = 0.2")).unwrap();
        assert_eq!(b.warnings.len(), 1, "{ty}");
        assert!(b.warnings[0].contains("mu_s"));
    }
}

#[test]
fn set_params_checks_the_length() {
    let mut m = default_model("stribeck").unwrap();
    let e = m.set_params(&[0.1, 0.2]).unwrap_err();
    assert_eq!(
        e,
        ModelError::ParamCount {
            model: "stribeck".into(),
            expected: 5,
            got: 2
        }
    );
}

#[test]
fn only_the_stribeck_exponent_is_fixed_by_default() {
    for l in listings() {
        for p in &l.parameters {
            assert_eq!(
                p.fixed_by_default,
                l.name == "stribeck" && p.name == "delta",
                "{}.{}",
                l.name,
                p.name
            );
        }
    }
}

/// Dahl's rate against its equation written with libm's `powf`: dF/dt = sigma0 v |r|^alpha
/// sgn(r), r = 1 - F sgn(v) / (mu_c N), over shapes and loads on both sides of r = 0 (the
/// model takes |r|^alpha as exp(alpha ln |r|), and exactly |r| at alpha = 1).
#[test]
fn dahl_rate_matches_its_equation() {
    for alpha in [0.3, 0.5, 1.0, 1.7, 4.0] {
        let m = Dahl {
            sigma0: 2e5,
            mu_c: 0.21,
            alpha,
        };
        let fc = m.mu_c * N;
        for f in [
            -1.9 * fc,
            -fc,
            -0.4 * fc,
            0.0,
            0.3 * fc,
            0.999 * fc,
            fc,
            1.5 * fc,
        ] {
            for v in [-0.2f64, -1e-4, 3e-3, 0.4] {
                let r = 1.0 - f * v.signum() / fc;
                let expected =
                    m.sigma0 * v * r.abs().powf(alpha) * r.signum() * (r != 0.0) as i32 as f64;
                let mut dz = [0.0];
                m.state_derivative(v, &[f], N, &mut dz);
                assert!(
                    close(dz[0], expected, 1e-13),
                    "alpha {alpha}, F {f}, v {v}: {} vs {expected}",
                    dz[0]
                );
                if alpha == 1.0 {
                    assert_eq!(dz[0], m.sigma0 * v * r.abs() * sgn(r));
                }
            }
        }
    }
}

/// Stribeck's curve against its equation written with libm's `powf`, for the shapes it
/// computes without it (delta = 1, 2) and others.
#[test]
fn stribeck_curve_matches_its_equation_for_any_shape() {
    for delta in [0.5, 1.0, 1.5, 2.0, 3.0] {
        let m = Stribeck {
            mu_c: 0.2,
            mu_s: 0.28,
            v_s: 0.02,
            delta,
            viscous: 0.0,
        };
        for v in [1e-6, 0.003, 0.02, 0.05, 0.3] {
            let expected = 0.2 + 0.08 * (-(v / 0.02f64).powf(delta)).exp();
            let got = m.coefficient(v);
            assert!(
                close(got, expected, 1e-15),
                "delta {delta}, v {v}: {got} vs {expected}"
            );
        }
    }
}
