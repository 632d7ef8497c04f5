//! The white-noise level of a sampled channel, estimated from the record itself.
//!
//! The k-th differences of a smooth signal sampled densely are tiny (a sinusoid of angular
//! frequency w sampled at dt shrinks by (w dt)^k), while those of white noise of standard
//! deviation sigma have the standard deviation sigma sqrt(C(2k, k)). The median absolute
//! deviation of the k-th differences, scaled to a standard deviation (1.4826), over
//! sqrt(C(2k, k)) therefore estimates sigma, robustly to the isolated jumps at reversals and
//! stops. The one estimator of the workspace: the energy analysis, the force domain and the
//! response channels use it with the order their signals need.

use super::Channel;
use std::collections::BTreeMap;

/// Difference order for response channels (velocity, displacement, acceleration): third
/// differences of the FMM motion (1 kHz, 2.2 Hz) are 1e-6 of the signal, far below any
/// instrument's noise.
pub(crate) const RESPONSE_ORDER: usize = 3;

/// Robust white-noise standard deviation of `values` from their `order`-th differences (see
/// the module docs); 0 when there are too few samples.
pub(crate) fn difference_noise(values: &[f64], order: usize) -> f64 {
    let d = differences(values, order);
    if d.is_empty() {
        return 0.0;
    }
    let centre = median(&d);
    let dev: Vec<f64> = d.iter().map(|x| (x - centre).abs()).collect();
    1.4826 * median(&dev) / central_binomial(order).sqrt()
}

/// The `order`-th differences of `values`, computed in place one order after the other.
fn differences(values: &[f64], order: usize) -> Vec<f64> {
    let mut d = values.to_vec();
    for _ in 0..order.min(d.len()) {
        for i in 0..d.len() - 1 {
            d[i] = d[i + 1] - d[i];
        }
        d.pop();
    }
    d
}

/// The RMS counterpart of [`difference_noise`]: the root mean square of the `order`-th
/// differences over sqrt(C(2k, k)). Where the median-based level ignores bursts (a force that
/// chatters on a few stretches of a record), this one counts them; 0 when there are too few
/// samples.
pub(crate) fn rms_difference_noise(values: &[f64], order: usize) -> f64 {
    let d = differences(values, order);
    if d.is_empty() {
        return 0.0;
    }
    let mean_square = d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64;
    (mean_square / central_binomial(order)).sqrt()
}

/// [`difference_noise`], never below 1e-6 of the values' RMS (noise-free records) nor zero:
/// a level to divide residuals by.
pub(crate) fn noise_floor_level(values: &[f64], order: usize) -> f64 {
    difference_noise(values, order).max(noise_floor(values))
}

/// The smallest level [`noise_floor_level`] returns: 1e-6 of the values' RMS, 1 for zeros.
pub(crate) fn noise_floor(values: &[f64]) -> f64 {
    let rms = (values.iter().map(|f| f * f).sum::<f64>() / values.len().max(1) as f64).sqrt();
    if rms > 0.0 {
        1e-6 * rms
    } else {
        1.0
    }
}

/// The quantisation step of `values` when they sit on a uniform grid (an encoder's counts, an
/// ADC's levels): the smallest non-zero difference between successive samples, kept when at
/// least 99 % of the samples lie within 5 % of a step of the grid through the first sample.
/// `None` for values that are not quantised (their smallest difference is a grazing one that
/// the other samples do not share), and for fewer than 10 non-zero differences.
pub(crate) fn quantisation_step(values: &[f64]) -> Option<f64> {
    let step = values
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| *d > 0.0 && d.is_finite());
    let (count, smallest) = step.fold((0usize, f64::INFINITY), |(n, m), d| (n + 1, m.min(d)));
    if count < 10 || !smallest.is_finite() {
        return None;
    }
    let origin = values.first().copied()?;
    let off_grid = values
        .iter()
        .filter(|&&x| {
            let steps = (x - origin) / smallest;
            !(steps.abs() < 1e7 && (steps - steps.round()).abs() <= 0.05)
        })
        .count();
    (off_grid * 100 <= values.len()).then_some(smallest)
}

/// C(2k, k): the variance gain of the k-th difference of white noise.
fn central_binomial(k: usize) -> f64 {
    (1..=k).fold(1.0, |c, i| c * (k + i) as f64 / i as f64)
}

