//! The GMS model's exact steps and parameter gradients (the model itself is in `gms.rs`).
//!
//! At constant v and N every element moves on its own: with its load y = sgn(v) k z / (w s(v))
//! and the dimensionless travel sigma = k |v| t / (w s(v)), its law dz/dt = v (1 - max(0,
//! sgn(v) rho)^m) reads
//!
//!   dy/dsigma = 1 - max(0, y)^m,
//!
//! separable in the travel. Unloaded (y <= 0) the element sticks, y grows by the travel, until
//! it crosses 0 within the step and loads from there on. Loading it relaxes towards y = 1:
//! 1 - y = (1 - y0) exp(-sigma) for m = 1, and for m = 2 y = tanh(atanh(y0) + sigma), written
//! y = (y0 + tanh sigma) / (1 + y0 tanh sigma) so that it holds for an overloaded element
//! (y0 > 1, where s(v) fell: it is coth(acoth(y0) + sigma)) as well. Other sharpnesses have no
//! such closed form: their relaxation is integrated in u = ln|1 - y|, where it is smooth
//! (du/dsigma = -(1 - y^m)/(1 - y), between -1 and -m, flat as the element saturates), by
//! classical Runge-Kutta with steps bounded by that rate's slope ([`relax`]): a few steps per
//! loading, one per interval once saturated, to about 1e-12 of the sliding deflection. A
//! frozen element (w s = 0) stays.
//!
//! Sensitivities: the load and the travel scale with rho = k / (w s), so a parameter moves an
//! element's step through d ln(rho)/dp (1/k, -1/w, -(ds/dp)/s for the Stribeck parameters):
//! dy0/dp = y0 d ln(rho)/dp + sgn(v) rho dz0/dp, dsigma/dp = sigma d ln(rho)/dp, and
//! dz1/dp = sgn(v) (dy1/dp - y1 d ln(rho)/dp) / rho with dy1 = (dy1/dy0) dy0 + (dy1/dsigma)
//! dsigma (+ dy1/dm for the sharpness). dy1/dm is integrated with the relaxation (its
//! variational equation, for m = 1 and 2 too), so every parameter has its sensitivity and a
//! force-domain fit with the sharpness free needs no difference quotient.

use super::gms::{Gms, GmsElement};
use crate::interval::Interval;
use crate::model::{sgn, ParamGradients, Propagator};

/// An element's exact step in its load y over the travel sigma.
struct LoadStep {
    /// y1 - y0.
    change: f64,
    /// dy1/dy0.
    gain: f64,
    /// dy1/dsigma (the rate 1 - max(0, y1)^m).
    slope: f64,
    /// The element stuck throughout (dz = v dt, whatever its parameters).
    stuck: bool,
    /// dy1/dm at fixed y0 and sigma (0 where not asked for).
    sharpness: f64,
}

/// tanh(x) and 1 - tanh(x)^2 for x >= 0, from exp(-2x) (no cancellation near 1).
fn tanh_and_rate(x: f64) -> (f64, f64) {
    let e2 = (-2.0 * x).exp();
    let t = -(-2.0 * x).exp_m1() / (1.0 + e2);
    (t, 4.0 * e2 / ((1.0 + e2) * (1.0 + e2)))
}

/// The load after the travel `rest` from y = 0 and the rate there: (y, 1 - y^m).
fn loaded_from_zero(two: bool, rest: f64) -> (f64, f64) {
    if two {
        tanh_and_rate(rest)
    } else {
        let kept = (-rest).exp();
        (-(-rest).exp_m1(), kept)
    }
}

