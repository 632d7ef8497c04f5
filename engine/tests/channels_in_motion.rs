//! Laws that read the position or a record channel, fitted in the velocity domain: the
//! engine simulates the axis under the measured input, handing the law the simulated x and
//! the record's channels (linear between samples), and compares the simulated velocity and
//! displacement with the record's.
//!
//! The records come from a reference written here for a driven slide without a spring,
//!
//!   M a + F(t, x, v) = u(t),  F = L(t, x) sgn(v) + b v,
//!
//! classical Runge-Kutta (1e-5 s, never across a sample of the input or the channel), the
//! reversals located by bisection on the step, the stick held while |u| <= L(t, x) and its
//! end bisected. Two truths:
//!
//! - a guide whose level ripples along the travel, L = Fc + Fr sin(2 pi x / p + phase)
//!   (`position_ripple`, reading the simulated x);
//! - a gearbox joint whose level grows with a measured load, L = Tc + mu_l |load(t)|
//!   (`coulomb_load`, reading the `load` channel).
//!
//! Each: every parameter within 1 % of the truth (the phase within 0.02 rad, modulo 2 pi)
//! from a start
//! well off it, and viscous_coulomb, which cannot follow the condition, at least five times
//! the residual.

use crate::util::{
    four_tones, linear_between_samples, multisine, sample_times, SlideLevel, SlideReference,
};
use frictionid_engine::identify::{fit, FitOptions, FitResult, ParamOptions};
use frictionid_engine::record::{Channel, TimeBase};
use frictionid_engine::testing::driven_slide;
use frictionid_engine::{Oscillator, Record};
use frictionid_models::{CoulombLoad, FrictionModel, PositionRipple, ViscousCoulomb};
use std::f64::consts::PI;

const MASS: f64 = 2.0;
const VISCOUS: f64 = 20.0;
const RATE: f64 = 500.0;
const DURATION: f64 = 2.0;

/// The input [N] at time `t`: four sines.
fn input(t: f64) -> f64 {
    multisine(&four_tones(0.9, 0.0), t)
}

/// The samples `s`, linear between them (as the engine reads an input and a channel).
fn linear(s: &[f64], t: f64) -> f64 {
    linear_between_samples(s, RATE, t)
}

/// The reference record of `level` from rest at x = 0, with its input and named channels.
fn record(name: &str, level: SlideLevel<'_>, named: &[(&str, Vec<f64>)]) -> Record {
    let u: Vec<f64> = sample_times(DURATION, RATE)
        .iter()
        .map(|&t| input(t))
        .collect();
    let record = SlideReference::new(MASS, VISCOUS, (&u, RATE), level).record(name);
    named.iter().fold(record, |r, (n, values)| {
        r.with_named_channel(*n, values.clone())
    })
}

/// The slide as the fit knows it: its mass given, no spring, levels in N.
fn slide() -> Oscillator {
    driven_slide(MASS, 0.0)
}

/// The velocity route with the law's parameters alone, from the given start.
fn options() -> FitOptions {
    FitOptions {
        params: ParamOptions {
            guess: false,
            ..ParamOptions::default()
        },
        ..FitOptions::default()
    }
}

