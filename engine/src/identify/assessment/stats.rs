//! Least-squares statistics: covariance from the Jacobian at the optimum, confidence
//! intervals, correlations and information criteria.

use nalgebra::DMatrix;

/// Two-sided 95 % quantile of Student's t distribution with `dof` degrees of freedom.
///
/// Exact values up to 4 degrees of freedom; beyond, the Cornish-Fisher expansion of t about
/// the normal quantile (Abramowitz & Stegun 26.7.5), accurate to better than 5e-4 from 5 dof.
pub fn t_quantile_975(dof: usize) -> f64 {
    match dof {
        0 => f64::INFINITY,
        1 => 12.706_204_736_174_7,
        2 => 4.302_652_729_749_46,
        3 => 3.182_446_305_284_26,
        4 => 2.776_445_105_197_8,
        _ => {
            let z: f64 = 1.959_963_984_540_054;
            let n = dof as f64;
            let z3 = z.powi(3);
            let z5 = z.powi(5);
            let z7 = z.powi(7);
            let z9 = z.powi(9);
            z + (z3 + z) / (4.0 * n)
                + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * n * n)
                + (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / (384.0 * n.powi(3))
                + (79.0 * z9 + 776.0 * z7 + 1482.0 * z5 - 1920.0 * z3 - 945.0 * z)
                    / (92160.0 * n.powi(4))
        }
    }
}

/// Covariance, standard errors and correlations of a least-squares estimate.
#[derive(Debug, Clone)]
pub struct Covariance {
    /// Covariance matrix s^2 (JᵀJ)^-1 (NaN where JᵀJ is singular).
    pub matrix: DMatrix<f64>,
    /// Standard errors.
    pub std_errors: Vec<f64>,
    /// Correlation matrix.
    pub correlation: DMatrix<f64>,
    /// Residual variance s^2 = SSR / (n - p).
    pub residual_variance: f64,
    /// Degrees of freedom n - p.
    pub dof: usize,
    /// Whether JᵀJ was numerically singular (parameters not separately identifiable).
    pub singular: bool,
}

/// Covariance from the (weighted) Jacobian `j` (n x p) at the optimum and the sum of squared
/// (weighted) residuals `ssr`.
pub fn covariance(j: &DMatrix<f64>, ssr: f64) -> Covariance {
    let (n, p) = j.shape();
    let dof = n.saturating_sub(p);
    let s2 = if dof > 0 { ssr / dof as f64 } else { f64::NAN };
    if p == 0 {
        return Covariance {
            matrix: DMatrix::zeros(0, 0),
            std_errors: Vec::new(),
            correlation: DMatrix::zeros(0, 0),
            residual_variance: s2,
            dof,
            singular: false,
        };
    }
    let jtj = j.tr_mul(j);
    // Scale to unit diagonal before inverting, so the condition test is unit-free.
    let d: Vec<f64> = (0..p).map(|i| jtj[(i, i)].max(0.0).sqrt()).collect();
    let mut scaled = jtj.clone();
    for r in 0..p {
        for c in 0..p {
            let den = d[r] * d[c];
            scaled[(r, c)] = if den > 0.0 { jtj[(r, c)] / den } else { 0.0 };
        }
    }
    let svd = scaled.clone().svd(false, false);
    let (smax, smin) = svd
        .singular_values
        .iter()
        .fold((0.0f64, f64::INFINITY), |(a, b), &s| (a.max(s), b.min(s)));
    let singular = p > 0 && (d.contains(&0.0) || smin <= 1e-12 * smax);
    let matrix = match (singular, scaled.try_inverse()) {
        (false, Some(inv)) => {
            let mut m = inv;
            for r in 0..p {
                for c in 0..p {
                    m[(r, c)] *= s2 / (d[r] * d[c]);
                }
            }
            m
        }
        _ => DMatrix::from_element(p, p, f64::NAN),
    };
    let std_errors: Vec<f64> = (0..p).map(|i| matrix[(i, i)].max(0.0).sqrt()).collect();
    let mut correlation = DMatrix::from_element(p, p, f64::NAN);
    for r in 0..p {
        for c in 0..p {
            let den = std_errors[r] * std_errors[c];
            if den > 0.0 {
                correlation[(r, c)] = matrix[(r, c)] / den;
            }
        }
    }
    Covariance {
        matrix,
        std_errors,
        correlation,
        residual_variance: s2,
        dof,
        singular,
    }
}

