//! The force domain's analytic Jacobian against central differences of its residuals.
//!
//! A force-domain fit takes the columns of the law's parameters from one replay with
//! sensitivities, and those of the force offset and of the inverse-dynamics balance from their
//! linear terms, each mapped to the solver's internal coordinates (log or scaled) and weighted
//! like the residuals (a record's weight, its noise level, the samples `min_speed` keeps). Here
//! the whole Jacobian of a fit problem is compared with central differences of its residual
//! vector in internal coordinates (steps h and h/2, extrapolated), column by column: within
//! 1e-6 of the column's largest entry. The records: two force records of different noise,
//! weight and normal force, one of them compared only where it slides, and a driven axis on a
//! linear spring fitted by inverse dynamics with its mass, damping, stiffness and input offset.

use crate::util::{force_route_options, free, measured_force_options};
use frictionid_engine::identify::problem::{FitProblem, ProblemParts, Residuals};
use frictionid_engine::identify::search::build_layout;
use frictionid_engine::identify::{FitOptions, ForceAlongMotion, ForceTarget, OscillatorParam};
use frictionid_engine::record::{Channel, TimeBase};
use frictionid_engine::simulate::SimOptions;
use frictionid_engine::{Oscillator, Record};
use frictionid_models::{Dahl, FrictionModel, Gms, LuGre, Stribeck, ViscousCoulomb};
use nalgebra::DVector;
use std::f64::consts::PI;
use std::sync::Arc;

/// A record of `n` samples at 1 kHz moving as x = a sin(2 pi f t) + drift t, with a measured
/// force `force(t)` (the Jacobian does not depend on how well it fits), a normal force around
/// `n0` and the stated noise level.
fn force_record(
    name: &str,
    n: usize,
    (a, f, drift): (f64, f64, f64),
    n0: f64,
    noise: f64,
) -> Record {
    let time: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
    let w = 2.0 * PI * f;
    let x = time.iter().map(|t| a * (w * t).sin() + drift * t).collect();
    let v: Vec<f64> = time.iter().map(|t| a * w * (w * t).cos() + drift).collect();
    let normal = time
        .iter()
        .map(|t| n0 * (1.0 + 0.1 * (2.0 * PI * 0.7 * t).sin()))
        .collect();
    let force = v.iter().map(|v| 0.2 * n0 * (v / 0.01).tanh()).collect();
    Record::from_time_base(name, TimeBase::new(time).expect("time base"))
        .with_channel(Channel::Displacement, x)
        .with_channel(Channel::Velocity, v)
        .with_channel(Channel::NormalForce, normal)
        .with_channel(Channel::Force, force)
        .with_noise(Channel::Force, noise)
}

fn force_records() -> Vec<Record> {
    let mut second = force_record("b", 1500, (2e-3, 0.9, 1e-3), 8.0, 0.05);
    second.weight = 0.4;
    vec![
        force_record("a", 2000, (5e-3, 1.7, 0.0), 14.5, 0.02),
        second,
    ]
}

/// A driven axis on a spring: its input u = m a + c v + k x + offset + a smooth friction.
fn driven_record() -> Record {
    let time: Vec<f64> = (0..3000).map(|i| i as f64 * 1e-3).collect();
    let w = 2.0 * PI * 1.1;
    let x: Vec<f64> = time.iter().map(|t| 4e-3 * (w * t).sin()).collect();
    let v: Vec<f64> = time.iter().map(|t| 4e-3 * w * (w * t).cos()).collect();
    let a: Vec<f64> = time.iter().map(|t| -4e-3 * w * w * (w * t).sin()).collect();
    let u = (0..time.len())
        .map(|i| 2.0 * a[i] + 3.0 * v[i] + 500.0 * x[i] + 0.3 + 1.5 * (v[i] / 0.005).tanh())
        .collect();
    Record::from_time_base("driven", TimeBase::new(time).expect("time base"))
        .with_channel(Channel::Displacement, x)
        .with_channel(Channel::Velocity, v)
        .with_channel(Channel::Acceleration, a)
        .with_channel(Channel::InputForce, u)
        .with_noise(Channel::InputForce, 0.05)
}

fn force_options(names: &[&str]) -> FitOptions {
    let mut opts = measured_force_options();
    opts.target.force_offset = true;
    opts.target.min_speed = Some(5e-4);
    opts.params.free = free(names);
    opts
}

fn inverse_options(names: &[&str]) -> FitOptions {
    let mut opts = force_route_options();
    opts.target.force_target = ForceTarget::InverseDynamics;
    opts.target.force_offset = true;
    opts.params.oscillator = vec![
        OscillatorParam::Mass,
        OscillatorParam::Damping,
        OscillatorParam::Stiffness,
        OscillatorParam::InputOffset,
    ];
    opts.params.free = free(names);
    opts
}

