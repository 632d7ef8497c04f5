//! Synthetic measurements: reproducible Gaussian noise and uniform sample times.

use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

/// Sample times 0, 1/rate, ... up to and including `duration` (to round-off).
pub fn uniform_times(duration: f64, sample_rate: f64) -> Vec<f64> {
    if !(duration.is_finite() && sample_rate.is_finite() && duration >= 0.0 && sample_rate > 0.0) {
        return Vec::new();
    }
    let n = (duration * sample_rate + 1e-9).floor() as usize + 1;
    (0..n).map(|i| i as f64 / sample_rate).collect()
}

/// Adds zero-mean Gaussian noise of standard deviation `sigma` to `values`, reproducibly for a
/// given `seed`. A non-positive or non-finite `sigma` leaves the values unchanged.
pub fn add_gaussian_noise(values: &mut [f64], sigma: f64, seed: u64) {
    let Ok(normal) = Normal::new(0.0, sigma) else {
        return;
    };
    if sigma <= 0.0 {
        return;
    }
    let mut rng = StdRng::seed_from_u64(seed);
    for v in values {
        *v += normal.sample(&mut rng);
    }
}

/// Synthetic measured records: the free vibration of `osc` with `model` released from rest at
/// each of `releases` [m], simulated for `duration` s, sampled at `sample_rate` Hz, with
/// Gaussian velocity noise of `noise` m/s (seed `seed + i` for the i-th release). Record
/// names are `x{mm}mm`.
pub fn release_records(
    osc: &crate::Oscillator,
    model: &dyn frictionid_models::FrictionModel,
    releases: &[f64],
    duration: f64,
    sample_rate: f64,
    noise: f64,
    seed: u64,
) -> Result<Vec<crate::Record>, crate::EngineError> {
    let times = uniform_times(duration, sample_rate);
    releases
        .iter()
        .enumerate()
        .map(|(i, &x0)| {
            let traj = crate::simulate(
                osc,
                model,
                &crate::Initial::at_rest(x0),
                duration,
                &times,
                &crate::SimOptions::default(),
            )?;
            let mut v = traj.v;
            add_gaussian_noise(&mut v, noise, seed + i as u64);
            Ok(crate::Record::new(
                format!("x{}mm", (x0 * 1e3).round()),
                times.clone(),
                v,
                x0,
            ))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_cover_the_duration() {
        let t = uniform_times(2.0, 1000.0);
        assert_eq!(t.len(), 2001);
        assert!((t[2000] - 2.0).abs() < 1e-12);
    }

    #[test]
    fn noise_has_the_requested_spread_and_is_reproducible() {
        let mut a = vec![0.0; 20000];
        add_gaussian_noise(&mut a, 2e-4, 7);
        let mut b = vec![0.0; 20000];
        add_gaussian_noise(&mut b, 2e-4, 7);
        assert_eq!(a, b);
        let mean = a.iter().sum::<f64>() / a.len() as f64;
        let sd = (a.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / a.len() as f64).sqrt();
        assert!(mean.abs() < 1e-5);
        assert!((sd / 2e-4 - 1.0).abs() < 0.03, "sd = {sd}");
    }
}
