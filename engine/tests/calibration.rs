//! Calibration of mu's standard error under coloured noise, against the exact piecewise
//! Coulomb solution (engine/src/exact.rs, independent of the fitted simulation): 200
//! realisations of the FMM case (three releases, 2 s at 1 kHz) with stationary AR(1) velocity
//! noise of lag-1 correlation 0.6 and 0.9. The 95 % interval must cover the truth in 92-98 %
//! of them and the spread of the estimates over the mean reported standard error stay within
//! 0.85-1.15. (`cargo run --release --example calibration` prints the same figures with the
//! uncertainty-budget runs beside them.)

use frictionid_engine::exact::coulomb_free_vibration;
use frictionid_engine::identify::{fit, FitOptions};
use frictionid_engine::synthetic::{add_coloured_noise, uniform_times};
use frictionid_engine::{Oscillator, Record};
use frictionid_models::Coulomb;

const MU: f64 = 0.24;
const NOISE: f64 = 2e-4;
const RELEASES: [f64; 3] = [0.010, 0.014, 0.022];
const REALISATIONS: usize = 200;

/// Coverage of the 95 % interval [%] and spread / mean standard error, over the realisations
/// with AR(1) noise of lag-1 correlation `phi`.
fn calibrate(phi: f64) -> (f64, f64) {
    let osc = Oscillator::fmm();
    let times = uniform_times(2.0, 1000.0);
    let exact: Vec<Vec<f64>> = RELEASES
        .iter()
        .map(|&x0| {
            coulomb_free_vibration(&osc, MU * osc.normal_force, x0, &times)
                .expect("exact solution")
                .v
        })
        .collect();
    let (mut covered, mut estimates, mut errors) = (0usize, Vec::new(), Vec::new());
    for k in 0..REALISATIONS {
        let records: Vec<Record> = RELEASES
            .iter()
            .zip(&exact)
            .enumerate()
            .map(|(i, (&x0, v))| {
                let mut v = v.clone();
                add_coloured_noise(&mut v, NOISE, phi, 20_000 + 3 * k as u64 + i as u64);
                Record::new(format!("r{i}"), times.clone(), v, x0)
            })
            .collect();
        let r = fit(&osc, &Coulomb::default(), &records, &FitOptions::default()).expect("fit");
        let p = r.param("mu").expect("mu");
        let [lo, hi] = p.ci95.expect("interval");
        covered += usize::from((lo..=hi).contains(&MU));
        estimates.push(p.value);
        errors.push(p.std_error.expect("standard error"));
    }
    let n = REALISATIONS as f64;
    let mean = estimates.iter().sum::<f64>() / n;
    let spread = (estimates.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let mean_error = errors.iter().sum::<f64>() / n;
    (100.0 * covered as f64 / n, spread / mean_error)
}

#[test]
fn mu_intervals_hold_under_coloured_noise() {
    for phi in [0.6, 0.9] {
        let (coverage, ratio) = calibrate(phi);
        eprintln!("AR(1) {phi}: coverage {coverage:.1} %, spread / standard error {ratio:.3}");
        assert!((92.0..=98.0).contains(&coverage), "phi {phi}: {coverage} %");
        assert!((0.85..=1.15).contains(&ratio), "phi {phi}: {ratio}");
    }
}
