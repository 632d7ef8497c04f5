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
//! (y0 > 1, where s(v) fell: it is coth(acoth(y0) + sigma)) as well. Every other sharpness
//! solves sigma = Phi(y1) - Phi(y0), Phi the integral of 1 / (1 - y^m), by Newton's method
//! (`gms_relaxation.rs`). A frozen element (w s = 0) stays.
//!
//! Sensitivities: the load and the travel scale with rho = k / (w s), so a parameter moves an
//! element's step through d ln(rho)/dp (1/k, -1/w, -(ds/dp)/s for the Stribeck parameters):
//! dy0/dp = y0 d ln(rho)/dp + sgn(v) rho dz0/dp, dsigma/dp = sigma d ln(rho)/dp, and
//! dz1/dp = sgn(v) (dy1/dp - y1 d ln(rho)/dp) / rho with dy1 = (dy1/dy0) dy0 + (dy1/dsigma)
//! dsigma, plus for the sharpness its direct dy1/dm (the implicit function theorem on
//! Phi(y1) - Phi(y0) = sigma, `gms_relaxation.rs`).

use super::gms::{Gms, GmsElement};
use super::gms_relaxation::{decay_and_change, relax};
use super::gms_sharpness::closed_sharpness_slope;
use super::gms_table::{table_for, RegularTable};
use crate::interval::Interval;
use crate::model::{sgn, ParamGradients, Propagator};
use std::rc::Rc;

/// An element's exact step in its load y over the travel sigma.
struct LoadStep {
    /// y1 - y0.
    change: f64,
    /// dy1/dy0.
    gain: f64,
    /// dy1/dsigma (the rate 1 - max(0, y1)^m).
    slope: f64,
    /// dy1/dm (0 unless asked for).
    sharpness: f64,
    /// The element stuck throughout (dz = v dt, whatever its parameters).
    stuck: bool,
}

/// tanh(x), 1 - tanh(x)^2 and exp(-2x) for x >= 0, from exp(-2x) (no cancellation near 1).
fn tanh_parts(x: f64) -> (f64, f64, f64) {
    let (e2, change) = decay_and_change(2.0 * x);
    let t = -change / (1.0 + e2);
    (t, 4.0 * e2 / ((1.0 + e2) * (1.0 + e2)), e2)
}

/// The load after the travel `rest` from y = 0 and the rate there: (y, 1 - y^m).
fn loaded_from_zero(two: bool, rest: f64) -> (f64, f64) {
    if two {
        let (t, rate, _) = tanh_parts(rest);
        (t, rate)
    } else {
        let (kept, change) = decay_and_change(rest);
        (-change, kept)
    }
}

/// The step of a loaded element (y0 > 0) over the travel `sigma`.
fn loaded_step(two: bool, y0: f64, sigma: f64) -> LoadStep {
    if two {
        let (t, rate, e2) = tanh_parts(sigma);
        let den = 1.0 + y0 * t;
        let change = t * (1.0 - y0) * (1.0 + y0) / den;
        // 1 - y1 = (1 - y0)(1 - tanh sigma) / den, with 1 - tanh sigma from exp(-2 sigma).
        let unloaded = (1.0 - y0) * (2.0 * e2 / (1.0 + e2)) / den;
        LoadStep {
            change,
            gain: rate / (den * den),
            slope: unloaded * (2.0 - unloaded),
            sharpness: 0.0,
            stuck: false,
        }
    } else {
        let (kept, kept_change) = decay_and_change(sigma);
        LoadStep {
            change: -(1.0 - y0) * kept_change,
            gain: kept,
            slope: (1.0 - y0) * kept,
            sharpness: 0.0,
            stuck: false,
        }
    }
}

/// The step of a loaded element (y0 >= 0) over the travel `sigma` at sharpness `m`: the
/// closed forms at m = 1 and 2, else the Newton solve; with dy1/dm when `with_m` (R from
/// `table`, the table at `m`, where it holds the loads).
fn loading_step(
    m: f64,
    y0: f64,
    sigma: f64,
    with_m: bool,
    table: Option<&RegularTable>,
) -> LoadStep {
    if m == 1.0 || m == 2.0 {
        let mut step = if y0 > 0.0 {
            loaded_step(m == 2.0, y0, sigma)
        } else {
            let (y1, rate) = loaded_from_zero(m == 2.0, sigma);
            LoadStep {
                change: y1,
                gain: rate,
                slope: rate,
                sharpness: 0.0,
                stuck: false,
            }
        };
        if with_m {
            step.sharpness = closed_sharpness_slope(m == 2.0, y0, step.change, step.slope);
        }
        return step;
    }
    let relaxed = relax(m, y0, sigma, with_m, table);
    LoadStep {
        change: relaxed.change,
        gain: relaxed.gain,
        slope: relaxed.slope,
        sharpness: relaxed.sharpness,
        stuck: false,
    }
}

