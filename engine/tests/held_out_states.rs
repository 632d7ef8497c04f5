//! Held-out blocks of one record for a law with states: a tribometer-like stroke (x = A sin
//! w t, its velocity and the friction force measured) of a Dahl truth, the force written from
//! the law's closed form along the stroke (alpha = 1: between reversals F relaxes
//! exponentially in the displacement towards s Fc). Compared alone, Dahl's held-out RMS on
//! contiguous blocks sits within the noise: each block's bristle state starts where the
//! replay of the samples before it left it. Started from a relaxed state instead, the same
//! closed form (from F = 0 at each block's start) lies far above the noise, so the test
//! would see a block that forgot its history.

use crate::util::no_oscillator_force_options;
use frictionid_engine::identify::{compare, ValidationScheme};
use frictionid_engine::record::{Channel, TimeBase};
use frictionid_engine::synthetic::add_gaussian_noise;
use frictionid_engine::Record;
use frictionid_models::{Dahl, FrictionModel};
use std::f64::consts::PI;

/// Stroke amplitude [m], frequency [Hz], sample rate [Hz] and length [s].
const AMPLITUDE: f64 = 2e-3;
const FREQUENCY: f64 = 0.4;
const RATE: f64 = 1e3;
const DURATION: f64 = 6.0;
/// The Dahl truth: rest stiffness [N/m] and Coulomb level [N] (no normal force given).
const SIGMA0: f64 = 1e5;
const LEVEL: f64 = 5.0;
/// Force noise [N].
const NOISE: f64 = 0.05;

/// The closed-form Dahl force (alpha = 1) along x(t) = A sin(w t) at `times`, starting from
/// `f0` at `times[0]`: between reversals, F = s Fc + (F_r - s Fc) exp(-sigma0 |x - x_r| / Fc)
/// with s the sliding direction and (x_r, F_r) where the phase began.
fn dahl_force(times: &[f64], f0: f64) -> Vec<f64> {
    let w = 2.0 * PI * FREQUENCY;
    let x = |t: f64| AMPLITUDE * (w * t).sin();
    let direction = |t: f64| (w * t).cos().signum();
    let (mut x_r, mut f_r) = (x(times[0]), f0);
    let mut s = direction(times[0]);
    times
        .iter()
        .map(|&t| {
            if direction(t) != s {
                // The reversal lies at the extreme of the stroke: restart the phase there.
                let turned = s * AMPLITUDE;
                f_r =
                    s * LEVEL + (f_r - s * LEVEL) * (-SIGMA0 * (turned - x_r).abs() / LEVEL).exp();
                x_r = turned;
                s = direction(t);
            }
            s * LEVEL + (f_r - s * LEVEL) * (-SIGMA0 * (x(t) - x_r).abs() / LEVEL).exp()
        })
        .collect()
}

/// The stroke's record: time, velocity and the noisy friction force.
fn stroke() -> Record {
    let n = (DURATION * RATE) as usize;
    let times: Vec<f64> = (0..n).map(|i| i as f64 / RATE).collect();
    let w = 2.0 * PI * FREQUENCY;
    let v: Vec<f64> = times
        .iter()
        .map(|t| AMPLITUDE * w * (w * t).cos())
        .collect();
    let mut force = dahl_force(&times, 0.0);
    add_gaussian_noise(&mut force, NOISE, 31);
    Record::from_time_base("stroke", TimeBase::new(times).expect("uniform times"))
        .with_channel(Channel::Velocity, v)
        .with_channel(Channel::Force, force)
}

/// RMS of the difference between the closed form started relaxed at each of three blocks'
/// starts and the closed form along the whole stroke.
fn relaxed_block_error(times: &[f64]) -> f64 {
    let whole = dahl_force(times, 0.0);
    let n = times.len();
    let mut sum = 0.0;
    for k in 0..3 {
        let (a, b) = (k * n / 3, (k + 1) * n / 3);
        let relaxed = dahl_force(&times[a..b], 0.0);
        sum += relaxed
            .iter()
            .zip(&whole[a..b])
            .map(|(r, w)| (r - w).powi(2))
            .sum::<f64>();
    }
    (sum / n as f64).sqrt()
}

#[test]
fn a_dahl_truth_scores_within_the_noise_on_held_out_blocks() {
    let record = stroke();
    let (osc, opts) = no_oscillator_force_options();
    let truth: Box<dyn FrictionModel> = Box::new(Dahl {
        sigma0: SIGMA0,
        mu_c: LEVEL / osc.normal_force,
        alpha: 1.0,
    });
    let c = compare(&osc, &[truth], std::slice::from_ref(&record), &opts).expect("a comparison");
    assert_eq!(c.validation_scheme, Some(ValidationScheme::Blocks));
    let v = c
        .validation
        .iter()
        .find(|v| v.model == "dahl")
        .expect("dahl");
    let rms = v.validation_rms.unwrap_or_else(|| panic!("{v:?}"));
    let relaxed = relaxed_block_error(record.time());
    eprintln!(
        "dahl: fitted rms {:.4} N, held-out rms {rms:.4} N (folds {:.4?}), noise {NOISE} N; \
         blocks started relaxed would be {relaxed:.3} N off",
        c.ranking[0].rms_residual, v.folds
    );
    assert!(rms < 1.1 * NOISE, "{v:?}");
    // The oracle's own check: a block started from a relaxed state is far from the truth.
    assert!(relaxed > 4.0 * NOISE, "{relaxed}");
}