/// The median (the upper one for an even count); 0 for no values.
fn median(values: &[f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let mid = values.len() / 2;
    let mut keys: Vec<u64> = values.iter().map(|&x| order_key(x)).collect();
    from_order_key(*keys.select_nth_unstable(mid).1)
}

/// The bits of `x` as an unsigned key in `f64::total_cmp`'s order: selecting on integers
/// gives the same element as selecting with `total_cmp`, at a fraction of the comparisons'
/// cost (the noise medians were a tenth of a first Coulomb fit).
fn order_key(x: f64) -> u64 {
    let bits = x.to_bits();
    if bits >> 63 == 1 {
        !bits
    } else {
        bits | (1 << 63)
    }
}

/// The value of an [`order_key`].
fn from_order_key(key: u64) -> f64 {
    f64::from_bits(if key >> 63 == 1 {
        key & !(1 << 63)
    } else {
        !key
    })
}

/// The [`difference_noise`] of a record's channels, each order computed once (a fit asks
/// for a record's velocity noise a dozen times: weights, the guess, the turning points, the
/// energy check). One of the facts a record derives from its samples (`SampleFacts`), not
/// part of its value.
#[derive(Debug, Default)]
pub(crate) struct NoiseCache(std::sync::Mutex<BTreeMap<(Channel, usize), f64>>);

impl NoiseCache {
    /// The cached noise of `channel`'s differences of `order`, else `estimate()` (then
    /// cached).
    pub(crate) fn get_or(
        &self,
        channel: Channel,
        order: usize,
        estimate: impl FnOnce() -> f64,
    ) -> f64 {
        let key = (channel, order);
        if let Some(level) = self.levels().and_then(|l| l.get(&key).copied()) {
            return level;
        }
        let level = estimate();
        if let Some(mut levels) = self.levels() {
            levels.insert(key, level);
        }
        level
    }

    /// Forgets every level (the samples changed).
    pub(crate) fn clear(&mut self) {
        if let Ok(levels) = self.0.get_mut() {
            levels.clear();
        }
    }

    fn levels(&self) -> Option<std::sync::MutexGuard<'_, BTreeMap<(Channel, usize), f64>>> {
        self.0.lock().ok()
    }
}

impl Clone for NoiseCache {
    fn clone(&self) -> Self {
        Self(std::sync::Mutex::new(
            self.levels().map(|l| l.clone()).unwrap_or_default(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::add_gaussian_noise;

    /// An encoder's counts of a sinusoid give back the count; the sinusoid itself, sampled
    /// finely enough to pass close to some values, has no step.
    #[test]
    fn the_step_of_quantised_values_is_found_and_smooth_values_have_none() {
        let q = 1.5e-6;
        let smooth: Vec<f64> = (0..5000)
            .map(|i| 0.01 * (i as f64 * 1e-3 * 13.8).sin() + 3e-4)
            .collect();
        let counts: Vec<f64> = smooth.iter().map(|x| (x / q).round() * q).collect();
        let step = quantisation_step(&counts).unwrap();
        assert!((step / q - 1.0).abs() < 1e-6, "{step}");
        assert_eq!(quantisation_step(&smooth), None);
        assert_eq!(quantisation_step(&counts[..5]), None);
    }

    /// White noise on a sinusoid sampled like the FMM records: every order from 1 (on a slow
    /// ramp) to 3 (on the oscillation) returns the noise's sigma within a few per cent.
    #[test]
    fn the_level_of_white_noise_on_a_smooth_signal_is_its_sigma() {
        let sigma = 2e-4;
        let mut ramp: Vec<f64> = (0..20_000).map(|i| 1.0 + 1e-5 * i as f64).collect();
        add_gaussian_noise(&mut ramp, sigma, 3);
        assert!((difference_noise(&ramp, 1) / sigma - 1.0).abs() < 0.03);
        let w = 2.0 * std::f64::consts::PI * 2.2;
        let mut v: Vec<f64> = (0..2001)
            .map(|i| 0.3 * (w * i as f64 * 1e-3).sin())
            .collect();
        add_gaussian_noise(&mut v, sigma, 4);
        for order in [2, 3] {
            let est = difference_noise(&v, order);
            assert!((est / sigma - 1.0).abs() < 0.06, "order {order}: {est}");
        }
    }

    /// The median by integer keys is the element `total_cmp` selects, signed zeros,
    /// infinities and ties included.
    #[test]
    fn the_median_is_the_total_order_median() {
        let mut rng_state = 11u64;
        let mut next = || {
            rng_state = rng_state.wrapping_mul(6364136223846793005).wrapping_add(1);
            ((rng_state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 10.0
        };
        for n in [1, 2, 3, 10, 101, 2000] {
            let mut values: Vec<f64> = (0..n).map(|_| next()).collect();
            values.extend([0.0, -0.0, 1.5, 1.5, f64::INFINITY, f64::NEG_INFINITY]);
            let mut by_cmp = values.clone();
            let mid = by_cmp.len() / 2;
            let expected = *by_cmp.select_nth_unstable_by(mid, f64::total_cmp).1;
            assert_eq!(median(&values).to_bits(), expected.to_bits(), "n {n}");
        }
        for x in [0.0, -0.0, 1e-300, -2.5, f64::MAX, f64::NEG_INFINITY] {
            assert_eq!(from_order_key(order_key(x)).to_bits(), x.to_bits());
        }
    }

    #[test]
    fn binomials_floors_and_short_series() {
        assert_eq!(central_binomial(1), 2.0);
        assert_eq!(central_binomial(3), 20.0);
        assert_eq!(difference_noise(&[1.0, 2.0], 3), 0.0);
        assert_eq!(noise_floor_level(&[2.0, 2.0, 2.0], 1), 2e-6);
        assert_eq!(noise_floor_level(&[0.0; 5], 1), 1.0);
    }
}