/// The exact step of an element's load from `y0` over the travel `sigma` >= 0 at sharpness
/// `m`, with dy1/dm when `with_m` (R from `table` where it holds the loads).
fn load_step(m: f64, y0: f64, sigma: f64, with_m: bool, table: Option<&RegularTable>) -> LoadStep {
    if y0 > 0.0 {
        return loading_step(m, y0, sigma, with_m, table);
    }
    if y0 + sigma <= 0.0 {
        return LoadStep {
            change: sigma,
            gain: 1.0,
            slope: 1.0,
            sharpness: 0.0,
            stuck: true,
        };
    }
    // Stuck until the load crosses 0, then loading over the rest of the travel.
    let from_zero = loading_step(m, 0.0, y0 + sigma, with_m, table);
    LoadStep {
        change: from_zero.change - y0,
        gain: from_zero.slope,
        ..from_zero
    }
}

/// An element's frame in one interval: rho = k / (w s), its load and its travel.
struct ElementFrame {
    rho: f64,
    y0: f64,
    sigma: f64,
    step: LoadStep,
}

impl Gms {
    /// Whether the steps are exact: a finite, positive sharpness.
    fn has_exact_steps(&self) -> bool {
        self.sharpness.is_finite() && self.sharpness > 0.0
    }

    /// The table of the element law's regular part at this sharpness, where a step needs it:
    /// every sharpness without a closed form (the closed forms' slopes in m have theirs,
    /// `gms_sharpness.rs`).
    fn relaxation_table(&self) -> Option<Rc<RegularTable>> {
        let m = self.sharpness;
        (m != 1.0 && m != 2.0).then(|| table_for(m)).flatten()
    }

    /// Steps the element `e` of deflection `z` over `interval` at the Stribeck level `s`
    /// (R from `table` where it holds the loads); `None` where it stays (frozen, or no motion).
    fn step_element(
        &self,
        e: &GmsElement,
        interval: Interval,
        s: f64,
        z: &mut f64,
        with_m: bool,
        table: Option<&RegularTable>,
    ) -> Option<ElementFrame> {
        let limit = e.weight * s;
        if limit.is_nan() || limit <= 0.0 || interval.v == 0.0 || interval.dt <= 0.0 {
            return None;
        }
        let u = sgn(interval.v);
        let rho = e.stiffness / limit;
        let y0 = u * rho * *z;
        let sigma = rho * interval.travel();
        let step = load_step(self.sharpness, y0, sigma, with_m, table);
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
        let (power, e) = self.stribeck_decay(v);
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
}

/// d ln(rho_i)/dp_j (see the module docs) of one element in one interval: 1/k_i for its
/// stiffness, -1/w_i for its weight, -(ds/dp)/s for the Stribeck parameters, 0 otherwise.
struct LogRhoSlopes {
    /// The element's index i and the element count n.
    i: usize,
    n: usize,
    stiffness: f64,
    weight: f64,
    /// -(ds/dp)/s for mu_c, mu_s, v_s and delta (the same for every element).
    stribeck: [f64; 4],
}

impl LogRhoSlopes {
    /// d ln(rho_i)/dp_j.
    fn of(&self, j: usize) -> f64 {
        let (i, n) = (self.i, self.n);
        if j == i {
            self.stiffness
        } else if j == n + i {
            self.weight
        } else if (3 * n..3 * n + 4).contains(&j) {
            self.stribeck[j - 3 * n]
        } else {
            0.0
        }
    }
}

impl Propagator for Gms {
    fn propagates_exactly(&self) -> bool {
        self.has_exact_steps()
    }

    fn propagate(&self, interval: Interval, z: &mut [f64]) {
        let s = self.s(interval.v, interval.normal);
        let table = self.relaxation_table();
        for (e, zi) in self.elements.iter().zip(z.iter_mut()) {
            self.step_element(e, interval, s, zi, false, table.as_deref());
        }
    }