/// The step of a loaded element (y0 > 0) over the travel `sigma`.
fn loaded_step(two: bool, y0: f64, sigma: f64) -> LoadStep {
    if two {
        let (t, rate) = tanh_and_rate(sigma);
        let den = 1.0 + y0 * t;
        let change = t * (1.0 - y0) * (1.0 + y0) / den;
        // 1 - y1 = (1 - y0)(1 - tanh sigma) / den, with 1 - tanh sigma from exp(-2 sigma).
        let e2 = (-2.0 * sigma).exp();
        let unloaded = (1.0 - y0) * (2.0 * e2 / (1.0 + e2)) / den;
        LoadStep {
            change,
            gain: rate / (den * den),
            slope: unloaded * (2.0 - unloaded),
            stuck: false,
            sharpness: 0.0,
        }
    } else {
        let kept = (-sigma).exp();
        LoadStep {
            change: -(1.0 - y0) * (-sigma).exp_m1(),
            gain: kept,
            slope: (1.0 - y0) * kept,
            stuck: false,
            sharpness: 0.0,
        }
    }
}

/// The exact step of an element's load from `y0` over the travel `sigma` >= 0 at sharpness
/// `m`: the closed forms for m = 1 and 2, [`relax`] for any other; with `dm` its derivative
/// with respect to m too (by [`relax`]'s sensitivity, the closed forms having none).
fn load_step(m: f64, y0: f64, sigma: f64, dm: bool) -> LoadStep {
    if y0 + sigma <= 0.0 {
        return LoadStep {
            change: sigma,
            gain: 1.0,
            slope: 1.0,
            stuck: true,
            sharpness: 0.0,
        };
    }
    let closed = m == 1.0 || m == 2.0;
    if closed && !dm {
        return closed_load_step(m == 2.0, y0, sigma);
    }
    let r = from_small_load(m, y0, sigma);
    if closed {
        let mut step = closed_load_step(m == 2.0, y0, sigma);
        step.sharpness = r.sharpness;
        return step;
    }
    LoadStep {
        change: r.change,
        gain: r.gain,
        slope: r.slope,
        stuck: false,
        sharpness: r.sharpness,
    }
}

/// Below this load a loading element's step starts from y = 0 ([`from_small_load`]).
const SMALL_LOAD: f64 = 1e-3;

/// The relaxation from `y0` over `sigma` (`y0 + sigma > 0`), started from y = 0 where the
/// load is below [`SMALL_LOAD`]: stuck until the load crosses 0 (y0 <= 0), or at the travel
/// G(y0) = sum_k y0^(k m + 1) / (k m + 1) that reaches y0 from 0 (0 < y0 < SMALL_LOAD), then
/// relaxing over the rest. A load just above and just below 0 then takes the same steps,
/// so the step is as smooth in y0 there as the law (a derivative by differences across 0
/// sees no change of the integration's grid).
fn from_small_load(m: f64, y0: f64, sigma: f64) -> Relaxed {
    if y0 >= SMALL_LOAD {
        return relax(m, y0, sigma);
    }
    let (reach, reach_dm) = if y0 > 0.0 {
        travel_from_zero(m, y0)
    } else {
        (y0, 0.0)
    };
    let r = relax(m, 0.0, reach + sigma);
    let start_rate = if y0 > 0.0 {
        -(m * y0.ln()).exp_m1()
    } else {
        1.0
    };
    Relaxed {
        change: r.change - y0,
        gain: r.slope / start_rate,
        slope: r.slope,
        sharpness: r.sharpness + r.slope * reach_dm,
    }
}

/// The travel G(y) = sum_k y^(k m + 1) / (k m + 1) from 0 to the load 0 < y < SMALL_LOAD and
/// its derivative in m (the series' terms fall by y^m <= 1e-3 each).
fn travel_from_zero(m: f64, y: f64) -> (f64, f64) {
    let (ln_y, ratio) = (y.ln(), (m * y.ln()).exp());
    let (mut power, mut travel, mut d_m) = (y, 0.0, 0.0);
    for k in 0..8 {
        let k = f64::from(k);
        let den = k * m + 1.0;
        travel += power / den;
        d_m += power * k * (ln_y / den - 1.0 / (den * den));
        power *= ratio;
    }
    (travel, d_m)
}

