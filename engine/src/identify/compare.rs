//! Fitting several models to the same records and ranking them.

use super::fit::fit;
use crate::error::EngineError;
use crate::identify::values::fit_options::FitOptions;
use crate::identify::values::layout::is_friction_level;
use crate::identify::values::outcome::{Check, Finding};
use crate::identify::values::result::FitResult;
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

/// Models whose AIC is within this of the best are indistinguishable on the data (Burnham
/// and Anderson's rule of thumb: substantial support).
pub const INDISTINGUISHABLE_DELTA_AIC: f64 = 2.0;

/// Models ranked by AIC (best first), with BIC and RMS in each fit.
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    /// The fits, best (lowest AIC) first, each with its [`crate::identify::values::Rank`].
    pub ranking: Vec<FitResult>,
    /// Models whose fit failed.
    pub failed: Vec<FailedFit>,
    /// What the ranking says (`None` when no model could be fitted).
    pub verdict: Option<ComparisonVerdict>,
    /// Models that did not converge, and failed fits, as sentences.
    pub warnings: Vec<String>,
    /// Wall time of the whole comparison [s].
    pub wall_time_s: f64,
}

/// The verdict of a comparison: the best model, those the data cannot tell from it, and
/// the simplest of these (fewest free parameters, then lowest AIC).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComparisonVerdict {
    /// The model with the lowest AIC.
    pub best: String,
    /// Every model within [`INDISTINGUISHABLE_DELTA_AIC`] of the best, best included.
    pub indistinguishable: Vec<String>,
    /// The simplest of `indistinguishable`: the model to report.
    pub simplest: String,
    /// One sentence for people.
    pub message: String,
}

impl Comparison {
    /// The verdict of the best fit (`None` when no model could be fitted): the CLI exits 2
    /// when it did not converge.
    pub fn best_verdict(&self) -> Option<crate::identify::values::Verdict> {
        self.ranking.first().map(FitResult::verdict)
    }
}

/// A model's name and its fit.
type ModelFit = (String, Result<FitResult, EngineError>);

/// Fits every model in `models` to `records` (in parallel when `opts.hooks.parallel`) and ranks
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
    let run = |m: &(dyn FrictionModel + 'static)| -> ModelFit {
        let names: Vec<String> = m.param_info().into_iter().map(|p| p.name).collect();
        let o = FitOptions {
            params: opts.params.for_model(&names),
            ..opts.clone()
        };
        (m.name().to_string(), fit(osc, m, records, &o))
    };
    let results: Vec<ModelFit> = if opts.hooks.parallel {
        let order = heaviest_first(models);
        let mut done: Vec<(usize, ModelFit)> = order
            .par_iter()
            .map(|&i| (i, run(models[i].as_ref())))
            .collect();
        done.sort_by_key(|(i, _)| *i);
        done.into_iter().map(|(_, r)| r).collect()
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
    rank(&mut ranking);
    let warnings = comparison_warnings(&ranking, &failed);
    Ok(Comparison {
        verdict: verdict(&ranking),
        ranking,
        failed,
        warnings,
        wall_time_s: clock.elapsed().as_secs_f64(),
    })
}

/// The models' indices, the likely longest fit first (more internal states, then more
/// parameters): rayon starts the first items first, so the long dynamic fits do not wait
/// behind the short static ones and the short ones fill the cores at the end.
fn heaviest_first(models: &[Box<dyn FrictionModel>]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..models.len()).collect();
    order.sort_by_key(|&i| {
        let m = &models[i];
        std::cmp::Reverse((m.n_states(), m.params().len()))
    });
    order
}

/// Sets every fit's delta AIC, Akaike weight and whether it is indistinguishable from the
/// best; `ranking` is sorted by AIC.
fn rank(ranking: &mut [FitResult]) {
    let Some(best) = ranking.first().map(|f| f.aic) else {
        return;
    };
    let relative: Vec<f64> = ranking
        .iter()
        .map(|f| (-(f.aic - best) / 2.0).exp())
        .collect();
    let total: f64 = relative.iter().sum();
    for (fit, l) in ranking.iter_mut().zip(relative) {
        let delta_aic = fit.aic - best;
        fit.rank = Some(crate::identify::values::Rank {
            delta_aic,
            akaike_weight: l / total,
            indistinguishable: delta_aic <= INDISTINGUISHABLE_DELTA_AIC,
        });
    }
}

