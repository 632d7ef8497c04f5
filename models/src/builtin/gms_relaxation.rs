//! A loading GMS element's exact step at any sharpness m, with its sensitivities (used by
//! `gms_steps.rs`, which keeps the closed forms of m = 1 and 2, and their slopes in m in
//! `gms_sharpness.rs`). The regular part R below
//! comes from the table of `gms_table.rs` at the step's sharpness where it holds the loads,
//! else from the series and panels of `gms_quadrature.rs`.
//!
//! A loading element's load y >= 0 obeys dy/dsigma = 1 - y^m in its dimensionless travel
//! sigma, separable: sigma = Phi(y1) - Phi(y0) with Phi(y) = integral dr / (1 - r^m) on the
//! side of 1 where y starts (below it the element loads towards 1, above it, overloaded after
//! its sliding force fell, it relaxes down to 1; it never crosses 1). Split
//!
//!   1 / (1 - r^m) = 1 / (m (1 - r)) + h_m(r),
//!
//! so Phi(y) = u / m + R(y) with u = -ln|1 - y| and R the integral of h_m, which is regular
//! at r = 1 (h_m(1) = (m - 1) / (2 m)). In w = ln r, h_m(e^w) e^w is analytic in the strip
//! |Im w| < 2 pi / max(m, 1) (the poles of 1 / (1 - e^(m w)) and 1 / (1 - e^w) other than the
//! removable one at w = 0, and no branch point: r^m = e^(m w)), so Gauss-Legendre panels of
//! length <= 1.5 / max(m, 1) in w integrate it to rounding. Below y^m = 1/4 (where the panels
//! would reach towards r = 0) R comes from the series Phi(y) = y sum_k y^(m k) / (m k + 1).
//! Near r = 1, h_m is evaluated from its Bernoulli and Gregory series (no cancellation).
//!
//! The end load solves F(u1) = (u1 - u0) / m + R(y(u1)) - R(y0) - sigma = 0 by Newton's method
//! in u, with y = 1 -+ e^(-u) on either side of 1 and F'(u) = (1 - y) / (1 - y^m) between 1/m
//! and 1 below 1: one or two iterations whatever the travel, for an element approaching 1 from
//! below (F concave in u, iterates from the left) as for an overloaded one relaxing from above
//! (F convex, iterates from the right after the first).
//!
//! Sensitivities by the implicit function theorem on Phi(y1) - Phi(y0) = sigma:
//! dy1/dy0 = (1 - y1^m) / (1 - y0^m), dy1/dsigma = 1 - y1^m and
//! dy1/dm = -(1 - y1^m) (dPhi/dm(y1) - dPhi/dm(y0)), dPhi/dm = -u / m^2 + dR/dm, with dR/dm
//! from the same series and panels differentiated in m.

use super::gms_quadrature::{panels, series, GAUSS_8, PANEL_REACH, SERIES_LIMIT};
use super::gms_table::{RegularTable, FAR_LEVEL};

/// The largest u = -ln|1 - y| the Newton iterates take: e^(-u) still a normal number.
const U_MAX: f64 = 600.0;
/// Most Newton iterations (two or three are the rule).
const NEWTON_ITERATIONS: usize = 60;

/// A loading element's step: its load's change and sensitivities.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Relaxed {
    /// y1 - y0.
    pub change: f64,
    /// dy1/dy0.
    pub gain: f64,
    /// dy1/dsigma (the rate 1 - y1^m).
    pub slope: f64,
    /// dy1/dm (0 unless asked for).
    pub sharpness: f64,
}

/// A load y >= 0 and its logarithm w = ln y.
#[derive(Debug, Clone, Copy)]
struct Load {
    y: f64,
    w: f64,
}

/// The regular part's change R(y1) - R(y0) and its derivative in m, for loads on the same
/// side of 1 with `span` = w1 - w0 (given apart, to the precision of a short step).
fn regular_change(m: f64, from: Load, to: Load, span: f64, with_m: bool) -> (f64, f64) {
    let wq = SERIES_LIMIT.ln() / m;
    if from.w > wq && to.w > wq {
        return panels(m, from.w, span, with_m);
    }
    // R(y) - R(yq) on either side of the series' limit.
    let from_limit = |load: Load| -> (f64, f64) {
        if load.w > wq {
            panels(m, wq, load.w - wq, with_m)
        } else {
            let (at, d_at) = series(m, load.y, with_m);
            let (limit, d_limit) = series(m, wq.exp(), with_m);
            (at - limit, d_at - d_limit)
        }
    };
    let (a, da) = from_limit(to);
    let (b, db) = from_limit(from);
    (a - b, da - db)
}

