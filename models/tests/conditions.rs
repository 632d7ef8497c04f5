//! Laws that read more than speed: the conditions a formula reads, their order, the values
//! it takes from them, and the names it refuses.

use frictionid_models::*;

fn toml_model(text: &str) -> Result<Built, ModelError> {
    let t: toml::Value = toml::from_str(text).map_err(|e| ModelError::Invalid(e.to_string()))?;
    build_toml(&t)
}

#[test]
fn a_formula_reads_x_a_u_and_its_channels_in_order_of_appearance() {
    let built = toml_model(
        "type = \"expression\"\n\
         force = \"Fc * (1 + kt * (temperature - 25)) * sign(v) + b * v + m2 * a + q * u * x\"\n\
         params = { Fc = 2.0, kt = -0.01, b = 0.5, m2 = 0.1, q = 0.3 }\n\
         channels = [\"temperature\"]",
    )
    .unwrap();
    let m = built.model.as_ref();
    assert_eq!(
        m.conditions(),
        vec![
            Condition::Channel("temperature".into()),
            Condition::Acceleration,
            Condition::InputForce,
            Condition::Displacement
        ]
    );
    let (v, n) = (0.2, 1.0);
    let (t, a, u, x) = (45.0, 3.0, 7.0, 0.05);
    let by_hand = 2.0 * (1.0 - 0.01 * (t - 25.0)) + 0.5 * v + 0.1 * a + 0.3 * u * x;
    let got = m.force_in(v, &[], n, &[t, a, u, x]);
    assert!((got - by_hand).abs() < 1e-12, "{got} against {by_hand}");
    // Without values every condition reads 0.
    let at_zero = 2.0 * (1.0 - 0.01 * (0.0 - 25.0)) + 0.5 * v;
    assert!((m.force(v, &[], n) - at_zero).abs() < 1e-12);
    // The config round-trips with its channels.
    let json = serde_json::to_value(&built.model).unwrap();
    assert_eq!(json["channels"], serde_json::json!(["temperature"]));
    let back: Box<dyn FrictionModel> = serde_json::from_value(json).unwrap();
    assert_eq!(back.conditions(), m.conditions());
}

#[test]
fn a_parameter_named_like_a_condition_stays_a_parameter() {
    let m = Expression::new("a * N * sign(v) + u * v", &[("a", 0.2), ("u", 0.5)]).unwrap();
    assert!(m.conditions().is_empty());
    assert_eq!(m.force_in(1.0, &[], 2.0, &[99.0]), 0.2 * 2.0 + 0.5);
}

#[test]
fn channels_must_be_valid_used_and_unreserved_and_unknown_names_stay_errors() {
    let base = "type = \"expression\"\nforce = \"mu * N * sign(v) * load\"\nparams = { mu = 0.2 }";
    for (channels, needle) in [
        ("[\"load\", \"speed\"]", "channel `speed` does not appear"),
        ("[\"load\", \"x\"]", "`x` is reserved"),
        (
            "[\"load\", \"mu\"]",
            "`mu` is both a parameter and a channel",
        ),
        ("[\"lo ad\"]", "is not a valid name"),
    ] {
        let msg = toml_model(&format!("{base}\nchannels = {channels}"))
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains(needle) && msg.contains("key `channels`"),
            "{msg}"
        );
    }
    let msg = toml_model(base).unwrap_err().to_string();
    assert!(msg.contains("unknown variable `load`"), "{msg}");
}

/// A law that reads nothing sees its `force` through `force_in` and its gradient through
/// `force_param_gradient_in`.
#[test]
fn laws_without_conditions_keep_their_force() {
    let law = ViscousCoulomb {
        mu: 0.3,
        viscous: 2.0,
    };
    assert!(law.conditions().is_empty());
    assert_eq!(
        law.force_in(0.1, &[], 5.0, &[1.0, 2.0]),
        law.force(0.1, &[], 5.0)
    );
    let (mut plain, mut with) = ([0.0; 2], [0.0; 2]);
    law.force_param_gradient(0.1, &[], 5.0, &mut plain);
    law.force_param_gradient_in(0.1, &[], 5.0, &[4.0], &mut with);
    assert_eq!(plain, with);
}

