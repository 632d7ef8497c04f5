//! The rigid-contact limit's test: the model's rigid limit fitted to the same records, and
//! whether they reject it (otherwise the contact stiffness is at most a lower bound).

use super::Standing;
use crate::identify::assessment::stats::chi_square_95;
use crate::identify::problem::least_squares::FitProblem;
use crate::identify::problem::residuals::Residuals;
use crate::identify::search::starts::StartRun;
use crate::identify::search::strategy::{
    fit_simpler, stage_options, FitTarget, Onto, SimplerFit, SimplerStarts,
};
use crate::identify::values::fit_options::FitOptions;
use crate::identify::values::layout::ParamKind;
use crate::identify::values::result::Identifiability;
use frictionid_models::start::TYPICAL_PRESLIDING_DISPLACEMENT;
use frictionid_models::{FrictionModel, StartContext, StribeckLevels};
use nalgebra::DVector;

/// The rigid-contact limit of the fitted model (`InternalStates::rigid_limit`) fitted to the
/// same records. The records resolve the contact's stiffness only when they reject the limit:
/// a likelihood-ratio test of the nested limit law, whose cost must lie more than
/// chi²(d, 95 %) / 2 residual variances above the best, d the parameters the limit removes.
/// Otherwise the stiffness's upper side is open (it is at most a lower bound).
pub(super) struct Limit {
    /// The slots of the stiffnesses in the layout (the first drives the approach).
    slots: Vec<usize>,
    /// The slots of the parameters that act only through presliding.
    presliding: Vec<usize>,
    /// The limit law's best cost.
    pub(super) cost: f64,
    /// The free parameters the limit removes (at least 1).
    removed: usize,
    /// The fitted limit law.
    law: Box<dyn FrictionModel>,
}

/// Decades of contact stiffness the target steps through on its way to a rigid limit that
/// fits clearly better than the fit's optimum (from a tenth of the typical presliding
/// displacement down; a step clipped at the stiffness's bound ends it).
pub const LIMIT_APPROACH_DECADES: i32 = 10;

impl Limit {
    /// The profiles of a limit the records do not reject: every stiffness (its lower side);
    /// and, when the limit's cost is within `within` (the best cost plus one parameter's 95 %
    /// rise), none of the presliding-only parameters, which are not identifiable: every value
    /// of one reaches the limit's cost as the stiffnesses grow.
    pub(super) fn plan_profiles(
        &self,
        within: f64,
        slots: &mut Vec<usize>,
        standings: &mut [Standing],
    ) {
        for &j in &self.slots {
            if !slots.contains(&j) {
                slots.push(j);
            }
        }
        if self.cost <= within {
            for &j in &self.presliding {
                standings[j] = Standing {
                    class: Identifiability::NotIdentifiable,
                    bound: None,
                };
            }
            slots.retain(|j| !self.presliding.contains(j));
        }
    }

    /// Whether slot `j` is one of the limit's stiffnesses.
    pub(super) fn is_stiffness(&self, j: usize) -> bool {
        self.slots.contains(&j)
    }

    /// Whether slot `j` is the limit's first stiffness, whose profile steps are re-optimised
    /// from two starts with more iterations (the others, e.g. GMS's further elements, are
    /// profiled as ordinary parameters with their upper side open).
    pub(super) fn is_first_stiffness(&self, j: usize) -> bool {
        self.slots.first() == Some(&j)
    }

    /// The cost rise that rejects the limit, in units of the one-parameter rise
    /// [`PROFILE_DELTA`]: chi²(d) / chi²(1).
    pub(super) fn rise_factor(&self) -> f64 {
        rise_factor(self.removed)
    }

    /// The target started from the fitted limit law at the presliding displacement of `ctx`
    /// (internal coordinates; the parameters that are not the model's where `best` has them).
    fn start_of_target<R: Residuals>(
        &self,
        reference: &FitProblem<R>,
        best: &StartRun,
        ctx: &StartContext,
    ) -> Option<DVector<f64>> {
        let at_best = reference.physical(&best.u);
        let onto = Onto {
            model: reference.model.as_ref(),
            params: &reference.layout,
            base: &at_best,
            keep: &[],
        };
        let p = onto.started_from(self.law.as_ref(), ctx)?;
        Some(reference.internal(&p))
    }

    /// The target mapped from the limit law with the stiffness in `slot` at the internal
    /// value `u` (the others at the same physical stiffness; internal coordinates); `None`
    /// when the law has no Coulomb level or the mapping fails.
    pub(super) fn target_at_stiffness<R: Residuals>(
        &self,
        reference: &FitProblem<R>,
        best: &StartRun,
        (slot, u): (usize, f64),
    ) -> Option<DVector<f64>> {
        let osc = &reference.oscillator;
        let level = StribeckLevels::from_model(self.law.as_ref())?.mu_c * osc.normal_force;
        let stiffness = reference.layout[slot].to_physical(u);
        let ctx = StartContext {
            presliding_displacement: level / stiffness,
            ..StartContext::new(osc.normal_force, osc.mass)
        };
        let mut at = self.start_of_target(reference, best, &ctx)?;
        at[slot] = u;
        Some(at)
    }

