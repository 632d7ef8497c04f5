//! Standard errors under coloured noise on a driven axis's input (the inverse-dynamics
//! route, the axis simulated by the event-locating reference of `inverse_dynamics.rs`): an
//! AR(1) noise of lag-1 correlation 0.9 and a ringing, AR(2) noise of pole radius 0.9 at
//! 50 Hz sampled at 1 kHz (a structure's resonance in a force record). The standard errors
//! the fit reports are confirmed by a Newey-West sum written out here from the Jacobian
//! (the regressors J a, v, sgn(v), 1 at the compared samples) and the residuals, and the
//! 95 % intervals cover the truth: a few draws in the suite, the long Monte Carlo behind
//! `#[ignore]`.

use crate::inverse_dynamics::{inverse_dynamics, truths, TRUTH};
use crate::util::estimate;
use frictionid_engine::identify::FitResult;
use frictionid_engine::record::Channel;
use frictionid_engine::Record;
use nalgebra::DMatrix;
use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

/// Samples per record (10 s at 1 kHz).
const SAMPLES: usize = 10_000;
/// The noise's standard deviation on u [N].
const SIGMA: f64 = 0.2;

/// A stationary AR(2) noise e_t = a1 e_(t-1) + a2 e_(t-2) + w_t scaled to `SIGMA`.
#[derive(Debug, Clone, Copy)]
struct Ar2Noise {
    a1: f64,
    a2: f64,
}

/// AR(1) of lag-1 correlation 0.9.
const AR1: Ar2Noise = Ar2Noise { a1: 0.9, a2: 0.0 };

/// A ringing: poles of radius 0.9 at 50 Hz sampled at 1 kHz.
fn ringing() -> Ar2Noise {
    let (rho, theta) = (0.9_f64, 2.0 * std::f64::consts::PI * 50.0 / 1000.0);
    Ar2Noise {
        a1: 2.0 * rho * theta.cos(),
        a2: -rho * rho,
    }
}

impl Ar2Noise {
    /// The variance of the process per unit innovation variance (Box and Jenkins 3.2.8).
    fn variance_per_innovation(&self) -> f64 {
        let (a1, a2) = (self.a1, self.a2);
        (1.0 - a2) / ((1.0 + a2) * ((1.0 - a2).powi(2) - a1 * a1))
    }

    /// `n` samples of standard deviation `SIGMA` (after a burn-in of 2000).
    fn draw(&self, n: usize, seed: u64) -> Vec<f64> {
        let mut rng = StdRng::seed_from_u64(seed);
        let w = Normal::new(0.0, SIGMA / self.variance_per_innovation().sqrt()).unwrap();
        let (mut e1, mut e2) = (0.0, 0.0);
        let mut out = Vec::with_capacity(n);
        for k in 0..n + 2000 {
            let e = self.a1 * e1 + self.a2 * e2 + w.sample(&mut rng);
            (e2, e1) = (e1, e);
            if k >= 2000 {
                out.push(e);
            }
        }
        out
    }
}

/// The clean record with `noise` added to its input.
fn noisy(clean: &Record, noise: &[f64]) -> Record {
    let u: Vec<f64> = clean
        .channel(Channel::InputForce)
        .unwrap()
        .iter()
        .zip(noise)
        .map(|(u, e)| u + e)
        .collect();
    clean.clone().with_channel(Channel::InputForce, u)
}

/// The regressors of M, Fv, Fc and the offset at the compared samples (J a from the
/// balance's inertial force over the fitted mass, v, sgn(v) from the fitted friction, 1)
/// and the residuals.
fn regressors(result: &FitResult) -> (DMatrix<f64>, Vec<f64>) {
    let rec = &result.records[0];
    let balance = rec.series.balance.as_ref().unwrap();
    let (mass, _) = estimate(result, "mass");
    let (viscous, _) = estimate(result, "viscous");
    let (coulomb, _) = estimate(result, "mu");
    let v = &rec.axes.velocity;
    let n = rec.series.measured.len();
    assert_eq!((v.len(), balance.inertia.len()), (n, n));
    let j = DMatrix::from_fn(n, 4, |t, c| match c {
        0 => balance.inertia[t] / mass,
        1 => v[t],
        2 => (balance.friction_fitted[t] - viscous * v[t]) / coulomb,
        _ => 1.0,
    });
    let r = (0..n)
        .map(|t| rec.series.fitted[t] - rec.series.measured[t])
        .collect();
    (j, r)
}

