//! Whether planned records would tell a law with bristles (LuGre, Dahl, GMS) from its rigid
//! limit: the fit calls a contact stiffness determined only when its records reject the
//! limit law by a likelihood-ratio test, so a small linearised standard error is not enough
//! when the whole way from the assumed stiffness to a rigid contact costs less than the
//! test's threshold. The limit law is fitted to the noise-free planned records (the fit's own
//! search); its weighted sum of squares, chi^2 = sum (v - v_limit)^2 / sigma^2, is the
//! records' expected evidence against the limit: the noncentrality of the fit's
//! likelihood-ratio statistic. The limit is taken as rejected when that noncentrality gives
//! the fit's test (at chi^2_95 of the parameters the limit removes) a power of [`POWER`]: a
//! noncentrality just at chi^2_95 would be a coin flip, the fit of one noisy record set
//! rejecting the limit about half the time.

use super::information::Assumed;
use crate::identify::assessment::stats::chi_square_95;
use crate::identify::{fit, FitOptions, ParamOptions};
use crate::record::{Channel, Record};

/// The probability with which the planned records' fit should reject the rigid limit for a
/// contact stiffness to count as within reach.
pub const POWER: f64 = 0.9;

/// The records' evidence against the rigid limit.
#[derive(Debug, Clone, PartialEq)]
pub struct Separation {
    /// The limit law's name.
    pub limit: String,
    /// The free stiffnesses the test decides about.
    pub stiffnesses: Vec<String>,
    /// chi^2 of the limit law fitted to the noise-free records.
    pub chi2: f64,
    /// chi^2_95 of the parameters the limit removes.
    pub threshold: f64,
    /// The noncentrality at which the fit's test rejects the limit with probability
    /// [`POWER`].
    pub needed: f64,
}

impl Separation {
    /// Whether a fit of the records would reject the limit with probability [`POWER`].
    pub fn rejects(&self) -> bool {
        self.chi2 >= self.needed
    }
}

/// The noncentrality lambda at which a chi-square test with `dof` degrees of freedom at
/// level 5 % rejects with probability `power`: P(chi^2(dof, lambda) > chi^2_95(dof)) = power,
/// by bisection on [`noncentral_tail`] over lambda in [0, 200].
pub fn needed_noncentrality(dof: usize, power: f64) -> f64 {
    let c = chi_square_95(dof);
    let (mut lo, mut hi) = (0.0, 200.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if noncentral_tail(dof, mid, c) < power {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// P(chi^2(dof, lambda) > c), the Poisson mixture sum_k Pois(k; lambda / 2) Q(dof / 2 + k,
/// c / 2) of regularised upper incomplete gamma functions, each from the one before by
/// Q(a + 1, x) = Q(a, x) + x^a e^-x / Gamma(a + 1), starting at Q(1/2, x) = erfc(sqrt x) or
/// Q(1, x) = e^-x (`dof` 0 is taken as 1).
pub fn noncentral_tail(dof: usize, lambda: f64, c: f64) -> f64 {
    let dof = dof.max(1);
    let x = 0.5 * c;
    // q = Q(a, x), term = x^a e^-x / Gamma(a + 1).
    let (mut a, mut q, mut term) = if dof % 2 == 1 {
        let root = x.sqrt();
        let term = 2.0 * root * (-x).exp() / std::f64::consts::PI.sqrt();
        (0.5, erfc(root), term)
    } else {
        (1.0, (-x).exp(), x * (-x).exp())
    };
    let step = |a: &mut f64, q: &mut f64, term: &mut f64| {
        *q += *term;
        *term *= x / (*a + 1.0);
        *a += 1.0;
    };
    while a < 0.5 * dof as f64 - 0.25 {
        step(&mut a, &mut q, &mut term);
    }
    let half = 0.5 * lambda;
    let mut weight = (-half).exp();
    let mut sum = weight * q;
    let terms = (half + 20.0 * half.sqrt() + 50.0) as usize;
    for k in 1..terms {
        step(&mut a, &mut q, &mut term);
        weight *= half / k as f64;
        sum += weight * q.min(1.0);
    }
    sum.min(1.0)
}

/// The complementary error function (Numerical Recipes' Chebyshev fit, relative error below
/// 1.2e-7).
fn erfc(x: f64) -> f64 {
    let t = 1.0 / (1.0 + 0.5 * x.abs());
    let poly = -x * x - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let e = t * poly.exp();
    if x >= 0.0 {
        e
    } else {
        2.0 - e
    }
}

/// The separation of `records` (noise-free, their noise declared) from the assumed law's
/// rigid limit, when it has one and a stiffness of it is among `free`; `None` otherwise or
/// when the limit cannot be fitted.
pub fn separation(
    assumed: &Assumed<'_>,
    records: &[Record],
    free: &[String],
) -> Option<Separation> {
    let declared = assumed.model.states()?.rigid_limit()?;
    let info = assumed.model.param_info();
    let stiffnesses: Vec<String> = declared
        .stiffnesses
        .iter()
        .filter_map(|&i| info.get(i).map(|p| p.name.clone()))
        .filter(|n| free.contains(n))
        .collect();
    if stiffnesses.is_empty() {
        return None;
    }
    let limit_free: Vec<String> = declared
        .law
        .param_info()
        .into_iter()
        .filter(|p| !p.fixed_by_default || declared.also_free.contains(&p.name.as_str()))
        .map(|p| p.name)
        .collect();
    let opts = FitOptions {
        params: ParamOptions {
            free: Some(limit_free.clone()),
            oscillator: assumed.params.oscillator.clone(),
            ..ParamOptions::default()
        },
        sim: assumed.sim,
        ..FitOptions::default()
    };
    let limit = fit(&assumed.oscillator, declared.law.as_ref(), records, &opts).ok()?;
    let chi2: f64 = limit
        .records
        .iter()
        .zip(records)
        .map(|(r, rec)| {
            let sigma = rec.noise_level(Channel::Velocity).unwrap_or(f64::NAN);
            r.rms_residual.powi(2) * r.samples as f64 / (sigma * sigma)
        })
        .sum();
    let model_free = free
        .iter()
        .filter(|n| info.iter().any(|p| &p.name == *n))
        .count();
    let removed = model_free.saturating_sub(limit_free.len()).max(1);
    Some(Separation {
        limit: declared.law.name().to_string(),
        stiffnesses,
        chi2,
        threshold: chi_square_95(removed),
        needed: needed_noncentrality(removed, POWER),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One degree of freedom: chi^2(1, lambda) is (Z + sqrt(lambda))^2, so 90 % power needs
    /// (1.95996 + 1.28155)^2 = 10.507 (the far tail adds 1e-5); two and four: 12.654 and
    /// 15.405 (power tables, e.g. Cohen 1988, table 7.4.15: lambda for u = 2, a = .05, power
    /// .90); at lambda 0 the tail is the test's 5 %.
    #[test]
    fn noncentralities_for_ninety_percent_power_match_the_tables() {
        let one = needed_noncentrality(1, 0.9);
        assert!((one - 10.507).abs() < 0.01, "{one}");
        let two = needed_noncentrality(2, 0.9);
        assert!((two - 12.654).abs() < 0.01, "{two}");
        let four = needed_noncentrality(4, 0.9);
        assert!((four - 15.405).abs() < 0.01, "{four}");
        for dof in [1, 2, 3, 7] {
            let size = noncentral_tail(dof, 0.0, chi_square_95(dof));
            assert!((size - 0.05).abs() < 1e-4, "{dof}: {size}");
        }
    }
}
