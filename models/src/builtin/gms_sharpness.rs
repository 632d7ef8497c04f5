//! The slope in the sharpness m of a GMS element's regular part R (`gms_relaxation.rs`) at
//! m = 1 and m = 2 in closed form, so that the closed-form steps of those sharpnesses get
//! their dy1/dm without a table or a quadrature.
//!
//! R(y) = integral_0^y h_m(r) dr with h_m(r) = 1 / (1 - r^m) - 1 / (m (1 - r)), so
//!
//!   dR/dm(y) = integral_0^y [r^m ln r / (1 - r^m)^2 + 1 / (m^2 (1 - r))] dr,
//!
//! regular at r = 1 (the two terms' poles cancel). With the dilogarithm Li2 (d/dt Li2(1 - t) =
//! ln t / (1 - t), d/dt Li2(-t) = -ln(1 + t) / t):
//!
//! - m = 1: integral t ln t / (1 - t)^2 dt = t ln t / (1 - t) - Li2(1 - t) + ln(1 - t), and
//!   the second term's -ln(1 - t) cancels the logarithm:
//!   dR/dm(y) = y ln y / (1 - y) - Li2(1 - y) + pi^2 / 6;
//! - m = 2: t^2 / (1 - t^2)^2 = [1 / (1 - t)^2 + 1 / (1 + t)^2 - 1 / (1 - t) - 1 / (1 + t)] / 4
//!   in partial fractions, and term by term
//!   dR/dm(y) = [2 y ln y / (1 - y^2) - ln(1 + y) (1 + ln y) - Li2(1 - y) - Li2(-y)] / 4
//!   + pi^2 / 24.
//!
//! Both hold on either side of 1 (Li2 is real on (-inf, 1]). Below y = 1/2 the reflection
//! Li2(1 - y) = pi^2 / 6 - ln y ln(1 - y) - Li2(y) takes out the constant, and the
//! logarithm's factor (y / (1 - y) + ln(1 - y) at m = 1, 2 y / (1 - y^2) - 2 atanh y at m = 2,
//! both of order y^2 or y^3) comes from its series for small loads; near 1 the load is
//! given with its distance d = y - 1 from 1, so that y ln y / (y - 1) = (1 + d) ln(1 + d) / d
//! keeps its precision.

use std::f64::consts::PI;

/// pi^2 / 6 = Li2(1).
const ZETA_2: f64 = PI * PI / 6.0;

/// B_n / (n + 1)! for n = 2, 4, ..., 22 (the Bernoulli numbers B_n of the series of Li2 in
/// u = -ln(1 - x); B_1 = -1/2 and the odd ones above it vanish).
const BERNOULLI: [f64; 11] = [
    1.0 / 36.0,
    -1.0 / 3_600.0,
    1.0 / 211_680.0,
    -1.0 / 10_886_400.0,
    (5.0 / 66.0) / 39_916_800.0,
    (-691.0 / 2_730.0) / 6_227_020_800.0,
    (7.0 / 6.0) / 1_307_674_368_000.0,
    (-3_617.0 / 510.0) / 355_687_428_096_000.0,
    (43_867.0 / 798.0) / 121_645_100_408_832_000.0,
    (-174_611.0 / 330.0) / 51_090_942_171_709_440_000.0,
    (854_513.0 / 138.0) / 25_852_016_738_884_976_640_000.0,
];

/// Li2(x) for -1 <= x <= 1/2 by its Bernoulli series in u = -ln(1 - x), |u| <= ln 2 (the
/// series converges for |u| < 2 pi: each further term is 80 times smaller); the caller gives
/// u (often from a logarithm it has anyway). Its tail in two interleaved halves (even and
/// odd terms in u^4), for half the latency of one chain.
fn dilog_of_log(u: f64) -> f64 {
    let u2 = u * u;
    let u4 = u2 * u2;
    let (mut even, mut odd) = (0.0, 0.0);
    for pair in BERNOULLI[1..].chunks(2).rev() {
        if let [a, b] = *pair {
            even = even * u4 + a;
            odd = odd * u4 + b;
        }
    }
    let tail = BERNOULLI[0] + u2 * (even + u2 * odd);
    u - 0.25 * u2 + u * u2 * tail
}

/// Li2 for -1 <= x <= 1/2 (see [`dilog_of_log`]).
fn dilog_series(x: f64) -> f64 {
    dilog_of_log(-(-x).ln_1p())
}

