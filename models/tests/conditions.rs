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
