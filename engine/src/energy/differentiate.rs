//! Numerical differentiation of a sampled velocity: the paper's recipe (central difference,
//! then a moving average) and a Savitzky-Golay least-squares polynomial derivative.

use crate::error::EngineError;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use std::sync::{Arc, Mutex};

/// The moving-average span of the paper's recipe (section 5: "a moving average filter with a
/// span of 10 points").
pub const PAPER_SPAN: usize = 10;

/// How the acceleration is obtained from the measured velocity.
///
/// Serialized with a `method` tag: `{"method": "paper"}` or
/// `{"method": "savitzky_golay", "window": 31, "order": 4}`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "snake_case", deny_unknown_fields)]
pub enum Differentiator {
    /// A quartic Savitzky-Golay derivative per half-cycle whose window is chosen from the
    /// record ([`auto_window`]): a fifteenth of the natural period (31 samples for the FMM at
    /// 1 kHz), at most [`MAX_AUTO_WINDOW`] samples, widened up to a quarter period when the
    /// velocity's noise or quantisation would dominate the derivative.
    Auto,
    /// The paper's recipe: central differences, then a centred moving average of span 10
    /// ([`paper_derivative`]). Applied to the whole record, as in the paper.
    Paper,
    /// A Savitzky-Golay derivative: the slope at each sample of the least-squares polynomial
    /// of degree `order` through `window` samples (odd, > `order`), applied separately to each
    /// half-cycle so that no fit straddles a velocity reversal ([`savitzky_golay_derivative`]).
    SavitzkyGolay {
        /// Number of samples in each fit (odd).
        window: usize,
        /// Polynomial degree (>= 1, < window).
        order: usize,
    },
}

impl Default for Differentiator {
    /// [`Differentiator::Auto`]: at 1 kHz on the FMM rig, Savitzky-Golay with a 31-sample
    /// window and a quartic; the fit spans 30 ms, about 1/15 of the FMM's 0.455 s period, so
    /// the quartic follows its sine to 4e-6 relative (3e-5 with the one-sided fits at the
    /// ends) while averaging white noise over 31 samples (see the `energy` module docs for
    /// the measured figures behind this choice). At other rates and periods the window keeps
    /// that span.
    fn default() -> Self {
        Differentiator::Auto
    }
}

/// The polynomial degree of [`Differentiator::Auto`].
pub const AUTO_ORDER: usize = 4;
/// The share of the natural period [`Differentiator::Auto`]'s window spans before any
/// widening.
pub(crate) const AUTO_PERIOD_SHARE: f64 = 1.0 / 15.0;
/// The largest share of the natural period the automatic window widens to (half a
/// half-cycle: a quartic still follows a sine over it to 1e-3).
pub(crate) const AUTO_MAX_PERIOD_SHARE: f64 = 0.25;
/// The most samples in an automatic window (its weight table grows with the square).
pub(crate) const MAX_AUTO_WINDOW: usize = 1001;
/// The share of the friction level the derivative's noise (times the mass) may reach before
/// the automatic window widens: below a quarter of the level, the mean |F| of Eq. 7 is
/// biased by less than 0.01 % by the noise's absolute value.
pub(crate) const AUTO_NOISE_SHARE: f64 = 0.25;

/// What [`auto_window`] chooses from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowInputs {
    /// Sample spacing \[s\].
    pub dt: f64,
    /// The oscillator's natural period \[s\].
    pub period: f64,
    /// The velocity's noise standard deviation, quantisation included \[m/s\].
    pub velocity_noise: f64,
    /// The mass that turns the acceleration into a force \[kg\].
    pub mass: f64,
    /// The friction level the derivative's noise is held against \[N\] (the half-cycle
    /// mean; NaN or 0 when unknown: no widening).
    pub level: f64,
}

