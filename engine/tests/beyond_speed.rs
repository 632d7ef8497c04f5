//! Laws that read more than the sliding speed, fitted along a measured motion against
//! records whose friction force is written here in closed form (not through the law):
//!
//! - a guide whose level ripples along its travel, F = (Fc + Fr sin(2 pi x / p + phase))
//!   sgn(v) + b v (`position_ripple`, reading the displacement);
//! - a gearbox joint whose Coulomb torque grows with its measured load torque,
//!   F = (Tc + mu_l |load|) sgn(v) + b v (`coulomb_load`, reading the `load` channel);
//! - a drive warming from 25 to 60 degC, F = Fc (1 + kt (T - 25)) sgn(v) + b v, as a formula
//!   reading the record's `temperature` channel.
//!
//! Each case: every parameter within 1 % of the truth on the noise-free record; within 3
//! standard errors with noise; and viscous_coulomb, which cannot follow the condition, worse
//! on the same noisy record by AIC and by held-out validation (`compare`). The gearbox is
//! also fitted by inverse dynamics, its inertia with the law.

use crate::util::{estimate, no_oscillator_force_options};
use frictionid_engine::identify::{compare, fit, FitOptions};
use frictionid_engine::record::{Channel, TimeBase};
use frictionid_engine::synthetic::{add_gaussian_noise, uniform_times};
use frictionid_engine::{Oscillator, Record};
use frictionid_models::{
    build_json, sgn, CoulombLoad, FrictionModel, PositionRipple, ViscousCoulomb,
};
use std::f64::consts::PI;

/// Sample rate of the records [Hz].
const RATE: f64 = 200.0;
/// Duration of the records [s].
const DURATION: f64 = 20.0;

/// A slow back-and-forth stroke: v = `amplitude` sin(2 pi t / `period`), x its integral from
/// x = 0 at t = 0 (both in closed form), with the measured `force` and named channels.
fn stroke(
    name: &str,
    amplitude: f64,
    period: f64,
    force: impl Fn(f64, f64, f64) -> f64,
    named: &[(&str, Vec<f64>)],
    noise: Option<(f64, u64)>,
) -> Record {
    let time = uniform_times(DURATION, RATE);
    let w = 2.0 * PI / period;
    let v: Vec<f64> = time.iter().map(|t| amplitude * (w * t).sin()).collect();
    let x: Vec<f64> = time
        .iter()
        .map(|t| amplitude / w * (1.0 - (w * t).cos()))
        .collect();
    let mut f: Vec<f64> = (0..time.len())
        .map(|i| force(time[i], x[i], v[i]))
        .collect();
    if let Some((sigma, seed)) = noise {
        add_gaussian_noise(&mut f, sigma, seed);
    }
    let record = Record::from_time_base(name, TimeBase::new(time).expect("a time base"))
        .with_channel(Channel::Velocity, v)
        .with_channel(Channel::Displacement, x)
        .with_channel(Channel::Force, f);
    named.iter().fold(record, |r, (n, values)| {
        r.with_named_channel(*n, values.clone())
    })
}

/// A parameter's truth and how close the noise-free fit must come: relative, or absolute
/// (a phase).
struct Truth {
    name: &'static str,
    value: f64,
    absolute: Option<f64>,
}

const fn relative(name: &'static str, value: f64) -> Truth {
    Truth {
        name,
        value,
        absolute: None,
    }
}

/// The force route on the measured force, no oscillator given (levels in N).
fn options() -> (Oscillator, FitOptions) {
    let (osc, mut opts) = no_oscillator_force_options();
    opts.params.guess = false;
    (osc, opts)
}

