//! A driven linear axis without a spring (a motor-driven slide),
//! M x'' + Fv x' + Fc sgn(x') + F0 = u(t), under a measured multisine input, against an independent reference written
//! here: fixed-step RK4 (1e-5 s, steps never straddling an input sample), reversals located
//! by bisection on the step, and sticks held while |u - F0| <= Fc with their ends located by
//! bisection on the piecewise-linear input. The velocity route (simulate the axis under the
//! measured input, compare velocities) recovers M, Fv, Fc and the offset F0.

use crate::util::{four_tones, sample_times};
use frictionid_engine::identify::{fit, FitOptions, FitResult, OscillatorParam, ParamOptions};
use frictionid_engine::record::Channel;
use frictionid_engine::testing::driven_slide;
use frictionid_engine::Record;
use frictionid_models::ViscousCoulomb;
use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

const MASS: f64 = 2.0;
const VISCOUS: f64 = 20.0;
const COULOMB: f64 = 5.0;
const OFFSET: f64 = 1.5;
const RATE: f64 = 1000.0;
const DURATION: f64 = 4.0;

/// The input: four sines [N] sampled at `RATE`.
fn multisine(phase: f64) -> (Vec<f64>, Vec<f64>) {
    let t = sample_times(DURATION, RATE);
    let parts = four_tones(0.7, phase);
    let u = t
        .iter()
        .map(|&t| crate::util::multisine(&parts, t))
        .collect();
    (t, u)
}

/// u(t), linear between samples.
fn input_at(t_s: &[f64], u: &[f64], t: f64) -> f64 {
    let i = ((t * RATE).floor() as usize).min(t_s.len() - 2);
    let w = (t - t_s[i]) * RATE;
    u[i] + w * (u[i + 1] - u[i])
}