/// The fit problem of `model` on `records` under `opts`, at its starting point moved off the
/// guess by a few per cent (so that no parameter sits where a derivative vanishes by symmetry).
fn problem(
    model: &(dyn FrictionModel + 'static),
    records: Vec<Record>,
    osc: Oscillator,
    opts: &FitOptions,
) -> (FitProblem<ForceAlongMotion>, Vec<f64>) {
    let residuals = ForceAlongMotion::new(&records, &osc, opts).expect("a force-domain problem");
    let model: Box<dyn FrictionModel> = frictionid_models::clone_model(model);
    let layout = build_layout(
        &osc,
        model.as_ref(),
        &records,
        &residuals,
        &opts.params,
        &opts.energy,
    )
    .expect("a layout");
    // GMS's sharpness stays where its steps are exact.
    let start: Vec<f64> = layout
        .start
        .iter()
        .zip(&layout.params)
        .enumerate()
        .map(|(j, (&p, f))| match p {
            _ if f.name == "sharpness" => p,
            0.0 => 0.05,
            _ => p * (1.0 + 0.03 * (j as f64 + 1.0).sin()),
        })
        .collect();
    let parts = ProblemParts {
        oscillator: osc,
        model: layout.start_model,
        records: records.into(),
        layout: layout.params,
        sim: SimOptions::default(),
        parallel: false,
    };
    (FitProblem::new(Arc::new(residuals), parts), start)
}

/// Column j of the residuals' derivative in internal coordinates by central differences with
/// steps h and h/2, extrapolated.
fn differenced(problem: &FitProblem<ForceAlongMotion>, u: &DVector<f64>, j: usize) -> DVector<f64> {
    let at = |d: f64| {
        let mut moved = u.clone();
        moved[j] += d;
        problem
            .residuals_at(&problem.physical(&moved))
            .expect("residuals")
    };
    let h = 1e-6 * u[j].abs().max(1.0);
    let central = |h: f64| (at(h) - at(-h)) / (2.0 * h);
    central(0.5 * h) * 2.0 - central(h)
}

/// Every column the producer gives matches central differences; the ones it leaves (named in
/// `left`: the fit takes them by forward differences through the numerical replay, whose
/// tolerance leaves them far less exact) are finite.
fn check(
    model: &(dyn FrictionModel + 'static),
    records: Vec<Record>,
    osc: Oscillator,
    opts: &FitOptions,
    left: &[&str],
) {
    let (problem, p) = problem(model, records, osc, opts);
    let r0 = problem.residuals_at(&p).expect("residuals");
    let u = problem.internal(&p);
    let jac = problem.jacobian_internal(&u, &r0);
    assert!(problem.residuals.has_jacobian());
    for (j, f) in problem.layout.iter().enumerate() {
        if left.contains(&f.name.as_str()) {
            assert!(jac.column(j).iter().all(|x| x.is_finite()), "{}", f.name);
            continue;
        }
        let expected = differenced(&problem, &u, j);
        let largest = expected.amax();
        let worst = (jac.column(j) - &expected).amax();
        assert!(
            worst <= 1e-6 * largest && largest > 0.0,
            "{} column {}: worst difference {worst:e}, largest entry {largest:e}",
            model.name(),
            f.name
        );
    }
}

#[test]
fn the_law_and_offset_columns_of_force_records_are_the_residuals_derivatives() {
    let lugre = ["sigma0", "sigma1", "sigma2", "mu_c", "mu_s", "v_s"];
    check(
        &LuGre::default(),
        force_records(),
        Oscillator::fmm(),
        &force_options(&lugre),
        &[],
    );
    let dahl = ["sigma0", "mu_c", "alpha"];
    let alpha = Dahl {
        alpha: 1.7,
        ..Dahl::default()
    };
    check(
        &Dahl::default(),
        force_records(),
        Oscillator::fmm(),
        &force_options(&dahl),
        &[],
    );
    check(
        &alpha,
        force_records(),
        Oscillator::fmm(),
        &force_options(&dahl),
        &[],
    );
    let gms = [
        "k_1",
        "k_2",
        "w_1",
        "sigma_1",
        "mu_c",
        "mu_s",
        "v_s",
        "delta",
        "sharpness",
        "viscous",
    ];
    let damped = Gms {
        sharpness: 1.0,
        ..Gms::with_elements(2)
    };
    let mut damped = damped;
    damped.elements[0].damping = 4.0;
    check(
        &damped,
        force_records(),
        Oscillator::fmm(),
        &force_options(&gms),
        &["sharpness"],
    );
    let stribeck = ["mu_c", "mu_s", "v_s", "delta", "viscous"];
    check(
        &Stribeck::default(),
        force_records(),
        Oscillator::fmm(),
        &force_options(&stribeck),
        &[],
    );
}

#[test]
fn the_balance_columns_of_inverse_dynamics_are_the_residuals_derivatives() {
    let osc = Oscillator {
        mass: 2.2,
        damping: 2.5,
        stiffness: 450.0,
        normal_force: 1.0,
        ..Oscillator::fmm()
    };
    let laws: [(&(dyn FrictionModel + 'static), [&str; 2]); 2] = [
        (&ViscousCoulomb::default(), ["mu", "viscous"]),
        (&Dahl::default(), ["sigma0", "mu_c"]),
    ];
    for (law, free) in laws {
        check(
            law,
            vec![driven_record()],
            osc,
            &inverse_options(&free),
            &[],
        );
    }
}

/// The columns the producer gives directly are every law parameter, GMS's sharpness included
/// (its steps are exact at any sharpness), and the offsets, not a restoring law's own
/// parameters.
#[test]
fn the_producer_gives_every_column_it_has_in_closed_form() {
    let gms = ["k_1", "w_1", "mu_c", "sharpness"];
    let (problem, p) = problem(
        &Gms::default(),
        force_records(),
        Oscillator::fmm(),
        &force_options(&gms),
    );
    let world = problem.realise(&p).expect("a world");
    let at = problem.evaluation(&world);
    for (index, record) in problem.records.iter().enumerate() {
        let case = frictionid_engine::identify::problem::RecordCase {
            index,
            record,
            nuisance: &world.nuisance[index],
        };
        let columns = problem
            .residuals
            .jacobian_columns(&at, case, &problem.layout)
            .expect("columns");
        let given: Vec<&str> = problem
            .layout
            .iter()
            .zip(&columns)
            .filter(|(_, c)| c.is_some())
            .map(|(f, _)| f.name.as_str())
            .collect();
        assert_eq!(
            given,
            [
                "k_1",
                "w_1",
                "mu_c",
                "sharpness",
                "force_offset[a]",
                "force_offset[b]"
            ],
            "record {index}"
        );
    }
}
