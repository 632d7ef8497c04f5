//! Nesting: a law that holds a static law with fewer parameters as a limit (it can be
//! started exactly, or for a law with presliding states nearly, at the static law's
//! optimum: `Staging::start_from`) must end at least as low. A law that ends above a law it holds is refitted from that law's
//! optimum; if it still ends above, its search failed and it is not ranked on that cost.

use super::super::assessment::property_refits::refit_options;
use super::super::fit::fit;
use crate::identify::values::fit_options::FitOptions;
use crate::identify::values::result::FitResult;
use crate::oscillator::Oscillator;
use crate::record::Record;
use frictionid_models::StartContext;
use frictionid_models::{clone_model, FrictionModel};

/// How far (relative RMS) a static law may end above a law it holds: rounding only.
const STATIC_SLACK: f64 = 1e-3;
/// How far a law with presliding states may end above a law it holds: its presliding
/// transients change the force the limit law reaches exactly.
const DYNAMIC_SLACK: f64 = 0.05;

/// A law whose search ended above a law it holds.
#[derive(Debug, Clone)]
pub struct NestingFailure {
    /// The law.
    pub model: String,
    /// Why it is not ranked.
    pub reason: String,
}

/// Checks every fit of `fits` against the simpler fits it holds, refits those that end
/// above from the simpler law's optimum (keeping the better fit), and takes out those that
/// still end above.
pub fn enforce_nesting(
    fits: Vec<FitResult>,
    osc: &Oscillator,
    records: &[Record],
    opts: &FitOptions,
) -> (Vec<FitResult>, Vec<NestingFailure>) {
    let snapshot: Vec<(String, usize, f64, Box<dyn FrictionModel>)> = fits
        .iter()
        .map(|f| {
            (
                f.model.clone(),
                model_free(f),
                f.rms_residual,
                f.fitted_model.clone(),
            )
        })
        .collect();
    let mut kept = Vec::new();
    let mut failed = Vec::new();
    for mut f in fits {
        let held: Vec<&(String, usize, f64, Box<dyn FrictionModel>)> = snapshot
            .iter()
            .filter(|(name, free, _, sub)| {
                *name != f.model
                    && *free < model_free(&f)
                    && sub.n_states() == 0
                    && holds(&f, sub.as_ref(), osc)
            })
            .collect();
        let slack = if f.fitted_model.n_states() > 0 {
            DYNAMIC_SLACK
        } else {
            STATIC_SLACK
        };
        let mut verdict = None;
        for (name, _, rms, sub) in held {
            let limit = rms * (1.0 + slack) + f64::EPSILON * rms.abs();
            if f.rms_residual <= limit {
                continue;
            }
            if let Some(better) = refit_from(&f, sub.as_ref(), osc, records, opts) {
                if better.rms_residual < f.rms_residual {
                    f = better;
                }
            }
            if f.rms_residual > limit {
                verdict = Some(format!(
                    "its search ended at RMS {:.4e} {}, above `{name}`'s {:.4e}, a law it holds as a limit, even when started from that law's optimum: the search failed, so it is not ranked",
                    f.rms_residual, f.residual_unit, rms
                ));
                break;
            }
        }
        match verdict {
            Some(reason) => failed.push(NestingFailure {
                model: f.model.clone(),
                reason,
            }),
            None => kept.push(f),
        }
    }
    (kept, failed)
}

/// The free model parameters of a fit (the oscillator's and the records' are common to all).
fn model_free(f: &FitResult) -> usize {
    let names: Vec<String> = f
        .fitted_model
        .param_info()
        .into_iter()
        .map(|p| p.name)
        .collect();
    f.parameters
        .iter()
        .filter(|p| p.free && names.contains(&p.name))
        .count()
}

/// Whether `fit`'s law can start at `sub`'s optimum.
fn holds(fit: &FitResult, sub: &dyn FrictionModel, osc: &Oscillator) -> bool {
    started_from(fit.fitted_model.as_ref(), sub, osc).is_some()
}

/// `model` started at `sub`'s optimum (`None` when it cannot be).
fn started_from(
    model: &(dyn FrictionModel + 'static),
    sub: &dyn FrictionModel,
    osc: &Oscillator,
) -> Option<Box<dyn FrictionModel>> {
    let mut m = clone_model(model);
    let ctx = StartContext::new(osc.normal_force, osc.mass);
    let staging = m.staging()?;
    staging.start_from(sub, &ctx).then_some(m)
}

/// `fit`'s law refitted from `sub`'s optimum (one local start; `None` when it fails).
fn refit_from(
    f: &FitResult,
    sub: &dyn FrictionModel,
    osc: &Oscillator,
    records: &[Record],
    opts: &FitOptions,
) -> Option<FitResult> {
    let start = started_from(f.fitted_model.as_ref(), sub, osc)?;
    let names: Vec<String> = start.param_info().into_iter().map(|p| p.name).collect();
    let mut o = refit_options(opts, start.as_ref());
    o.params = o.params.for_model(&names);
    o.params.guess = false;
    o.search.prefit = false;
    fit(osc, start.as_ref(), records, &o).ok()
}