/// The reference velocity at the input's sample times, from rest.
fn reference(t_s: &[f64], u: &[f64]) -> Vec<f64> {
    const H: f64 = 1e-5;
    let net = |t: f64| input_at(t_s, u, t) - OFFSET;
    let acc = |t: f64, v: f64, d: f64| (net(t) - VISCOUS * v - COULOMB * d) / MASS;
    let rk4 = |t: f64, v: f64, d: f64, h: f64| {
        let k1 = acc(t, v, d);
        let k2 = acc(t + 0.5 * h, v + 0.5 * h * k1, d);
        let k3 = acc(t + 0.5 * h, v + 0.5 * h * k2, d);
        let k4 = acc(t + h, v + h * k3, d);
        v + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    };
    // None: stuck.
    let mut dir: Option<f64> = None;
    let (mut t, mut v) = (0.0, 0.0);
    let mut out = Vec::with_capacity(t_s.len());
    for &t_sample in t_s {
        while t < t_sample {
            let h = H.min(t_sample - t);
            match dir {
                None => {
                    if net(t + h).abs() <= COULOMB {
                        t += h;
                        continue;
                    }
                    let (mut lo, mut hi) = (t, t + h);
                    for _ in 0..80 {
                        let mid = 0.5 * (lo + hi);
                        if net(mid).abs() <= COULOMB {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    t = hi;
                    dir = Some(net(t).signum());
                }
                Some(d) => {
                    let v1 = rk4(t, v, d, h);
                    if d * v1 > 0.0 {
                        (t, v) = (t + h, v1);
                        continue;
                    }
                    let (mut lo, mut hi) = (0.0, h);
                    for _ in 0..60 {
                        let mid = 0.5 * (lo + hi);
                        if d * rk4(t, v, d, mid) > 0.0 {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    t += hi;
                    v = 0.0;
                    dir = (net(t).abs() > COULOMB).then(|| net(t).signum());
                }
            }
        }
        out.push(v);
    }
    out
}

pub(crate) fn record(name: &str, phase: f64, noise: f64, seed: u64) -> Record {
    let (t, u) = multisine(phase);
    let mut v = reference(&t, &u);
    if noise > 0.0 {
        let mut rng = StdRng::seed_from_u64(seed);
        let normal = Normal::new(0.0, noise).expect("a noise level");
        v.iter_mut().for_each(|v| *v += normal.sample(&mut rng));
    }
    Record::new(name, t, v, 0.0).with_channel(Channel::InputForce, u)
}

fn identify(records: &[Record]) -> FitResult {
    let model = ViscousCoulomb {
        mu: 4.0,
        viscous: 15.0,
    };
    identify_with(&model, records)
}

/// The velocity route's fit of `model` (its start) with the mass and the input offset.
pub(crate) fn identify_with(
    model: &(dyn frictionid_models::FrictionModel + 'static),
    records: &[Record],
) -> FitResult {
    let start = driven_slide(1.5, 0.0);
    let opts = FitOptions {
        params: ParamOptions {
            oscillator: vec![OscillatorParam::Mass, OscillatorParam::InputOffset],
            guess: false,
            ..ParamOptions::default()
        },
        ..FitOptions::default()
    };
    fit(&start, model, records, &opts).expect("a fit")
}

const TRUTH: [(&str, f64); 4] = [
    ("mass", MASS),
    ("viscous", VISCOUS),
    ("mu", COULOMB),
    ("input_offset", OFFSET),
];

#[test]
fn the_velocity_route_recovers_mass_friction_and_offset_without_noise() {
    let records = [record("a", 0.0, 0.0, 0), record("b", 0.8, 0.0, 0)];
    let r = identify(&records);
    for p in &r.parameters {
        eprintln!("{} = {} +- {:?}", p.name, p.value, p.std_error);
    }
    eprintln!(
        "{} {} iterations, rms {}",
        r.termination, r.iterations, r.rms_residual
    );
    assert!(r.converged, "{}", r.termination);
    for (name, truth) in TRUTH {
        let value = r.value(name).unwrap_or(f64::NAN);
        eprintln!("noise-free {name}: {value} (truth {truth})");
        assert!((value - truth).abs() < 5e-3 * truth, "{name} {value}");
    }
}

/// The velocity noise of the noisy records [m/s].
const NOISE: f64 = 5e-3;

/// Noise draw `draw` of the two records (seeds 2 draw and 2 draw + 1).
fn noisy_records(draw: u64) -> [Record; 2] {
    [
        record("a", 0.0, NOISE, 2 * draw),
        record("b", 0.8, NOISE, 2 * draw + 1),
    ]
}

/// The standard score (estimate - truth) / standard error of each parameter of `TRUTH`.
fn scores(r: &FitResult) -> [f64; 4] {
    TRUTH.map(|(name, truth)| {
        let p = r.param(name).expect("a fitted parameter");
        (p.value - truth) / p.std_error.unwrap_or(f64::NAN)
    })
}

/// One noise draw (seeds 7 and 8): every estimate within three standard errors of the truth.
#[test]
fn with_noise_the_truth_lies_within_three_standard_errors() {
    let records = [record("a", 0.0, NOISE, 7), record("b", 0.8, NOISE, 8)];
    let r = identify(&records);
    eprintln!(
        "{} rms {} iterations {}",
        r.termination, r.rms_residual, r.iterations
    );
    assert!(r.converged, "{}", r.termination);
    for ((name, truth), z) in TRUTH.into_iter().zip(scores(&r)) {
        eprintln!("noisy {name}: {} standard errors from {truth}", z);
        assert!(z.abs() < 3.0, "{name}: {z} standard errors off");
    }
}

/// How the standard errors of `draws` noise draws cover the truth: per parameter of `TRUTH`,
/// the number of draws whose estimate lies within two standard errors, and the RMS of the
/// standard scores (1 when the standard errors are the estimates' spread).
fn coverage(draws: std::ops::Range<u64>) -> [(usize, f64); 4] {
    let n = draws.end - draws.start;
    let all: Vec<[f64; 4]> = draws
        .map(|d| scores(&identify(&noisy_records(d))))
        .collect();
    std::array::from_fn(|k| {
        let within = all.iter().filter(|z| z[k].abs() < 2.0).count();
        let rms = (all.iter().map(|z| z[k] * z[k]).sum::<f64>() / n as f64).sqrt();
        eprintln!(
            "{}: {within} of {n} within 2 standard errors, RMS score {rms:.3}",
            TRUTH[k].0
        );
        (within, rms)
    })
}

/// Over 40 noise draws, each parameter's estimate lies within two standard errors in at
/// least 33 (a nominal 95 % interval misses more than 7 of 40 with probability 0.3 %), and
/// the RMS of its standard scores is within [0.6, 1.5] (the sampling spread of an RMS of 40
/// unit normals is 0.11). A simulation whose integration error varied erratically with the
/// parameters (steps across the input's knots) gave a Jacobian of that noise and stopped
/// the solver short of the optimum: 14 of 40 offsets within two standard errors, RMS
/// scores of 9 to 77.
#[test]
fn standard_errors_cover_the_truth_over_noise_draws() {
    for (k, (within, rms)) in coverage(0..40).into_iter().enumerate() {
        let name = TRUTH[k].0;
        assert!(
            within >= 33,
            "{name}: {within} of 40 within 2 standard errors"
        );
        assert!((0.6..1.5).contains(&rms), "{name}: RMS score {rms}");
    }
}

/// The same over 400 draws (about a minute in the test profile):
/// `cargo test -p frictionid-engine --test driven_axis -- --ignored`.
#[test]
#[ignore = "400 fits: run on demand"]
fn standard_errors_cover_the_truth_over_400_noise_draws() {
    for (k, (within, rms)) in coverage(0..400).into_iter().enumerate() {
        let name = TRUTH[k].0;
        let fraction = within as f64 / 400.0;
        assert!((0.92..=0.985).contains(&fraction), "{name}: {fraction}");
        assert!((0.85..1.15).contains(&rms), "{name}: RMS score {rms}");
    }
}

#[test]
fn the_engine_follows_the_reference_under_the_input() {
    let (t, u) = multisine(0.0);
    let reference = reference(&t, &u);
    let model = ViscousCoulomb {
        mu: COULOMB,
        viscous: VISCOUS,
    };
    let sim = crate::util::driven_from_rest(&driven_slide(MASS, OFFSET), &model, &t, &u);
    let worst = sim
        .v
        .iter()
        .zip(&reference)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "{} events, worst velocity difference {worst} m/s",
        sim.events.len()
    );
    assert!(worst < 1e-9, "{worst}");
}

/// LuGre on the FMM stage driven from rest by the input `u` (sampled at 1 kHz over 1 s)
/// against fixed-step RK4 at 1e-5 s written here over the law's own state derivative and
/// force, the input linear between its samples: the largest velocity error relative to the
/// largest speed, and that speed.
fn lugre_drive_against_rk4(u: &[f64]) -> (f64, f64) {
    use frictionid_engine::simulate::{simulate_driven, Input, RunInputs, SampleGrid};
    use frictionid_engine::{Initial, Oscillator, SimOptions};
    use frictionid_models::{FrictionModel, LuGre};
    let osc = Oscillator::fmm();
    let law = LuGre::default();
    let t = sample_times(1.0, RATE);
    let input = Input::new(t.clone(), u.to_vec()).unwrap();
    let opts = SimOptions {
        rtol: 1e-10,
        atol: 1e-12,
        ..SimOptions::default()
    };
    let run = simulate_driven(RunInputs {
        osc: &osc,
        model: &law,
        init: &Initial::at_rest(0.0),
        input: Some(&input),
        channels: None,
        grid: SampleGrid {
            t_end: 1.0,
            sample_times: &t,
        },
        opts: &opts,
    })
    .unwrap();
    let states = law.states().unwrap();
    let rate = |s: f64, y: [f64; 3]| -> [f64; 3] {
        let mut dz = [0.0];
        let f = states.state_derivative_and_force(y[1], &y[2..], osc.normal_force, &mut dz);
        let a = (input.at(s) - osc.damping * y[1] - osc.stiffness * y[0] - f) / osc.mass;
        [y[1], a, dz[0]]
    };
    let h = 1e-5;
    let mut y = [0.0; 3];
    let (mut worst, mut fastest) = (0.0f64, 0.0f64);
    for (i, &ts) in t.iter().enumerate().skip(1) {
        let mut s = t[i - 1];
        while s < ts - 1e-12 {
            let k1 = rate(s, y);
            let at = |k: [f64; 3], c: f64| [0, 1, 2].map(|j| y[j] + c * h * k[j]);
            let k2 = rate(s + h / 2.0, at(k1, 0.5));
            let k3 = rate(s + h / 2.0, at(k2, 0.5));
            let k4 = rate(s + h, at(k3, 1.0));
            y = [0, 1, 2].map(|j| y[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]));
            s += h;
        }
        worst = worst.max((run.v[i] - y[1]).abs());
        fastest = fastest.max(y[1].abs());
    }
    (worst / fastest, fastest)
}

/// The drive by `u` moves the mass (0.05 m/s at least) and follows RK4 within 1e-6 of its
/// largest speed.
fn assert_lugre_follows_rk4(u: &[f64]) {
    let (error, fastest) = lugre_drive_against_rk4(u);
    assert!(fastest > 0.05, "the reference moves: {fastest}");
    assert!(
        error < 1e-6,
        "velocity off by {error:e} of the largest speed"
    );
}

/// u = 8 sin(3 pi t) N starts at 0: LuGre is in balance at t = 0, and the mass must move
/// with the input at once (it was held at rest for the whole record).
#[test]
fn a_drive_starting_in_balance_moves_a_law_without_a_static_limit() {
    let u: Vec<f64> = sample_times(1.0, RATE)
        .iter()
        .map(|s| 8.0 * (3.0 * std::f64::consts::PI * s).sin())
        .collect();
    assert_lugre_follows_rk4(&u);
}

/// The same input held at 0 for its first 0.2 s: the mass rests in balance, then moves when
/// the input leaves 0.
#[test]
fn a_drive_held_flat_in_balance_moves_when_the_input_leaves() {
    let u: Vec<f64> = sample_times(1.0, RATE)
        .iter()
        .map(|s| 8.0 * (3.0 * std::f64::consts::PI * (s - 0.2).max(0.0)).sin())
        .collect();
    assert_lugre_follows_rk4(&u);
}