fn is_indistinguishable(fit: &FitResult) -> bool {
    fit.rank.is_some_and(|r| r.indistinguishable)
}

/// The best model, its indistinguishable rivals and the simplest of them.
fn verdict(ranking: &[FitResult]) -> Option<ComparisonVerdict> {
    let best = ranking.first()?;
    let close: Vec<&FitResult> = ranking.iter().filter(|f| is_indistinguishable(f)).collect();
    let simplest = close
        .iter()
        .min_by(|a, b| {
            a.free_parameters
                .cmp(&b.free_parameters)
                .then(a.aic.total_cmp(&b.aic))
        })
        .map_or(best, |f| *f);
    let names: Vec<String> = close.iter().map(|f| f.model.clone()).collect();
    let message = if names.len() > 1 {
        format!(
            "{} are indistinguishable on this data (AIC within {INDISTINGUISHABLE_DELTA_AIC} of the best); the simplest is `{}`",
            names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", "),
            simplest.model
        )
    } else {
        let margin = ranking
            .get(1)
            .map(|f| format!(" (next: `{}`, delta AIC {:.1})", f.model, f.aic - best.aic))
            .unwrap_or_default();
        format!("best: `{}`{margin}", best.model)
    };
    let mut named = vec![best];
    if simplest.model != best.model {
        named.push(simplest);
    }
    let caveats: Vec<String> = named.into_iter().filter_map(pinned_caveat).collect();
    let message = if caveats.is_empty() {
        message
    } else {
        format!("{message}; but {}", caveats.join("; "))
    };
    Some(ComparisonVerdict {
        best: best.model.clone(),
        indistinguishable: names,
        simplest: simplest.model.clone(),
        message,
    })
}

/// The findings of `fit` that say a friction level is at its bound (a viscous coefficient at
/// 0 is an answer; a level at its bound is a level the bounds or a missing normal force set).
fn at_bounds(fit: &FitResult) -> impl Iterator<Item = &Finding> {
    fit.diagnostics.iter().filter(|d| {
        d.check == Check::ParameterAtBound
            && d.parameter.as_deref().is_some_and(|name| {
                fit.parameters
                    .iter()
                    .any(|p| p.name == name && is_friction_level(&p.name, &p.unit))
            })
    })
}

/// What the verdict adds about a model it names with friction levels at their bounds:
/// which, at what value, and what to do (`None` when none is).
fn pinned_caveat(fit: &FitResult) -> Option<String> {
    let pinned: Vec<String> = at_bounds(fit)
        .map(|d| {
            let name = d.parameter.as_deref().unwrap_or("a parameter");
            let value = d.value.map(|v| format!(" = {v}")).unwrap_or_default();
            format!("`{name}`{value}")
        })
        .collect();
    (!pinned.is_empty()).then(|| {
        format!(
            "`{}` has {} at a bound, so its rank is not reliable: widen its [fit] bounds or set the normal force",
            fit.model,
            pinned.join(", ")
        )
    })
}

/// A warning per model that did not converge, and per friction level of a ranked model at
/// its bound.
fn comparison_warnings(ranking: &[FitResult], failed: &[FailedFit]) -> Vec<String> {
    let unconverged = ranking.iter().filter(|f| !f.converged).map(|f| {
        format!(
            "model `{}` did not converge ({}): its rank is not reliable",
            f.model, f.termination
        )
    });
    let failures = failed
        .iter()
        .map(|f| format!("model `{}` could not be fitted: {}", f.model, f.error));
    let pinned = ranking
        .iter()
        .flat_map(|f| at_bounds(f).map(move |d| format!("model `{}`: {}", f.model, d.message)));
    unconverged.chain(failures).chain(pinned).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use frictionid_models::default_model;

    #[test]
    fn the_dynamic_fits_start_first_and_the_single_parameter_laws_last() {
        let names = ["coulomb", "viscous_coulomb", "stribeck", "dahl", "lugre"];
        let models: Vec<Box<dyn FrictionModel>> = names
            .iter()
            .map(|n| default_model(n).expect("a registered model"))
            .collect();
        let order: Vec<&str> = heaviest_first(&models)
            .into_iter()
            .map(|i| names[i])
            .collect();
        assert_eq!(
            order,
            ["lugre", "dahl", "stribeck", "viscous_coulomb", "coulomb"]
        );
    }
}