/// The closed-form step of a loading element (m = 2 when `two`, else m = 1), `y0 + sigma > 0`.
fn closed_load_step(two: bool, y0: f64, sigma: f64) -> LoadStep {
    if y0 > 0.0 {
        return loaded_step(two, y0, sigma);
    }
    let (y1, rate) = loaded_from_zero(two, y0 + sigma);
    LoadStep {
        change: y1 - y0,
        gain: rate,
        slope: rate,
        stuck: false,
        sharpness: 0.0,
    }
}

/// The relaxation of a loaded element's load towards 1 at any sharpness m >= 1, integrated in
/// u = ln|1 - y|: du/dsigma = -lambda(y), lambda = (1 - y^m) / (1 - y), which lies between
/// 1 and m on 0 <= y <= 1 and whose slope d lambda/du = m y^(m-1) - lambda vanishes as the
/// element saturates, so the step in u is smooth where the step in y is stiff. Classical
/// Runge-Kutta carries u with its sensitivity b = du/dm (db/dsigma = -(d lambda/du) b -
/// d lambda/dm), each step bounded by [`RELAX_STEP`] and [`RELAX_TURN`] (one step once the
/// element is saturated). The law being autonomous, dy1/dy0 = f(y1) / f(y0) and dy1/dsigma =
/// f(y1) with f(y) = 1 - y^m = lambda (1 - y).
struct Relaxed {
    /// y1 - y0, taken as (1 - y0) - (1 - y1).
    change: f64,
    gain: f64,
    slope: f64,
    /// dy1/dm.
    sharpness: f64,
}

/// The largest step of the relaxation times |d lambda / du| (the rate's own change).
const RELAX_STEP: f64 = 0.01;
/// The largest change of u in one step where the element is far from saturation; the
/// allowance grows as |1 - y|^(-1/5) towards it, where the rate flattens (RK4's local error
/// in u, about (lambda h)^5 |1 - y|, then stays even): u to about 5e-10 over a whole loading,
/// so the element's deflection to 1e-10 of its sliding one and its distance from saturation,
/// which carries the sensitivities there, to 5e-10 of itself.
const RELAX_TURN: f64 = 0.02;
/// Below this |1 - y| the relaxation is finished in closed form ([`saturating_tail`]).
const RELAX_TAIL: f64 = 1e-6;
/// Near y = 0 each step is at most this fraction of the load (after a first step of
/// [`RELAX_FIRST`]): y^m and the sharpness's rate y^m ln y are not smooth at 0 for every m, and
/// steps growing with y keep their error in proportion.
const RELAX_GRADE: f64 = 0.25;
/// The first step of a relaxation from y = 0.
const RELAX_FIRST: f64 = 1e-7;
/// Most steps of one relaxation (a guard: a loading element needs a few hundred at most).
const RELAX_MAX_STEPS: usize = 100_000;

/// lambda, d lambda/du and d lambda/dm at w = 1 - y (see [`Relaxed`]).
fn relax_rates(m: f64, w: f64) -> (f64, f64, f64) {
    if w == 0.0 {
        return (m, 0.0, 1.0);
    }
    let ln_y = (-w).ln_1p();
    let y_m_less_1 = (m * ln_y).exp_m1();
    let y_m = 1.0 + y_m_less_1;
    let lambda = -y_m_less_1 / w;
    let y_m1 = if m == 1.0 {
        1.0
    } else if y_m == 0.0 {
        0.0
    } else {
        y_m / (1.0 - w)
    };
    let d_m = if y_m == 0.0 { 0.0 } else { -y_m * ln_y / w };
    (lambda, m * y_m1 - lambda, d_m)
}

/// The right-hand side of (u, b) at u with sign `side` of 1 - y.
fn relax_rhs(m: f64, side: f64, state: [f64; 2]) -> [f64; 2] {
    let w = side * state[0].exp();
    let (lambda, d_u, d_m) = relax_rates(m, w);
    [-lambda, -d_u * state[1] - d_m]
}