/// The Newey-West standard errors, the Bartlett-weighted lag sum of the scores
/// g_t = J_t r_t written out pair by pair up to `lags`, in the sandwich (JᵀJ)^-1 S (JᵀJ)^-1
/// with the factor n / (n - p); and the classical ones, s² (JᵀJ)^-1.
fn newey_west_by_hand(j: &DMatrix<f64>, r: &[f64], lags: usize) -> (Vec<f64>, Vec<f64>) {
    let (n, p) = j.shape();
    let bread = (j.transpose() * j).try_inverse().unwrap();
    let g: Vec<Vec<f64>> = (0..n)
        .map(|t| (0..p).map(|c| j[(t, c)] * r[t]).collect())
        .collect();
    let mut meat = DMatrix::<f64>::zeros(p, p);
    for l in 0..=lags {
        let w = 1.0 - l as f64 / (lags as f64 + 1.0);
        for t in l..n {
            let (now, then) = (&g[t], &g[t - l]);
            for a in 0..p {
                for b in 0..p {
                    let pair = now[a] * then[b];
                    meat[(a, b)] += if l == 0 {
                        pair
                    } else {
                        w * (pair + then[a] * now[b])
                    };
                }
            }
        }
    }
    let hac = &bread * meat * &bread * (n as f64 / (n - p) as f64);
    let s2 = r.iter().map(|x| x * x).sum::<f64>() / (n - p) as f64;
    let se = |m: &DMatrix<f64>, k: usize| m[(k, k)].sqrt();
    (
        (0..p).map(|k| se(&hac, k)).collect(),
        (0..p).map(|k| s2.sqrt() * se(&bread, k)).collect(),
    )
}

/// Under the ringing, the reported standard errors of M, Fv, Fc and the offset agree within
/// 20 % with the Newey-West sum written out here (200 lags: the ringing's correlation has
/// decayed to 0.9^200 by then, and Bartlett's bias at that bandwidth is 1.5 %), and are well
/// above the classical ones, which take the ringing for white noise.
#[test]
fn standard_errors_under_a_ringing_match_an_independent_newey_west_sum() {
    let clean = TRUTH.record(SAMPLES);
    let result = inverse_dynamics(&noisy(&clean, &ringing().draw(SAMPLES, 3)));
    let (j, r) = regressors(&result);
    let (hac, classical) = newey_west_by_hand(&j, &r, 200);
    for (k, (name, _)) in truths().into_iter().enumerate() {
        let (_, reported) = estimate(&result, name);
        eprintln!(
            "{name}: reported {reported:.4e}, Newey-West {:.4e}, classical {:.4e}",
            hac[k], classical[k]
        );
        assert!(
            (reported / hac[k] - 1.0).abs() < 0.2,
            "{name}: reported {reported} against Newey-West {}",
            hac[k]
        );
    }
    assert!(hac[0] > 1.4 * classical[0], "{hac:?} vs {classical:?}");
}

/// Over `draws` records of each noise: the share of the 95 % intervals of M, Fv, Fc and the
/// offset that hold the truth, and the RMS of the standard scores (estimate - truth) /
/// standard error.
fn coverage(noise: Ar2Noise, draws: u64, seed: u64) -> (f64, f64) {
    let clean = TRUTH.record(SAMPLES);
    let (mut inside, mut total, mut squares) = (0usize, 0usize, 0.0);
    for d in 0..draws {
        let result = inverse_dynamics(&noisy(&clean, &noise.draw(SAMPLES, seed + d)));
        for (name, truth) in truths() {
            let p = result
                .parameters
                .iter()
                .find(|p| p.name == name || p.name.starts_with(&format!("{name}[")))
                .unwrap();
            let [lo, hi] = p.ci95.unwrap();
            inside += usize::from(lo <= truth && truth <= hi);
            total += 1;
            squares += ((p.value - truth) / p.std_error.unwrap()).powi(2);
        }
    }
    (
        inside as f64 / total as f64,
        (squares / total as f64).sqrt(),
    )
}

/// A few draws of each noise: the intervals hold the truth at least 85 % of the time and
/// the standard scores' RMS is within [0.6, 1.5] (the classical errors give about 2 under
/// the ringing and 4 under the AR(1)).
#[test]
fn intervals_cover_the_truth_under_coloured_noise() {
    for (label, noise) in [("AR(1) 0.9", AR1), ("ringing", ringing())] {
        let (covered, rms) = coverage(noise, 12, 500);
        eprintln!("{label}: coverage {covered:.3}, RMS score {rms:.3}");
        assert!(covered >= 0.85, "{label}: coverage {covered}");
        assert!((0.6..1.5).contains(&rms), "{label}: RMS score {rms}");
    }
}

/// The Monte Carlo: 400 records of each noise (1600 intervals): coverage within 92-98 %.
#[test]
#[ignore = "Monte Carlo of 800 fits: run with --ignored"]
fn intervals_cover_the_truth_under_coloured_noise_monte_carlo() {
    for (label, noise) in [("AR(1) 0.9", AR1), ("ringing", ringing())] {
        let (covered, rms) = coverage(noise, 400, 10_000);
        eprintln!("{label}: coverage {covered:.4}, RMS score {rms:.3}");
        assert!(
            (0.92..=0.98).contains(&covered),
            "{label}: coverage {covered}"
        );
    }
}