/// The dilogarithm Li2(x) = -integral_0^x ln(1 - t) / t dt for real x <= 1 (NaN above 1,
/// where it is complex): the series for -1 <= x <= 1/2, the reflection
/// Li2(x) = pi^2 / 6 - ln x ln(1 - x) - Li2(1 - x) above 1/2 and the inversion
/// Li2(x) = -pi^2 / 6 - ln^2(-x) / 2 - Li2(1 / x) below -1.
pub(super) fn dilog(x: f64) -> f64 {
    if x > 1.0 || x.is_nan() {
        f64::NAN
    } else if x == 1.0 {
        ZETA_2
    } else if x > 0.5 {
        ZETA_2 - x.ln() * (-x).ln_1p() - dilog_series(1.0 - x)
    } else if x >= -1.0 {
        dilog_series(x)
    } else {
        let log = (-x).ln();
        -ZETA_2 - 0.5 * log * log - dilog_series(1.0 / x)
    }
}

/// Below this load the logarithm's factors come from their series.
const SMALL_LOAD: f64 = 0.05;
/// Terms of those series (0.05^14 is below 1e-18).
const SMALL_TERMS: usize = 16;

/// y / (1 - y) + ln(1 - y) = sum_{k >= 2} (k - 1) / k y^k, for 0 <= y < 1/2.
fn first_factor(y: f64) -> f64 {
    if y >= SMALL_LOAD {
        return y / (1.0 - y) + (-y).ln_1p();
    }
    (2..SMALL_TERMS + 2).rev().fold(0.0, |acc, k| {
        let k = k as f64;
        acc * y + (k - 1.0) / k
    }) * y
        * y
}

/// 2 y / (1 - y^2) - 2 atanh y = 2 sum_{k >= 1} 2k / (2k + 1) y^(2k + 1), for 0 <= y < 1/2.
fn second_factor(y: f64) -> f64 {
    if y >= SMALL_LOAD {
        return 2.0 * y / (1.0 - y * y) - 2.0 * y.atanh();
    }
    let y2 = y * y;
    (1..SMALL_TERMS / 2 + 1).rev().fold(0.0, |acc, k| {
        let k = k as f64;
        acc * y2 + 2.0 * k / (2.0 * k + 1.0)
    }) * 2.0
        * y
        * y2
}

/// Li2(-d) for d > -1/2, from l = ln(1 + d) where the series takes it.
fn dilog_of_minus(d: f64, l: f64) -> f64 {
    if d <= 1.0 {
        dilog_of_log(-l)
    } else {
        dilog(-d)
    }
}

/// dR/dm at m = 1 of the load y >= 0 at the distance `d` = y - 1 from 1 (module docs).
fn first_slope(y: f64, d: f64) -> f64 {
    if y <= 0.0 {
        return 0.0;
    }
    if y < 0.5 {
        return y.ln() * first_factor(y) + dilog(y);
    }
    let l = d.ln_1p();
    let ratio = if d == 0.0 { 1.0 } else { l / d };
    -(1.0 + d) * ratio - dilog_of_minus(d, l) + ZETA_2
}

/// Li2(-y) for y >= 1/2 with l = ln y and lp = ln(1 + y): the series in u = -lp up to 1,
/// by the inversion (u = -ln(1 + 1/y) = l - lp) up to 2.
fn dilog_of_minus_load(y: f64, l: f64, lp: f64) -> f64 {
    if y <= 1.0 {
        dilog_of_log(-lp)
    } else if y <= 2.0 {
        -ZETA_2 - 0.5 * l * l - dilog_of_log(l - lp)
    } else {
        dilog(-y)
    }
}

/// dR/dm at m = 2 of the load y >= 0 at the distance `d` = y - 1 from 1 (module docs).
fn second_slope(y: f64, d: f64) -> f64 {
    if y <= 0.0 {
        return 0.0;
    }
    if y < 0.5 {
        return 0.25 * (y.ln() * second_factor(y) - y.ln_1p() + dilog(y) - dilog(-y));
    }
    let l = d.ln_1p();
    let lp = (2.0 + d).ln();
    let ratio = if d == 0.0 { 1.0 } else { l / d };
    let first = -2.0 * (1.0 + d) * ratio / (2.0 + d);
    let rest = lp * (1.0 + l) + dilog_of_minus(d, l) + dilog_of_minus_load(y, l, lp);
    0.25 * (first - rest) + 0.25 * ZETA_2
}

/// dR/dm of the load `y` >= 0 at the distance `d` = y - 1 from 1 (given apart, to keep its
/// precision near 1) at sharpness 1 (`two` false) or 2.
pub(super) fn regular_slope(two: bool, y: f64, d: f64) -> f64 {
    if two {
        second_slope(y, d)
    } else {
        first_slope(y, d)
    }
}