    /// The way from the fit's optimum to a limit that fits better by more than `delta`: the
    /// target mapped from the limit law at stiffnesses a decade apart; the first point whose
    /// cost is within `delta` of the limit's, else the lowest one.
    pub(super) fn approach<R: Residuals>(
        &self,
        reference: &FitProblem<R>,
        best: &StartRun,
        delta: f64,
    ) -> Option<DVector<f64>> {
        let osc = &reference.oscillator;
        let mut lowest: Option<(f64, DVector<f64>)> = None;
        let mut previous: Option<DVector<f64>> = None;
        for k in 1..=LIMIT_APPROACH_DECADES {
            let ctx = StartContext {
                presliding_displacement: TYPICAL_PRESLIDING_DISPLACEMENT * 10f64.powi(-k),
                ..StartContext::new(osc.normal_force, osc.mass)
            };
            let u = self.start_of_target(reference, best, &ctx)?;
            if previous.as_ref() == Some(&u) {
                break;
            }
            let cost = reference
                .residuals_at(&reference.physical(&u))
                .ok()
                .map(|r| 0.5 * r.norm_squared())
                .filter(|c| c.is_finite());
            if let Some(c) = cost {
                if c <= self.cost + delta {
                    return Some(u);
                }
                if lowest.as_ref().is_none_or(|(l, _)| c < *l) {
                    lowest = Some((c, u.clone()));
                }
            }
            previous = Some(u);
        }
        lowest.map(|(_, u)| u)
    }
}

/// How far above the rejection threshold (in units of it) a rigid limit's first fit may end
/// and still be refitted from more starts: there, a local run stopped short of the limit
/// law's optimum would decide the verdict.
pub const NARROW_REJECTION: f64 = 2.0;

/// The model's rigid limit fitted to the records (from its own guess, or from `stage` when
/// the staged search fitted the same law from it, and from the fit's best mapped onto it),
/// when the model declares one and a stiffness of it is free; `None` otherwise or when the
/// limit cannot be fitted. A limit the records reject by less than [`NARROW_REJECTION`]
/// times the threshold is fitted again from the local starts a fit of the limit law takes
/// around its guess, the lower optimum kept: the test compares the fit with the limit law's
/// optimum, and one local run ending in a shallow minimum would reject a limit the records
/// allow.
pub(super) fn rigid_limit<R: Residuals + 'static>(
    reference: &FitProblem<R>,
    best: &StartRun,
    opts: &FitOptions,
    stage: Option<&SimplerFit>,
) -> Option<Limit> {
    let declared = reference.model.states()?.rigid_limit()?;
    let slots_of = |indices: &[usize]| -> Vec<usize> {
        (0..reference.layout.len())
            .filter(|&j| matches!(reference.layout[j].kind, ParamKind::Model(i) if indices.contains(&i)))
            .collect()
    };
    let slots = slots_of(&declared.stiffnesses);
    if slots.is_empty() {
        return None;
    }
    let fitted = reference.realise(&reference.physical(&best.u)).ok()?.model;
    let osc = &reference.oscillator;
    let ctx = StartContext::new(osc.normal_force, osc.mass);
    let on = FitTarget {
        residuals: &reference.residuals,
        osc,
        records: &reference.records,
    };
    let mut limit_opts = stage_options(opts);
    limit_opts.params.oscillator = opts.params.oscillator.clone();
    limit_opts.params.free = limit_free(declared.law.as_ref(), &declared.also_free);
    let law = declared.law.as_ref();
    let first = SimplerStarts {
        also_from: &[(fitted.as_ref(), ctx)],
        fitted: stage,
        spread: None,
    };
    let mut fit = fit_simpler(&on, law, &limit_opts, first)?;
    let removed = reference.layout.len().saturating_sub(fit.free).max(1);
    let threshold = rejection_rise(reference, best, removed);
    if fit.cost > best.cost + threshold && fit.cost <= best.cost + NARROW_REJECTION * threshold {
        let again = SimplerStarts {
            also_from: &[],
            fitted: Some(&fit),
            spread: Some(&opts.search),
        };
        if let Some(lower) = fit_simpler(&on, law, &limit_opts, again).filter(|f| f.cost < fit.cost)
        {
            fit = lower;
        }
    }
    Some(Limit {
        slots,
        presliding: slots_of(&declared.presliding),
        cost: fit.cost,
        removed,
        law: fit.model,
    })
}

/// The cost rise over `best` that rejects a limit removing `removed` free parameters:
/// chi²(removed, 95 %) / 2 residual variances, the variance the residuals at `best` leave
/// over their degrees of freedom.
fn rejection_rise<R: Residuals>(reference: &FitProblem<R>, best: &StartRun, removed: usize) -> f64 {
    let dof = reference
        .n_residuals()
        .saturating_sub(reference.layout.len())
        .max(1);
    let variance = 2.0 * best.cost / dof as f64;
    0.5 * chi_square_95(removed) * variance
}

/// chi²(removed, 95 %) / chi²(1, 95 %): the rise that rejects a limit removing `removed`
/// free parameters, in units of one parameter's.
fn rise_factor(removed: usize) -> f64 {
    chi_square_95(removed) / chi_square_95(1)
}

/// The free parameters of a limit law: its defaults and `also_free`; `None` (the defaults)
/// when there is nothing to add.
fn limit_free(law: &dyn FrictionModel, also_free: &[&str]) -> Option<Vec<String>> {
    if also_free.is_empty() {
        return None;
    }
    let free = law
        .param_info()
        .into_iter()
        .filter(|p| !p.fixed_by_default || also_free.contains(&p.name.as_str()))
        .map(|p| p.name)
        .collect();
    Some(free)
}