    fn propagate_with_sensitivities(&self, interval: Interval, z: &mut [f64], sens: &mut [f64]) {
        let (s, s_slopes) = self.s_and_param_slopes(interval.v, interval.normal);
        // The parameter vector: three per element, then six shared ones.
        let n = self.elements.len();
        let np = 3 * n + 6;
        let sharpness = 3 * n + 4;
        let u = sgn(interval.v);
        let table = self.relaxation_table();
        let stribeck = s_slopes.map(|d| -d / s);
        for (i, (e, zi)) in self.elements.iter().zip(z.iter_mut()).enumerate() {
            let Some(row) = sens.get_mut(i * np..(i + 1) * np) else {
                return;
            };
            let Some(frame) = self.step_element(e, interval, s, zi, true, table.as_deref()) else {
                continue;
            };
            if frame.step.stuck {
                continue;
            }
            let slopes = LogRhoSlopes {
                i,
                n,
                stiffness: 1.0 / e.stiffness,
                weight: -1.0 / e.weight,
                stribeck,
            };
            let y1 = frame.y0 + frame.step.change;
            // sgn(v) / rho, one division for the row.
            let back = u / frame.rho;
            let step = |g: f64, direct: f64, sj: f64| {
                let dy0 = frame.y0 * g + u * frame.rho * sj;
                let dy1 = frame.step.gain * dy0 + direct;
                (dy1 - y1 * g) * back
            };
            // The element's own stiffness and weight, the Stribeck parameters and the
            // sharpness move its load or its travel; every other parameter only carries a
            // sensitivity the element already has (none, in a replay from rest).
            for j in [i, n + i].into_iter().chain(3 * n..=sharpness) {
                let Some(sj) = row.get_mut(j) else {
                    continue;
                };
                let g = slopes.of(j);
                let direct = if j == sharpness {
                    frame.step.sharpness
                } else {
                    frame.step.slope * frame.sigma * g
                };
                *sj = step(g, direct, *sj);
            }
            // A parameter that does not move the load has slope 0, so its direct term is
            // slope * sigma * 0: kept as that product (0, or NaN where slope * sigma is not
            // finite) so that a carried entry is what the full step above would give it.
            let unmoved = frame.step.slope * frame.sigma * 0.0;
            for carried in [0..i, i + 1..n + i, n + i + 1..3 * n, sharpness + 1..np] {
                let Some(part) = row.get_mut(carried) else {
                    continue;
                };
                for sj in part.iter_mut().filter(|sj| **sj != 0.0) {
                    *sj = step(0.0, unmoved, *sj);
                }
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
            // The rate's slopes act through the damping only.
            let (rate, d_load, d_m) = self.rate_and_slopes(e, v, zi, s, e.damping != 0.0);
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

    /// Row i: a loading element's rate v (1 - load^m) moves with ln(load) (d/dk_i = 1/k_i,
    /// d/dw_i = -1/w_i, d/dp = -(ds/dp)/s for the Stribeck parameters) and with the sharpness;
    /// an unloading (stuck) or frozen element's rate, v or 0, with no parameter.
    fn state_param_gradient(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]) -> bool {
        let n = self.elements.len();
        let np = 3 * n + 6;
        out.iter_mut().for_each(|o| *o = 0.0);
        let (s, s_slopes) = self.s_and_param_slopes(v, normal);
        for (i, e) in self.elements.iter().enumerate() {
            let zi = z.get(i).copied().unwrap_or(0.0);
            let (_, d_load, d_m) = self.rate_and_slopes(e, v, zi, s, true);
            let Some(row) = out.get_mut(i * np..(i + 1) * np) else {
                break;
            };
            if d_load == 0.0 && d_m == 0.0 {
                continue;
            }
            row[i] = d_load / e.stiffness;
            row[n + i] = -d_load / e.weight;
            for (k, slope) in s_slopes.iter().enumerate() {
                row[3 * n + k] = -d_load * slope / s;
            }
            row[3 * n + 4] = d_m;
        }
        true
    }
}

impl Gms {
    /// An element's rate v (1 - max(0, load)^m) (as [`Gms::z_dot`] computes it, to the bit)
    /// and, when `with_slopes`, a loading element's d(rate)/d(ln load) = -v m load^m and
    /// d(rate)/dm = -v load^m ln(load), from one power; (0, 0) unloading or frozen.
    fn rate_and_slopes(
        &self,
        e: &GmsElement,
        v: f64,
        z: f64,
        s: f64,
        with_slopes: bool,
    ) -> (f64, f64, f64) {
        match Gms::element_load(e, v, z, s) {
            None => (0.0, 0.0, 0.0),
            Some((_, load)) if load > 0.0 => {
                let p = self.load_power(load);
                let rate = v * (1.0 - p);
                if with_slopes {
                    (rate, -v * self.sharpness * p, -v * p * load.ln())
                } else {
                    (rate, 0.0, 0.0)
                }
            }
            Some(_) => (v, 0.0, 0.0),
        }
    }
}