/// The step of a loading element (y0 >= 0) over the travel `sigma` at sharpness `m`.
fn relax(m: f64, y0: f64, sigma: f64) -> Relaxed {
    let w0 = 1.0 - y0;
    if w0 == 0.0 {
        return Relaxed {
            change: 0.0,
            gain: (-m * sigma).exp(),
            slope: 0.0,
            sharpness: 0.0,
        };
    }
    let side = w0.signum();
    let mut state = [w0.abs().ln(), 0.0];
    let mut rest = sigma;
    for _ in 0..RELAX_MAX_STEPS {
        if rest <= 0.0 || state[0] < RELAX_TAIL.ln() {
            break;
        }
        let (lambda, d_u, _) = relax_rates(m, side * state[0].exp());
        let y = 1.0 - side * state[0].exp();
        let allowed = (RELAX_STEP / d_u.abs())
            .min(RELAX_TURN * (-0.2 * state[0]).exp() / lambda)
            .min(RELAX_GRADE * y.max(RELAX_FIRST));
        let h = rest.min(allowed);
        state = rk4(m, side, state, h);
        rest -= h;
    }
    let (w1, b1) = if rest > 0.0 {
        saturating_tail(m, side * state[0].exp(), state[1], rest)
    } else {
        (side * state[0].exp(), state[1])
    };
    let f1 = relax_rates(m, w1).0 * w1;
    let f0 = relax_rates(m, w0).0 * w0;
    Relaxed {
        change: w0 - w1,
        gain: f1 / f0,
        slope: f1,
        sharpness: -w1 * b1,
    }
}

/// The end of a relaxation from w = 1 - y within [`RELAX_TAIL`] of saturation, with b =
/// du/dm there, over the travel `rest`: dw/dsigma = -lambda w with lambda = m - c m w +
/// O(w^2), c = (m - 1) / 2, is Bernoulli's equation, w1 = q / (1/w - c + c q) with
/// q = exp(-m rest) (the neglected terms change w by about m^2 w^2 of itself). Returns w1 and
/// its b.
fn saturating_tail(m: f64, w: f64, b: f64, rest: f64) -> (f64, f64) {
    let c = 0.5 * (m - 1.0);
    let q = (-m * rest).exp();
    let a = 1.0 / w - c;
    let den = a + c * q;
    let w1 = q / den;
    if w1 == 0.0 {
        return (0.0, 0.0);
    }
    // dw1/dw = q / (w den)^2; dw1/dm at fixed w: -q (rest a - 1/2 + q/2) / den^2 (c's
    // derivative 1/2 included).
    let through_start = q / (w * w * den * den) * (w * b);
    let direct = q * (rest * a - 0.5 + 0.5 * q) / (den * den);
    (w1, (through_start - direct) / w1)
}

