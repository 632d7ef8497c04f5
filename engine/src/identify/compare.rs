//! Fitting several models to the same records and ranking them.

use super::fit::{fit, FitResult};
use super::options::FitOptions;
use super::setup::non_model_bound_keys;
use crate::error::EngineError;
use crate::oscillator::Oscillator;
use crate::record::Record;
use frictionid_models::FrictionModel;
use rayon::prelude::*;
use serde::Serialize;

/// A model that could not be fitted.
#[derive(Debug, Clone, Serialize)]
pub struct FailedFit {
    /// Model name.
    pub model: String,
    /// Why.
    pub error: String,
}

/// Models ranked by AIC (best first), with BIC and RMS in each fit.
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    /// The fits, best (lowest AIC) first.
    pub ranking: Vec<FitResult>,
    /// Models whose fit failed.
    pub failed: Vec<FailedFit>,
    /// Wall time of the whole comparison [s].
    pub wall_time_s: f64,
}

/// Fits every model in `models` to `records` (in parallel when `opts.parallel`) and ranks
/// them by AIC. Each model is fitted with `opts` (its free list, bounds and initial values
/// apply only to parameters the model has; others are ignored).
pub fn compare(
    osc: &Oscillator,
    models: &[Box<dyn FrictionModel>],
    records: &[Record],
    opts: &FitOptions,
) -> Result<Comparison, EngineError> {
    let clock = std::time::Instant::now();
    if models.is_empty() {
        return Err(EngineError::InvalidInput("no models to compare".into()));
    }
    let run = |m: &(dyn FrictionModel + 'static)| -> (String, Result<FitResult, EngineError>) {
        let names: Vec<String> = m.param_info().into_iter().map(|p| p.name).collect();
        let mut o = opts.clone();
        o.free = opts
            .free
            .as_ref()
            .map(|f| f.iter().filter(|n| names.contains(n)).cloned().collect());
        let other_keys = non_model_bound_keys();
        o.bounds
            .retain(|k, _| names.contains(k) || other_keys.contains(&k.as_str()));
        o.keep_initial.retain(|k| names.contains(k));
        (m.name().to_string(), fit(osc, m, records, &o))
    };
    let results: Vec<(String, Result<FitResult, EngineError>)> = if opts.parallel {
        models.par_iter().map(|m| run(m.as_ref())).collect()
    } else {
        models.iter().map(|m| run(m.as_ref())).collect()
    };
    let mut ranking = Vec::new();
    let mut failed = Vec::new();
    for (name, r) in results {
        match r {
            Ok(f) => ranking.push(f),
            Err(e) => failed.push(FailedFit {
                model: name,
                error: e.to_string(),
            }),
        }
    }
    ranking.sort_by(|a, b| a.aic.total_cmp(&b.aic));
    Ok(Comparison {
        ranking,
        failed,
        wall_time_s: clock.elapsed().as_secs_f64(),
    })
}