/// The three checks of a case: noise-free within tolerance, noisy within 3 standard errors,
/// viscous_coulomb worse by AIC and by validation.
fn accept(
    case: &str,
    start: &(dyn FrictionModel + 'static),
    truths: &[Truth],
    clean: Record,
    noisy: Record,
) {
    let (osc, opts) = options();
    let exact = fit(&osc, start, &[clean], &opts).expect("a noise-free fit");
    assert!(exact.converged, "{case}: {}", exact.termination);
    for t in truths {
        let value = exact.value(t.name).unwrap_or(f64::NAN);
        let off = (value - t.value).abs();
        let tolerance = t.absolute.unwrap_or(0.01 * t.value.abs());
        eprintln!("{case} noise-free {}: {value} (truth {})", t.name, t.value);
        assert!(
            off <= tolerance,
            "{case} {}: {value} against {}",
            t.name,
            t.value
        );
    }
    let noisy = [noisy];
    let fitted = fit(&osc, start, &noisy, &opts).expect("a noisy fit");
    for t in truths {
        let (value, se) = estimate(&fitted, t.name);
        eprintln!(
            "{case} noisy {}: {value} +- {se} (truth {})",
            t.name, t.value
        );
        assert!(
            (value - t.value).abs() <= 3.0 * se,
            "{case} {}: {value} +- {se} against {}",
            t.name,
            t.value
        );
    }
    let plain = ViscousCoulomb {
        mu: 1.0,
        viscous: 1.0,
    };
    let models: Vec<Box<dyn FrictionModel>> =
        vec![Box::new(plain), frictionid_models::clone_model(start)];
    let c = compare(&osc, &models, &noisy, &opts).expect("a comparison");
    assert!(c.failed.is_empty(), "{case}: {:?}", c.failed);
    let aic = |name: &str| c.ranking.iter().find(|f| f.model == name).map(|f| f.aic);
    let held = |name: &str| {
        c.validation
            .iter()
            .find(|v| v.model == name)
            .and_then(|v| v.validation_rms)
    };
    let (law, vc) = (start.name(), "viscous_coulomb");
    eprintln!(
        "{case}: AIC {:?} against viscous_coulomb's {:?}; held-out RMS {:?} against {:?}",
        aic(law),
        aic(vc),
        held(law),
        held(vc)
    );
    assert!(aic(law).unwrap() < aic(vc).unwrap(), "{case}: AIC");
    assert!(held(law).unwrap() < held(vc).unwrap(), "{case}: validation");
}

/// A drive warming from 25 to 60 degC along the record: its Coulomb level falls by 0.4 %
/// per kelvin, read by a formula from the record's `temperature` channel.
#[test]
fn a_formula_reading_the_temperature_recovers_its_drift() {
    let (fc, kt, b) = (4.0, -0.004, 12.0);
    let temperature = |t: f64| 25.0 + 35.0 * t / DURATION;
    let truth =
        |t: f64, _x: f64, v: f64| fc * (1.0 + kt * (temperature(t) - 25.0)) * sgn(v) + b * v;
    let channel: Vec<f64> = uniform_times(DURATION, RATE)
        .iter()
        .map(|&t| temperature(t))
        .collect();
    let named = [("temperature", channel)];
    let record = |noise| stroke("warming.csv", 0.05, 4.0, truth, &named, noise);
    let start = build_json(&serde_json::json!({
        "type": "expression",
        "force": "Fc * (1 + kt * (temperature - 25)) * sign(v) + b * v",
        "params": { "Fc": 3.0, "kt": 0.0, "b": 8.0 },
        "channels": ["temperature"],
    }))
    .expect("a formula")
    .model;
    accept(
        "warming",
        start.as_ref(),
        &[relative("Fc", fc), relative("kt", kt), relative("b", b)],
        record(None),
        record(Some((0.05, 7))),
    );
}

/// A guide that rubs harder every 10 mm of its travel, along a slow back-and-forth stroke:
/// F = (Fc + Fr sin(2 pi x / p + phase)) sgn(v) + b v, fitted by `position_ripple` from a
/// period 2 % off.
#[test]
fn position_ripple_recovers_the_ripple_of_a_stroke() {
    let (fc, fr, p, phase, b) = (3.0, 0.4, 0.01, 1.0, 10.0);
    let truth =
        |_t: f64, x: f64, v: f64| (fc + fr * (2.0 * PI * x / p + phase).sin()) * sgn(v) + b * v;
    let record = |noise| stroke("guide.csv", 0.05, 4.0, truth, &[], noise);
    let start = PositionRipple {
        mu: 2.5,
        ripple: 0.2,
        period: 0.0102,
        phase: 0.7,
        viscous: 8.0,
    };
    accept(
        "ripple",
        &start,
        &[
            relative("mu", fc),
            relative("ripple", fr),
            relative("period", p),
            Truth {
                name: "phase",
                value: phase,
                absolute: Some(0.02),
            },
            relative("viscous", b),
        ],
        record(None),
        record(Some((0.05, 11))),
    );
}

/// A strain-wave gearbox whose Coulomb torque grows with the load torque it transmits,
/// measured beside the motion: F = (Tc + mu_l |load|) sgn(v) + b v, fitted by
/// `coulomb_load` reading the record's `load` channel.
#[test]
fn coulomb_load_recovers_a_gearbox_s_load_dependence() {
    let (tc, mu_l, b) = (2.0, 0.03, 5.0);
    let load =
        |t: f64| 30.0 * (2.0 * PI * 0.13 * t).sin() + 10.0 * (2.0 * PI * 0.41 * t + 1.0).sin();
    let truth = |t: f64, _x: f64, v: f64| (tc + mu_l * load(t).abs()) * sgn(v) + b * v;
    let channel: Vec<f64> = uniform_times(DURATION, RATE)
        .iter()
        .map(|&t| load(t))
        .collect();
    let named = [("load", channel)];
    let record = |noise| stroke("joint.csv", 0.5, 3.0, truth, &named, noise);
    let start = CoulombLoad {
        mu: 1.5,
        mu_load: 0.01,
        viscous: 3.0,
    };
    accept(
        "gearbox",
        &start,
        &[
            relative("mu", tc),
            relative("mu_load", mu_l),
            relative("viscous", b),
        ],
        record(None),
        record(Some((0.05, 13))),
    );
}

/// The gearbox joint by inverse dynamics: its motion imposed in closed form (x, v, a), the
/// drive's torque u = J a + (Tc + mu_l |load|) sgn(v) + b v written here; `coulomb_load` and
/// the inertia fitted together from u recover every value within 1 %.
#[test]
fn coulomb_load_by_inverse_dynamics_recovers_the_joint() {
    let (inertia, tc, mu_l, b) = (2.0, 2.0, 0.03, 5.0);
    let (amplitude, w) = (0.5, 2.0 * PI / 3.0);
    let time = uniform_times(DURATION, RATE);
    let load: Vec<f64> = time
        .iter()
        .map(|t| 30.0 * (2.0 * PI * 0.13 * t).sin() + 10.0 * (2.0 * PI * 0.41 * t + 1.0).sin())
        .collect();
    let v: Vec<f64> = time.iter().map(|t| amplitude * (w * t).sin()).collect();
    let x: Vec<f64> = time
        .iter()
        .map(|t| amplitude / w * (1.0 - (w * t).cos()))
        .collect();
    let a: Vec<f64> = time.iter().map(|t| amplitude * w * (w * t).cos()).collect();
    let u: Vec<f64> = (0..time.len())
        .map(|i| inertia * a[i] + (tc + mu_l * load[i].abs()) * sgn(v[i]) + b * v[i])
        .collect();
    let record = Record::from_time_base("joint.csv", TimeBase::new(time).expect("a time base"))
        .with_channel(Channel::Velocity, v)
        .with_channel(Channel::Displacement, x)
        .with_channel(Channel::Acceleration, a)
        .with_channel(Channel::InputForce, u)
        .with_named_channel("load", load);
    let (osc, mut opts) = crate::util::inverse_dynamics_options();
    opts.params.guess = false;
    let start = CoulombLoad {
        mu: 1.5,
        mu_load: 0.01,
        viscous: 3.0,
    };
    let fitted = fit(&osc, &start, &[record], &opts).expect("an inverse-dynamics fit");
    for (name, truth) in [
        ("mass", inertia),
        ("mu", tc),
        ("mu_load", mu_l),
        ("viscous", b),
    ] {
        let value = fitted.value(name).unwrap_or(f64::NAN);
        eprintln!("inverse dynamics {name}: {value} (truth {truth})");
        assert!((value / truth - 1.0).abs() < 0.01, "{name}: {value}");
    }
}