/// Every truth (name, value, tolerance: relative, or absolute where `absolute`) met by the
/// fit of `start`, and viscous_coulomb's residual at least five times the law's.
fn accept(
    case: &str,
    start: &(dyn FrictionModel + 'static),
    truths: &[(&str, f64, f64, bool)],
    records: &[Record],
) -> FitResult {
    let fitted = fit(&slide(), start, records, &options()).expect("a velocity fit");
    assert!(fitted.converged, "{case}: {}", fitted.termination);
    for &(name, truth, tolerance, absolute) in truths {
        let value = fitted.value(name).unwrap_or(f64::NAN);
        // An angle (absolute tolerance) is compared on the circle: a phase and that phase
        // less 2 pi are one ripple.
        let (off, allowed) = if absolute {
            ((value - truth + PI).rem_euclid(2.0 * PI) - PI, tolerance)
        } else {
            (value - truth, tolerance * truth.abs())
        };
        eprintln!("{case} {name}: {value} (truth {truth})");
        assert!(off.abs() <= allowed, "{case} {name}: {value}");
    }
    let plain = ViscousCoulomb {
        mu: 3.0,
        viscous: 15.0,
    };
    let other = fit(&slide(), &plain, records, &options()).expect("a viscous_coulomb fit");
    eprintln!(
        "{case}: rms {:e} against viscous_coulomb's {:e}",
        fitted.rms_residual, other.rms_residual
    );
    assert!(
        other.rms_residual > 5.0 * fitted.rms_residual.max(1e-12),
        "{case}"
    );
    fitted
}

/// A guide that rubs harder every 20 mm of its travel, driven back and forth over several
/// periods: `position_ripple` from a period 2 % off recovers every parameter.
#[test]
fn position_ripple_is_recovered_from_the_simulated_motion() {
    let (fc, fr, p, phase) = (3.0, 0.6, 0.02, 1.0);
    let level = |_t: f64, x: f64, _d: f64| fc + fr * (2.0 * PI * x / p + phase).sin();
    let records = [record("guide.csv", &level, &[])];
    let travel = records[0]
        .channel(Channel::Displacement)
        .map(|x| x.iter().fold(0.0f64, |m, v| m.max(v.abs())))
        .unwrap_or(0.0);
    assert!(travel > 2.0 * p, "the stroke spans {travel} m");
    let start = PositionRipple {
        mu: 2.5,
        ripple: 0.3,
        period: 0.0204,
        phase: 0.8,
        viscous: 15.0,
    };
    accept(
        "ripple",
        &start,
        &[
            ("mu", fc, 0.01, false),
            ("ripple", fr, 0.01, false),
            ("period", p, 0.01, false),
            ("phase", phase, 0.02, true),
            ("viscous", VISCOUS, 0.01, false),
        ],
        &records,
    );
}

/// A gearbox joint whose level grows with the load torque measured beside the motion:
/// `coulomb_load` reading the record's `load` channel, interpolated by the simulation,
/// recovers its unloaded level and load coefficient.
#[test]
fn coulomb_load_is_recovered_from_the_simulated_motion() {
    let (tc, mu_l) = (2.0, 0.05);
    let load_at =
        |t: f64| 30.0 * (2.0 * PI * 0.6 * t).sin() + 10.0 * (2.0 * PI * 1.7 * t + 1.0).sin();
    let load: Vec<f64> = sample_times(DURATION, RATE)
        .iter()
        .map(|&t| load_at(t))
        .collect();
    let level = |t: f64, _x: f64, _d: f64| tc + mu_l * linear(&load, t).abs();
    let records = [record("joint.csv", &level, &[("load", load.clone())])];
    let start = CoulombLoad {
        mu: 1.5,
        mu_load: 0.01,
        viscous: 15.0,
    };
    accept(
        "gearbox",
        &start,
        &[
            ("mu", tc, 0.01, false),
            ("mu_load", mu_l, 0.01, false),
            ("viscous", VISCOUS, 0.01, false),
        ],
        &records,
    );
}

/// What a simulation cannot give is refused before any fit: a channel the record lacks
/// (named with the record) and the acceleration (pointing to the force domain).
#[test]
fn a_velocity_fit_names_the_condition_a_record_cannot_give() {
    let time = sample_times(0.1, RATE);
    let u: Vec<f64> = time.iter().map(|&t| input(t)).collect();
    let v = vec![0.0; time.len()];
    let record = Record::from_time_base("bare.csv", TimeBase::new(time).expect("a time base"))
        .with_channel(Channel::Velocity, v)
        .with_channel(Channel::InputForce, u)
        .with_named_channel("temperature", vec![25.0; 51]);
    let load = CoulombLoad::default();
    let e = fit(&slide(), &load, std::slice::from_ref(&record), &options())
        .expect_err("no load channel")
        .to_string();
    assert!(
        e.contains("bare.csv") && e.contains("`load`") && e.contains("temperature"),
        "{e}"
    );
    let inertial =
        frictionid_models::Expression::new("fc * sign(v) + m0 * a", &[("fc", 1.0), ("m0", 0.1)])
            .expect("a formula");
    let e = fit(&slide(), &inertial, &[record], &options())
        .expect_err("a is refused")
        .to_string();
    assert!(e.contains("`a`") && e.contains("domain = \"force\""), "{e}");
}

/// The stick test reads the level at the channel's value of the moment: the FMM rig held at
/// 5 mm by `coulomb_load` while its load falls linearly from 20 N to 0 over a second breaks
/// away exactly when mu N + mu_load |load(t)| has fallen to the spring's k x0, and stays
/// put until then.
#[test]
fn a_mass_held_by_a_falling_load_breaks_away_when_its_level_meets_the_spring() {
    use frictionid_engine::simulate::{
        simulate_driven, ChannelSeries, EventKind, Initial, RunInputs, SampleGrid, SimOptions,
    };
    let osc = Oscillator::fmm();
    let (mu, mu_load, x0) = (0.2, 0.5, 0.005);
    let law = CoulombLoad {
        mu,
        mu_load,
        viscous: 0.0,
    };
    let channels = ChannelSeries::new("falling")
        .with_channel("load", vec![0.0, 1.0], vec![20.0, 0.0])
        .expect("a channel");
    let times = sample_times(0.5, 1000.0);
    let motion = simulate_driven(RunInputs {
        osc: &osc,
        model: &law,
        init: &Initial::at_rest(x0),
        input: None,
        channels: Some(&channels),
        grid: SampleGrid {
            t_end: 0.5,
            sample_times: &times,
        },
        opts: &SimOptions::default(),
    })
    .expect("a simulation");
    // mu N + mu_load 20 (1 - t) = k x0.
    let t_b = 1.0 - (osc.stiffness * x0 - mu * osc.normal_force) / (mu_load * 20.0);
    let kinds: Vec<EventKind> = motion.events.iter().map(|e| e.kind).collect();
    assert_eq!(
        kinds[..2],
        [EventKind::Stick, EventKind::Breakaway],
        "{kinds:?}"
    );
    let found = motion.events[1].time;
    eprintln!("breakaway at {found} s (closed form {t_b} s)");
    assert!((found - t_b).abs() < 1e-9, "{found} against {t_b}");
    for (t, x) in times.iter().zip(&motion.x) {
        if *t < t_b {
            assert_eq!(*x, x0, "t = {t}");
        }
    }
    assert!(
        motion.x.last().is_some_and(|&x| x < x0),
        "the spring pulls it back"
    );
}
