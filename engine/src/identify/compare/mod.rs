//! Fitting several models to the same records, ranking them, scoring each on data its fit
//! did not see ([`validation`]), holding nested laws to their sub-laws' optimum
//! ([`nesting`]) and naming the law to use ([`verdict`]).

mod nesting;
pub(crate) mod validation;
pub(crate) mod verdict;

pub use validation::{LawValidation, ValidationScheme};
pub use verdict::SetAside;

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
pub(crate) const INDISTINGUISHABLE_DELTA_AIC: f64 = 2.0;

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
    /// How the held-out validation split the records (`None` when they were too short).
    pub validation_scheme: Option<ValidationScheme>,
    /// Each ranked law's held-out score, in ranking order.
    pub validation: Vec<LawValidation>,
    /// Wall time of the held-out validation [s] (part of `wall_time_s`).
    pub validation_wall_time_s: f64,
    /// Wall time of the whole comparison [s].
    pub wall_time_s: f64,
}

/// The verdict of a comparison: the law to use (`recommended`), the laws set aside and why,
/// and the information criteria's view (the best model by AIC, those it cannot tell from
/// it, and the simplest of these: fewest free parameters, then lowest AIC).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComparisonVerdict {
    /// The law to use: the simplest whose held-out error is within the folds' noise of the
    /// best held-out error, with nothing set against it (`None` when every law is set aside).
    pub recommended: Option<String>,
    /// The law with the lowest held-out error.
    pub best_validated: Option<String>,
    /// Laws not recommended, and why.
    pub set_aside: Vec<SetAside>,
    /// Why the information criteria are shown only as information.
    pub information_criteria: String,
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
    let (mut ranking, nested) = nesting::enforce_nesting(ranking, osc, records, opts);
    failed.extend(nested.into_iter().map(|n| FailedFit {
        model: n.model,
        error: n.reason,
    }));
    ranking.sort_by(|a, b| a.aic.total_cmp(&b.aic));
    rank(&mut ranking);
    let validation_clock = std::time::Instant::now();
    let (validation_scheme, validation) =
        match validation::validate(&ranking, records, opts, opts.hooks.parallel) {
            Some((scheme, scores)) => (Some(scheme), scores),
            None => (None, Vec::new()),
        };
    let mut warnings = comparison_warnings(&ranking, &failed);
    warnings.extend(validation.iter().filter_map(|v| {
        v.error.as_ref().map(|e| {
            format!(
                "model `{}` could not be validated on held-out data: {e}",
                v.model
            )
        })
    }));
    Ok(Comparison {
        verdict: verdict(&ranking, &validation),
        ranking,
        failed,
        warnings,
        validation_scheme,
        validation,
        validation_wall_time_s: validation_clock.elapsed().as_secs_f64(),
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

/// The law to use, the laws set aside, and the information criteria's view.
fn verdict(ranking: &[FitResult], validation: &[LawValidation]) -> Option<ComparisonVerdict> {
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
    let set_aside: Vec<SetAside> = ranking
        .iter()
        .filter_map(|f| {
            verdict::set_aside_reason(f).map(|reason| SetAside {
                model: f.model.clone(),
                reason,
            })
        })
        .collect();
    let choice = recommend(ranking, validation, &set_aside, simplest);
    let message = verdict_message(&choice, &set_aside, validation.is_empty());
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
        recommended: choice.recommended.clone(),
        best_validated: choice.best_validated.clone(),
        set_aside,
        information_criteria: verdict::information_note(best),
        best: best.model.clone(),
        indistinguishable: names,
        simplest: simplest.model.clone(),
        message,
    })
}

/// The verdict's choice: the law to use and the best held-out law.
struct Choice {
    recommended: Option<String>,
    best_validated: Option<String>,
    /// Laws within the folds' noise of the best held-out error (the recommended among them).
    within: Vec<String>,
    /// A better held-out law that was set aside.
    better_set_aside: Option<String>,
}