/// The Newey-West (HAC) covariance of a least-squares estimate under autocorrelated
/// residuals: B S B n / (n - p) with the bread B = (JᵀJ)^-1 (`bread`) and the meat
/// S = sum over lags |l| <= `lags` of (1 - |l| / (lags + 1)) sum_t g_t g_(t-l)ᵀ,
/// g_t = J_t r_t, with pairs taken within each segment (record) of `segments` lengths only.
///
/// The Bartlett-weighted meat is computed as (1 / (L + 1)) sum_t u_t u_tᵀ with u_t the sum of
/// the scores over the window t - L ..= t (clipped to the segment, t running L past its
/// end): each pair of scores l <= L apart shares L + 1 - l windows, so this is the lag sum
/// exactly, in O(n p²) instead of O(n L p²).
pub fn newey_west(
    j: &DMatrix<f64>,
    r: &[f64],
    segments: &[usize],
    lags: usize,
    bread: &DMatrix<f64>,
) -> DMatrix<f64> {
    newey_west_prewhitened(j, r, segments, lags, bread, 0.0)
}

/// [`newey_west`] after AR(1) prewhitening (Andrews and Monahan, Econometrica 60, 1992): the
/// meat is that of the filtered scores g_t - `phi` g_(t-1) (within each segment), recoloured
/// by 1 / (1 - phi)^2. For residuals that are AR(1) noise of lag-1 correlation phi the
/// filtered scores are nearly white, so a few lags suffice and the Bartlett kernel's
/// downward bias on a slowly decaying correlation is gone; `phi` = 0 is [`newey_west`].
pub fn newey_west_prewhitened(
    j: &DMatrix<f64>,
    r: &[f64],
    segments: &[usize],
    lags: usize,
    bread: &DMatrix<f64>,
    phi: f64,
) -> DMatrix<f64> {
    let filters = vec![Ar2 { a1: phi, a2: 0.0 }; j.ncols()];
    newey_west_filtered(j, r, segments, lags, bread, &filters)
}

/// [`newey_west`] after prewhitening each parameter's scores by its own filter (a diagonal
/// VAR(2) in Andrews and Monahan's scheme): the meat is that of the filtered scores
/// f_(t,c) = g_(t,c) - a1_c g_(t-1,c) - a2_c g_(t-2,c) (within each segment), recoloured
/// entry by entry by 1 / (A_a(1) A_b(1)), A_c(1) = 1 - a1_c - a2_c the filter's gain at zero
/// frequency.
pub fn newey_west_filtered(
    j: &DMatrix<f64>,
    r: &[f64],
    segments: &[usize],
    lags: usize,
    bread: &DMatrix<f64>,
    filters: &[Ar2],
) -> DMatrix<f64> {
    let (n, p) = j.shape();
    let filtered = filtered_scores(j, r, segments, filters);
    let mut meat = bartlett_meat(&filtered, segments, lags);
    for a in 0..p {
        for b in 0..p {
            meat[(a, b)] /= filters[a].gain_at_zero() * filters[b].gain_at_zero();
        }
    }
    let dof = n.saturating_sub(p).max(1) as f64;
    bread * meat * bread * (n as f64 / dof)
}

/// Each estimate's heteroskedasticity and autocorrelation consistent variance, and how it
/// was made.
#[derive(Debug, Clone)]
pub struct Hac {
    /// Each parameter's variance, in the order of the Jacobian's columns.
    pub variances: Vec<f64>,
    /// The Bartlett lags.
    pub lags: usize,
    /// Each parameter's prewhitening filter.
    pub filters: Vec<Ar2>,
}

/// Each estimate's HAC variance with every choice made from the data. An estimate moves
/// with its influence series h_(t,k) = sum_a B_(k,a) J_(t,a) r_t (B the bread), so its
/// variance is that series' long-run variance: each parameter's series is prewhitened by its
/// own Yule-Walker AR(2) filter ([`Ar2::of_scores`]; it follows AR(1) noise and a ringing's
/// oscillatory correlation alike, and its gain at zero frequency is positive whatever the
/// data), then Bartlett lags by Andrews' plug-in rule on what the filters leave (the most
/// any parameter's series asks for, at most `cap`), then [`newey_west_filtered`] with the
/// identity as bread.
///
/// Filtering each column's scores J_(t,a) r_t by its own filter before the bread combines
/// them (a diagonal VAR(2) on the scores) recolours two nearly collinear columns by
/// different gains, and their large, opposite bread entries no longer cancel: on a linear
/// model whose two estimates correlate -0.9999 under AR(1) noise that overstated their
/// standard errors 1.7 times, and on a three-element GMS fit to a drive's friction force
/// 2 to 3 times (widening them up to 1 268 times the classical ones, where each estimate's
/// own series widens them up to 405 times).
pub fn hac_covariance(
    j: &DMatrix<f64>,
    r: &[f64],
    segments: &[usize],
    bread: &DMatrix<f64>,
    cap: usize,
) -> Hac {
    let (n, p) = j.shape();
    let influence = j * bread.transpose();
    let filters: Vec<Ar2> = (0..p)
        .map(|c| {
            let scores: Vec<f64> = influence
                .column(c)
                .iter()
                .zip(r)
                .map(|(a, b)| a * b)
                .collect();
            Ar2::of_scores(&scores, segments)
        })
        .collect();
    let filtered = filtered_scores(&influence, r, segments, &filters);
    let lags = (0..p)
        .map(|c| {
            let column: Vec<f64> = filtered.column(c).iter().copied().collect();
            let rho = pooled_autocorrelation(&column, segments, 1);
            andrews_lags(rho, n, cap)
        })
        .max()
        .unwrap_or(1);
    let identity = DMatrix::identity(p, p);
    let matrix = newey_west_filtered(&influence, r, segments, lags, &identity, &filters);
    Hac {
        variances: matrix.diagonal().iter().copied().collect(),
        lags,
        filters,
    }
}

