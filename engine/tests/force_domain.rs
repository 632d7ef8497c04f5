//! Fits in the force domain against independent truths: a LuGre force along a prescribed
//! sinusoidal motion under a varying normal force, integrated in this file by a fixed-step
//! classical Runge-Kutta scheme (not the engine's stepper); and the energy-based route
//! (Eq. 7, no force sensor) on the exact Coulomb free vibration and on Stribeck records.

use crate::util::{
    force_route_options, measured_force_options, records, rel, stribeck_truth, two_element_gms,
    NOISE,
};
use frictionid_engine::energy::model_force_along;
use frictionid_engine::exact::coulomb_free_vibration;
use frictionid_engine::identify::{fit, FitOptions, ForceTarget, Identifiability, TargetOptions};
use frictionid_engine::record::{Channel, TimeBase};
use frictionid_engine::synthetic::add_gaussian_noise;
use frictionid_engine::{Oscillator, Record};
use frictionid_models::{Coulomb, FrictionModel, Gms, LuGre, Stribeck};
use std::f64::consts::PI;

/// The prescribed motion: x = A sin(w t), 5 mm at 2 Hz.
const AMPLITUDE: f64 = 5e-3;
const OMEGA: f64 = 2.0 * PI * 2.0;

fn x_of(t: f64) -> f64 {
    AMPLITUDE * (OMEGA * t).sin()
}

fn v_of(t: f64) -> f64 {
    AMPLITUDE * OMEGA * (OMEGA * t).cos()
}

/// The normal force: 10 N with a 2 N swing at 0.3 Hz.
fn n_of(t: f64) -> f64 {
    10.0 + 2.0 * (2.0 * PI * 0.3 * t).sin()
}

fn lugre_truth() -> LuGre {
    LuGre {
        sigma0: 1e5,
        sigma1: 300.0,
        sigma2: 5.0,
        mu_c: 0.2,
        mu_s: 0.3,
        v_s: 0.01,
    }
}

/// LuGre written out here: dz/dt = v - sigma0 |v| z / g(v), F = sigma0 z + sigma1 z' + sigma2 v.
fn lugre_rates(p: &LuGre, t: f64, z: f64) -> (f64, f64) {
    let v = v_of(t);
    let g = n_of(t) * (p.mu_c + (p.mu_s - p.mu_c) * (-(v / p.v_s).powi(2)).exp());
    let dz = v - p.sigma0 * v.abs() * z / g;
    (dz, p.sigma0 * z + p.sigma1 * dz + p.sigma2 * v)
}

/// The truth force at `samples` sample instants 1 ms apart, from z(0) = 0, by classical RK4
/// with 100 fixed steps per sample (h = 1e-5 s; the bristle rate sigma0 |v| / g is at most
/// 3e3 1/s, so h * rate <= 0.03).
fn lugre_force_record(p: &LuGre, samples: usize) -> (Vec<f64>, Vec<f64>) {
    let dt = 1e-3;
    let sub = 100;
    let h = dt / sub as f64;
    let (mut t, mut z) = (0.0, 0.0);
    let mut time = Vec::with_capacity(samples);
    let mut force = Vec::with_capacity(samples);
    for i in 0..samples {
        if i > 0 {
            for _ in 0..sub {
                let k1 = lugre_rates(p, t, z).0;
                let k2 = lugre_rates(p, t + h / 2.0, z + h / 2.0 * k1).0;
                let k3 = lugre_rates(p, t + h / 2.0, z + h / 2.0 * k2).0;
                let k4 = lugre_rates(p, t + h, z + h * k3).0;
                z += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                t += h;
            }
        }
        t = i as f64 * dt;
        time.push(t);
        force.push(lugre_rates(p, t, z).1);
    }
    (time, force)
}

fn force_record(time: Vec<f64>, force: Vec<f64>) -> Record {
    let x = time.iter().map(|&t| x_of(t)).collect();
    let v = time.iter().map(|&t| v_of(t)).collect();
    let n = time.iter().map(|&t| n_of(t)).collect();
    Record::from_time_base("lugre-rig", TimeBase::new(time).expect("time base"))
        .with_channel(Channel::Displacement, x)
        .with_channel(Channel::Velocity, v)
        .with_channel(Channel::NormalForce, n)
        .with_channel(Channel::Force, force)
}

/// m, c, k play no part: a measured force needs only the normal force.
fn force_options() -> FitOptions {
    measured_force_options()
}

