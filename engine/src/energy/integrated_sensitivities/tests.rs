use super::*;
use crate::energy::model_force::{force_derivatives_along, replay_interval, MeasuredMotion};
use frictionid_models::{Dahl, Gms, LuGre};
use std::f64::consts::PI;

/// A motion of `seconds` at 1 kHz with reversals, slow and fast stretches: v(t) from
/// 0.15 sin(2 pi 1.1 t) cos(2 pi 0.2 t) + 2 mm/s, N swinging around 14.5 N.
fn motion(seconds: f64) -> (Vec<f64>, Vec<f64>, NormalForce) {
    let time: Vec<f64> = (0..=(seconds * 1000.0) as usize)
        .map(|i| i as f64 * 1e-3)
        .collect();
    let v = time
        .iter()
        .map(|&t| 0.15 * (2.0 * PI * 1.1 * t).sin() * (2.0 * PI * 0.2 * t).cos() + 2e-3)
        .collect();
    let normal = time
        .iter()
        .map(|&t| 14.5 + 2.0 * (2.0 * PI * 0.3 * t).sin())
        .collect();
    (time, v, NormalForce::Sampled(normal))
}

/// The integrated derivatives of `model` along the motion at every sample.
fn integrated(
    model: &dyn FrictionModel,
    m: &(Vec<f64>, Vec<f64>, NormalForce),
) -> ForceDerivatives {
    let (time, v, normal) = m;
    let replay = |i: usize| replay_interval(time, v, normal, i);
    let samples: Vec<usize> = (0..time.len()).collect();
    let motion = SampledMotion::new(time, v, normal, &replay);
    integrated_force_derivatives(model, motion, &samples, &ConditionColumns::none())
        .expect("integrated sensitivities")
}

/// The derivatives from the law's own route (exact steps where it has them).
fn along(model: &dyn FrictionModel, m: &(Vec<f64>, Vec<f64>, NormalForce)) -> ForceDerivatives {
    let (time, v, normal) = m;
    let samples: Vec<usize> = (0..time.len()).collect();
    force_derivatives_along(model, MeasuredMotion { time, v, normal }, &samples)
        .expect("a checked motion")
        .expect("derivatives")
}

/// Each parameter's column of `got` is within `tolerance` of `want`'s largest entry of that
/// column, over the parameters `want` gives.
fn assert_columns_agree(
    name: &str,
    want: &ForceDerivatives,
    got: &ForceDerivatives,
    tolerance: f64,
) {
    let np = want.given.len();
    let samples = want.force.len();
    for j in (0..np).filter(|&j| want.given[j]) {
        let scale = (0..samples).fold(0.0f64, |a, k| a.max(want.at(k, j).abs()));
        let worst = (0..samples).fold(0.0f64, |a, k| a.max((want.at(k, j) - got.at(k, j)).abs()));
        assert!(
            worst <= tolerance * scale,
            "{name} parameter {j}: {worst:e} of {scale:e}"
        );
    }
}

/// Integrated with the states, the sensitivities give the force's derivatives of the exact
/// steps' closed-form sensitivities (Dahl's, LuGre's, and GMS's at sharpness 1 and at 3,
/// where its step solves the element law by Newton's method) along a motion with
/// reversals, and the forces to 1e-5 of the largest: the replay's tolerance accumulated
/// over 2 000 intervals (rtol 1e-8 per step, and atol 1e-12 per state and interval, which
/// dominates for GMS's deflections of micrometres: the numerical replay's own test allows
/// it too). The derivatives agree to 1e-5 of each parameter's largest for the smooth laws
/// (Dahl and LuGre reach 2e-6), and to 1e-3 for GMS (it reaches 2.5e-4): an element's rate
/// has a kink where it starts loading (its slope in z jumps at zero load), which the exact
/// steps locate and the integrator steps over, its error control holding the states alone.
/// Either is far finer than a Jacobian of a fit needs.
#[test]
fn integrated_sensitivities_give_the_exact_steps_derivatives() {
    let m = motion(2.0);
    let gms3 = Gms {
        sharpness: 3.0,
        ..Gms::default()
    };
    let laws: [(Box<dyn FrictionModel>, f64); 4] = [
        (Box::new(Dahl::default()), 1e-5),
        (Box::new(LuGre::default()), 1e-5),
        (Box::new(Gms::default()), 1e-3),
        (Box::new(gms3), 1e-3),
    ];
    for (law, tolerance) in laws {
        let exact = along(law.as_ref(), &m);
        let got = integrated(law.as_ref(), &m);
        let force_scale = exact.force.iter().fold(0.0f64, |a, f| a.max(f.abs()));
        for (a, b) in exact.force.iter().zip(&got.force) {
            assert!(
                (a - b).abs() <= 1e-5 * force_scale,
                "{}: {a} vs {b}",
                law.name()
            );
        }
        assert_columns_agree(law.name(), &exact, &got, tolerance);
    }
}
