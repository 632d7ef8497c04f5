//! Synthetic measurements: reproducible Gaussian noise and uniform sample times.

use crate::error::EngineError;
use crate::oscillator::Oscillator;
use crate::record::Record;
use crate::simulate::{simulate, Initial, SimOptions};
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
    osc: &Oscillator,
    model: &dyn frictionid_models::FrictionModel,
    releases: &[f64],
    duration: f64,
    sample_rate: f64,
    noise: f64,
    seed: u64,
) -> Result<Vec<Record>, EngineError> {
    let times = uniform_times(duration, sample_rate);
    releases
        .iter()
        .enumerate()
        .map(|(i, &x0)| {
            let mut v = released_velocity(osc, model, x0, duration, &times)?;
            add_gaussian_noise(&mut v, noise, seed + i as u64);
            Ok(Record::new(
                format!("x{}mm", (x0 * 1e3).round()),
                times.clone(),
                v,
                x0,
            ))
        })
        .collect()
}

/// The velocity of the free vibration of `osc` with `model` released from rest at `x0`,
/// simulated until `t_end` with the default options, at `times`.
fn released_velocity(
    osc: &Oscillator,
    model: &dyn frictionid_models::FrictionModel,
    x0: f64,
    t_end: f64,
    times: &[f64],
) -> Result<Vec<f64>, EngineError> {
    let initial = Initial::at_rest(x0);
    let opts = SimOptions::default();
    Ok(simulate(osc, model, &initial, t_end, times, &opts)?.v)
}

/// Adds stationary AR(1) ("coloured") noise of standard deviation `sigma` and lag-one
/// correlation `correlation` (in [0, 1)) to `values`, reproducibly for a given `seed`:
/// e_i = rho e_{i-1} + sqrt(1 - rho^2) w_i with w white Gaussian of deviation `sigma`.
pub fn add_coloured_noise(values: &mut [f64], sigma: f64, correlation: f64, seed: u64) {
    let rho = correlation.clamp(0.0, 0.999_999);
    let mut white = vec![0.0; values.len()];
    add_gaussian_noise(&mut white, sigma, seed);
    let gain = (1.0 - rho * rho).sqrt();
    // Start in the stationary distribution: e_0 = w_0.
    let mut e = white.first().copied().unwrap_or(0.0);
    for (i, v) in values.iter_mut().enumerate() {
        if i > 0 {
            e = rho * e + gain * white[i];
        }
        *v += e;
    }
}

/// The defects of a real free-vibration measurement, for [`defective_record`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Defects {
    /// Pre-trigger rest before the release \[s\] (the instrument already records).
    pub rest: f64,
    /// Constant velocity offset [m/s].
    pub offset: f64,
    /// Standard deviation of the velocity noise [m/s].
    pub noise: f64,
    /// Lag-one correlation of the noise (0: white).
    pub correlation: f64,
}

/// A measured-like velocity record of `model` on `osc` released from rest at `x0`: `rest`
/// seconds at rest, then `duration` seconds of free vibration, sampled at `sample_rate` Hz
/// from t = 0, with the offset and the (coloured) noise of `defects` over the whole record.
/// The release is at t = `defects.rest`; the record's x0 is the true one.
pub fn defective_record(
    osc: &Oscillator,
    model: &dyn frictionid_models::FrictionModel,
    x0: f64,
    duration: f64,
    sample_rate: f64,
    defects: &Defects,
    seed: u64,
) -> Result<Record, EngineError> {
    let times = uniform_times(defects.rest + duration, sample_rate);
    let first_moving = times.partition_point(|&t| t < defects.rest);
    let moving: Vec<f64> = times[first_moving..]
        .iter()
        .map(|t| (t - defects.rest).max(0.0))
        .collect();
    let end = moving.last().copied().unwrap_or(0.0);
    let mut v = vec![0.0; first_moving];
    v.extend(released_velocity(osc, model, x0, end, &moving)?);
    add_coloured_noise(&mut v, defects.noise, defects.correlation, seed);
    v.iter_mut().for_each(|x| *x += defects.offset);
    Ok(Record::new(
        format!("x{}mm-rest", (x0 * 1e3).round()),
        times,
        v,
        x0,
    ))
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

    #[test]
    fn coloured_noise_has_its_spread_and_correlation() {
        let mut e = vec![0.0; 50000];
        add_coloured_noise(&mut e, 2e-4, 0.8, 3);
        let n = e.len() as f64;
        let var = e.iter().map(|x| x * x).sum::<f64>() / n;
        let lag1 = e.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / (n - 1.0);
        assert!((var.sqrt() / 2e-4 - 1.0).abs() < 0.05, "sd {}", var.sqrt());
        assert!((lag1 / var - 0.8).abs() < 0.02, "rho {}", lag1 / var);
    }

    #[test]
    fn a_defective_record_rests_then_moves() {
        let osc = crate::Oscillator::fmm();
        let model = frictionid_models::Coulomb { mu: 0.24 };
        let defects = Defects {
            rest: 0.25,
            offset: 1e-3,
            noise: 0.0,
            correlation: 0.0,
        };
        let r = defective_record(&osc, &model, 0.014, 0.5, 1000.0, &defects, 1).unwrap();
        assert_eq!(r.len(), 751);
        assert!(r.velocity()[..251].iter().all(|&v| v == 1e-3));
        // The exact Coulomb solution 0.1 s after the release.
        let w = (osc.stiffness / osc.mass).sqrt();
        let a = 0.014 - 0.24 * 14.5 / osc.stiffness;
        let expected = -a * w * (w * 0.1).sin() + 1e-3;
        assert!(
            (r.velocity()[350] - expected).abs() < 2e-3 * a * w,
            "{}",
            r.velocity()[350]
        );
    }
}
