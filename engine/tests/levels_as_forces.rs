//! Velocity fits without a normal force: neither the oscillator nor any record gives N, so the
//! law's levels are forces (torques on a rotary axis), fitted over N = 1 with bounds from the
//! records. The records are the exact piecewise solution of the free decay
//! (`frictionid_engine::exact`, independent of the simulation driver) with a known Coulomb
//! force, and for a viscous + Coulomb law the same solution with the law's viscous
//! coefficient added to the damping (F = F_c sgn(v) + b v is Coulomb friction on a stage of
//! damping c + b). A record with its own normal force keeps the levels coefficients.

use frictionid_engine::axis::Axis;
use frictionid_engine::exact::coulomb_free_vibration;
use frictionid_engine::identify::{fit, FitOptions, FitResult, Status, TargetOptions};
use frictionid_engine::oscillator::OscillatorProperty;
use frictionid_engine::record::NormalForce;
use frictionid_engine::synthetic::{add_gaussian_noise, uniform_times};
use frictionid_engine::{Oscillator, Record};
use frictionid_models::{Coulomb, FrictionModel, ViscousCoulomb};

/// The FMM stage without its normal force (m, c and k as the paper gives them).
fn linear_stage() -> Oscillator {
    Oscillator {
        normal_force: 0.0,
        ..Oscillator::fmm()
    }
}

/// A torsional stage: J = 0.05 kg m^2, c = 0.01 N m s/rad, k = 20 N m/rad.
fn rotary_stage() -> Oscillator {
    Oscillator {
        mass: 0.05,
        damping: 0.01,
        stiffness: 20.0,
        normal_force: 0.0,
        axis: Axis::Rotary,
        ..Oscillator::fmm()
    }
}

/// The exact decay of `osc` (its damping plus `viscous`) from `x0` under the Coulomb force
/// `level`, sampled at 1 kHz for `duration`, with Gaussian velocity noise `noise`.
fn decay(
    osc: &Oscillator,
    level: f64,
    viscous: f64,
    (x0, duration, noise): (f64, f64, f64),
) -> Record {
    let damped = Oscillator {
        damping: osc.damping + viscous,
        ..*osc
    };
    let time = uniform_times(duration, 1000.0);
    let exact = coulomb_free_vibration(&damped, level, x0, &time).expect("an exact decay");
    let mut v = exact.v;
    add_gaussian_noise(&mut v, noise, 11);
    Record::new("decay", time, v, x0)
}