/// The simplest law with nothing against it whose held-out error is within the folds' noise
/// of the best (without validation: the simplest of the AIC-indistinguishable laws with
/// nothing against it, else the best such law by AIC).
fn recommend(
    ranking: &[FitResult],
    validation: &[LawValidation],
    set_aside: &[SetAside],
    simplest: &FitResult,
) -> Choice {
    let clean = |f: &FitResult| !set_aside.iter().any(|s| s.model == f.model);
    let score = |f: &FitResult| {
        validation
            .iter()
            .find(|v| v.model == f.model && v.validation_rms.is_some())
    };
    let best_validated = ranking
        .iter()
        .filter_map(|f| score(f).map(|v| (f, v)))
        .min_by(|a, b| {
            a.1.validation_rms
                .unwrap_or(f64::INFINITY)
                .total_cmp(&b.1.validation_rms.unwrap_or(f64::INFINITY))
        });
    let Some((top, top_score)) = best_validated else {
        let recommended = if clean(simplest) {
            Some(simplest)
        } else {
            ranking.iter().find(|f| clean(f))
        };
        return Choice {
            recommended: recommended.map(|f| f.model.clone()),
            best_validated: None,
            within: Vec::new(),
            better_set_aside: None,
        };
    };
    let within: Vec<&FitResult> = ranking
        .iter()
        .filter(|f| score(f).is_some_and(|v| verdict::within_noise(v, top_score)))
        .collect();
    let clean_within: Vec<&FitResult> = within.iter().copied().filter(|f| clean(f)).collect();
    let (recommended, better_set_aside) = if clean_within.is_empty() {
        let fallback = ranking
            .iter()
            .filter(|f| clean(f) && score(f).is_some())
            .min_by(|a, b| {
                let r = |f: &FitResult| {
                    score(f)
                        .and_then(|v| v.validation_rms)
                        .unwrap_or(f64::INFINITY)
                };
                r(a).total_cmp(&r(b))
            });
        (fallback, Some(top.model.clone()))
    } else {
        let rms = |f: &FitResult| {
            score(f)
                .and_then(|v| v.validation_rms)
                .unwrap_or(f64::INFINITY)
        };
        let simplest_within = clean_within.into_iter().min_by(|a, b| {
            a.free_parameters
                .cmp(&b.free_parameters)
                .then(rms(a).total_cmp(&rms(b)))
        });
        (simplest_within, None)
    };
    Choice {
        recommended: recommended.map(|f| f.model.clone()),
        best_validated: Some(top.model.clone()),
        within: within.iter().map(|f| f.model.clone()).collect(),
        better_set_aside,
    }
}

/// The verdict's sentence: the law to use first, then why.
fn verdict_message(choice: &Choice, set_aside: &[SetAside], unvalidated: bool) -> String {
    let reasons = |name: &str| {
        set_aside
            .iter()
            .find(|s| s.model == name)
            .map(|s| s.reason.clone())
            .unwrap_or_default()
    };
    let Some(law) = &choice.recommended else {
        let why: Vec<String> = set_aside
            .iter()
            .map(|s| format!("`{}`: {}", s.model, s.reason))
            .collect();
        return format!("no law can be recommended: {}", why.join("; "));
    };
    let mut text = format!("use `{law}`");
    if unvalidated || choice.best_validated.is_none() {
        text.push_str(" (the records were too short to hold data out: chosen by AIC)");
    } else if let Some(better) = &choice.better_set_aside {
        text.push_str(&format!(
            ": `{better}` scores better on held-out data but is set aside ({})",
            reasons(better)
        ));
    } else if choice.within.len() > 1 {
        let others: Vec<String> = choice
            .within
            .iter()
            .filter(|n| *n != law)
            .map(|n| format!("`{n}`"))
            .collect();
        text.push_str(&format!(
            ": the simplest law whose held-out error is within the folds' noise of the best (also within: {})",
            others.join(", ")
        ));
    } else {
        text.push_str(": the lowest held-out error");
    }
    let others: Vec<String> = set_aside
        .iter()
        .filter(|s| Some(&s.model) != choice.better_set_aside.as_ref())
        .map(|s| format!("`{}` is set aside: {}", s.model, s.reason))
        .collect();
    if !others.is_empty() {
        text.push_str(&format!("; {}", others.join("; ")));
    }
    text
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