/// 1 - y^m for y = 1 + `delta`, without cancellation near 1.
fn rate(m: f64, delta: f64) -> f64 {
    -(m * delta.ln_1p()).exp_m1()
}

/// exp(-x) and exp(-x) - 1 for x >= 0 from one exponential: the second from `exp_m1` while
/// the first is above 1/2 (1 plus it is then exact to rounding), else the first from `exp`
/// (less 1 it then loses nothing either).
pub(super) fn decay_and_change(x: f64) -> (f64, f64) {
    if x < std::f64::consts::LN_2 {
        let change = (-x).exp_m1();
        (1.0 + change, change)
    } else {
        let kept = (-x).exp();
        (kept, kept - 1.0)
    }
}

/// The end of a step from `y0` (not 1) that moved u = -ln|1 - y| by `advance`: the load, its
/// distance y1 - 1, the span w1 - w0 (from the change, so that a short step keeps its
/// precision) and the change y1 - y0.
fn end_of(y0: f64, w0: f64, advance: f64) -> (Load, f64, f64, f64) {
    let d0 = y0 - 1.0;
    let (kept, kept_change) = decay_and_change(advance);
    let delta = d0 * kept;
    let change = d0 * kept_change;
    let span = if y0 > 0.0 {
        (change / y0).ln_1p()
    } else {
        f64::INFINITY
    };
    let w = if delta.abs() < 0.5 || y0 <= 0.0 {
        delta.ln_1p()
    } else {
        w0 + span
    };
    (Load { y: 1.0 + delta, w }, delta, span, change)
}

/// dy1/dm of a step from `from` to `to` that moved u = -ln|1 - y| by `advance` over the
/// span w1 - w0, the rate at its end `rate1` = 1 - y1^m.
/// dR/dm from the table where it holds both loads, else from the series and panels.
fn sharpness_slope(step: &Step, from: Load, to: Load, span: f64, rate1: f64) -> f64 {
    if rate1 == 0.0 {
        return 0.0;
    }
    let m = step.m;
    let d_regular = match step.table_for(from, to) {
        Some(t) => t.regular(to.y, to.w, true).1 - t.regular(from.y, from.w, true).1,
        None => regular_change(m, from, to, span, true).1,
    };
    -rate1 * (-step.advance / (m * m) + d_regular)
}

/// A step's sharpness, the table of R at it (if any) and the advance in u it made.
struct Step<'a> {
    m: f64,
    table: Option<&'a RegularTable>,
    advance: f64,
}

impl Step<'_> {
    /// The table, where it is the step's sharpness's and holds both loads.
    fn table_for(&self, from: Load, to: Load) -> Option<&RegularTable> {
        self.table
            .filter(|t| t.sharpness() == self.m && t.holds(from.w) && t.holds(to.w))
    }
}

/// r / (r^m - 1) at r = e^x (x > 0), the travel per unit of ln y of an overloaded element,
/// and its derivative in m (0 unless `with_m`).
fn overload_integrand(m: f64, x: f64, with_m: bool) -> (f64, f64) {
    let r = x.exp();
    let em = (m * x).exp_m1();
    let value = r / em;
    let d_m = if with_m {
        -x * r / (em * -(-m * x).exp_m1())
    } else {
        0.0
    };
    (value, d_m)
}

/// The travel from e^`wb` down to e^`wa` (0 < wa <= wb) of an overloaded element, the
/// integral of r / (r^m - 1) in ln r, and its derivative in m: panels graded towards the
/// pole at ln r = 0 (each at most half its distance from it) and short enough for the poles
/// at +-2 pi i / m.
fn overload_travel(m: f64, wa: f64, wb: f64, with_m: bool) -> (f64, f64) {
    let longest = PANEL_REACH / m.max(1.0);
    // The integrand falls as e^((1 - m) x): beyond 40 / (m - 1) past `wa` the rest is below
    // e^-40 of what came before.
    let wb = if m > 1.0 {
        wb.min(wa + 40.0 / (m - 1.0))
    } else {
        wb
    };
    let (mut sum, mut d_sum) = (0.0, 0.0);
    let mut lo = wa;
    while lo < wb {
        let width = (0.5 * lo).min(longest).min(wb - lo);
        let (half, mid) = (0.5 * width, lo + 0.5 * width);
        for &(x, weight) in &GAUSS_8 {
            for at in [mid - half * x, mid + half * x] {
                let (f, df) = overload_integrand(m, at, with_m);
                sum += weight * half * f;
                d_sum += weight * half * df;
            }
        }
        lo += width;
    }
    (sum, d_sum)
}