/// An autoregressive filter of order 2, x_t - a1 x_(t-1) - a2 x_(t-2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ar2 {
    /// The lag-1 coefficient.
    pub a1: f64,
    /// The lag-2 coefficient.
    pub a2: f64,
}

impl Ar2 {
    /// The identity filter.
    pub const WHITE: Self = Self { a1: 0.0, a2: 0.0 };

    /// The Yule-Walker filter of the lag-1 and lag-2 autocorrelations `rho1`, `rho2`, its
    /// characteristic roots shrunk to a modulus of at most [`MAX_PLUG_IN_CORRELATION`] (a
    /// bounded recolouring, as Andrews and Monahan bound theirs). Autocorrelations of one
    /// series give a stationary filter; anything else (not finite, |rho1| >= 1) the
    /// identity.
    pub fn yule_walker(rho1: f64, rho2: f64) -> Self {
        let den = 1.0 - rho1 * rho1;
        if !(rho1.is_finite() && rho2.is_finite() && den > 1e-12) {
            return Self::WHITE;
        }
        let raw = Self {
            a1: rho1 * (1.0 - rho2) / den,
            a2: (rho2 - rho1 * rho1) / den,
        };
        let modulus = raw.largest_root();
        if !modulus.is_finite() {
            return Self::WHITE;
        }
        let shrink = (MAX_PLUG_IN_CORRELATION / modulus).min(1.0);
        Self {
            a1: raw.a1 * shrink,
            a2: raw.a2 * shrink * shrink,
        }
    }

    /// The Yule-Walker filter of a series cut into `segments` (pairs within a segment).
    pub fn of_scores(values: &[f64], segments: &[usize]) -> Self {
        Self::yule_walker(
            pooled_autocorrelation(values, segments, 1),
            pooled_autocorrelation(values, segments, 2),
        )
    }

    /// The largest modulus of the roots of z^2 - a1 z - a2.
    fn largest_root(&self) -> f64 {
        let disc = self.a1 * self.a1 + 4.0 * self.a2;
        if disc < 0.0 {
            (-self.a2).sqrt()
        } else {
            let s = disc.sqrt();
            (self.a1 + s).abs().max((self.a1 - s).abs()) / 2.0
        }
    }

    /// The gain at zero frequency, 1 - a1 - a2: positive for roots inside the unit circle.
    pub fn gain_at_zero(&self) -> f64 {
        1.0 - self.a1 - self.a2
    }
}

/// The lag-`lag` autocorrelation of `values` cut into `segments` (pairs within a segment,
/// about zero: scores at a least-squares optimum sum to zero), 0 for a zero series.
pub fn pooled_autocorrelation(values: &[f64], segments: &[usize], lag: usize) -> f64 {
    let mut start = 0;
    let slices: Vec<&[f64]> = segments
        .iter()
        .map(|&len| {
            let end = (start + len).min(values.len());
            let s = &values[start.min(end)..end];
            start = end;
            s
        })
        .collect();
    autocorrelation(&slices, lag)
}

/// Lag-`lag` autocorrelation of the segments pooled (pairs within a segment only, about
/// zero), 0 for zero segments.
pub(crate) fn autocorrelation<S: AsRef<[f64]>>(segments: &[S], lag: usize) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for s in segments.iter().map(AsRef::as_ref) {
        den += s.iter().map(|x| x * x).sum::<f64>();
        num += s
            .iter()
            .zip(s.iter().skip(lag))
            .map(|(a, b)| a * b)
            .sum::<f64>();
    }
    if den > 0.0 {
        num / den
    } else {
        0.0
    }
}

