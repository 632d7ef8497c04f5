//! Nesting: a law that holds a static law with fewer parameters as a limit (it can be
//! started at the static law's optimum, `Staging::start_from`, and there has the same
//! steady-state force at every speed) must end at least as low. A law that ends above a law
//! it holds is refitted from that law's optimum, at presliding displacements ever shorter
//! ([`REFIT_PRESLIDING`]: a law with presliding states then starts ever nearer its rigid
//! limit, the static law's cost); if it still ends above, its search failed and it is not
//! ranked on that cost. A law whose steady state cannot take the static law's (Dahl has no
//! viscous term to take viscous_coulomb's) does not hold it, and is ranked on its own cost.

use super::super::assessment::property_refits::refit_options;
use super::super::fit::fit;
use crate::identify::values::fit_options::FitOptions;
use crate::identify::values::levels::UNIT_NORMAL_FORCE;
use crate::identify::values::result::FitResult;
use crate::oscillator::Oscillator;
use crate::record::Record;
use frictionid_models::start::TYPICAL_PRESLIDING_DISPLACEMENT;
use frictionid_models::StartContext;
use frictionid_models::{clone_model, FrictionModel};

/// How far (relative RMS) a static law may end above a law it holds: rounding only.
const STATIC_SLACK: f64 = 1e-3;
/// How far a law with presliding states may end above a law it holds: its presliding
/// transients change the force the limit law reaches exactly.
const DYNAMIC_SLACK: f64 = 0.05;
/// The presliding displacements (multiples of the typical one) a law that ends above a law
/// it holds is refitted from, in turn, until it ends at least as low.
const REFIT_PRESLIDING: [f64; 3] = [1.0, 1e-2, 1e-4];
/// Speeds (multiples of the records' largest) at which a held law's steady-state force must
/// be the holder's started at it.
const STEADY_SPEEDS: [f64; 6] = [1e-4, 1e-3, 1e-2, 0.1, 0.5, 1.0];
/// How far (relative to the held law's largest force there) the steady states may differ.
const STEADY_TOLERANCE: f64 = 1e-6;
/// A law whose search ended above a law it holds.
#[derive(Debug, Clone)]
pub(super) struct NestingFailure {
    /// The law.
    pub model: String,
    /// Why it is not ranked.
    pub reason: String,
}

/// Checks every fit of `fits` against the simpler fits it holds, refits those that end
/// above from the simpler law's optimum (keeping the better fit), and takes out those that
/// still end above.
pub(super) fn enforce_nesting(
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
                    && holds(&f, sub.as_ref(), osc, top_speed(records))
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
            let aim = rms * (1.0 + STATIC_SLACK) + f64::EPSILON * rms.abs();
            if f.rms_residual > aim {
                f = refit_down_to(f, sub.as_ref(), aim, (osc, records, opts));
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

/// `f` refitted from `sub`'s optimum at each presliding displacement of [`REFIT_PRESLIDING`]
/// in turn (the better fit kept) until it ends at `aim` or below.
fn refit_down_to(
    mut f: FitResult,
    sub: &dyn FrictionModel,
    aim: f64,
    (osc, records, opts): (&Oscillator, &[Record], &FitOptions),
) -> FitResult {
    for scale in REFIT_PRESLIDING {
        let at = context(osc, scale);
        let refit = refit_from(&f, sub, (osc, &at), records, opts);
        if let Some(better) = refit.filter(|b| b.rms_residual < f.rms_residual) {
            f = better;
        }
        if f.rms_residual <= aim {
            break;
        }
    }
    f
}

/// The start context on `osc` at `scale` times the typical presliding displacement.
fn context(osc: &Oscillator, scale: f64) -> StartContext {
    StartContext {
        presliding_displacement: scale * TYPICAL_PRESLIDING_DISPLACEMENT,
        ..StartContext::new(osc.normal_force, osc.mass)
    }
}

/// The largest speed of the records' velocity channels (1 where none has one).
fn top_speed(records: &[Record]) -> f64 {
    let top = records
        .iter()
        .flat_map(|r| r.velocity().iter())
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    if top.is_finite() && top > 0.0 {
        top
    } else {
        1.0
    }
}

/// Whether `fit`'s law holds `sub`: it can start at `sub`'s optimum, and there its
/// steady-state force is `sub`'s at every speed of [`STEADY_SPEEDS`] (times `speed`), both
/// directions.
fn holds(fit: &FitResult, sub: &dyn FrictionModel, osc: &Oscillator, speed: f64) -> bool {
    let ctx = context(osc, 1.0);
    let Some(started) = started_from(fit.fitted_model.as_ref(), sub, &ctx) else {
        return false;
    };
    let n = nesting_normal_force(fit, osc);
    let speeds: Vec<f64> = STEADY_SPEEDS
        .iter()
        .flat_map(|s| [s * speed, -s * speed])
        .collect();
    let scale = speeds
        .iter()
        .fold(0.0_f64, |m, &v| m.max(sub.steady_state(v, n).abs()));
    // A held law with no force at any of these speeds tells nothing about the holder.
    scale > 0.0
        && speeds.iter().all(|&v| {
            let gap = (started.steady_state(v, n) - sub.steady_state(v, n)).abs();
            gap <= STEADY_TOLERANCE * scale
        })
}

/// The normal force the steady states are compared under: the fit's or the oscillator's,
/// else (no normal force given: the levels are forces) [`UNIT_NORMAL_FORCE`]. Under N = 0
/// every law's force vanishes and any law would seem to hold any other.
fn nesting_normal_force(fit: &FitResult, osc: &Oscillator) -> f64 {
    [fit.oscillator.normal_force, osc.normal_force]
        .into_iter()
        .find(|n| n.is_finite() && *n > 0.0)
        .unwrap_or(UNIT_NORMAL_FORCE)
}

/// `model` started at `sub`'s optimum in `ctx` (`None` when it cannot be).
fn started_from(
    model: &(dyn FrictionModel + 'static),
    sub: &dyn FrictionModel,
    ctx: &StartContext,
) -> Option<Box<dyn FrictionModel>> {
    let mut m = clone_model(model);
    let staging = m.staging()?;
    staging.start_from(sub, ctx).then_some(m)
}

/// `fit`'s law refitted from `sub`'s optimum in `ctx` (one local start; `None` when it
/// fails).
fn refit_from(
    f: &FitResult,
    sub: &dyn FrictionModel,
    (osc, ctx): (&Oscillator, &StartContext),
    records: &[Record],
    opts: &FitOptions,
) -> Option<FitResult> {
    let start = started_from(f.fitted_model.as_ref(), sub, ctx)?;
    let names: Vec<String> = start.param_info().into_iter().map(|p| p.name).collect();
    let mut o = refit_options(opts, start.as_ref());
    o.params = o.params.for_model(&names);
    o.params.guess = false;
    // One local run from the start itself: a staged search would race it against its stages
    // and report their optimum instead.
    o.search = o.search.one_start(true);
    o.search.prefit = false;
    fit(osc, start.as_ref(), records, &o).ok()
}