/// The step of an element overloaded past y^m = 2 (`w0` = ln y0 > ln 2 / m): solved in
/// ln y, where the travel is a well-conditioned integral, down to y^m = 2 at most; from there
/// on (when the travel goes on) by [`relax_near`].
fn relax_far(
    m: f64,
    y0: f64,
    w0: f64,
    sigma: f64,
    with_m: bool,
    table: Option<&RegularTable>,
) -> Relaxed {
    let w_far = FAR_LEVEL.ln() / m;
    let rate0 = -(m * w0).exp_m1();
    let (to_far, d_to_far) = overload_travel(m, w_far, w0, with_m);
    if sigma >= to_far {
        let y_far = w_far.exp();
        let near = relax_near(m, y_far, sigma - to_far, with_m, table);
        return Relaxed {
            change: (y_far - y0) + near.change,
            gain: near.slope / rate0,
            slope: near.slope,
            sharpness: near.sharpness - near.slope * d_to_far,
        };
    }
    // G(s) = travel over the span s = w0 - w1 - sigma, convex and increasing: from the
    // asymptotic start (y^(1-m) grows by (m - 1) sigma, which overestimates s) Newton's
    // iterates come down to the root.
    let most = w0 - w_far;
    let asymptotic = if m > 1.0 {
        w0 + ((1.0 - m) * w0).exp().mul_add(1.0, (m - 1.0) * sigma).ln() / (m - 1.0)
    } else {
        most
    };
    let mut span = if asymptotic.is_finite() {
        asymptotic.clamp(0.0, most)
    } else {
        most
    };
    let mut last = f64::INFINITY;
    for _ in 0..NEWTON_ITERATIONS {
        let (travel, _) = overload_travel(m, w0 - span, w0, false);
        let (slope, _) = overload_integrand(m, w0 - span, false);
        let step = -(travel - sigma) / slope;
        if !step.is_finite() {
            break;
        }
        let next = (span + step).clamp(0.0, most);
        // Held by a bound: every further iteration would repeat this one.
        if next == span {
            break;
        }
        span = next;
        let small = step.abs() <= 1e-8 * span;
        if step.abs() <= 1e-14 * span || (small && step.abs() > 0.5 * last) {
            break;
        }
        last = step.abs();
    }
    let w1 = w0 - span;
    let rate1 = -(m * w1).exp_m1();
    let sharpness = if with_m {
        let (_, d_travel) = overload_travel(m, w1, w0, true);
        -rate1 * d_travel
    } else {
        0.0
    };
    Relaxed {
        change: y0 * (-span).exp_m1(),
        gain: rate1 / rate0,
        slope: rate1,
        sharpness,
    }
}

/// The exact step of a loading element's load from `y0` >= 0 over the travel `sigma` >= 0 at
/// sharpness `m` > 0, with dy1/dm when `with_m`; R from `table` (the table at `m`) where it
/// holds the loads, else from the series and panels.
pub(super) fn relax(
    m: f64,
    y0: f64,
    sigma: f64,
    with_m: bool,
    table: Option<&RegularTable>,
) -> Relaxed {
    let w0 = y0.ln();
    if m * w0 > FAR_LEVEL.ln() && sigma > 0.0 {
        return relax_far(m, y0, w0, sigma, with_m, table);
    }
    relax_near(m, y0, sigma, with_m, table)
}