/// dF/dp of `law` at (v, N, conditions `at`) by central differences of `force_in`.
fn numerical_gradient(law: &dyn FrictionModel, v: f64, normal: f64, at: &[f64]) -> Vec<f64> {
    let p0 = law.params();
    let mut probe = dyn_clone::clone_box(law);
    (0..p0.len())
        .map(|j| {
            let h = 1e-6 * p0[j].abs().max(1e-3);
            let mut p = p0.clone();
            p[j] = p0[j] + h;
            probe.set_params(&p).unwrap();
            let plus = probe.force_in(v, &[], normal, at);
            p[j] = p0[j] - h;
            probe.set_params(&p).unwrap();
            let minus = probe.force_in(v, &[], normal, at);
            (plus - minus) / (2.0 * h)
        })
        .collect()
}

fn assert_gradient_matches(law: &dyn FrictionModel, v: f64, normal: f64, at: &[f64]) {
    let mut exact = vec![0.0; law.params().len()];
    law.param_gradients()
        .unwrap()
        .force_param_gradient_in(v, &[], normal, at, &mut exact);
    for (j, (e, n)) in exact
        .iter()
        .zip(numerical_gradient(law, v, normal, at))
        .enumerate()
    {
        assert!(
            (e - n).abs() <= 1e-6 * (1.0 + n.abs()),
            "{} parameter {j}: {e} against {n}",
            law.name()
        );
    }
}

/// The load law against its equation by hand, its exact gradient against differences, and
/// its load-free limit: `viscous_coulomb`, from which it starts exactly.
#[test]
fn coulomb_load_reads_the_load_channel() {
    let law = CoulombLoad {
        mu: 0.3,
        mu_load: 0.02,
        viscous: 1.5,
    };
    assert_eq!(law.conditions(), vec![Condition::Channel("load".into())]);
    for (v, load) in [(0.1, 40.0), (-0.2, -25.0), (0.05, -3.0), (0.0, 10.0)] {
        // sgn(v), 0 at rest (std's signum gives +-1 at +-0).
        let s = if v == 0.0 { 0.0 } else { f64::signum(v) };
        let by_hand = (0.3 * 2.0 + 0.02 * f64::abs(load)) * s + 1.5 * v;
        assert!((law.force_in(v, &[], 2.0, &[load]) - by_hand).abs() < 1e-12);
        if v != 0.0 {
            assert_gradient_matches(&law, v, 2.0, &[load]);
        }
    }
    let plain = ViscousCoulomb {
        mu: 0.25,
        viscous: 3.0,
    };
    let mut started = CoulombLoad::default();
    let ctx = StartContext::new(2.0, 1.0);
    assert!(started.staging().unwrap().start_from(&plain, &ctx));
    assert_eq!(started.params(), vec![0.25, 0.0, 3.0]);
    for v in [-0.3, 0.01, 0.7] {
        assert_eq!(
            started.force_in(v, &[], 2.0, &[55.0]),
            plain.force(v, &[], 2.0)
        );
    }
}

/// The ripple law against its equation by hand, its exact gradient against differences (the
/// period's included, away from x = 0), and its ripple-free limit.
#[test]
fn position_ripple_reads_the_displacement() {
    let law = PositionRipple {
        mu: 0.2,
        ripple: 0.05,
        period: 0.01,
        phase: 0.7,
        viscous: 2.0,
    };
    assert_eq!(law.conditions(), vec![Condition::Displacement]);
    for (v, x) in [(0.1, 0.0123), (-0.05, -0.031), (0.3, 0.5)] {
        let s = if v > 0.0 { 1.0 } else { -1.0 };
        let theta = 2.0 * std::f64::consts::PI * x / 0.01 + 0.7;
        let by_hand = (0.2 + 0.05 * f64::sin(theta)) * 3.0 * s + 2.0 * v;
        assert!((law.force_in(v, &[], 3.0, &[x]) - by_hand).abs() < 1e-12);
        assert_gradient_matches(&law, v, 3.0, &[x]);
    }
    let mut started = law.clone();
    let plain = Coulomb { mu: 0.3 };
    assert!(started
        .staging()
        .unwrap()
        .start_from(&plain, &StartContext::new(3.0, 1.0)));
    assert_eq!(
        started.force_in(0.2, &[], 3.0, &[0.004]),
        plain.force(0.2, &[], 3.0)
    );
}
