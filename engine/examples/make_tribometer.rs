//! Writes `fixtures/tribometer/tribometer-sim.txt`: a reciprocating tribometer record made by
//! frictionid's own replay, with a known truth, in the export format of the real record that
//! FrictionModels.jl publishes (tab-separated; `Time [s]`, `Normal [uN]`, `Position [mm]`,
//! `Friction [uN]`, the friction negated), so that one reader config reads either.
//!
//! The truth (fixtures/README.md): an imposed sinusoidal stroke, x = X_C - A cos(2 pi f t)
//! (A = 0.12 mm about X_C = -109.92 mm at f = 0.5 Hz, from rest at one end), under a normal
//! force that drifts and wobbles about 4.8 N; Dahl's law (sigma0 6e4 N/m, mu_c 0.45,
//! alpha 1) replayed along the sampled motion from relaxed bristles by
//! `energy::model_force_with_normal` under the true N(t); then a load-cell offset of 0.15 N
//! on the friction channel, Gaussian noise (0.02 N on the friction force, 0.03 N on the normal
//! force, seeds 7 and 8) and the export's resolution (0.1 uN, 0.1 um).
//!
//! Run (from the repository root):
//! `cargo run --release -p frictionid-engine --example make_tribometer [-- OUTPUT]`

use frictionid_engine::energy::model_force_with_normal;
use frictionid_engine::record::NormalForce;
use frictionid_engine::synthetic::{add_gaussian_noise, uniform_times};
use frictionid_models::Dahl;
use std::f64::consts::TAU;
use std::fmt::Write as _;

/// Sample rate [Hz] and duration [s]: 1 201 samples, as the real record's rate.
const RATE: f64 = 200.0;
const DURATION: f64 = 6.0;
/// The stroke: amplitude [m], centre [m] and frequency [Hz].
const AMPLITUDE: f64 = 0.12e-3;
const CENTRE: f64 = -109.92e-3;
const FREQUENCY: f64 = 0.5;
/// The true normal force [N]: mean, linear drift over the record, wobble amplitude and
/// wobble frequency [Hz].
const NORMAL_MEAN: f64 = 4.8;
const NORMAL_DRIFT: f64 = 0.3;
const NORMAL_WOBBLE: f64 = 0.2;
const NORMAL_WOBBLE_HZ: f64 = 1.3;
/// The load cell's offset on the friction channel [N].
const FORCE_OFFSET: f64 = 0.15;
/// Noise standard deviations [N] and seeds.
const FORCE_NOISE: f64 = 0.02;
const NORMAL_NOISE: f64 = 0.03;
const FORCE_SEED: u64 = 7;
const NORMAL_SEED: u64 = 8;

/// The true friction law.
fn truth() -> Dahl {
    Dahl {
        sigma0: 6e4,
        mu_c: 0.45,
        alpha: 1.0,
    }
}

/// The imposed stroke at `t`: (position [m], velocity [m/s]).
fn stroke(t: f64) -> (f64, f64) {
    let w = TAU * FREQUENCY;
    (
        CENTRE - AMPLITUDE * (w * t).cos(),
        AMPLITUDE * w * (w * t).sin(),
    )
}

/// The true normal force at `t` [N].
fn normal_force(t: f64) -> f64 {
    NORMAL_MEAN + NORMAL_DRIFT * t / DURATION + NORMAL_WOBBLE * (TAU * NORMAL_WOBBLE_HZ * t).sin()
}

/// The export's text: the header, then one tab-separated row a sample, forces in uN to
/// 0.1 uN, the position in mm to 0.1 um, the friction negated as the real export has it.
fn export(time: &[f64], normal: &[f64], position: &[f64], friction: &[f64]) -> String {
    let mut text = String::from("Time [s]\tNormal [uN]\tPosition [mm]\tFriction [uN]\n");
    for i in 0..time.len() {
        let _ = writeln!(
            text,
            "{}\t{:.1}\t{:.4}\t{:.1}",
            time[i],
            normal[i] * 1e6,
            position[i] * 1e3,
            -friction[i] * 1e6
        );
    }
    text
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let output = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "fixtures/tribometer/tribometer-sim.txt".into());
    let time: Vec<f64> = uniform_times(DURATION, RATE)
        .iter()
        .map(|t| (t * RATE).round() / RATE)
        .collect();
    let (position, velocity): (Vec<f64>, Vec<f64>) = time.iter().map(|&t| stroke(t)).unzip();
    let true_normal: Vec<f64> = time.iter().map(|&t| normal_force(t)).collect();
    let normal = NormalForce::Sampled(true_normal.clone());
    let mut friction = model_force_with_normal(&truth(), &time, &velocity, &normal)?;
    for f in &mut friction {
        *f += FORCE_OFFSET;
    }
    add_gaussian_noise(&mut friction, FORCE_NOISE, FORCE_SEED);
    let mut measured_normal = true_normal;
    add_gaussian_noise(&mut measured_normal, NORMAL_NOISE, NORMAL_SEED);
    std::fs::write(
        &output,
        export(&time, &measured_normal, &position, &friction),
    )?;
    println!("{output}: {} samples", time.len());
    Ok(())
}
