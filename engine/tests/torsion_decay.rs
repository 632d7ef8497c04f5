//! A torsion pendulum (J 0.05 kg m^2, k 20 N m/rad, c 0.004 N m s/rad, Coulomb torque
//! 0.038 N m, released at 0.5 rad) that rings 15 s and rests the other 15 s of a 30 s record
//! sampled at 1 kHz, its velocity carrying 0.02 rad/s of Gaussian noise. Its records come
//! from the closed form per half-cycle of `util::CoulombDecay` (the stop located at the first
//! turning point where the spring's torque is within the Coulomb torque). The velocity fit's
//! cost has one minimum per count of half-cycles before the stop; viscous_coulomb, fitted
//! with the stiffness and the damping as oscillator properties and started 4 % off in
//! stiffness, must reach the truth's count (the Coulomb torque within 1 %) or say that its
//! optimum is suspect, and a fit from a good start says nothing of the kind.

use crate::util::{free, rel, sample_times, CoulombDecay};
use frictionid_engine::axis::Axis;
use frictionid_engine::identify::{fit, FitOptions, FitResult, OscillatorParam, ParamOptions};
use frictionid_engine::identify::{Check, Search, Status};
use frictionid_engine::synthetic::add_gaussian_noise;
use frictionid_engine::{Oscillator, Record};
use frictionid_models::ViscousCoulomb;

const TRUTH: CoulombDecay = CoulombDecay {
    inertia: 0.05,
    stiffness: 20.0,
    damping: 0.004,
    coulomb: 0.038,
    x0: 0.5,
};
const RATE: f64 = 1000.0;
const DURATION: f64 = 30.0;
const NOISE: f64 = 0.02;

/// The decay as a noisy velocity record.
fn record() -> Record {
    let time = sample_times(DURATION, RATE);
    let mut v = TRUTH.velocity(&time);
    add_gaussian_noise(&mut v, NOISE, 41);
    Record::new("torsion", time, v, TRUTH.x0)
}

/// The pendulum with stiffness `k`, the truth's damping; its levels are torques (N = 1).
fn pendulum(k: f64) -> Oscillator {
    Oscillator {
        mass: TRUTH.inertia,
        damping: TRUTH.damping,
        stiffness: k,
        normal_force: 1.0,
        axis: Axis::Rotary,
        ..Oscillator::fmm()
    }
}

/// viscous_coulomb (its Coulomb torque fitted, its viscous term held at zero: the damping is
/// the oscillator's) fitted with the stiffness and the damping from stiffness `k`, under
/// `search`.
fn fitted(k: f64, search: Option<Search>) -> FitResult {
    let mut opts = FitOptions {
        params: ParamOptions {
            oscillator: vec![OscillatorParam::Stiffness, OscillatorParam::Damping],
            free: free(&["mu"]),
            ..ParamOptions::default()
        },
        ..FitOptions::default()
    };
    opts.search.strategy = search;
    let law = ViscousCoulomb {
        mu: 0.02,
        viscous: 0.0,
    };
    fit(&pendulum(k), &law, &[record()], &opts).expect("a fit")
}

/// The fitted Coulomb torque's relative error and the residual RMS in noise levels, printed
/// with the fit's values and findings.
fn report(label: &str, r: &FitResult) -> (f64, f64) {
    let t_c = r.value("mu").unwrap_or(f64::NAN);
    let ratio = r.rms_residual / NOISE;
    eprintln!(
        "{label}: k {:.5} (truth {}), c {:.6} ({}), T_c {t_c:.5} ({}, {:+.2} %); RMS {ratio:.2} noise levels; best start {} ({})",
        r.oscillator.stiffness,
        TRUTH.stiffness,
        r.oscillator.damping,
        TRUTH.damping,
        TRUTH.coulomb,
        100.0 * (t_c / TRUTH.coulomb - 1.0),
        r.best_start,
        r.best_start_origin
    );
    for f in &r.diagnostics {
        if f.status != Status::Pass || f.check == Check::SuspectOptimum {
            eprintln!("  {:?} {:?}: {}", f.check, f.status, f.message);
        }
    }
    (rel(t_c, TRUTH.coulomb), ratio)
}

/// The status of the suspect-optimum finding, if the search went further.
fn suspect(r: &FitResult) -> Option<Status> {
    crate::util::finding(r, Check::SuspectOptimum).map(|f| f.status)
}

/// The record is the case described: the pendulum rings about 15 s and rests the rest.
#[test]
fn the_pendulum_rings_fifteen_seconds_and_rests() {
    let (slips, stuck_at) = TRUTH.slips();
    eprintln!("{} half-cycles, stuck at {stuck_at:.3} s", slips.len());
    assert!((14.0..16.0).contains(&stuck_at), "{stuck_at}");
}

/// Started 4 % stiff (the default search): the fit reaches the truth's count of half-cycles,
/// the Coulomb torque within 1 % and the residual at the noise, or says its optimum is
/// suspect. (It reaches the truth: T_c -0.04 %, RMS 1.00 noise levels; the ignored sweep below
/// holds the same for starts 4 to 10 % off on either side and other set-ups.)
#[test]
fn started_four_percent_stiff_the_fit_reaches_the_truth_or_says_so() {
    let r = fitted(1.04 * TRUTH.stiffness, None);
    let (error, ratio) = report("4 % stiff", &r);
    let reached = error < 0.01 && ratio < 1.2;
    assert!(
        reached || suspect(&r) == Some(Status::Warn),
        "T_c off by {:.2} %, RMS {ratio:.2} noise levels, unsaid",
        100.0 * error
    );
}

