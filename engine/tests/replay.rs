//! The replay of dynamic laws along long measured motions against an independent integration
//! of the same motion. A synthetic record of 100 000 samples at 1 kHz alternates slow stretches
//! (2 mm/s), fast ones (up to 0.25 m/s, with a 7 Hz ripple) and stretches of constant velocity,
//! with hundreds of reversals, under a normal force that swings by 3 N. The engine replays it
//! with the laws' exact steps; the reference integrates each law's `state_derivative` over every
//! sample interval at the replay's constant velocity and normal force (the convention of
//! `energy::model_force`) with the model harness's step-doubling Dormand-Prince integration at
//! rtol 1e-12, knowing nothing of the exact steps. The forces agree within 1e-9 of the force
//! level; the replay's force derivatives agree with central differences of the replayed force
//! (extrapolated, so that a load crossing zero within a step costs no accuracy) within 1e-6 of
//! each parameter's largest derivative.

use crate::util::{assert_derivative_matches, central_difference};
use frictionid_engine::energy::{
    force_derivatives_along, model_force_with_normal, replay_interval, states_along, MeasuredMotion,
};
use frictionid_engine::record::NormalForce;
use frictionid_models::testing::reference::{integrate, Tolerance};
use frictionid_models::{Dahl, FrictionModel, Gms, LuGre};
use std::f64::consts::PI;

const SAMPLES: usize = 100_000;
const RATE: f64 = 1000.0;

/// The velocity at `t`: ten-second blocks of slow oscillation, fast oscillation with a ripple,
/// and constant velocity (forwards, then backwards).
fn velocity(t: f64) -> f64 {
    let block = (t / 10.0) as usize % 4;
    match block {
        0 => 2e-3 * (2.0 * PI * 0.2 * t).sin(),
        1 => 0.2 * (2.0 * PI * 1.3 * t).sin() + 0.05 * (2.0 * PI * 7.0 * t).sin(),
        2 => {
            if (t % 10.0) < 5.0 {
                0.03
            } else {
                -2e-3
            }
        }
        _ => 0.1 * (2.0 * PI * 0.4 * t).sin() + 1e-3,
    }
}

struct Motion {
    time: Vec<f64>,
    v: Vec<f64>,
    normal: NormalForce,
}

fn motion() -> Motion {
    let time: Vec<f64> = (0..SAMPLES).map(|i| i as f64 / RATE).collect();
    let v = time.iter().map(|&t| velocity(t)).collect();
    let normal = time
        .iter()
        .map(|&t| 14.5 + 3.0 * (2.0 * PI * 0.05 * t).sin())
        .collect();
    Motion {
        time,
        v,
        normal: NormalForce::Sampled(normal),
    }
}

impl Motion {
    fn measured(&self) -> MeasuredMotion<'_> {
        MeasuredMotion {
            time: &self.time,
            v: &self.v,
            normal: &self.normal,
        }
    }
}

/// Each state's scale along the record (the largest it reaches in the replay), for the
/// reference's absolute tolerance.
fn state_scales(model: &dyn FrictionModel, m: &Motion) -> Vec<f64> {
    let n = model.n_states();
    let states = states_along(model, m.measured()).expect("a replay");
    (0..n)
        .map(|j| {
            states
                .iter()
                .skip(j)
                .step_by(n)
                .fold(0.0f64, |a, z| a.max(z.abs()))
        })
        .collect()
}

/// The reference force at every sample: each interval integrated from the last.
fn reference_force(model: &dyn FrictionModel, m: &Motion) -> Vec<f64> {
    let law = model.states().expect("a law with states");
    let tol = Tolerance {
        rtol: 1e-12,
        atol: state_scales(model, m).iter().map(|s| 1e-14 * s).collect(),
    };
    let mut z = vec![0.0; law.n_states()];
    let mut force = Vec::with_capacity(SAMPLES);
    for i in 0..SAMPLES {
        if i > 0 {
            let interval = replay_interval(&m.time, &m.v, &m.normal, i);
            integrate(law, interval, &mut z, &tol).expect("the reference integration");
        }
        force.push(model.force(m.v[i], &z, m.normal.at(i)));
    }
    force
}

fn laws() -> Vec<Box<dyn FrictionModel>> {
    vec![
        Box::new(Dahl {
            sigma0: 1e5,
            mu_c: 0.2,
            alpha: 1.0,
        }),
        Box::new(LuGre::default()),
        Box::new(Gms::default()),
        Box::new(Gms {
            sharpness: 1.0,
            ..Gms::with_elements(2)
        }),
    ]
}

#[test]
fn exact_replays_follow_an_independent_integration_of_a_long_record() {
    let m = motion();
    for model in laws() {
        let replayed =
            model_force_with_normal(model.as_ref(), &m.time, &m.v, &m.normal).expect("a replay");
        let reference = reference_force(model.as_ref(), &m);
        let level = reference.iter().fold(0.0f64, |a, f| a.max(f.abs()));
        let worst = replayed
            .iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f64, f64::max);
        assert!(
            worst <= 1e-9 * level,
            "{}: worst difference {worst:e} N at a force level of {level} N",
            model.name()
        );
    }
}

/// The replayed force with parameter `j` at `value`.
fn force_at(model: &(dyn FrictionModel + 'static), m: &Motion, j: usize, value: f64) -> Vec<f64> {
    let mut moved = frictionid_models::clone_model(model);
    let mut p = moved.params();
    p[j] = value;
    moved.set_params(&p).expect("parameters");
    model_force_with_normal(moved.as_ref(), &m.time, &m.v, &m.normal).expect("a replay")
}

#[test]
fn replayed_force_derivatives_match_central_differences() {
    let m = motion();
    let samples: Vec<usize> = (0..SAMPLES).collect();
    for model in laws() {
        let d = force_derivatives_along(model.as_ref(), m.measured(), &samples)
            .expect("a valid motion")
            .expect("exact steps and a parameter gradient");
        let names: Vec<String> = model.param_info().into_iter().map(|p| p.name).collect();
        for (j, name) in names.iter().enumerate() {
            if !d.given[j] {
                assert_eq!(
                    (model.name(), name.as_str()),
                    ("gms", "sharpness"),
                    "only GMS's sharpness has no closed-form sensitivity"
                );
                continue;
            }
            let p = model.params()[j];
            let expected = central_difference(p, |value| force_at(model.as_ref(), &m, j, value));
            let what = format!("{} dF/d{name}", model.name());
            assert_derivative_matches(|k| d.at(k, j), &expected, 1e-6, &what);
        }
    }
}