/// A velocity fit with no normal force given anywhere (as a configuration without
/// `[oscillator] normal_force` asks for it).
fn fit_without_normal_force(
    osc: &Oscillator,
    model: &(dyn FrictionModel + 'static),
    record: Record,
) -> FitResult {
    let opts = FitOptions {
        target: TargetOptions {
            unknown_oscillator: vec![OscillatorProperty::NormalForce],
            ..TargetOptions::default()
        },
        ..FitOptions::default()
    };
    let result = fit(osc, model, &[record], &opts).expect("a fit");
    for finding in &result.diagnostics {
        eprintln!("{:?}: {}", finding.status, finding.message);
    }
    assert!(result.converged, "{}", result.termination);
    let failed: Vec<&str> = result
        .diagnostics
        .iter()
        .filter(|f| f.status == Status::Fail)
        .map(|f| f.message.as_str())
        .collect();
    assert!(failed.is_empty(), "{failed:?}");
    result
}

/// `name`'s value and unit.
fn value_and_unit(result: &FitResult, name: &str) -> (f64, String) {
    let p = result.param(name).expect("a fitted parameter");
    (p.value, p.unit.clone())
}

/// A Coulomb level of 20 N (a coefficient's start would be clipped at 5, its bound is 10): the
/// fit returns 20 N within 0.5 %.
#[test]
fn a_coulomb_level_without_normal_force_is_fitted_in_newtons() {
    let osc = linear_stage();
    let record = decay(&osc, 20.0, 0.0, (0.1, 1.5, 2e-4));
    let result = fit_without_normal_force(&osc, &Coulomb { mu: 0.2 }, record);
    let (mu, unit) = value_and_unit(&result, "mu");
    eprintln!("mu = {mu} {unit}");
    assert_eq!(unit, "N");
    assert!((mu / 20.0 - 1.0).abs() < 5e-3, "{mu}");
}

/// A viscous + Coulomb law: the level (3.48 N) in N within 0.5 %, the viscous coefficient
/// (2 N s/m) in N s/m within 5 %.
#[test]
fn a_viscous_coulomb_law_without_normal_force_is_fitted_in_newtons() {
    let osc = linear_stage();
    let record = decay(&osc, 3.48, 2.0, (0.022, 2.0, 2e-4));
    let model = ViscousCoulomb {
        mu: 0.2,
        viscous: 0.5,
    };
    let result = fit_without_normal_force(&osc, &model, record);
    let (mu, mu_unit) = value_and_unit(&result, "mu");
    let (viscous, viscous_unit) = value_and_unit(&result, "viscous");
    eprintln!("mu = {mu} {mu_unit}, viscous = {viscous} {viscous_unit}");
    assert_eq!((mu_unit.as_str(), viscous_unit.as_str()), ("N", "N s/m"));
    assert!((mu / 3.48 - 1.0).abs() < 5e-3, "{mu}");
    assert!((viscous / 2.0 - 1.0).abs() < 0.05, "{viscous}");
}

/// On a rotary axis the level is a torque: 0.3 N m within 0.5 %, and a viscous coefficient
/// (0.02 N m s/rad) in N m s/rad.
#[test]
fn on_a_rotary_axis_the_levels_are_torques_in_newton_metres() {
    let osc = rotary_stage();
    let record = decay(&osc, 0.3, 0.02, (0.2, 3.0, 1e-3));
    let model = ViscousCoulomb {
        mu: 0.2,
        viscous: 0.5,
    };
    let result = fit_without_normal_force(&osc, &model, record);
    let (mu, mu_unit) = value_and_unit(&result, "mu");
    let (viscous, viscous_unit) = value_and_unit(&result, "viscous");
    eprintln!("mu = {mu} {mu_unit}, viscous = {viscous} {viscous_unit}");
    assert_eq!(
        (mu_unit.as_str(), viscous_unit.as_str()),
        ("N m", "N m s/rad")
    );
    assert!((mu / 0.3 - 1.0).abs() < 5e-3, "{mu}");
    assert!((viscous / 0.02 - 1.0).abs() < 0.05, "{viscous}");
}

/// A record with its own normal force (14.5 N) keeps the levels coefficients: mu = 0.24 of a
/// 3.48 N level, dimensionless. Beside a record without one (and no oscillator's), it is an
/// error naming that record.
#[test]
fn a_records_own_normal_force_keeps_the_levels_coefficients() {
    let osc = linear_stage();
    let mut own = decay(&osc, 3.48, 0.0, (0.014, 1.5, 2e-4));
    own.set_normal_force(Some(NormalForce::Constant(14.5)));
    let result = fit_without_normal_force(&osc, &Coulomb { mu: 0.2 }, own.clone());
    let (mu, unit) = value_and_unit(&result, "mu");
    eprintln!("mu = {mu} {unit}");
    assert_eq!(unit, "1");
    assert!((mu / 0.24 - 1.0).abs() < 5e-3, "{mu}");
    let mut bare = decay(&osc, 3.48, 0.0, (0.022, 1.5, 2e-4));
    bare.name = "bare".into();
    let opts = FitOptions {
        target: TargetOptions {
            unknown_oscillator: vec![OscillatorProperty::NormalForce],
            ..TargetOptions::default()
        },
        ..FitOptions::default()
    };
    let e = fit(&osc, &Coulomb { mu: 0.2 }, &[own, bare], &opts).unwrap_err();
    assert_eq!(
        e.to_string(),
        "record `bare`: no normal force: give [oscillator] normal_force, the record's \
         `normal_force` or a normal_force channel (other records have one)"
    );
}