fn lugre_errors(fitted: &dyn FrictionModel) -> Vec<(String, f64)> {
    let truth = lugre_truth().params();
    fitted
        .param_info()
        .into_iter()
        .zip(fitted.params().into_iter().zip(truth))
        .map(|(p, (got, want))| (p.name, rel(got, want)))
        .collect()
}

#[test]
fn lugre_is_recovered_from_its_force_along_a_sinusoid_under_a_varying_normal_force() {
    let (time, force) = lugre_force_record(&lugre_truth(), 3001);
    let record = force_record(time, force);
    let osc = Oscillator::fmm();
    let r = fit(&osc, &LuGre::default(), &[record], &force_options()).unwrap();
    assert!(r.converged, "{}", r.termination);
    assert_eq!(
        (r.compared.as_str(), r.residual_unit.as_str()),
        ("force", "N")
    );
    for (name, e) in lugre_errors(r.fitted_model.as_ref()) {
        assert!(e < 1e-3, "noise-free {name}: relative error {e:e}");
    }
}

#[test]
fn lugre_is_recovered_within_two_percent_from_a_noisy_force_with_a_load_cell_offset() {
    let (time, mut force) = lugre_force_record(&lugre_truth(), 3001);
    let sigma = 0.02;
    add_gaussian_noise(&mut force, sigma, 7);
    for f in &mut force {
        *f += 0.15;
    }
    let record = force_record(time, force);
    let opts = FitOptions {
        target: TargetOptions {
            force_offset: true,
            ..force_options().target.clone()
        },
        ..force_options()
    };
    let r = fit(&Oscillator::fmm(), &LuGre::default(), &[record], &opts).unwrap();
    assert!(r.converged, "{}", r.termination);
    for (name, e) in lugre_errors(r.fitted_model.as_ref()) {
        assert!(e < 0.02, "noisy {name}: relative error {e}");
    }
    let offset = r.value("force_offset[lugre-rig]").unwrap();
    assert!(
        (offset - 0.15).abs() < 3.0 * sigma / 10.0,
        "offset {offset}"
    );
    // The residuals are the noise, in N.
    assert!(rel(r.rms_residual, sigma) < 0.05, "rms {}", r.rms_residual);
}

/// The exact Coulomb free vibration from 10, 14 and 22 mm (2 s at 1 kHz).
fn coulomb_records(osc: &Oscillator, mu: f64, noise: f64) -> Vec<Record> {
    let time: Vec<f64> = (0..2001).map(|i| i as f64 * 1e-3).collect();
    [0.010, 0.014, 0.022]
        .iter()
        .enumerate()
        .map(|(i, &x0)| {
            let mut v = coulomb_free_vibration(osc, mu * osc.normal_force, x0, &time)
                .expect("exact solution")
                .v;
            if noise > 0.0 {
                add_gaussian_noise(&mut v, noise, 40 + i as u64);
            }
            Record::new(format!("x{i}"), time.clone(), v, x0)
        })
        .collect()
}

fn energy_options() -> FitOptions {
    let mut opts = force_route_options();
    opts.target.force_target = ForceTarget::Energy;
    opts
}

#[test]
fn the_energy_based_route_gives_coulomb_mu() {
    let osc = Oscillator::fmm();
    let clean = fit(
        &osc,
        &Coulomb::default(),
        &coulomb_records(&osc, 0.24, 0.0),
        &energy_options(),
    )
    .unwrap();
    let mu = clean.value("mu").unwrap();
    assert!(rel(mu, 0.24) < 5e-3, "noise-free mu = {mu}");
    assert!(clean.param("mu").unwrap().std_error.is_some());
    let noisy = fit(
        &osc,
        &Coulomb::default(),
        &coulomb_records(&osc, 0.24, NOISE),
        &energy_options(),
    )
    .unwrap();
    let mu = noisy.value("mu").unwrap();
    assert!(rel(mu, 0.24) < 1e-2, "noisy mu = {mu}");
}