/// The scores g_(t,c) = J_(t,c) r_t filtered by each column's `filters` within each segment
/// (the filter starts afresh at each segment's first sample).
fn filtered_scores(
    j: &DMatrix<f64>,
    r: &[f64],
    segments: &[usize],
    filters: &[Ar2],
) -> DMatrix<f64> {
    let (n, p) = j.shape();
    let g = |t: usize, c: usize| j[(t, c)] * r[t];
    let mut out = DMatrix::zeros(n, p);
    let mut start = 0;
    for &len in segments {
        let end = (start + len).min(n);
        for t in start..end {
            for (c, f) in filters.iter().enumerate().take(p) {
                let mut v = g(t, c);
                if t > start {
                    v -= f.a1 * g(t - 1, c);
                }
                if t > start + 1 {
                    v -= f.a2 * g(t - 2, c);
                }
                out[(t, c)] = v;
            }
        }
        start = end;
    }
    out
}

/// The Bartlett-weighted meat of the scores `f` (rows in time) with pairs within each
/// segment (see [`newey_west`]).
fn bartlett_meat(f: &DMatrix<f64>, segments: &[usize], lags: usize) -> DMatrix<f64> {
    let (n, p) = f.shape();
    let mut meat = DMatrix::zeros(p, p);
    let mut start = 0;
    for &len in segments {
        let end = (start + len).min(n);
        add_bartlett_meat(&mut meat, p, |t, c| f[(t, c)], start..end, lags);
        start = end;
    }
    meat
}

/// Adds one segment's Bartlett-weighted products of the `p` scores `score(t, c)` (see
/// [`newey_west`]) to `meat`.
fn add_bartlett_meat(
    meat: &mut DMatrix<f64>,
    p: usize,
    score: impl Fn(usize, usize) -> f64,
    rows: std::ops::Range<usize>,
    lags: usize,
) {
    let mut u = vec![0.0; p];
    for t in rows.start..rows.end + lags {
        for (c, uc) in u.iter_mut().enumerate() {
            if t < rows.end {
                *uc += score(t, c);
            }
            if t > rows.start + lags {
                *uc -= score(t - lags - 1, c);
            }
        }
        for a in 0..p {
            for b in 0..p {
                meat[(a, b)] += u[a] * u[b] / (lags + 1) as f64;
            }
        }
    }
}

/// The Bartlett kernel's lag count by Andrews' AR(1) plug-in rule (Econometrica 59, 1991,
/// eq. 6.4): the bandwidth 1.1447 (alpha n)^(1/3) with alpha = 4 rho^2 / ((1 - rho)^2
/// (1 + rho)^2), from the lag-1 correlation `rho` of the (prewhitened) residuals, taken in
/// [0, [`MAX_PLUG_IN_CORRELATION`]] so that the count stays bounded; at least 1 lag, at
/// most `cap`.
pub fn andrews_lags(rho: f64, n: usize, cap: usize) -> usize {
    let rho = if rho.is_finite() {
        rho.clamp(0.0, MAX_PLUG_IN_CORRELATION)
    } else {
        0.0
    };
    let alpha = 4.0 * rho * rho / ((1.0 - rho).powi(2) * (1.0 + rho).powi(2));
    let bandwidth = 1.1447 * (alpha * n as f64).cbrt();
    (bandwidth.ceil() as usize).clamp(1, cap.max(1))
}

/// The largest lag-1 correlation Andrews' plug-in rule and the prewhitening take (the
/// bound Andrews and Monahan put on the prewhitening filter).
pub const MAX_PLUG_IN_CORRELATION: f64 = 0.97;

/// Akaike's information criterion for Gaussian least squares: n ln(SSR/n) + 2 p.
pub fn aic(n: usize, ssr: f64, p: usize) -> f64 {
    let n = n as f64;
    n * (ssr / n).ln() + 2.0 * p as f64
}

/// The Bayesian (Schwarz) information criterion: n ln(SSR/n) + p ln(n).
pub fn bic(n: usize, ssr: f64, p: usize) -> f64 {
    let nf = n as f64;
    nf * (ssr / nf).ln() + p as f64 * nf.ln()
}