/// The automatic Savitzky-Golay window (odd, at least `AUTO_ORDER + 3` samples) and the
/// standard deviation of the force m a it leaves from the velocity's noise \[N\]: a
/// fifteenth of the natural period, bounded by [`MAX_AUTO_WINDOW`] and a quarter period,
/// widened by half at a time while that force noise exceeds [`AUTO_NOISE_SHARE`] of the
/// friction level.
pub fn auto_window(inputs: &WindowInputs) -> Result<(usize, f64), EngineError> {
    let samples = |share: f64| inputs.period * share / inputs.dt;
    let cap = nearest_odd(samples(AUTO_MAX_PERIOD_SHARE).floor() - 1.0)
        .clamp(AUTO_ORDER + 3, MAX_AUTO_WINDOW);
    let mut window = auto_base_window(inputs.dt, inputs.period).min(cap);
    let noise = |w: usize| -> Result<f64, EngineError> {
        Ok(inputs.mass * inputs.velocity_noise * centre_weight_norm(w, AUTO_ORDER)? / inputs.dt)
    };
    let allowed = AUTO_NOISE_SHARE * inputs.level;
    let mut force_noise = noise(window)?;
    while allowed > 0.0 && force_noise > allowed && window < cap {
        window = nearest_odd(window as f64 * 1.5).clamp(window + 2, cap);
        force_noise = noise(window)?;
    }
    Ok((window, force_noise))
}

/// The automatic window before any widening: the odd sample count nearest to
/// [`AUTO_PERIOD_SHARE`] of the natural `period` at spacing `dt`, within `AUTO_ORDER + 3`
/// and [`MAX_AUTO_WINDOW`]; also the fewest samples a record needs for it.
pub(crate) fn auto_base_window(dt: f64, period: f64) -> usize {
    nearest_odd(period * AUTO_PERIOD_SHARE / dt).clamp(AUTO_ORDER + 3, MAX_AUTO_WINDOW)
}

/// The odd number nearest to `x` (1 at least; an even `x` rounds up).
fn nearest_odd(x: f64) -> usize {
    if !x.is_finite() || x < 1.0 {
        return 1;
    }
    let below = ((x - 1.0) / 2.0).floor() as usize * 2 + 1;
    if x - below as f64 >= 1.0 {
        below + 2
    } else {
        below
    }
}

/// The Euclidean norm of the centred Savitzky-Golay derivative weights (unit spacing) of
/// `window` samples and degree `order`: the derivative's noise is the samples' white noise
/// times it, over the spacing.
pub fn centre_weight_norm(window: usize, order: usize) -> Result<f64, EngineError> {
    let h = (window / 2) as f64;
    let offsets: Vec<f64> = (0..window).map(|j| j as f64 - h).collect();
    Ok(derivative_weights(&offsets, order)?
        .iter()
        .map(|w| w * w)
        .sum::<f64>()
        .sqrt())
}

/// The norm of the paper's derivative weights (unit spacing): a central difference averaged
/// over 9 samples telescopes to (v\[i+5\] + v\[i+4\] - v\[i-4\] - v\[i-5\]) / 18.
pub(crate) const PAPER_WEIGHT_NORM: f64 = 2.0 / 18.0;

impl Differentiator {
    /// The fewest samples a record needs for this method.
    pub fn min_samples(&self) -> usize {
        match *self {
            Differentiator::Auto => AUTO_ORDER + 3,
            Differentiator::Paper => PAPER_SPAN,
            Differentiator::SavitzkyGolay { window, .. } => window,
        }
    }

    /// Checks the method's parameters.
    pub fn validate(&self) -> Result<(), EngineError> {
        if let Differentiator::SavitzkyGolay { window, order } = *self {
            if order == 0 || order > 10 {
                return Err(EngineError::InvalidInput(format!(
                    "savitzky_golay `order` must be in 1..=10, got {order}"
                )));
            }
            if window % 2 == 0 || window <= order {
                return Err(EngineError::InvalidInput(format!(
                    "savitzky_golay `window` must be odd and greater than `order` = {order}, \
                     got {window}"
                )));
            }
        }
        Ok(())
    }
}

/// Central differences of `v` over `time` (second-order one-sided differences at the two
/// ends, as `numpy.gradient(..., edge_order=2)`; the three-point formulas for uneven spacing).
/// Needs at least 3 samples; returns zeros for fewer than 2.
pub fn central_difference(time: &[f64], v: &[f64]) -> Vec<f64> {
    let n = time.len().min(v.len());
    let mut d = vec![0.0; n];
    if n < 2 {
        return d;
    }
    if n == 2 {
        let s = (v[1] - v[0]) / (time[1] - time[0]);
        return vec![s, s];
    }
    for i in 1..n - 1 {
        d[i] = three_point(&time[i - 1..=i + 1], &v[i - 1..=i + 1], time[i]);
    }
    d[0] = three_point(&time[..3], &v[..3], time[0]);
    d[n - 1] = three_point(&time[n - 3..], &v[n - 3..], time[n - 1]);
    d
}