/// From the truth's stiffness the fit ends at the truth and nothing calls it suspect.
#[test]
fn a_fit_from_a_good_start_is_not_called_suspect() {
    let r = fitted(TRUTH.stiffness, None);
    let (error, ratio) = report("good start", &r);
    assert!(error < 0.01, "T_c off by {:.2} %", 100.0 * error);
    assert!(ratio < 1.2, "RMS {ratio} noise levels");
    assert_ne!(suspect(&r), Some(Status::Warn));
}

/// One set-up of the sweep: which law parameters are free, which oscillator properties, the
/// law's start, whether the data-driven guess runs, and the noise.
struct Setup {
    label: &'static str,
    mu_start: f64,
    free: &'static [&'static str],
    properties: &'static [OscillatorParam],
    viscous_start: f64,
    guess: bool,
    noise: f64,
}

/// The set-up fitted from stiffness `k` under `search`, on the record with its noise.
fn fitted_setup(s: &Setup, k: f64, search: Option<Search>) -> FitResult {
    let mut opts = FitOptions {
        params: ParamOptions {
            oscillator: s.properties.to_vec(),
            free: free(s.free),
            guess: s.guess,
            ..ParamOptions::default()
        },
        ..FitOptions::default()
    };
    opts.search.strategy = search;
    let time = sample_times(DURATION, RATE);
    let mut v = TRUTH.velocity(&time);
    add_gaussian_noise(&mut v, s.noise, 43);
    let rec = Record::new("torsion", time, v, TRUTH.x0);
    let mut osc = pendulum(k);
    if !s.properties.contains(&OscillatorParam::Damping) {
        osc.damping = 0.0;
    }
    let law = ViscousCoulomb {
        mu: s.mu_start,
        viscous: s.viscous_start,
    };
    fit(&osc, &law, &[rec], &opts).expect("a fit")
}

/// The sweep behind the case: set-ups (the damping as the oscillator's or as the law's
/// viscous term, both free together, no data-driven guess, five times the noise, the Coulomb
/// torque started 12 % low where a wrong count was once reported to end) from
/// stiffness starts 4 to 10 % off on either side, under the default and the global search.
/// Every fit reaches the truth's count of half-cycles (the Coulomb torque within 1 %) or says
/// its optimum is suspect.
#[test]
#[ignore = "slow: a sweep of 60 fits of a 30 s record (about 75 s)"]
fn a_sweep_of_starts_reaches_the_truth_or_says_so() {
    use OscillatorParam::{Damping, Stiffness};
    let setups = [
        Setup {
            label: "damping as the oscillator's",
            mu_start: 0.02,
            free: &["mu"],
            properties: &[Stiffness, Damping],
            viscous_start: 0.0,
            guess: true,
            noise: NOISE,
        },
        Setup {
            label: "damping as the law's viscous term",
            mu_start: 0.02,
            free: &["mu", "viscous"],
            properties: &[Stiffness],
            viscous_start: 0.5,
            guess: true,
            noise: NOISE,
        },
        Setup {
            label: "both free",
            mu_start: 0.02,
            free: &["mu", "viscous"],
            properties: &[Stiffness, Damping],
            viscous_start: 0.5,
            guess: true,
            noise: NOISE,
        },
        Setup {
            label: "no guess, five times the noise",
            mu_start: 0.02,
            free: &["mu", "viscous"],
            properties: &[Stiffness],
            viscous_start: 0.5,
            guess: false,
            noise: 5.0 * NOISE,
        },
        Setup {
            label: "no guess, the level started 12 % low",
            mu_start: 0.88 * TRUTH.coulomb,
            free: &["mu", "viscous"],
            properties: &[Stiffness],
            viscous_start: 0.0,
            guess: false,
            noise: NOISE,
        },
    ];
    let only = std::env::var("SWEEP_ONLY").ok();
    let setups: Vec<&Setup> = setups
        .iter()
        .filter(|s| only.as_deref().is_none_or(|o| s.label.contains(o)))
        .collect();
    let mut unsaid = Vec::new();
    for s in setups {
        for factor in [0.90, 0.94, 0.96, 1.04, 1.06, 1.10] {
            for search in [None, Some(Search::Global)] {
                let r = fitted_setup(s, factor * TRUTH.stiffness, search);
                let t_c = r.value("mu").unwrap_or(f64::NAN);
                let error = rel(t_c, TRUTH.coulomb);
                let ratio = r.rms_residual / s.noise;
                let said = suspect(&r);
                eprintln!(
                    "{}, k x {factor}, {search:?}: T_c {:+.2} %, k {:.4}, RMS {ratio:.2} noise levels, suspect {said:?}",
                    s.label,
                    100.0 * (t_c / TRUTH.coulomb - 1.0),
                    r.oscillator.stiffness
                );
                if !(error < 0.01 && ratio < 1.2) && said != Some(Status::Warn) {
                    unsaid.push(format!("{} k x {factor} {search:?}", s.label));
                }
            }
        }
    }
    assert!(unsaid.is_empty(), "{unsaid:?}");
}