#[test]
fn the_energy_based_route_gives_the_stribeck_curve() {
    let osc = Oscillator::fmm();
    let truth = stribeck_truth();
    let clean = fit(
        &osc,
        &Stribeck::default(),
        &records(&osc, &truth, 0.0, 1),
        &energy_options(),
    )
    .unwrap();
    for (name, want) in [
        ("mu_c", truth.mu_c),
        ("mu_s", truth.mu_s),
        ("v_s", truth.v_s),
        ("viscous", truth.viscous),
    ] {
        let got = clean.value(name).unwrap();
        assert!(
            rel(got, want) < 5e-3,
            "noise-free {name} = {got}, truth {want}"
        );
    }
    let noisy = fit(
        &osc,
        &Stribeck::default(),
        &records(&osc, &truth, NOISE, 51),
        &energy_options(),
    )
    .unwrap();
    let mu_c = noisy.value("mu_c").unwrap();
    assert!(rel(mu_c, truth.mu_c) < 1e-2, "noisy mu_c = {mu_c}");
}

/// A reciprocating record whose reversals stick: the table slides at up to 20 mm/s for two
/// thirds of each 1 s cycle (v = 0.02 (|sin| - 1/2) / (1/2) sgn(sin), zero while |sin| < 1/2)
/// and dwells for the rest, where the measured velocity is a dither of +-1e-5 m/s (encoder
/// noise) and the force reverses with the drive from +-F to -+F (F = 2 F_s sin: the contact's
/// static load). The sliding force is Coulomb, F_s = mu N = 0.3 x 10 N = 3 N: the oracle.
fn sticking_reversals() -> Record {
    let (sliding, normal) = (3.0, 10.0);
    let n = 4000;
    let dt = 1e-3;
    let omega = 2.0 * PI;
    let mut time = Vec::with_capacity(n);
    let (mut v, mut f) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for i in 0..n {
        let t = i as f64 * dt;
        let s = (omega * t).sin();
        time.push(t);
        if s.abs() >= 0.5 {
            v.push(0.02 * (s.abs() - 0.5) / 0.5 * s.signum());
            f.push(sliding * s.signum());
        } else {
            v.push(if i % 2 == 0 { 1e-5 } else { -1e-5 });
            f.push(2.0 * sliding * s);
        }
    }
    Record::from_time_base("reversals", TimeBase::new(time).expect("time base"))
        .with_channel(Channel::Velocity, v)
        .with_channel(Channel::Force, f)
        .with_channel(Channel::NormalForce, vec![normal; n])
}

#[test]
fn min_speed_recovers_the_sliding_level_that_stick_phases_drag_down() {
    let record = sticking_reversals();
    let osc = Oscillator::fmm();
    let all = fit(
        &osc,
        &Coulomb::default(),
        std::slice::from_ref(&record),
        &force_options(),
    )
    .unwrap();
    let dragged = all.value("mu").unwrap();
    assert!(dragged < 0.8 * 0.3, "every sample: mu = {dragged}");
    assert!(all.records[0].sliding.is_none());
    let sliding = FitOptions {
        target: TargetOptions {
            min_speed: Some(1e-3),
            ..force_options().target.clone()
        },
        ..force_options()
    };
    let r = fit(&osc, &Coulomb::default(), &[record], &sliding).unwrap();
    let mu = r.value("mu").unwrap();
    assert!(rel(mu, 0.3) < 1e-9, "sliding samples: mu = {mu}");
    let kept = r.records[0].sliding.expect("the kept samples are reported");
    assert_eq!((kept.min_speed, kept.of), (1e-3, 4000));
    // |v| >= 1 mm/s where |sin| >= 0.525: 1 - (2/pi) asin(0.525) = 64.8 % of the samples.
    assert!(
        (2400..2667).contains(&kept.kept),
        "kept {} of {}",
        kept.kept,
        kept.of
    );
    // Every writer shows the record table: its last column holds the count.
    let table = frictionid_engine::report::fit::record_table(&r);
    assert_eq!(
        table.headers.last().map(String::as_str),
        Some("samples with |v| >= 0.001 m/s")
    );
    assert_eq!(
        table.rows[0].last(),
        Some(&format!("{} of 4000", kept.kept))
    );
    let json = serde_json::to_value(&r.records[0]).unwrap();
    assert_eq!(json["sliding"]["kept"].as_u64(), Some(kept.kept as u64));
    let plain = frictionid_engine::report::fit::record_table(&all);
    assert!(!plain.headers.iter().any(|h| h.contains("|v|")));
}