/// One classical Runge-Kutta step of (u, b) over `h`.
fn rk4(m: f64, side: f64, s: [f64; 2], h: f64) -> [f64; 2] {
    let at = |k: &[f64; 2], f: f64| [s[0] + f * k[0], s[1] + f * k[1]];
    let k1 = relax_rhs(m, side, s);
    let k2 = relax_rhs(m, side, at(&k1, 0.5 * h));
    let k3 = relax_rhs(m, side, at(&k2, 0.5 * h));
    let k4 = relax_rhs(m, side, at(&k3, h));
    std::array::from_fn(|i| s[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
}

/// An element's frame in one interval: rho = k / (w s), its load and its travel.
struct ElementFrame {
    rho: f64,
    y0: f64,
    sigma: f64,
    step: LoadStep,
}

impl Gms {
    /// Whether the element law has an exact step: any sharpness m >= 1 (closed forms for 1
    /// and 2, [`relax`] for the others).
    fn has_exact_step(&self) -> bool {
        self.sharpness.is_finite() && self.sharpness >= 1.0
    }

    /// Steps the element `e` of deflection `z` over `interval` at the Stribeck level `s` (with
    /// the step's derivative in the sharpness when `dm`); `None` where it stays (frozen, or no
    /// motion).
    fn step_element(
        &self,
        e: &GmsElement,
        interval: Interval,
        s: f64,
        z: &mut f64,
        dm: bool,
    ) -> Option<ElementFrame> {
        let limit = e.weight * s;
        if limit.is_nan() || limit <= 0.0 || interval.v == 0.0 || interval.dt <= 0.0 {
            return None;
        }
        let u = sgn(interval.v);
        let rho = e.stiffness / limit;
        let y0 = u * rho * *z;
        let sigma = rho * interval.travel();
        let step = load_step(self.sharpness, y0, sigma, dm);
        *z += if step.stuck {
            interval.v * interval.dt
        } else {
            u * step.change / rho
        };
        Some(ElementFrame {
            rho,
            y0,
            sigma,
            step,
        })
    }

    /// s(v) and its derivatives with respect to mu_c, mu_s, v_s and delta (s computed as
    /// [`Gms::s`] computes it, to the bit).
    fn s_and_param_slopes(&self, v: f64, normal: f64) -> (f64, [f64; 4]) {
        let power = (v / self.v_s).abs().powf(self.delta);
        let e = crate::model::decay(power);
        let s = normal * (self.mu_c + (self.mu_s - self.mu_c) * e);
        let dip = normal * (self.mu_s - self.mu_c) * e;
        let (d_vs, d_delta) = if power > 0.0 {
            let ln_ratio = (v / self.v_s).abs().ln();
            (dip * self.delta * power / self.v_s, -dip * power * ln_ratio)
        } else {
            (0.0, 0.0)
        };
        (s, [normal * (1.0 - e), normal * e, d_vs, d_delta])
    }

    /// d ln(rho_i)/dp_j for element `i` (see the module docs), `n` elements.
    fn log_rho_slope(&self, i: usize, j: usize, s: f64, s_slopes: &[f64; 4]) -> f64 {
        let n = self.elements.len();
        let e = &self.elements[i];
        if j == i {
            1.0 / e.stiffness
        } else if j == n + i {
            -1.0 / e.weight
        } else if (3 * n..3 * n + 4).contains(&j) {
            -s_slopes[j - 3 * n] / s
        } else {
            0.0
        }
    }
}

impl Propagator for Gms {
    fn propagates_exactly(&self) -> bool {
        self.has_exact_step()
    }

    fn propagate(&self, interval: Interval, z: &mut [f64]) {
        let s = self.s(interval.v, interval.normal);
        for (e, zi) in self.elements.iter().zip(z.iter_mut()) {
            self.step_element(e, interval, s, zi, false);
        }
    }

    fn propagate_with_sensitivities(&self, interval: Interval, z: &mut [f64], sens: &mut [f64]) {
        let (s, s_slopes) = self.s_and_param_slopes(interval.v, interval.normal);
        // The parameter vector: three per element, then six shared ones.
        let np = 3 * self.elements.len() + 6;
        let sharpness = 3 * self.elements.len() + 4;
        let u = sgn(interval.v);
        for (i, (e, zi)) in self.elements.iter().zip(z.iter_mut()).enumerate() {
            let Some(row) = sens.get_mut(i * np..(i + 1) * np) else {
                return;
            };
            let Some(frame) = self.step_element(e, interval, s, zi, true) else {
                continue;
            };
            if frame.step.stuck {
                continue;
            }
            let y1 = frame.y0 + frame.step.change;
            for (j, sj) in row.iter_mut().enumerate() {
                let g = self.log_rho_slope(i, j, s, &s_slopes);
                let dy0 = frame.y0 * g + u * frame.rho * *sj;
                let mut dy1 = frame.step.gain * dy0 + frame.step.slope * frame.sigma * g;
                if j == sharpness {
                    dy1 += frame.step.sharpness;
                }
                *sj = u * (dy1 - y1 * g) / frame.rho;
            }
        }
    }
}

impl ParamGradients for Gms {
    /// Per element F_i = k_i z_i + sigma_i dz_i/dt: the spring's k_i, and through a damped
    /// element's rate v (1 - load^m) (load = sgn(v) k z / (w s) > 0) its k_i, w_i, the
    /// Stribeck parameters and the sharpness; sigma_i gives the rate; the viscous term v.
    fn force_param_gradient(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]) {
        let n = self.elements.len();
        out.iter_mut().for_each(|o| *o = 0.0);
        let (s, s_slopes) = self.s_and_param_slopes(v, normal);
        let mut d_s = 0.0;
        let mut d_sharpness = 0.0;
        for (i, e) in self.elements.iter().enumerate() {
            let zi = z.get(i).copied().unwrap_or(0.0);
            let rate = self.z_dot(e, v, zi, s);
            let (d_load, d_m) = self.rate_slopes(e, v, zi, s);
            let (d_k, d_w) = if d_load == 0.0 || e.damping == 0.0 {
                (0.0, 0.0)
            } else {
                d_s -= e.damping * d_load / s;
                d_sharpness += e.damping * d_m;
                (
                    e.damping * d_load / e.stiffness,
                    -e.damping * d_load / e.weight,
                )
            };
            for (k, d) in [zi + d_k, d_w, rate].into_iter().enumerate() {
                if let Some(o) = out.get_mut(k * n + i) {
                    *o = d;
                }
            }
        }
        for (k, slope) in s_slopes.iter().enumerate() {
            if let Some(o) = out.get_mut(3 * n + k) {
                *o = d_s * slope;
            }
        }
        if let Some(o) = out.get_mut(3 * n + 4) {
            *o = d_sharpness;
        }
        if let Some(o) = out.get_mut(3 * n + 5) {
            *o = v;
        }
    }
}

impl Gms {
    /// A loading element's d(rate)/d(ln load) = -v m load^m and d(rate)/dm = -v load^m
    /// ln(load); (0, 0) unloading or frozen.
    fn rate_slopes(&self, e: &GmsElement, v: f64, z: f64, s: f64) -> (f64, f64) {
        match Gms::element_load(e, v, z, s) {
            Some((_, load)) if load > 0.0 => {
                let p = load.powf(self.sharpness);
                (-v * self.sharpness * p, -v * p * load.ln())
            }
            _ => (0.0, 0.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The integrated relaxation against the closed forms of m = 1 and 2 (a loaded, an
    /// overloaded and a nearly saturated element, short and long travels).
    #[test]
    fn the_integrated_relaxation_matches_the_closed_forms() {
        for two in [false, true] {
            let m = if two { 2.0 } else { 1.0 };
            for y0 in [1e-9, 0.3, 0.999_999, 1.0, 1.7, 25.0] {
                for sigma in [1e-6, 0.05, 1.3, 40.0] {
                    let exact = loaded_step(two, y0, sigma);
                    let r = relax(m, y0, sigma);
                    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * (1.0 + b.abs());
                    assert!(
                        close(r.change, exact.change)
                            && close(r.gain, exact.gain)
                            && close(r.slope, exact.slope),
                        "m = {m}, y0 = {y0}, sigma = {sigma}: {} {} {} vs {} {} {}",
                        r.change,
                        r.gain,
                        r.slope,
                        exact.change,
                        exact.gain,
                        exact.slope
                    );
                }
            }
        }
    }

    /// dy1/dm of the relaxation against central differences of the step in m (one-sided
    /// at m = 1, the least sharpness).
    #[test]
    fn the_sharpness_sensitivity_matches_central_differences() {
        for m in [1.0, 1.5, 2.0, 3.5, 12.0] {
            for y0 in [0.0, 0.2, 0.9, 1.4] {
                for sigma in [0.01, 0.7, 6.0] {
                    let h = 1e-5;
                    let y1 = |m: f64| y0 + relax(m, y0, sigma).change;
                    let expected = if m == 1.0 {
                        (4.0 * y1(m + h) - y1(m + 2.0 * h) - 3.0 * y1(m)) / (2.0 * h)
                    } else {
                        (y1(m + h) - y1(m - h)) / (2.0 * h)
                    };
                    let got = relax(m, y0, sigma).sharpness;
                    assert!(
                        (got - expected).abs() <= 1e-6 * (1.0 + expected.abs()),
                        "m = {m}, y0 = {y0}, sigma = {sigma}: {got} vs {expected}"
                    );
                }
            }
        }
    }
}