/// dy1/dm of a closed-form step (m = 1, or 2 when `two`) of the load from `y0` >= 0 by
/// `change` (staying on its side of 1) to the rate `rate1` = 1 - y1^m: by the implicit
/// function theorem on Phi(y1) - Phi(y0) = sigma, -(1 - y1^m) (dPhi/dm(y1) - dPhi/dm(y0))
/// with dPhi/dm = -u / m^2 + dR/dm and u = -ln|1 - y| (`gms_relaxation.rs`).
pub(super) fn closed_sharpness_slope(two: bool, y0: f64, change: f64, rate1: f64) -> f64 {
    let m = if two { 2.0 } else { 1.0 };
    let d0 = y0 - 1.0;
    let d1 = d0 + change;
    // At 1 to rounding (or past it by a rounding): no slope left.
    if d0 == 0.0 || rate1 == 0.0 || d1 * d0 <= 0.0 {
        return 0.0;
    }
    let advance = (-change / d1).ln_1p();
    let d_regular = regular_slope(two, 1.0 + d1, d1) - regular_slope(two, y0, d0);
    -rate1 * (-advance / (m * m) + d_regular)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin::gms_relaxation::relax;
    use crate::builtin::gms_table::RegularTable;

    /// Li2 to 20 digits (mpmath's polylog(2, x) at 40 digits), more than an f64 holds.
    #[allow(clippy::excessive_precision)]
    const DILOG: [(f64, f64); 18] = [
        (-1e6, -97.079_099_055_459_640_626),
        (-50.0, -9.276_995_185_332_621_840_1),
        (-7.0, -3.400_162_044_428_386_645_7),
        (-2.0, -1.436_746_366_883_680_946_4),
        (-1.2, -0.957_405_308_558_781_248_2),
        (-1.0, -0.822_467_033_424_113_218_24),
        (-0.9, -0.752_163_179_217_261_620_37),
        (-0.5, -0.448_414_206_923_646_202_44),
        (-0.3, -0.280_074_333_759_582_904_23),
        (-1e-3, -0.000_999_750_111_048_651_083_35),
        (1e-8, 0.000_000_010_000_000_025_000_000_111),
        (0.1, 0.102_617_791_099_391_131_11),
        (0.4, 0.449_282_974_471_281_664_46),
        (0.5, 0.582_240_526_465_012_505_9),
        (0.6, 0.727_586_307_716_333_389_51),
        (0.9, 1.299_714_723_004_958_725_2),
        (0.999, 1.637_022_605_276_117_742_7),
        (1.0, 1.644_934_066_848_226_436_5),
    ];

    #[test]
    fn the_dilogarithm_matches_high_precision_values() {
        for (x, want) in DILOG {
            let got = dilog(x);
            assert!(
                (got - want).abs() <= 1e-15 * want.abs(),
                "Li2({x}) = {got} against {want}"
            );
        }
        assert!(dilog(1.5).is_nan());
    }

    #[test]
    fn the_dilogarithm_matches_its_defining_series() {
        // sum x^k / k^2 for |x| <= 1/2: 60 terms reach 1e-20.
        for i in -50..=50 {
            let x = 0.01 * f64::from(i);
            let mut want = 0.0;
            for k in (1..=60).rev() {
                want += x.powi(k) / f64::from(k * k);
            }
            let got = dilog(x);
            assert!(
                (got - want).abs() <= 5e-16 * want.abs(),
                "Li2({x}) = {got} against {want}"
            );
        }
    }

    /// dR/dm at m = 1 and m = 2 to 20 digits (the closed forms at 50 digits in mpmath, at
    /// the loads' binary values), more than an f64 holds.
    #[allow(clippy::excessive_precision)]
    const SLOPES: [(f64, f64, f64); 13] = [
        (
            1e-6,
            0.000_000_999_993_342_235_621_733_05,
            0.000_000_250_000_124_995_367_040_79,
        ),
        (
            0.01,
            0.009_791_748_206_314_833_196_9,
            0.002_510_937_603_308_428_315_7,
        ),
        (
            0.05,
            0.046_630_150_217_450_587_025,
            0.012_684_212_009_829_028_508,
        ),
        (
            0.3,
            0.239_568_097_851_072_264_79,
            0.073_829_432_116_907_748_972,
        ),
        (
            0.365,
            0.283_546_837_868_610_331_61,
            0.088_171_522_992_847_608_974,
        ),
        (
            0.5,
            0.369_546_359_823_268_621_15,
            0.115_623_348_738_177_391_73,
        ),
        (
            0.7,
            0.486_563_020_915_708_124_65,
            0.150_872_205_126_153_345_65,
        ),
        (
            0.999_999,
            0.644_933_566_848_143_088_73,
            0.193_563_354_928_046_499_38,
        ),
        (
            1.000_001,
            0.644_934_566_848_143_062_03,
            0.193_563_604_928_046_492_72,
        ),
        (
            1.3,
            0.788_096_587_915_348_135_48,
            0.226_809_689_752_296_772_87,
        ),
        (
            1.9,
            1.042_072_375_257_099_050_3,
            0.273_941_194_654_009_159_1,
        ),
        (
            5.0,
            2.003_076_473_303_966_800_2,
            0.354_517_192_690_009_463_12,
        ),
        (
            40.0,
            6.191_765_487_785_738_821_9,
            0.200_546_231_401_265_424_25,
        ),
    ];

    #[test]
    fn the_closed_slopes_match_high_precision_values() {
        for (y, first, second) in SLOPES {
            for (two, want) in [(false, first), (true, second)] {
                let got = regular_slope(two, y, y - 1.0);
                assert!(
                    (got - want).abs() <= 2e-15 * want,
                    "two = {two}, y = {y}: {got} against {want}"
                );
            }
        }
    }

    /// dR/dm of the table at its sharpness (the series and the panels' reference).
    fn tabled(table: &RegularTable, y: f64) -> f64 {
        table.regular(y, y.ln(), true).1
    }

    #[test]
    fn the_closed_slopes_match_the_table_below_and_above_one() {
        for (two, m) in [(false, 1.0f64), (true, 2.0)] {
            let table = RegularTable::new(m).expect("a table");
            let top = 2f64.powf(1.0 / m);
            let mut loads: Vec<f64> = (1..=400).map(|i| top * f64::from(i) / 400.0).collect();
            loads.extend([1e-9, 1e-5, 0.049_999, 0.05, 0.499_999, 0.5]);
            loads.extend([1.0 - 1e-12, 1.0 - 1e-7, 1.0 + 1e-12, 1.0 + 1e-7]);
            for y in loads {
                let got = regular_slope(two, y, y - 1.0);
                let want = tabled(&table, y);
                assert!(
                    (got - want).abs() <= 1e-13 * want.abs(),
                    "m = {m}, y = {y}: {got} against {want}"
                );
            }
            assert_eq!(regular_slope(two, 0.0, -1.0), 0.0);
        }
    }

    #[test]
    fn small_loads_follow_the_leading_terms() {
        // Integrating the integrand's expansion in r term by term: dR/dm = y + y^2 / 2
        // + y^2 ln y / 2 - y^2 / 4 + O(y^3 ln y) at m = 1, y / 4 + y^2 / 8 + O(y^3 ln y) at
        // m = 2.
        for y in [1e-12f64, 1e-8, 1e-5, 1e-3] {
            let left = y * y * y * (1.0 - y.ln()) + 4e-16 * y;
            let first = regular_slope(false, y, y - 1.0);
            let want = y + 0.5 * y * y + y * y * (0.5 * y.ln() - 0.25);
            assert!((first - want).abs() <= left, "m = 1, y = {y}: {first}");
            let second = regular_slope(true, y, y - 1.0);
            let want = 0.25 * y + 0.125 * y * y;
            assert!((second - want).abs() <= left, "m = 2, y = {y}: {second}");
        }
    }

    #[test]
    fn closed_step_slopes_match_the_quadrature_steps() {
        // The loads of `gms_relaxation`'s checks: from 0, below 1, near 1, overloaded.
        let cases = crate::builtin::gms_relaxation::tests::TABLED_CASES;
        for (two, m) in [(false, 1.0), (true, 2.0)] {
            for (y0, sigma) in cases {
                let exact = relax(m, y0, sigma, true, None);
                let got = closed_sharpness_slope(two, y0, exact.change, exact.slope);
                let want = exact.sharpness;
                assert!(
                    (got - want).abs() <= 1e-11 * want.abs().max(1.0),
                    "m = {m}, y0 = {y0}, sigma = {sigma}: {got} against {want}"
                );
            }
        }
    }

    #[test]
    fn far_overloads_match_a_fine_quadrature() {
        // Composite Simpson on the integrand in ln r from y = 1.5 up: dR/dm(y) - dR/dm(1.5).
        for (two, m) in [(false, 1.0f64), (true, 2.0)] {
            let integrand = |w: f64| {
                let r = w.exp();
                let p = r.powf(m);
                (p * w / ((1.0 - p) * (1.0 - p)) + 1.0 / (m * m * (1.0 - r))) * r
            };
            for y in [3.0f64, 8.0, 40.0] {
                let (a, b) = (1.5f64.ln(), y.ln());
                let n = 20_000;
                let h = (b - a) / f64::from(n);
                let mut sum = integrand(a) + integrand(b);
                for i in 1..n {
                    let weight = if i % 2 == 1 { 4.0 } else { 2.0 };
                    sum += weight * integrand(a + h * f64::from(i));
                }
                let want = sum * h / 3.0;
                let got = regular_slope(two, y, y - 1.0) - regular_slope(two, 1.5, 0.5);
                assert!(
                    (got - want).abs() <= 1e-12 * want.abs(),
                    "m = {m}, y = {y}: {got} against {want}"
                );
            }
        }
    }
}