#[test]
fn min_speed_is_a_force_domain_option_and_a_speed() {
    let record = sticking_reversals();
    let osc = Oscillator::fmm();
    for (opts, says) in [
        (
            FitOptions {
                target: TargetOptions {
                    min_speed: Some(1e-3),
                    ..TargetOptions::default()
                },
                ..FitOptions::default()
            },
            "min_speed applies to force-domain fits only",
        ),
        (
            FitOptions {
                target: TargetOptions {
                    min_speed: Some(-1.0),
                    ..force_options().target.clone()
                },
                ..force_options()
            },
            "min_speed must be a speed >= 0 (m/s), got -1",
        ),
        (
            FitOptions {
                target: TargetOptions {
                    min_speed: Some(1.0),
                    ..force_options().target.clone()
                },
                ..force_options()
            },
            "0 samples slide with |v| >= [fit.options] min_speed = 1 m/s; lower it",
        ),
    ] {
        let e = fit(
            &osc,
            &Coulomb::default(),
            std::slice::from_ref(&record),
            &opts,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains(says), "{e}");
    }
}

/// GMS's two elements ([`two_element_gms`]) along the prescribed motion under a constant
/// 10 N, replayed exactly (its Jacobian is the replay's sensitivities), with 0.01 N of noise.
fn gms_force_record() -> (Gms, Record) {
    let truth = two_element_gms();
    let time: Vec<f64> = (0..2000).map(|i| i as f64 * 1e-3).collect();
    let x: Vec<f64> = time.iter().map(|&t| x_of(t)).collect();
    let v: Vec<f64> = time.iter().map(|&t| v_of(t)).collect();
    let osc = Oscillator {
        normal_force: 10.0,
        ..Oscillator::fmm()
    };
    let mut force = model_force_along(&truth, &osc, &time, &v).unwrap();
    add_gaussian_noise(&mut force, 0.01, 17);
    let record = Record::from_time_base("gms", TimeBase::new(time).unwrap())
        .with_channel(Channel::Displacement, x)
        .with_channel(Channel::Velocity, v)
        .with_channel(Channel::Force, force);
    (truth, record)
}

/// The sliding force is each weight times the levels: scaling the weights up and the levels
/// down by one factor changes nothing, so with both free the records fix only their
/// products. Each weight and level is reported not identifiable, no standard error, named by
/// one identifiability warning (their profiles' verdicts overruled, not beside it); the
/// stiffnesses stay determined. With the weights fixed at
/// the truth the levels are determined and within 3 standard errors of it.
#[test]
fn gms_weights_and_levels_free_together_are_reported_redundant() {
    let (truth, record) = gms_force_record();
    let osc = Oscillator {
        normal_force: 10.0,
        ..Oscillator::fmm()
    };
    let records = [record];
    let every = fit(
        &osc,
        &Gms::with_elements(2),
        &records,
        &measured_force_options(),
    )
    .unwrap();
    for name in ["w_1", "w_2", "mu_c", "mu_s"] {
        let p = every.param(name).unwrap();
        assert_eq!(
            p.identifiability,
            Some(Identifiability::NotIdentifiable),
            "{p:?}"
        );
        assert!(p.std_error.is_none(), "{p:?}");
    }
    for name in ["k_1", "k_2"] {
        let p = every.param(name).unwrap();
        assert_eq!(
            p.identifiability,
            Some(Identifiability::Determined),
            "{p:?}"
        );
    }
    let named = every
        .diagnostics
        .iter()
        .filter(|f| f.message.contains("not identifiable one by one"))
        .count();
    assert_eq!(named, 1, "{:?}", every.diagnostics);
    // Their profiles' own verdicts are overruled, not reported beside it.
    let profile_verdicts = every.diagnostics.iter().filter(|f| {
        ["w_1", "w_2", "mu_c", "mu_s"].iter().any(|n| {
            f.message.starts_with(&format!("{n} "))
                || f.message
                    .starts_with(&format!("`{n}` is not identifiable from"))
        })
    });
    assert_eq!(profile_verdicts.count(), 0, "{:?}", every.diagnostics);
    let mut weights_fixed = measured_force_options();
    weights_fixed.params.free = Some(
        ["k_1", "k_2", "mu_c", "mu_s", "v_s"]
            .map(String::from)
            .to_vec(),
    );
    let levels = fit(&osc, &truth, &records, &weights_fixed).unwrap();
    for (name, t) in [("mu_c", truth.mu_c), ("mu_s", truth.mu_s)] {
        let p = levels.param(name).unwrap();
        assert_eq!(
            p.identifiability,
            Some(Identifiability::Determined),
            "{p:?}"
        );
        let se = p.std_error.unwrap();
        assert!((p.value - t).abs() <= 3.0 * se, "{p:?}");
    }
}
