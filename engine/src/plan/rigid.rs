//! Whether planned records would tell a law with bristles (LuGre, Dahl, GMS) from its rigid
//! limit: the fit calls a contact stiffness determined only when its records reject the
//! limit law by a likelihood-ratio test, so a small linearised standard error is not enough
//! when the whole way from the assumed stiffness to a rigid contact costs less than the
//! test's threshold. The limit law is fitted to the noise-free planned records (the fit's own
//! search); its weighted sum of squares, chi^2 = sum (v - v_limit)^2 / sigma^2, is the
//! records' expected evidence against the limit, compared with chi^2_95 of the parameters
//! the limit removes.

use super::information::Assumed;
use crate::identify::assessment::stats::chi_square_95;
use crate::identify::{fit, FitOptions, ParamOptions};
use crate::record::{Channel, Record};

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
}

impl Separation {
    /// Whether the records would reject the limit.
    pub fn rejects(&self) -> bool {
        self.chi2 >= self.threshold
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
    })
}