/// Slope at `t` of the parabola through three points (exact for quadratics).
fn three_point(t: &[f64], v: &[f64], at: f64) -> f64 {
    let (t0, t1, t2) = (t[0], t[1], t[2]);
    let l0 = (2.0 * at - t1 - t2) / ((t0 - t1) * (t0 - t2));
    let l1 = (2.0 * at - t0 - t2) / ((t1 - t0) * (t1 - t2));
    let l2 = (2.0 * at - t0 - t1) / ((t2 - t0) * (t2 - t1));
    l0 * v[0] + l1 * v[1] + l2 * v[2]
}

/// A centred moving average with the convention of MATLAB's `smooth(y, span)`, which the
/// paper's authors used: an even span is reduced by one so that the window stays centred (a
/// 10-point average would shift the signal by half a sample, i.e. lag the acceleration by
/// dt/2), and near the ends the window shrinks symmetrically (1, 3, 5, ... samples) so that
/// every output is a centred average.
pub fn moving_average(values: &[f64], span: usize) -> Vec<f64> {
    let n = values.len();
    let width = if span % 2 == 0 {
        span.saturating_sub(1)
    } else {
        span
    }
    .max(1);
    let half = width / 2;
    // Prefix sums make every window O(1).
    let mut prefix = Vec::with_capacity(n + 1);
    prefix.push(0.0);
    let mut acc = 0.0;
    for &x in values {
        acc += x;
        prefix.push(acc);
    }
    (0..n)
        .map(|i| {
            let h = half.min(i).min(n - 1 - i);
            let (lo, hi) = (i - h, i + h + 1);
            (prefix[hi] - prefix[lo]) / (hi - lo) as f64
        })
        .collect()
}

/// The paper's acceleration: central differences of the velocity, smoothed by a centred
/// moving average of span [`PAPER_SPAN`] (see [`moving_average`] for the even span).
pub fn paper_derivative(time: &[f64], v: &[f64]) -> Vec<f64> {
    moving_average(&central_difference(time, v), PAPER_SPAN)
}

/// Savitzky-Golay weights on a uniform grid of unit spacing, by window size and degree, each
/// by the sample's place in its window. They depend on nothing else, so one table serves
/// every record and every call (a fit analyses each record twice: for its starting hint and
/// for its energy check).
type WeightTable = Arc<Vec<Vec<f64>>>;

/// Tables kept at most: window sizes other than the configured one come only from segments
/// shorter than it.
const MAX_TABLES: usize = 64;

/// Weights kept at most over all tables (16 MiB): a table holds window² weights (8 MB for
/// the widest window, 1001 samples), so a process that met many wide windows would otherwise
/// keep up to half a gigabyte.
const MAX_KEPT_WEIGHTS: usize = 2 << 20;

static UNIT_WEIGHTS: Mutex<Vec<((usize, usize), WeightTable)>> = Mutex::new(Vec::new());

/// The unit-spacing weight table of `window` samples and degree `order`.
fn unit_weights(window: usize, order: usize) -> Result<WeightTable, EngineError> {
    let key = (window, order);
    let cached = |tables: &[((usize, usize), WeightTable)]| {
        tables
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, t)| t.clone())
    };
    if let Some(table) = UNIT_WEIGHTS.lock().ok().and_then(|t| cached(&t)) {
        return Ok(table);
    }
    let table: WeightTable = Arc::new(
        (0..window)
            .map(|place| {
                let offsets: Vec<f64> = (0..window).map(|j| j as f64 - place as f64).collect();
                derivative_weights(&offsets, order)
            })
            .collect::<Result<_, _>>()?,
    );
    if let Ok(mut tables) = UNIT_WEIGHTS.lock() {
        let kept: usize = tables.iter().map(|(k, _)| k.0 * k.0).sum();
        if tables.len() >= MAX_TABLES || kept + window * window > MAX_KEPT_WEIGHTS {
            tables.clear();
        }
        tables.push((key, table.clone()));
    }
    Ok(table)
}