/// [`relax`] in u = -ln|1 - y|, for loads below y^m = 2 (above it the equation in u loses
/// the precision of a short step to the cancellation of its two terms).
fn relax_near(m: f64, y0: f64, sigma: f64, with_m: bool, table: Option<&RegularTable>) -> Relaxed {
    let d0 = y0 - 1.0;
    if sigma == 0.0 || d0 == 0.0 {
        return Relaxed {
            change: 0.0,
            gain: if d0 == 0.0 { (-m * sigma).exp() } else { 1.0 },
            slope: rate(m, d0),
            sharpness: 0.0,
        };
    }
    let from = Load { y: y0, w: y0.ln() };
    let rate0 = rate(m, d0);
    // F(x) = x / m + R(y1) - R(y0) - sigma in the advance x = u1 - u0, and F'(x) =
    // delta / ((1 + delta)^m - 1), delta = y1 - 1 = d0 e^(-x).
    // The iterates stay between y0 and 1: the table (if any) holds them all when it holds y0.
    let start = Step {
        m,
        table,
        advance: 0.0,
    };
    let tabled = start
        .table_for(from, from)
        .map(|t| (t, t.regular(y0, from.w, false).0));
    // Below the series' limit R(y0) (and R at the limit) once for every iteration.
    let wq = SERIES_LIMIT.ln() / m;
    let series_start = (tabled.is_none() && from.w <= wq).then(|| {
        let at_start = series(m, y0, false).0;
        (at_start, series(m, wq.exp(), false).0 - at_start)
    });
    let residual = |advance: f64| -> (f64, f64) {
        let (to, delta, span, _) = end_of(y0, from.w, advance);
        let regular = match (tabled, series_start) {
            (Some((t, at_start)), _) => t.regular(to.y, to.w, false).0 - at_start,
            (None, None) => panels(m, from.w, span, false).0,
            (None, Some((at_start, _))) if to.w <= wq => series(m, to.y, false).0 - at_start,
            (None, Some((_, to_limit))) => to_limit + panels(m, wq, to.w - wq, false).0,
        };
        let value = advance / m + regular - sigma;
        (value, delta / (m * to.w).exp_m1())
    };
    // Beyond u = U_MAX the load is 1 to rounding (and e^(-u) would underflow).
    let most = (U_MAX + d0.abs().ln()).min(U_MAX);
    // From sigma / F'(0): left of the root below 1 (F concave), right of it above (F convex).
    let mut advance = (sigma * (rate0 / -d0)).min(most);
    let mut last = f64::INFINITY;
    for _ in 0..NEWTON_ITERATIONS {
        let (value, slope) = residual(advance);
        let step = -value / slope;
        if !step.is_finite() {
            break;
        }
        let next = (advance + step).min(most);
        // Held by the bound (a load at 1 to rounding): every further iteration would repeat
        // this one.
        if next == advance {
            break;
        }
        advance = next;
        // Converged, or down to the residual's rounding (the steps stop shrinking).
        let small = step.abs() <= 1e-8 * advance.abs();
        if step.abs() <= 1e-14 * advance.abs() || (small && step.abs() > 0.5 * last) {
            break;
        }
        last = step.abs();
    }
    let (to, delta1, span, change) = end_of(y0, from.w, advance);
    let rate1 = rate(m, delta1);
    let sharpness = if with_m {
        let step = Step { m, table, advance };
        sharpness_slope(&step, from, to, span, rate1)
    } else {
        0.0
    };
    Relaxed {
        change,
        gain: rate1 / rate0,
        slope: rate1,
        sharpness,
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// dy/dsigma = 1 - y^m by classical RK4 with `steps` steps (y > 0 throughout).
    fn rk4(m: f64, y0: f64, sigma: f64, steps: usize) -> f64 {
        let f = |y: f64| 1.0 - y.powf(m);
        let h = sigma / steps as f64;
        let mut y = y0;
        for _ in 0..steps {
            let k1 = f(y);
            let k2 = f(y + 0.5 * h * k1);
            let k3 = f(y + 0.5 * h * k2);
            let k4 = f(y + h * k3);
            y += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        y
    }

    /// Loads and travels of the tabled-step checks: from 0, below 1, near 1, overloaded near
    /// and far (y^m > 2 at the larger sharpnesses), short and long travels.
    pub(in crate::builtin) const TABLED_CASES: [(f64, f64); 12] = [
        (0.0, 1e-7),
        (0.0, 0.05),
        (0.0, 3.0),
        (0.3, 1e-9),
        (0.3, 0.4),
        (0.97, 0.02),
        (0.999_999, 5.0),
        (1.000_001, 0.3),
        (1.02, 1e-6),
        (1.5, 0.1),
        (1.2, 4.0),
        (8.0, 0.01),
    ];

    fn close(got: f64, want: f64, tolerance: f64) -> bool {
        (got - want).abs() <= tolerance * want.abs().max(1.0)
    }

    #[test]
    fn tabled_steps_match_the_quadrature_steps_and_the_closed_forms() {
        for m in [1.0, 1.3, 2.0, 2.7, 6.0, 20.0] {
            let table = RegularTable::new(m).expect("a table");
            for (y0, sigma) in TABLED_CASES {
                let case = format!("m = {m}, y0 = {y0}, sigma = {sigma}");
                let exact = relax(m, y0, sigma, true, None);
                let tabled = relax(m, y0, sigma, true, Some(&table));
                let y1 = y0 + tabled.change;
                assert!(
                    close(y1, y0 + exact.change, 1e-14),
                    "{case}: {tabled:?} {exact:?}"
                );
                assert!(
                    close(tabled.gain, exact.gain, 1e-12),
                    "{case}: {tabled:?} {exact:?}"
                );
                assert!(
                    close(tabled.slope, exact.slope, 1e-12),
                    "{case}: {tabled:?} {exact:?}"
                );
                let (got, want) = (tabled.sharpness, exact.sharpness);
                assert!(close(got, want, 1e-11), "{case}: {tabled:?} {exact:?}");
                // The closed forms: 1 - y = (1 - y0) e^-sigma at m = 1, y = (y0 + tanh sigma)
                // / (1 + y0 tanh sigma) at m = 2.
                let closed = match m {
                    1.0 => Some(1.0 + (y0 - 1.0) * (-sigma).exp()),
                    2.0 => Some((y0 + sigma.tanh()) / (1.0 + y0 * sigma.tanh())),
                    _ => None,
                };
                if let Some(closed) = closed {
                    assert!(close(y1, closed, 1e-14), "{case}: {y1} against {closed}");
                }
            }
        }
    }

    #[test]
    fn tabled_slopes_in_the_sharpness_match_central_differences() {
        for m in [1.0, 1.3, 2.0, 2.7, 6.0] {
            let table = RegularTable::new(m).expect("a table");
            let h = 1e-5 * m;
            let end = |m: f64, y0: f64, sigma: f64| {
                let table = RegularTable::new(m).expect("a table");
                y0 + relax(m, y0, sigma, false, Some(&table)).change
            };
            for (y0, sigma) in TABLED_CASES {
                let slope = relax(m, y0, sigma, true, Some(&table)).sharpness;
                let difference = (end(m + h, y0, sigma) - end(m - h, y0, sigma)) / (2.0 * h);
                // The difference's own rounding: the loads' to 1e-16 over 2 h.
                let floor = 1e-16 / h;
                assert!(
                    (slope - difference).abs() <= 1e-6 * slope.abs() + floor,
                    "m = {m}, y0 = {y0}, sigma = {sigma}: {slope} against {difference}"
                );
            }
        }
    }

    #[test]
    fn steps_follow_a_fine_integration_below_and_above_one() {
        for m in [1.3, 2.7, 6.0, 20.0] {
            for (y0, sigma) in [
                (0.0f64, 0.05),
                (0.0, 3.0),
                (0.3, 0.4),
                (0.97, 0.02),
                (1.5, 0.1),
                (1.2, 4.0),
                (8.0, 0.01),
            ] {
                let steps = 50_000;
                if m * y0.powf(m - 1.0) * sigma / steps as f64 > 0.1 {
                    continue; // too stiff for the explicit reference
                }
                let step = relax(m, y0, sigma, false, None);
                let reference = rk4(m, y0, sigma, steps);
                let y1 = y0 + step.change;
                assert!(
                    (y1 - reference).abs() <= 1e-11 * reference.abs().max(1.0),
                    "m = {m}, y0 = {y0}, sigma = {sigma}: {y1} against {reference}"
                );
            }
        }
    }

    #[test]
    fn one_exponential_gives_the_decay_and_its_change_to_rounding() {
        for x in [0.0, 1e-300, 1e-9, 0.3, 0.693, 0.694, 2.0, 40.0, 800.0] {
            let (kept, change) = decay_and_change(x);
            let (want_kept, want_change) = ((-x).exp(), (-x).exp_m1());
            assert!(
                (kept - want_kept).abs() <= 2.3e-16 * want_kept,
                "exp(-{x}): {kept} against {want_kept}"
            );
            assert!(
                (change - want_change).abs() <= 2.3e-16 * want_change.abs(),
                "exp(-{x}) - 1: {change} against {want_change}"
            );
        }
    }
}
