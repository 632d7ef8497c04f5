//! The quadrature of the regular part R of a loading GMS element's travel integral and its
//! derivative in the sharpness (see `gms_relaxation.rs` for the element law and its split):
//! Gauss-Legendre panels in w = ln r of the integrand h_m(e^w) e^w, regular at r = 1 (its
//! Bernoulli and Gregory series there), and the power series of R below y^m = 1/4. The exact
//! reference both the tabulated steps (`gms_table.rs`) and the steps without a table use.

/// Gauss-Legendre nodes and weights on [-1, 1], 4 points (the positive halves).
const GAUSS_4: [(f64, f64); 2] = [
    (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_8),
];
/// Gauss-Legendre nodes and weights on [-1, 1], 8 points (the positive halves).
pub(super) const GAUSS_8: [(f64, f64); 4] = [
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
];
/// Longest panel, as (its length in w) x max(m, 1): 8 points then integrate to rounding (the
/// integrand's poles lie 2 pi / max(m, 1) off the real axis).
pub(super) const PANEL_REACH: f64 = 1.5;
/// Panels up to this reach take 4 points.
const SHORT_REACH: f64 = 0.5;
/// The series of R serves loads with y^m up to this value.
pub(super) const SERIES_LIMIT: f64 = 0.25;
/// Most series terms (y^m <= 1/4: 30 reach rounding).
pub(super) const SERIES_TERMS: usize = 60;

/// 1/(1 - e^(-t)) - 1/t and its derivative in t (Bernoulli series near t = 0).
fn bernoulli_part(t: f64) -> (f64, f64) {
    if t.abs() < 0.2 {
        let t2 = t * t;
        let value =
            0.5 + t * (1.0 / 12.0 + t2 * (-1.0 / 720.0 + t2 * (1.0 / 30_240.0 - t2 / 1_209_600.0)));
        let slope = 1.0 / 12.0 + t2 * (-1.0 / 240.0 + t2 * (1.0 / 6_048.0 - t2 / 172_800.0));
        (value, slope)
    } else {
        let half = (0.5 * t).sinh();
        (
            1.0 / -(-t).exp_m1() - 1.0 / t,
            1.0 / (t * t) - 0.25 / (half * half),
        )
    }
}

/// 1/a - 1/eps for eps = 1 - r and a = -ln r (Gregory series near r = 1).
fn gregory_part(eps: f64, a: f64) -> f64 {
    if eps.abs() < 1e-2 {
        let tail = 3.0 / 160.0 + eps * (863.0 / 60_480.0 + eps * 275.0 / 24_192.0);
        -0.5 - eps * (1.0 / 12.0 + eps * (1.0 / 24.0 + eps * (19.0 / 720.0 + eps * tail)))
    } else {
        1.0 / a - 1.0 / eps
    }
}

/// Below this |w| = |ln r| the integrand comes from the series (the direct form's two terms,
/// each near 1 / (m |w|), would cancel).
const NEAR_ONE: f64 = 0.2;

/// h_m(e^w) e^w and its derivative in m (0 unless `with_m`).
fn integrand(m: f64, w: f64, with_m: bool) -> (f64, f64) {
    let r = w.exp();
    let (h, dh) = if w.abs() > NEAR_ONE {
        // h = 1 / (m (r - 1)) - 1 / (r^m - 1), dh/dm = w r^m / (r^m - 1)^2 - 1 / (m^2 (r - 1)).
        let (em, e1) = ((m * w).exp_m1(), w.exp_m1());
        let h = 1.0 / (m * e1) - 1.0 / em;
        let dh = if with_m {
            w / (em * -(-m * w).exp_m1()) - 1.0 / (m * m * e1)
        } else {
            0.0
        };
        (h, dh)
    } else {
        // h = (1/(1 - e^(-t)) - 1/t) + (1/a - 1/eps) / m with a = -w, t = m a, eps = 1 - r.
        let a = -w;
        let (b, db) = bernoulli_part(m * a);
        let g = gregory_part(-w.exp_m1(), a);
        let dh = if with_m { a * db - g / (m * m) } else { 0.0 };
        (b + g / m, dh)
    };
    (h * r, dh * r)
}

/// One Gauss-Legendre panel from `lo` over `width` in w.
fn panel(m: f64, lo: f64, width: f64, short: bool, with_m: bool) -> (f64, f64) {
    let half = 0.5 * width;
    let mid = lo + half;
    let nodes: &[(f64, f64)] = if short { &GAUSS_4 } else { &GAUSS_8 };
    let (mut sum, mut d_sum) = (0.0, 0.0);
    for &(x, weight) in nodes {
        for w in [mid - half * x, mid + half * x] {
            let (f, df) = integrand(m, w, with_m);
            sum += weight * f;
            d_sum += weight * df;
        }
    }
    (half * sum, half * d_sum)
}

/// The integral of h_m from r = e^`wa` to e^(`wa` + `span`) (and its derivative in m), by
/// panels short enough for the integrand's poles.
pub(super) fn panels(m: f64, wa: f64, span: f64, with_m: bool) -> (f64, f64) {
    let reach = span.abs() * m.max(1.0);
    if reach == 0.0 {
        return (0.0, 0.0);
    }
    if !reach.is_finite() {
        return (f64::NAN, f64::NAN);
    }
    let count = (reach / PANEL_REACH).ceil().max(1.0);
    let width = span / count;
    let short = reach / count <= SHORT_REACH;
    let (mut sum, mut d_sum) = (0.0, 0.0);
    let mut done = 0.0;
    while done < count {
        let (f, df) = panel(m, wa + width * done, width, short, with_m);
        sum += f;
        d_sum += df;
        done += 1.0;
    }
    (sum, d_sum)
}

/// R(y) = Phi(y) + ln(1 - y) / m and dR/dm by the series, for 0 <= y with y^m <= 1/4.
pub(super) fn series(m: f64, y: f64, with_m: bool) -> (f64, f64) {
    if y <= 0.0 {
        return (0.0, 0.0);
    }
    let ln_y = y.ln();
    let x = (m * ln_y).exp();
    let (mut sum, mut d_sum, mut power, mut k) = (0.0, 0.0, 1.0, 0.0);
    for _ in 0..SERIES_TERMS {
        let den = m * k + 1.0;
        let term = power / den;
        sum += term;
        if with_m {
            d_sum += term * k * (ln_y - 1.0 / den);
        }
        if term <= 1e-17 * sum {
            break;
        }
        power *= x;
        k += 1.0;
    }
    let log_rest = (-y).ln_1p();
    (y * sum + log_rest / m, y * d_sum - log_rest / (m * m))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_quadrature_rules_integrate_polynomials_exactly() {
        for (nodes, degree) in [(&GAUSS_4[..], 7), (&GAUSS_8[..], 15)] {
            for p in 0..=degree {
                let sum: f64 = nodes
                    .iter()
                    .map(|&(x, w)| w * (x.powi(p) + (-x).powi(p)))
                    .sum();
                let exact = if p % 2 == 0 {
                    2.0 / (p as f64 + 1.0)
                } else {
                    0.0
                };
                assert!(
                    (sum - exact).abs() < 1e-15,
                    "{} points, x^{p}: {sum}",
                    2 * nodes.len()
                );
            }
        }
    }
}