/// The 95 % quantile of the chi-square distribution with `dof` degrees of freedom: exact for
/// 1 (the squared normal quantile) and 2 (-2 ln 0.05), tabulated to 4 decimals up to 20,
/// beyond by the Wilson-Hilferty cube (relative error below 5e-4).
pub fn chi_square_95(dof: usize) -> f64 {
    const TABLE: [f64; 18] = [
        7.8147, 9.4877, 11.0705, 12.5916, 14.0671, 15.5073, 16.9190, 18.3070, 19.6751, 21.0261,
        22.3620, 23.6848, 24.9958, 26.2962, 27.5871, 28.8693, 30.1435, 31.4104,
    ];
    match dof {
        0 => 0.0,
        1 => 3.841_458_820_694_124,
        2 => -2.0 * 0.05f64.ln(),
        3..=20 => TABLE[dof - 3],
        _ => {
            let z = 1.644_853_626_951_472_7;
            let k = dof as f64;
            let a = 2.0 / (9.0 * k);
            k * (1.0 - a + z * a.sqrt()).powi(3)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi_square_quantiles_match_tables() {
        // Tabulated 95 % values (e.g. NIST/SEMATECH e-Handbook, table 1.3.6.7.4).
        for (dof, q) in [
            (1, 3.841),
            (2, 5.991),
            (3, 7.815),
            (6, 12.592),
            (10, 18.307),
            (11, 19.675),
            (20, 31.410),
            (21, 32.671),
            (50, 67.505),
            (100, 124.342),
        ] {
            let got = chi_square_95(dof);
            assert!((got - q).abs() < 5e-4 * q, "dof {dof}: {got} vs {q}");
        }
        // One degree of freedom: the square of the two-sided normal quantile.
        assert!((chi_square_95(1) - 1.959_963_984_540_054f64.powi(2)).abs() < 1e-12);
    }

    #[test]
    fn t_quantiles_match_tables() {
        // Tabulated two-sided 95 % values.
        for (dof, t) in [
            (1, 12.706),
            (2, 4.303),
            (3, 3.182),
            (5, 2.571),
            (10, 2.228),
            (30, 2.042),
            (120, 1.980),
        ] {
            assert!((t_quantile_975(dof) - t).abs() < 2e-3, "dof {dof}");
        }
        assert!((t_quantile_975(100_000) - 1.95996).abs() < 1e-4);
    }

    /// Straight line y = a + b x: the covariance equals the textbook formulas.
    #[test]
    fn straight_line_covariance_matches_the_closed_form() {
        let x: Vec<f64> = (0..20).map(|i| i as f64 * 0.5).collect();
        let n = x.len() as f64;
        let j = DMatrix::from_fn(x.len(), 2, |r, c| if c == 0 { 1.0 } else { x[r] });
        let ssr = 3.6;
        let cov = covariance(&j, ssr);
        let s2 = ssr / (n - 2.0);
        let mean = x.iter().sum::<f64>() / n;
        let sxx: f64 = x.iter().map(|v| (v - mean).powi(2)).sum();
        let var_b = s2 / sxx;
        let var_a = s2 * (1.0 / n + mean * mean / sxx);
        assert!((cov.std_errors[1] - var_b.sqrt()).abs() < 1e-12);
        assert!((cov.std_errors[0] - var_a.sqrt()).abs() < 1e-12);
        let rho = -mean * s2 / sxx / (var_a.sqrt() * var_b.sqrt());
        assert!((cov.correlation[(0, 1)] - rho).abs() < 1e-12);
        assert!(!cov.singular);
    }

    #[test]
    fn collinear_columns_are_flagged_singular() {
        let j = DMatrix::from_fn(10, 2, |r, c| (r as f64 + 1.0) * (c as f64 + 1.0));
        let cov = covariance(&j, 1.0);
        assert!(cov.singular);
        assert!(cov.std_errors.iter().all(|s| s.is_nan() || *s == 0.0));
    }

    #[test]
    fn information_criteria_by_hand() {
        let (n, ssr) = (100, 2.5);
        assert!((aic(n, ssr, 3) - (100.0 * (0.025f64).ln() + 6.0)).abs() < 1e-12);
        assert!((bic(n, ssr, 3) - (100.0 * (0.025f64).ln() + 3.0 * (100f64).ln())).abs() < 1e-12);
    }

    /// Andrews' rule by hand: rho = 0.6 over 6000 residuals gives alpha = 1.44 / (0.16 *
    /// 2.56) = 3.516 and 1.1447 (21094)^(1/3) = 31.6, so 32 lags; white residuals take one,
    /// and a correlation near 1 is bounded by the plug-in's cap of 0.97 and by `cap`.
    #[test]
    fn andrews_lags_follow_the_plug_in_rule_and_stay_bounded() {
        assert_eq!(andrews_lags(0.6, 6000, 10_000), 32);
        assert_eq!(andrews_lags(0.0, 6000, 10_000), 1);
        let near_one = andrews_lags(0.999, 25_000, 10_000);
        assert_eq!(near_one, andrews_lags(0.97, 25_000, 10_000));
        assert!(near_one < 400, "{near_one}");
        assert_eq!(andrews_lags(0.97, 25_000, 50), 50);
        assert_eq!(andrews_lags(f64::NAN, 100, 50), 1);
    }

    /// `n` samples of AR(1) noise e_t = `phi` e_(t-1) + w_t, w_t standard normal (seeded).
    fn ar1_noise(n: usize, phi: f64, seed: u64) -> Vec<f64> {
        use rand::rngs::StdRng;
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let mut rng = StdRng::seed_from_u64(seed);
        let normal = Normal::new(0.0, 1.0).unwrap();
        let mut e = 0.0;
        (0..n)
            .map(|_| {
                e = phi * e + normal.sample(&mut rng);
                e
            })
            .collect()
    }

    /// AR(1) scores: the prewhitened estimate with the true phi recovers the long-run
    /// variance that Bartlett's kernel alone underestimates at the same lag count.
    #[test]
    fn prewhitening_recovers_the_long_run_variance_of_ar1_scores() {
        let (n, phi) = (200_000, 0.9);
        let r = ar1_noise(n, phi, 7);
        let j = DMatrix::from_element(n, 1, 1.0);
        let bread = DMatrix::from_element(1, 1, 1.0 / n as f64);
        // Var(mean) of AR(1) with innovation variance 1: n^-1 / (1 - phi)^2.
        let truth = 1.0 / (n as f64 * (1.0 - phi).powi(2));
        let plain = newey_west(&j, &r, &[n], 5, &bread)[(0, 0)];
        let white = newey_west_prewhitened(&j, &r, &[n], 5, &bread, phi)[(0, 0)];
        assert!(plain < 0.5 * truth, "{plain} vs {truth}");
        assert!((white / truth - 1.0).abs() < 0.1, "{white} vs {truth}");
    }

    /// With white residuals and no lags, the Newey-West covariance is White's
    /// heteroskedasticity-consistent one; for a constant-variance straight line it is close
    /// to the classical one.
    #[test]
    fn newey_west_without_lags_is_whites_estimate() {
        let n = 200;
        let x: Vec<f64> = (0..n).map(|i| i as f64 / n as f64).collect();
        let j = DMatrix::from_fn(n, 2, |r, c| if c == 0 { 1.0 } else { x[r] });
        // Residuals +-1 alternating: white, unit variance.
        let r: Vec<f64> = (0..n)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let ssr = n as f64;
        let cov = covariance(&j, ssr);
        let bread = cov.matrix.clone() / cov.residual_variance;
        let hac = newey_west(&j, &r, &[n], 0, &bread);
        for i in 0..2 {
            let ratio = hac[(i, i)] / cov.matrix[(i, i)];
            assert!((ratio - 1.0).abs() < 0.05, "{ratio}");
        }
        // Alternating residuals are negatively correlated at lag 1: lags shrink the variance.
        let with_lags = newey_west(&j, &r, &[n], 5, &bread);
        assert!(with_lags[(0, 0)] < hac[(0, 0)]);
    }

    use nalgebra::DVector;
    /// The AR(2) ringing e_t = 2 rho cos(theta) e_(t-1) - rho^2 e_(t-2) + w_t.
    fn ringing(rho: f64, theta: f64) -> Ar2 {
        Ar2 {
            a1: 2.0 * rho * theta.cos(),
            a2: -rho * rho,
        }
    }

    /// Yule-Walker on an AR(2)'s own autocorrelations, rho1 = a1 / (1 - a2) and
    /// rho2 = a1 rho1 + a2, gives the filter back; a filter whose roots lie beyond the bound
    /// is shrunk onto it; a unit lag-1 correlation or a NaN gives the identity.
    #[test]
    fn yule_walker_recovers_an_ar2_and_bounds_its_roots() {
        for truth in [
            ringing(0.9, 0.314),
            ringing(0.5, 2.5),
            Ar2 { a1: 0.6, a2: 0.2 },
        ] {
            let rho1 = truth.a1 / (1.0 - truth.a2);
            let rho2 = truth.a1 * rho1 + truth.a2;
            let got = Ar2::yule_walker(rho1, rho2);
            assert!((got.a1 - truth.a1).abs() < 1e-12, "{got:?} vs {truth:?}");
            assert!((got.a2 - truth.a2).abs() < 1e-12, "{got:?} vs {truth:?}");
        }
        let near_unit = ringing(0.999, 0.1);
        let rho1 = near_unit.a1 / (1.0 - near_unit.a2);
        let got = Ar2::yule_walker(rho1, near_unit.a1 * rho1 + near_unit.a2);
        assert!(
            (-got.a2).sqrt() <= MAX_PLUG_IN_CORRELATION + 1e-12,
            "{got:?}"
        );
        assert!(got.gain_at_zero() > 0.0);
        assert_eq!(Ar2::yule_walker(1.0, 1.0), Ar2::WHITE);
        assert_eq!(Ar2::yule_walker(f64::NAN, 0.0), Ar2::WHITE);
    }

    /// Autocorrelations of any series give a filter whose gain at zero frequency is
    /// positive: the recolouring cannot turn a variance negative (an alternating series, a
    /// ringing near the Nyquist rate, a slow drift).
    #[test]
    fn the_prewhitening_gain_is_positive_for_any_series() {
        let series: [Vec<f64>; 4] = [
            (0..500)
                .map(|t| if t % 2 == 0 { 1.0 } else { -1.0 })
                .collect(),
            (0..500).map(|t| (t as f64 * 2.9).sin()).collect(),
            (0..500).map(|t| (t as f64 * 0.01).sin() + 0.3).collect(),
            (0..500).map(|t| ((t * t) as f64 * 0.7).cos()).collect(),
        ];
        for s in &series {
            let f = Ar2::of_scores(s, &[s.len()]);
            assert!(f.gain_at_zero() > 0.0, "{f:?}");
            assert!(f.largest_root() <= MAX_PLUG_IN_CORRELATION + 1e-12, "{f:?}");
        }
    }

    /// The filtered estimate is the textbook lag sum of the scores filtered by hand,
    /// recoloured entry by entry by the filters' gains at zero frequency.
    #[test]
    fn newey_west_filtered_is_the_lag_sum_of_the_filtered_scores() {
        let segments = [41, 3, 56];
        let n: usize = segments.iter().sum();
        let p = 3;
        let j = DMatrix::from_fn(n, p, |t, c| ((t * (c + 3)) as f64 * 0.29).cos() + 0.5);
        let r: Vec<f64> = (0..n).map(|t| (t as f64 * 0.7).sin() - 0.1).collect();
        let bread = DMatrix::from_fn(p, p, |a, b| if a == b { 2.0 } else { 0.3 });
        let filters = [Ar2 { a1: 0.5, a2: 0.2 }, ringing(0.8, 0.6), Ar2::WHITE];
        // The filtered scores, written out, into a Jacobian against unit residuals.
        let mut f = DMatrix::zeros(n, p);
        let mut start = 0;
        for &len in &segments {
            for t in start..start + len {
                for c in 0..p {
                    let g = |s: usize| j[(s, c)] * r[s];
                    let back1 = if t > start { g(t - 1) } else { 0.0 };
                    let back2 = if t >= start + 2 { g(t - 2) } else { 0.0 };
                    f[(t, c)] = g(t) - filters[c].a1 * back1 - filters[c].a2 * back2;
                }
            }
            start += len;
        }
        let ones = vec![1.0; n];
        for lags in [0, 2, 7, 60] {
            let mut meat = lag_sum_meat(&f, &ones, &segments, lags);
            for a in 0..p {
                for b in 0..p {
                    let ga = 1.0 - filters[a].a1 - filters[a].a2;
                    let gb = 1.0 - filters[b].a1 - filters[b].a2;
                    meat[(a, b)] /= ga * gb;
                }
            }
            let want = &bread * meat * &bread * (n as f64 / (n - p) as f64);
            let got = newey_west_filtered(&j, &r, &segments, lags, &bread, &filters);
            let scale = want.abs().max();
            assert!((got - &want).abs().max() < 1e-12 * scale, "lags {lags}");
        }
    }

    /// The mean of an AR(2) ringing (rho 0.9 at 50 Hz sampled at 1 kHz): the data-driven HAC
    /// recovers the long-run variance sigma^2 / (n A(1)^2), 3.8 times the classical one.
    #[test]
    fn hac_recovers_the_long_run_variance_of_a_ringing_mean() {
        use rand::rngs::StdRng;
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let n = 100_000;
        let truth_filter = ringing(0.9, 2.0 * std::f64::consts::PI * 50.0 / 1000.0);
        let mut rng = StdRng::seed_from_u64(11);
        let normal = Normal::new(0.0, 1.0).unwrap();
        let (mut e1, mut e2) = (0.0, 0.0);
        let r: Vec<f64> = (0..n)
            .map(|_| {
                let e = truth_filter.a1 * e1 + truth_filter.a2 * e2 + normal.sample(&mut rng);
                (e2, e1) = (e1, e);
                e
            })
            .collect();
        let j = DMatrix::from_element(n, 1, 1.0);
        let bread = DMatrix::from_element(1, 1, 1.0 / n as f64);
        let truth = 1.0 / (n as f64 * truth_filter.gain_at_zero().powi(2));
        let hac = hac_covariance(&j, &r, &[n], &bread, n / 4);
        let got = hac.variances[0];
        assert!((got / truth - 1.0).abs() < 0.15, "{got} vs {truth}");
        assert!(
            (hac.filters[0].a1 - truth_filter.a1).abs() < 0.05,
            "{:?}",
            hac.filters
        );
    }

    /// Sum_s phi^|t - s| x_s for every t, by a forward and a backward recursion.
    fn ar1_smoothed(x: &[f64], phi: f64) -> Vec<f64> {
        let (mut forward, mut backward) = (vec![0.0; x.len()], vec![0.0; x.len()]);
        let mut acc = 0.0;
        for (t, &v) in x.iter().enumerate() {
            acc = v + phi * acc;
            forward[t] = acc;
        }
        acc = 0.0;
        for (t, &v) in x.iter().enumerate().rev() {
            acc = v + phi * acc;
            backward[t] = acc;
        }
        (0..x.len())
            .map(|t| forward[t] + backward[t] - x[t])
            .collect()
    }

    /// Least squares on two nearly collinear columns (a slow sine, and the same sine plus a
    /// hundredth of a fast one: estimates correlated -0.9999) and a third, under AR(1) noise
    /// (phi 0.5): each HAC standard error is within 15 % of the exact one,
    /// B Xᵀ Sigma X B with Sigma_(t,s) = phi^|t-s| / (1 - phi^2). Filtering each column's
    /// scores by its own filter overstated the collinear pair's by 1.7 times.
    #[test]
    fn hac_errors_of_nearly_collinear_columns_match_the_exact_covariance() {
        let (n, phi) = (20_000, 0.5);
        let tau = 2.0 * std::f64::consts::PI;
        let x = DMatrix::from_fn(n, 3, |t, c| {
            let time = t as f64 / 1000.0;
            let slow = (tau * 0.3 * time).sin();
            match c {
                0 => slow,
                1 => slow + 1e-2 * (tau * 150.0 * time).sin(),
                _ => (tau * 1.1 * time).cos(),
            }
        });
        let noise = ar1_noise(n, phi, 1);
        let bread = (x.transpose() * &x).try_inverse().unwrap();
        let noise_v = DVector::from_column_slice(&noise);
        let beta = &bread * x.transpose() * &noise_v;
        let r: Vec<f64> = (noise_v - &x * beta).iter().copied().collect();
        let smoothed = DMatrix::from_fn(n, 3, |_, _| 0.0);
        let smoothed = (0..3).fold(smoothed, |mut m, c| {
            let column: Vec<f64> = x.column(c).iter().copied().collect();
            m.set_column(c, &DVector::from_vec(ar1_smoothed(&column, phi)));
            m
        });
        let exact = &bread * x.transpose() * smoothed * &bread / (1.0 - phi * phi);
        let hac = hac_covariance(&x, &r, &[n], &bread, n / 4);
        let correlation = exact[(0, 1)] / (exact[(0, 0)] * exact[(1, 1)]).sqrt();
        assert!(correlation < -0.9998, "{correlation}");
        for c in 0..3 {
            let ratio = (hac.variances[c] / exact[(c, c)]).sqrt();
            assert!((ratio - 1.0).abs() < 0.15, "column {c}: {ratio}");
        }
    }

    /// The textbook lag sum of the meat, pair by pair within each segment.
    fn lag_sum_meat(j: &DMatrix<f64>, r: &[f64], segments: &[usize], lags: usize) -> DMatrix<f64> {
        let p = j.ncols();
        let g = |t: usize| DVector::from_fn(p, |c, _| j[(t, c)] * r[t]);
        let mut meat = DMatrix::zeros(p, p);
        let mut start = 0;
        for &len in segments {
            for t in start..start + len {
                for s in start..start + len {
                    let l = t.abs_diff(s);
                    if l <= lags {
                        let w = 1.0 - l as f64 / (lags as f64 + 1.0);
                        meat += g(t) * g(s).transpose() * w;
                    }
                }
            }
            start += len;
        }
        meat
    }

    #[test]
    fn newey_west_equals_the_bartlett_weighted_lag_sum_within_segments() {
        let segments = [37, 5, 58];
        let n: usize = segments.iter().sum();
        let j = DMatrix::from_fn(n, 3, |t, c| ((t * (c + 2)) as f64 * 0.37).sin() + c as f64);
        let r: Vec<f64> = (0..n).map(|t| (t as f64 * 0.11).cos() + 0.3).collect();
        let bread = DMatrix::from_fn(3, 3, |a, b| if a == b { 1.0 + a as f64 } else { 0.1 });
        let dof_factor = n as f64 / (n - 3) as f64;
        for lags in [0, 1, 4, 9, 80] {
            let want = &bread * lag_sum_meat(&j, &r, &segments, lags) * &bread * dof_factor;
            let got = newey_west(&j, &r, &segments, lags, &bread);
            let scale = want.abs().max();
            assert!((got - &want).abs().max() < 1e-12 * scale, "lags {lags}");
        }
    }
}
