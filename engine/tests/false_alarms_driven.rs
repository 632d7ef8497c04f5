//! The false-alarm matrix on driven axes: the velocity route (the axis simulated under its
//! measured input, `driven_axis.rs`'s reference) and the inverse-dynamics route (u = M a +
//! F(v) + offset, `inverse_dynamics.rs`'s event-locating reference), each fitted with the
//! true law (viscous + Coulomb) on records with and without noise (white, AR(1) of lag-1
//! correlation 0.9, a 50 Hz ringing on the input): no diagnostic may fail. Its wrong-model
//! twin: Coulomb alone (no viscous term) on the same records, every fit warns or fails.

use crate::driven_axis::{identify_with, record};
use crate::inverse_dynamics::{options, TRUTH};
use crate::util::{false_alarms, unflagged};
use frictionid_engine::identify::{fit, FitResult};
use frictionid_engine::record::Channel;
use frictionid_engine::synthetic::{add_coloured_noise, add_gaussian_noise};
use frictionid_engine::Record;
use frictionid_models::{Coulomb, FrictionModel, ViscousCoulomb};

/// The velocity noise of the velocity route's noisy records [m/s].
const V_NOISE: f64 = 5e-3;
/// The input noise of the inverse-dynamics records [N].
const U_NOISE: f64 = 0.2;

/// The velocity route's records: noise-free, or with white velocity noise.
fn velocity_records(noise: f64) -> [Record; 2] {
    [record("a", 0.0, noise, 7), record("b", 0.8, noise, 8)]
}

/// The inverse-dynamics record with `kind` of noise on its input.
fn input_record(kind: &str) -> Record {
    let clean = TRUTH.record(10_000);
    let mut u = clean.channel(Channel::InputForce).unwrap().to_vec();
    match kind {
        "white" => add_gaussian_noise(&mut u, U_NOISE, 3),
        "ar1" => add_coloured_noise(&mut u, U_NOISE, 0.9, 4),
        "ringing" => {
            let theta = 2.0 * std::f64::consts::PI * 50.0 / 1000.0;
            let (a1, a2) = (1.8 * theta.cos(), -0.81);
            let (mut e1, mut e2) = (0.0, 0.0);
            let mut white = vec![0.0; u.len()];
            add_gaussian_noise(&mut white, 0.05, 5);
            for (u, w) in u.iter_mut().zip(white) {
                let e = a1 * e1 + a2 * e2 + w;
                (e2, e1) = (e1, e);
                *u += e;
            }
        }
        _ => {}
    }
    clean.with_channel(Channel::InputForce, u)
}

fn inverse_dynamics_fit(model: &(dyn FrictionModel + 'static), record: &Record) -> FitResult {
    let (osc, opts) = options();
    fit(&osc, model, std::slice::from_ref(record), &opts).unwrap()
}

/// Every case: its label and its fit with `model`.
fn cases(model: &(dyn FrictionModel + 'static)) -> Vec<(String, FitResult)> {
    let mut out = Vec::new();
    for (label, noise) in [("clean", 0.0), ("white", V_NOISE)] {
        let fit = identify_with(model, &velocity_records(noise));
        out.push((format!("velocity route, {label}"), fit));
    }
    for kind in ["clean", "white", "ar1", "ringing"] {
        let fit = inverse_dynamics_fit(model, &input_record(kind));
        out.push((format!("inverse dynamics, {kind}"), fit));
    }
    out
}

/// The true law on every driven case: no failed diagnostic.
#[test]
fn correct_laws_on_driven_axes_raise_no_failed_diagnostic() {
    let truth = ViscousCoulomb {
        mu: 4.0,
        viscous: 15.0,
    };
    let outcomes = cases(&truth);
    let alarmed = false_alarms(&outcomes);
    assert!(alarmed.is_empty(), "false alarms: {alarmed:?}");
}

/// Coulomb alone on the same records (the viscous term missing): every fit warns or fails.
#[test]
fn a_wrong_law_on_driven_axes_is_flagged() {
    let outcomes = cases(&Coulomb { mu: 4.0 });
    let missed = unflagged(&outcomes);
    assert!(missed.is_empty(), "not flagged: {missed:?}");
}