/// Savitzky-Golay derivative of `v` sampled at `time`.
///
/// At each sample the polynomial of degree `order` is fitted by least squares to `window`
/// samples and its slope at that sample is returned. The samples are split into segments at
/// the indices in `breaks` (each the first sample of a new segment; out-of-range indices are
/// ignored); a fit never
/// reaches across a break. Inside a segment the window is centred where it fits and slides
/// inwards near the segment ends (a one-sided fit of the same size, evaluated at the end
/// sample). A segment shorter than `window` is fitted whole with the degree reduced to its
/// length minus one; a one-sample segment borrows its neighbours.
///
/// The weights come from a small least-squares solve (normal equations of the scaled
/// Vandermonde matrix, Cholesky). On a uniform grid (spacing equal to 1e-6 relative) they come
/// from a unit-spacing table per window size and degree, shared by every call, and the slope
/// is divided by the spacing; otherwise every sample gets its own fit in the actual time
/// offsets.
pub fn savitzky_golay_derivative(
    time: &[f64],
    v: &[f64],
    window: usize,
    order: usize,
    breaks: &[usize],
) -> Result<Vec<f64>, EngineError> {
    Differentiator::SavitzkyGolay { window, order }.validate()?;
    let n = time.len().min(v.len());
    let mut out = vec![0.0; n];
    if n < 2 {
        return Ok(out);
    }
    let uniform_dt = uniform_spacing(&time[..n]);
    for seg in segment_bounds(breaks, n).windows(2) {
        let (s, e, w, p) = segment_span(seg, n, window, order);
        // Uniform grid: the weights depend only on the sample's place in its window.
        let table = match uniform_dt {
            Some(_) => Some(unit_weights(w, p)?),
            None => None,
        };
        // Where the window is centred, every sample has the centre row: one sweep per tap.
        let centred = (s + w / 2)..(e + w / 2 + 1 - w).max(s + w / 2);
        let centred = match (&table, uniform_dt) {
            (Some(table), Some(dt)) if seg[0] <= centred.start && centred.end <= seg[1] => {
                centred_slopes(&table[w / 2], v, centred.clone(), dt, &mut out);
                centred
            }
            _ => 0..0,
        };
        for i in (seg[0]..seg[1]).filter(|i| !centred.contains(i)) {
            let lo = i.saturating_sub(w / 2).clamp(s, e - w);
            let hi = lo + w;
            let slope = match (&table, uniform_dt) {
                (Some(table), Some(dt)) => dot(&table[i - lo], &v[lo..hi]) / dt,
                _ => {
                    let offsets: Vec<f64> = (lo..hi).map(|j| time[j] - time[i]).collect();
                    dot(&derivative_weights(&offsets, p)?, &v[lo..hi])
                }
            };
            out[i] = slope;
        }
    }
    Ok(out)
}

/// The bounds of the segments between `breaks` in `n` samples: 0, the breaks inside, n.
fn segment_bounds(breaks: &[usize], n: usize) -> Vec<usize> {
    let mut bounds: Vec<usize> = Vec::with_capacity(breaks.len() + 2);
    bounds.push(0);
    bounds.extend(breaks.iter().copied().filter(|&b| b > 0 && b < n));
    bounds.push(n);
    bounds.sort_unstable();
    bounds.dedup();
    bounds
}

/// Where the windows of segment `seg` (of `n` samples) may lie, `(start, end)`, and the
/// window and order fitted there: `window` and `order`, shortened to a shorter span. A lone
/// sample between two breaks is fitted with its whole-record neighbourhood.
fn segment_span(
    seg: &[usize],
    n: usize,
    window: usize,
    order: usize,
) -> (usize, usize, usize, usize) {
    let (s, e) = if seg[1] - seg[0] < 2 {
        (0, n)
    } else {
        (seg[0], seg[1])
    };
    let len = e - s;
    let (w, p) = if len >= window {
        (window, order)
    } else {
        (len, order.min(len - 1))
    };
    (s, e, w, p)
}

/// The noise gain of [`savitzky_golay_derivative`] at each of `n` samples with the same
/// `window`, `order` and `breaks`: the norm of the sample's weights (unit spacing) over that
/// of a centred window, so 1 where the window is centred and more where it slides inwards
/// near a break (a one-sided fit amplifies the velocity's noise most at the run's end
/// sample). Computed in sample offsets: on an uneven grid it is the gain on the grid's
/// average spacing.
pub fn savitzky_golay_noise_gains(
    n: usize,
    window: usize,
    order: usize,
    breaks: &[usize],
) -> Result<Vec<f64>, EngineError> {
    Differentiator::SavitzkyGolay { window, order }.validate()?;
    let mut gains = vec![1.0; n];
    if n < 2 {
        return Ok(gains);
    }
    let centre = centre_weight_norm(window, order)?;
    for seg in segment_bounds(breaks, n).windows(2) {
        let (s, e, w, p) = segment_span(seg, n, window, order);
        let table = unit_weights(w, p)?;
        let norm = |row: &[f64]| row.iter().map(|x| x * x).sum::<f64>().sqrt();
        for (i, gain) in gains.iter_mut().enumerate().take(seg[1]).skip(seg[0]) {
            let lo = i.saturating_sub(w / 2).clamp(s, e - w);
            *gain = norm(&table[i - lo]) / centre;
        }
    }
    Ok(gains)
}

/// The slopes at the samples `at` of a window centred on each, from the centre row `weights`
/// of the unit-spacing table: out\[i\] = sum_k weights\[k\] v\[i - h + k\] / dt (h = half the
/// window), summed tap after tap over all samples at once (contiguous sweeps the compiler
/// vectorises; a dot product per sample took seven instructions per tap).
fn centred_slopes(
    weights: &[f64],
    v: &[f64],
    at: std::ops::Range<usize>,
    dt: f64,
    out: &mut [f64],
) {
    let h = weights.len() / 2;
    let w = weights.len();
    let slopes = &mut out[at.clone()];
    // Blocks of BLOCK samples summed in registers, tap after tap: each slope is the same
    // sum in the same order (0 + c_0 v_0 + c_1 v_1 + ...) as one sample at a time, without
    // storing the partial sums between taps.
    let mut blocks = slopes.chunks_exact_mut(BLOCK);
    for (b, block) in blocks.by_ref().enumerate() {
        let first = at.start + b * BLOCK - h;
        let window = &v[first..first + w - 1 + BLOCK];
        let mut acc = [0.0; BLOCK];
        for (k, &c) in weights.iter().enumerate() {
            let shifted = &window[k..k + BLOCK];
            for (a, &vk) in acc.iter_mut().zip(shifted) {
                *a += c * vk;
            }
        }
        for (x, a) in block.iter_mut().zip(acc) {
            *x = a / dt;
        }
    }
    let done = at.len() - blocks.into_remainder().len();
    for (i, x) in (at.start + done..at.end).zip(&mut out[at.start + done..at.end]) {
        let mut acc = 0.0;
        for (k, &c) in weights.iter().enumerate() {
            acc += c * v[i + k - h];
        }
        *x = acc / dt;
    }
}

/// Samples whose centred slopes are summed together in registers.
const BLOCK: usize = 8;

/// sum a_j b_j in four interleaved partial sums (independent chains the CPU overlaps; a
/// 31-tap window costs about a quarter of the serial sum).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a4, b4) = (a[..n].chunks_exact(4), b[..n].chunks_exact(4));
    let tail: f64 = a4
        .remainder()
        .iter()
        .zip(b4.remainder())
        .map(|(x, y)| x * y)
        .sum();
    let mut acc = [0.0; 4];
    for (x, y) in a4.zip(b4) {
        for k in 0..4 {
            acc[k] += x[k] * y[k];
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// The common spacing of `time` if it is uniform to 1e-6 relative.
fn uniform_spacing(time: &[f64]) -> Option<f64> {
    let n = time.len();
    if n < 2 {
        return None;
    }
    let dt = (time[n - 1] - time[0]) / (n - 1) as f64;
    let uniform = dt > 0.0
        && time
            .windows(2)
            .all(|w| ((w[1] - w[0]) - dt).abs() <= 1e-6 * dt);
    uniform.then_some(dt)
}

/// Weights w such that sum_j w_j y_j is the slope at offset 0 of the least-squares polynomial
/// of degree `order` through (offsets_j, y_j). The offsets are scaled to [-1, 1] before the
/// solve to keep the normal equations well conditioned.
pub fn derivative_weights(offsets: &[f64], order: usize) -> Result<Vec<f64>, EngineError> {
    let n = offsets.len();
    let scale = offsets.iter().fold(0.0_f64, |m, &o| m.max(o.abs()));
    if order == 0 || n <= order || scale <= 0.0 || !scale.is_finite() {
        return Err(EngineError::InvalidInput(format!(
            "cannot fit a degree-{order} polynomial to {n} samples"
        )));
    }
    let a = DMatrix::from_fn(n, order + 1, |r, c| (offsets[r] / scale).powi(c as i32));
    let normal = a.transpose() * &a;
    let chol = normal.cholesky().ok_or_else(|| {
        EngineError::InvalidInput(format!(
            "singular Savitzky-Golay fit (degree {order}, {n} samples)"
        ))
    })?;
    let mut e1 = DVector::zeros(order + 1);
    e1[1] = 1.0;
    let y = chol.solve(&e1);
    let w = a * y;
    Ok(w.iter().map(|x| x / scale).collect())
}
