//! Search strategies of a fit (`[fit.options] search`): where the starts of the multi-start
//! Levenberg-Marquardt come from.
//!
//! - `local`: the data-driven guess and points spread around it ([`super::starts`]).
//! - `staged`: first the static laws along the model hierarchy (coulomb, then stribeck when
//!   the target has Stribeck levels), each one start, one run; their optima are mapped onto
//!   the target through `Staging::start_from` under the normal force the records' levels are
//!   fitted under (presliding stiffness from the presliding displacement the records show
//!   when they measure the friction force along the motion, [`super::presliding`], else from
//!   the typical one and a tenth of it), the stage's other fitted values (a force offset)
//!   carried over, and start the target alongside the local starts.
//! - `global`: the staged starts, plus a seeded Latin hypercube over the physical box in the
//!   solver's (log) coordinates; all are screened and the best few refined.
//!
//! A velocity fit seeded by the force-domain prefit ([`super::prefit`]) has its optimum as
//! one more start, the last ([`plan_fit_starts`]).

use super::free_params::{build_layout, Layout};
use super::prefit::PREFIT_ORIGIN;
use super::presliding::{presliding_displacement, record_travels};
use super::starts::{fit_starting_points, run_starts, start_count};
use crate::identify::problem::least_squares::{FitProblem, ProblemParts};
use crate::identify::problem::residuals::Residuals;
use crate::identify::values::fit_options::FitOptions;
use crate::identify::values::layout::{FreeParam, ParamKind};
use crate::identify::values::levels::FrictionLevels;
use crate::identify::values::param_options::ParamOptions;
use crate::identify::values::search::{fits_directly, Search, SearchOptions};
use crate::oscillator::Oscillator;
use crate::record::Record;
use frictionid_models::start::TYPICAL_PRESLIDING_DISPLACEMENT;
use frictionid_models::{clone_model, Coulomb, FrictionModel, StartContext, Stribeck};
use std::sync::Arc;

/// Latin-hypercube starts a `global` search adds.
pub(crate) const GLOBAL_STARTS: usize = 12;

/// Half-width of the global box around the start, as a factor (log coordinates).
pub(crate) const GLOBAL_SPAN: f64 = 100.0;

/// Seed of the global search's Latin hypercube (runs are reproducible).
pub(crate) const GLOBAL_SEED: u64 = 0x5eed_0014;

/// Presliding displacements (multiples of the typical one) that map the last stage onto
/// the target when the records do not show their own ([`super::presliding`]): the typical
/// one and a stiffer contact.
pub(crate) const STAGED_PRESLIDING: [f64; 2] = [1.0, 0.1];

/// The presliding displacement (a multiple of the typical one) of the compliant start a law
/// with several elements (several stiffnesses, as GMS) takes after [`STAGED_PRESLIDING`]'s:
/// elements stiff enough to saturate within a sample leave the force all but independent of
/// their stiffnesses (the rigid limit's plateau, where the search cannot soften them), while
/// from the compliant side it stiffens them.
pub(crate) const COMPLIANT_PRESLIDING: f64 = 10.0;

/// A starting point and where it came from.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Seeded {
    /// Physical values of the free parameters.
    pub point: Vec<f64>,
    /// `data-driven guess`, `spread around the guess`, `staged from coulomb`, ...
    pub origin: String,
}

/// What the starts of a fit need to know.
pub(crate) struct StartPlan<'a, R: Residuals> {
    /// The residuals of the fit (the stages use them too).
    pub residuals: &'a Arc<R>,
    /// The oscillator.
    pub osc: &'a Oscillator,
    /// The model as configured.
    pub model: &'a (dyn FrictionModel + 'static),
    /// The records.
    pub records: &'a [Record],
    /// The target's layout.
    pub layout: &'a Layout,
    /// The fit's options.
    pub opts: &'a FitOptions,
}

/// Every start of a fit: the starts of `search` ([`plan_starts`]) and, last (where the
/// prefit finding looks for it), the prefit's optimum when there is one.
pub(crate) fn plan_fit_starts<R: Residuals + 'static>(
    plan: &StartPlan<'_, R>,
    search: Search,
    n_starts: usize,
    prefit: Option<&dyn FrictionModel>,
) -> Planned {
    let mut planned = plan_starts(plan, search, n_starts);
    if let Some(prefit) = prefit {
        planned.seeded.push(Seeded {
            point: seeded_point(plan.layout, prefit),
            origin: PREFIT_ORIGIN.into(),
        });
    }
    planned
}

/// The layout's starting point with the free model parameters at `seeded`'s values (clipped
/// to their bounds).
fn seeded_point(layout: &Layout, seeded: &dyn FrictionModel) -> Vec<f64> {
    let values = seeded.params();
    layout
        .params
        .iter()
        .zip(&layout.start)
        .map(|(f, &x)| match f.kind {
            ParamKind::Model(i) => values.get(i).copied().unwrap_or(x).clamp(f.lower, f.upper),
            _ => x,
        })
        .collect()
}

/// Every starting point of `search`: staged ones first, then the local ones, then (global)
/// the Latin hypercube; duplicates dropped; with the cost of the target's nested limit law
/// when a stage fitted it.
pub(crate) fn plan_starts<R: Residuals + 'static>(
    plan: &StartPlan<'_, R>,
    search: Search,
    n_local: usize,
) -> Planned {
    let mut out = Vec::new();
    let mut limit_stage = None;
    if search != Search::Local {
        let mut fitted = stages(plan);
        out.extend(staged_points(plan, &fitted));
        limit_stage = nested_limit(plan.model, &mut fitted);
    }
    let local = fit_starting_points(
        &plan.layout.params,
        &plan.layout.start,
        plan.model,
        &plan.opts.params,
        n_local,
    );
    for (i, point) in local.into_iter().enumerate() {
        let origin = if i == 0 {
            "data-driven guess"
        } else {
            "spread around the guess"
        };
        out.push(Seeded {
            point,
            origin: origin.into(),
        });
    }
    if search == Search::Global {
        out.extend(global_points(plan.layout, GLOBAL_STARTS, GLOBAL_SEED));
    }
    let mut unique: Vec<Seeded> = Vec::with_capacity(out.len());
    for s in out {
        if !unique.iter().any(|u| u.point == s.point) {
            unique.push(s);
        }
    }
    Planned {
        seeded: unique,
        reachable: limit_stage.as_ref().map(|f| f.cost),
        limit_stage,
    }
}

/// The starts of a fit and what the stages found.
pub(crate) struct Planned {
    /// Every starting point, staged ones first.
    pub seeded: Vec<Seeded>,
    /// The cost of the stage that is the target's rigid limit (`InternalStates::rigid_limit`):
    /// the target reaches it as its stiffness grows, so a screened start left far above it
    /// is abandoned.
    pub reachable: Option<f64>,
    /// That stage's fit, which starts the fit of the rigid limit in the assessment (in place
    /// of the guess it was itself fitted from).
    pub limit_stage: Option<SimplerFit>,
}

/// The fitted stage that is `model`'s rigid-limit law, if any (taken out of `fitted`).
fn nested_limit(model: &dyn FrictionModel, fitted: &mut Vec<SimplerFit>) -> Option<SimplerFit> {
    let law = model.states()?.rigid_limit()?.law;
    let at = fitted.iter().position(|f| f.model.name() == law.name())?;
    Some(fitted.swap_remove(at))
}

/// Whether a model has Stribeck levels (a static and a Coulomb level and a Stribeck
/// velocity), so that a Stribeck fit can start it.
fn has_stribeck_levels(model: &dyn FrictionModel) -> bool {
    let names: Vec<String> = model.param_info().into_iter().map(|p| p.name).collect();
    ["mu_s", "v_s"].iter().all(|n| names.iter().any(|m| m == n))
}

/// The stages below the target: coulomb, then stribeck (each only when it is not the target
/// itself), each fitted from its data-driven guess; most refined last.
fn stages<R: Residuals + 'static>(plan: &StartPlan<'_, R>) -> Vec<SimplerFit> {
    let target = plan.layout.start_model.name();
    let mut out = Vec::new();
    if target != "coulomb" {
        out.extend(stage_fit(plan, &Coulomb::default()));
    }
    if target != "stribeck" && has_stribeck_levels(plan.layout.start_model.as_ref()) {
        out.extend(stage_fit(plan, &Stribeck::default()));
    }
    out
}

/// The options of a stage: one start, one local run, the model's own parameters and
/// bounds, the oscillator fixed, no uncertainty budget, no progress.
pub(crate) fn stage_options(opts: &FitOptions) -> FitOptions {
    FitOptions {
        params: opts.params.for_simpler_law(),
        search: opts.search.one_start(true),
        uncertainty: Default::default(),
        hooks: opts.hooks.quiet(),
        ..opts.clone()
    }
}

/// Fits `stage` (one start, one run); `None` when it fails (the target then starts from its
/// other starts).
fn stage_fit<R: Residuals + 'static>(
    plan: &StartPlan<'_, R>,
    stage: &(dyn FrictionModel + 'static),
) -> Option<SimplerFit> {
    let on = FitTarget {
        residuals: plan.residuals,
        osc: plan.osc,
        records: &plan.records.into(),
    };
    let starts = SimplerStarts {
        also_from: &[],
        fitted: None,
        spread: None,
    };
    fit_simpler(&on, stage, &stage_options(plan.opts), starts)
}

/// The records a simpler law is fitted to, with the fit's residuals and oscillator.
pub(crate) struct FitTarget<'a, R: Residuals> {
    /// The residuals of the fit.
    pub residuals: &'a Arc<R>,
    /// The oscillator.
    pub osc: &'a Oscillator,
    /// The records.
    pub records: &'a Arc<[Record]>,
}

/// A simpler law fitted to the records of a fit.
pub(crate) struct SimplerFit {
    /// The fitted law.
    pub model: Box<dyn FrictionModel>,
    /// Its cost (half the sum of squared residuals, as the fit's).
    pub cost: f64,
    /// Its free parameters (the model's and the others alike).
    pub free: usize,
    /// Their names, in the layout's order.
    pub free_names: Vec<String>,
    /// Their fitted values (physical), in the same order.
    pub values: Vec<f64>,
}

impl SimplerFit {
    /// Whether this is a fit of `law` over the free parameters `layout` lays out.
    fn fits_the_same(&self, law: &dyn FrictionModel, layout: &Layout) -> bool {
        self.model.name() == law.name()
            && self.free_names.len() == layout.params.len()
            && self
                .free_names
                .iter()
                .zip(&layout.params)
                .all(|(n, f)| *n == f.name)
    }

    /// `point` (of the free parameters `params`) with every parameter that is not the
    /// model's and that this fit also fitted (a record's force or velocity offset, release
    /// shift or x0, an oscillator property) at its fitted value, clipped to its bounds. The
    /// stage fitted them to the same records through the same residuals, and the target
    /// nests the stage (its rigid limit, or a law whose levels it maps): the target starts
    /// where the records put them, not at their blind start (an offset at 0, which a step
    /// cap scaled to its typical size lets grow only threefold per iteration).
    fn carried(&self, params: &[FreeParam], point: Vec<f64>) -> Vec<f64> {
        params
            .iter()
            .zip(point)
            .map(|(f, x)| match f.kind {
                ParamKind::Model(_) => x,
                _ => self
                    .free_names
                    .iter()
                    .position(|n| *n == f.name)
                    .and_then(|i| self.values.get(i))
                    .filter(|v| v.is_finite())
                    .map_or(x, |&v| f.clip(v)),
            })
            .collect()
    }
}

/// Where the local runs of a simpler law's fit start.
#[derive(Clone, Copy)]
pub(crate) struct SimplerStarts<'a> {
    /// Models mapped onto the law by `start_from`, each a start.
    pub also_from: &'a [(&'a dyn FrictionModel, StartContext)],
    /// An earlier fit of the same law over the same free parameters (e.g. a stage of the
    /// staged search, itself one run from the guess), whose optimum starts in place of the
    /// guess.
    pub fitted: Option<&'a SimplerFit>,
    /// The search whose local starts around the guess (as many as a fit of the law under
    /// it takes) are started too; `None`: the guess (or `fitted`) alone.
    pub spread: Option<&'a SearchOptions>,
}

/// Fits `law` with `opts` (local runs from `starts`, every one to its end, the best kept);
/// `None` when it fails.
pub(crate) fn fit_simpler<R: Residuals + 'static>(
    on: &FitTarget<'_, R>,
    law: &(dyn FrictionModel + 'static),
    opts: &FitOptions,
    starts: SimplerStarts<'_>,
) -> Option<SimplerFit> {
    let layout = build_layout(
        on.osc,
        law,
        on.records,
        on.residuals.as_ref(),
        &opts.params,
        &opts.energy,
    )
    .ok()?;
    if layout.params.is_empty() {
        return None;
    }
    let make = || {
        FitProblem::new(
            on.residuals.clone(),
            ProblemParts {
                oscillator: *on.osc,
                model: layout.start_model.clone(),
                records: on.records.clone(),
                layout: layout.params.clone(),
                sim: opts.sim,
                parallel: opts.hooks.parallel,
            },
        )
        .with_loss(opts.search.robust_loss())
    };
    let first = match starts.fitted.filter(|f| f.fits_the_same(law, &layout)) {
        Some(f) => {
            let seeded = seeded_point(&layout, f.model.as_ref());
            layout.projected(&f.carried(&layout.params, seeded))
        }
        None => layout.start.clone(),
    };
    let mut points = vec![first];
    let n_spread = starts.spread.map_or(1, |search| {
        let direct = fits_directly(law, on.residuals.simulates_response());
        start_count(search, layout.n_model_free(), direct).unwrap_or(1)
    });
    if n_spread > 1 {
        let around =
            fit_starting_points(&layout.params, &layout.start, law, &opts.params, n_spread);
        for point in around.into_iter().skip(1).map(|p| layout.projected(&p)) {
            if !points.contains(&point) {
                points.push(point);
            }
        }
    }
    for (from, ctx) in starts.also_from {
        points.extend(
            mapped_point(&layout, *from, ctx, &opts.params).filter(|p| !points.contains(p)),
        );
    }
    let reference = make();
    let (search, hooks) = (&opts.search, &opts.hooks);
    // The spread starts are screened as a staged search's are; the others all run to the end.
    let promoted = match starts.spread {
        Some(_) => Search::Staged.promoted(),
        None => points.len(),
    };
    let runs = run_starts(make, &reference, &points, search, hooks, promoted, None).ok()?;
    let p = reference.physical(&runs.best.u);
    let model = reference.realise(&p).ok()?.model;
    Some(SimplerFit {
        model,
        cost: runs.best.cost,
        free: layout.params.len(),
        free_names: layout.params.iter().map(|f| f.name.clone()).collect(),
        values: p,
    })
}

/// The staged starting points: each stage mapped onto the target under the normal force the
/// records' levels are fitted under (the last, most refined stage at the presliding
/// displacement the records show when they measure the friction force along the motion,
/// else at every presliding scale of [`STAGED_PRESLIDING`]; a law with several elements at
/// [`COMPLIANT_PRESLIDING`] too), with the parameters the stage fitted besides its law's
/// (a force offset) at the stage's values ([`SimplerFit::carried`]).
fn staged_points<R: Residuals + 'static>(
    plan: &StartPlan<'_, R>,
    fitted: &[SimplerFit],
) -> Vec<Seeded> {
    let base = StartContext::new(fitted_normal_force(plan), plan.osc.mass);
    let at = |scale: f64| StartContext {
        presliding_displacement: scale * TYPICAL_PRESLIDING_DISPLACEMENT,
        ..base
    };
    let mut last: Vec<StartContext> = match measured_presliding(plan) {
        Some(d) => vec![StartContext {
            presliding_displacement: d,
            ..base
        }],
        None => STAGED_PRESLIDING.iter().map(|&s| at(s)).collect(),
    };
    if has_several_elements(plan.model) {
        last.push(StartContext {
            normal_force: fitted_normal_force(plan),
            ..at(COMPLIANT_PRESLIDING)
        });
    }
    let mut out = Vec::new();
    for (k, stage) in fitted.iter().enumerate().rev() {
        let contexts = if k + 1 == fitted.len() {
            &last[..]
        } else {
            &last[..1]
        };
        for ctx in contexts {
            if let Some(point) =
                mapped_point(plan.layout, stage.model.as_ref(), ctx, &plan.opts.params)
            {
                out.push(Seeded {
                    point: stage.carried(&plan.layout.params, point),
                    origin: format!("staged from {}", stage.model.name()),
                });
            }
        }
    }
    out
}

/// The presliding displacement the records show ([`super::presliding`]) when the fit compares
/// a measured friction force along their displacement; `None` otherwise, or when they show
/// none.
fn measured_presliding<R: Residuals>(plan: &StartPlan<'_, R>) -> Option<f64> {
    let mut travels = Vec::new();
    for (i, record) in plan.records.iter().enumerate() {
        if plan.residuals.measures_friction(i) {
            let axes = plan.residuals.sample_axes(i, record);
            let force = plan.residuals.measured(i, record);
            travels.extend(record_travels(&axes.displacement, force));
        }
    }
    presliding_displacement(travels)
}

/// Whether `model` has several elements (several stiffnesses that run to its rigid limit).
fn has_several_elements(model: &dyn FrictionModel) -> bool {
    model
        .states()
        .and_then(|s| s.rigid_limit())
        .is_some_and(|limit| limit.stiffnesses.len() > 1)
}

/// The normal force the records' levels are fitted under, their mean
/// ([`FrictionLevels::mean_normal_force`]: 1 N when the levels are read as forces, else each
/// record's own or the oscillator's), or the oscillator's where that gives none.
fn fitted_normal_force<R: Residuals>(plan: &StartPlan<'_, R>) -> f64 {
    let unknown = &plan.opts.target.unknown_oscillator;
    FrictionLevels::mean_normal_force(plan.records, plan.osc, unknown)
        .filter(|mean| mean.is_finite() && *mean > 0.0)
        .unwrap_or(plan.osc.normal_force)
}

/// The target started from a fitted simpler model (`start_from`), as a point of the layout:
/// free model parameters take the mapped values (except those kept at their initial value),
/// everything else its start. `None` when the target cannot start from it.
fn mapped_point(
    layout: &Layout,
    fitted: &dyn FrictionModel,
    ctx: &StartContext,
    params: &ParamOptions,
) -> Option<Vec<f64>> {
    let onto = Onto {
        model: layout.start_model.as_ref(),
        params: &layout.params,
        base: &layout.start,
        keep: &params.keep_initial,
    };
    onto.started_from(fitted, ctx)
}

/// A model and the free parameters of a fit, onto which a fitted model is mapped.
pub(crate) struct Onto<'a> {
    /// The model whose `start_from` maps.
    pub model: &'a (dyn FrictionModel + 'static),
    /// The free parameters (the layout).
    pub params: &'a [FreeParam],
    /// Physical values of every free parameter where the mapping gives none.
    pub base: &'a [f64],
    /// Free model parameters that keep their `base` value.
    pub keep: &'a [String],
}

impl Onto<'_> {
    /// The physical point of the model started from `fitted` at `ctx`: free model parameters
    /// take the mapped values (clipped to their bounds; a non-finite one, or one in `keep`,
    /// its base value), the others their base values. `None` when the model cannot start
    /// from `fitted`.
    pub(crate) fn started_from(
        &self,
        fitted: &dyn FrictionModel,
        ctx: &StartContext,
    ) -> Option<Vec<f64>> {
        let mut started = clone_model(self.model);
        if !started.staging().is_some_and(|s| s.start_from(fitted, ctx)) {
            return None;
        }
        let values = started.params();
        let point = self
            .params
            .iter()
            .zip(self.base)
            .map(|(f, &x)| match f.kind {
                ParamKind::Model(i) if !self.keep.contains(&f.name) => values
                    .get(i)
                    .copied()
                    .filter(|v| v.is_finite())
                    .map_or(x, |v| f.clip(v)),
                _ => x,
            })
            .collect();
        Some(point)
    }
}

/// A small seeded generator (SplitMix64) for the Latin hypercube.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `n` points of a Latin hypercube in [0, 1)^d: each coordinate has exactly one point in
/// each of its `n` strata.
pub(crate) fn latin_hypercube(n: usize, d: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = SplitMix64(seed);
    let columns: Vec<Vec<f64>> = (0..d)
        .map(|_| {
            let mut strata: Vec<usize> = (0..n).collect();
            for i in (1..n).rev() {
                let j = (rng.next_u64() % (i as u64 + 1)) as usize;
                strata.swap(i, j);
            }
            strata
                .iter()
                .map(|&k| (k as f64 + rng.unit()) / n as f64)
                .collect()
        })
        .collect();
    (0..n)
        .map(|i| columns.iter().map(|c| c[i]).collect())
        .collect()
}

/// The value at fraction `q` of a free parameter's global box: a factor [`GLOBAL_SPAN`]
/// either side of its start in log coordinates (a positive parameter), else three scales
/// either side; within its bounds.
fn in_box(f: &FreeParam, x0: f64, q: f64) -> f64 {
    if x0 > 0.0 && f.lower >= 0.0 {
        let c = x0.ln();
        let w = GLOBAL_SPAN.ln();
        let lo = if f.lower > 0.0 { f.lower.ln() } else { c - w };
        let hi = if f.upper.is_finite() {
            f.upper.ln()
        } else {
            c + w
        };
        let (a, b) = ((c - w).max(lo), (c + w).min(hi));
        f.clip((a + q * (b - a)).exp())
    } else {
        let u0 = f.to_internal(x0);
        let (lo, hi) = f.internal_bounds();
        let (a, b) = ((u0 - 3.0).max(lo), (u0 + 3.0).min(hi));
        f.clip(f.to_physical(a + q * (b - a)))
    }
}

/// `n` Latin-hypercube starts over the free model parameters' global box (the others at
/// their start).
fn global_points(layout: &Layout, n: usize, seed: u64) -> Vec<Seeded> {
    let slots: Vec<usize> = (0..layout.params.len())
        .filter(|&s| matches!(layout.params[s].kind, ParamKind::Model(_)))
        .collect();
    latin_hypercube(n, slots.len(), seed)
        .into_iter()
        .map(|q| {
            let mut point = layout.start.clone();
            for (&s, &qs) in slots.iter().zip(&q) {
                point[s] = in_box(&layout.params[s], layout.start[s], qs);
            }
            Seeded {
                point,
                origin: "latin hypercube".into(),
            }
        })
        .collect()
}

#[cfg(test)]
/// A damper's stroke (Dahl, alpha 1, sigma0 4e5 N/m, level 50 N, 0.2 N noise) read by a
/// load cell whose zero is off by `offset` N, and the force-domain options of a Dahl fit
/// with that offset free, the levels read as forces (no normal force given).
pub(crate) fn offset_stroke(offset: f64) -> (Record, Oscillator, FitOptions) {
    use crate::identify::values::target_options::{FitDomain, TargetOptions};
    use crate::record::Channel;
    let stroke = crate::testing::DamperStroke::short().record(4000);
    let force: Vec<f64> = stroke.channel(Channel::Force).unwrap().to_vec();
    let record = stroke.with_channel(Channel::Force, force.iter().map(|f| f + offset).collect());
    let (osc, unknown) = crate::oscillator::PartialOscillator::default().resolve();
    let mut opts = FitOptions {
        target: TargetOptions {
            domain: FitDomain::Force,
            force_offset: true,
            unknown_oscillator: unknown,
            ..TargetOptions::default()
        },
        ..FitOptions::default()
    };
    opts.params.free = Some(vec!["sigma0".into(), "mu_c".into()]);
    (record, osc, opts)
}

#[cfg(test)]
/// The force-domain problem of the law `truth` along `records` under `opts` (a fresh one
/// per call: a solver run takes its problem), with the layout started at `truth`: the
/// problem and the start (physical values).
pub(crate) fn law_force_problem(
    records: &Arc<[Record]>,
    osc: Oscillator,
    opts: &FitOptions,
    truth: &(dyn FrictionModel + 'static),
) -> (
    FitProblem<crate::identify::problem::force_along_motion::ForceAlongMotion>,
    Vec<f64>,
) {
    use crate::identify::problem::force_along_motion::ForceAlongMotion;
    let residuals = Arc::new(ForceAlongMotion::new(records, &osc, opts).unwrap());
    let layout = build_layout(
        &osc,
        truth,
        records,
        residuals.as_ref(),
        &opts.params,
        &opts.energy,
    )
    .unwrap();
    let problem = FitProblem::new(
        residuals,
        ProblemParts {
            oscillator: osc,
            model: layout.start_model.clone(),
            records: records.clone(),
            layout: layout.params.clone(),
            sim: opts.sim,
            parallel: false,
        },
    );
    (problem, layout.start)
}

#[cfg(test)]
mod tests {
    use super::*;
    use frictionid_models::LuGre;

    /// A layout of `names`, all free model parameters of Stribeck's law.
    fn stribeck_layout(names: &[&str]) -> Layout {
        let params = names
            .iter()
            .enumerate()
            .map(|(i, n)| {
                FreeParam::linear((*n).into(), "", ParamKind::Model(i), (0.0, 10.0), 0.1, 1.0)
            })
            .collect::<Vec<_>>();
        Layout {
            start_model: Box::new(Stribeck::default()),
            start: vec![0.1; params.len()],
            params,
            levels: Default::default(),
        }
    }

    fn stage(model: Box<dyn FrictionModel>, names: &[&str]) -> SimplerFit {
        SimplerFit {
            model,
            cost: 1.0,
            free: names.len(),
            free_names: names.iter().map(|n| n.to_string()).collect(),
            values: vec![1.0; names.len()],
        }
    }

    #[test]
    fn a_stage_starts_the_limit_fit_only_for_the_same_law_and_free_parameters() {
        let names = ["mu_c", "mu_s", "v_s", "viscous"];
        let layout = stribeck_layout(&names);
        let same = stage(Box::new(Stribeck::default()), &names);
        assert!(same.fits_the_same(&Stribeck::default(), &layout));
        // Another law, fewer or other free parameters: the limit starts from its guess.
        let coulomb = stage(Box::new(Coulomb::default()), &names);
        assert!(!coulomb.fits_the_same(&Stribeck::default(), &layout));
        let fewer = stage(Box::new(Stribeck::default()), &names[..3]);
        assert!(!fewer.fits_the_same(&Stribeck::default(), &layout));
        let other = stage(
            Box::new(Stribeck::default()),
            &["mu_c", "mu_s", "v_s", "delta"],
        );
        assert!(!other.fits_the_same(&Stribeck::default(), &layout));
    }

    /// The staged start of Dahl along a measured stroke: the Coulomb stage mapped at the
    /// presliding displacement the stroke shows, ln 3 F_c / sigma0 for Dahl's closed form
    /// (one start in place of the typical displacement and a tenth of it), under the unit
    /// normal force of levels read as forces, with the stage's offset. Against the truth:
    /// the start's level over its stiffness is that displacement, and its offset the load
    /// cell's.
    #[test]
    fn a_measured_stroke_stages_dahl_at_the_presliding_it_shows() {
        staged_dahl_at_the_presliding_it_shows(None);
    }

    /// The same stroke with its own normal force (a channel of 5 N): the levels are
    /// coefficients of it, and the staged start's stiffness is its level times the records'
    /// normal force over the presliding displacement (the oscillator's normal force, not
    /// given, played no part).
    #[test]
    fn a_stroke_with_its_own_normal_force_stages_dahl_under_its_mean() {
        staged_dahl_at_the_presliding_it_shows(Some(5.0));
    }

    /// The staged Dahl start along [`offset_stroke`] (with a normal-force channel of mean
    /// `normal` when given), checked against the closed form ln 3 F_c / sigma0.
    fn staged_dahl_at_the_presliding_it_shows(normal: Option<f64>) {
        use crate::identify::problem::force_along_motion::ForceAlongMotion;
        use crate::record::Channel;
        let (mut record, osc, opts) = offset_stroke(3.0);
        if let Some(n) = normal {
            let samples = record.len();
            record = record.with_channel(Channel::NormalForce, vec![n; samples]);
        }
        let records = [record];
        let residuals = Arc::new(ForceAlongMotion::new(&records, &osc, &opts).unwrap());
        let model = frictionid_models::Dahl::default();
        let layout = build_layout(
            &osc,
            &model,
            &records,
            residuals.as_ref(),
            &opts.params,
            &opts.energy,
        )
        .unwrap();
        let plan = StartPlan {
            residuals: &residuals,
            osc: &osc,
            model: &model,
            records: &records,
            layout: &layout,
            opts: &opts,
        };
        let planned = plan_starts(&plan, Search::Staged, 1);
        let staged: Vec<&Seeded> = planned
            .seeded
            .iter()
            .filter(|s| s.origin == "staged from coulomb")
            .collect();
        assert_eq!(staged.len(), 1, "{:?}", planned.seeded);
        let value = |name: &str| {
            let at = layout.params.iter().position(|f| f.name == name).unwrap();
            staged[0].point[at]
        };
        let level = value("mu_c") * normal.unwrap_or(1.0);
        let presliding = level / value("sigma0");
        let exact = 3f64.ln() * 50.0 / 4e5;
        assert!(
            (presliding / exact - 1.0).abs() < 0.03,
            "{presliding} {exact}"
        );
        let offset = value("force_offset[stroke]");
        assert!((offset - 3.0).abs() < 0.1, "offset {offset}");
    }

    #[test]
    fn a_latin_hypercube_fills_every_stratum_once() {
        let n = 9;
        let cube = latin_hypercube(n, 4, 7);
        assert_eq!(cube.len(), n);
        for d in 0..4 {
            let mut strata: Vec<usize> = cube.iter().map(|p| (p[d] * n as f64) as usize).collect();
            strata.sort_unstable();
            assert_eq!(strata, (0..n).collect::<Vec<_>>());
        }
        assert_eq!(cube, latin_hypercube(n, 4, 7));
        assert_ne!(cube, latin_hypercube(n, 4, 8));
    }

    #[test]
    fn dynamic_or_wide_models_search_staged_and_coulomb_locally() {
        let lugre = LuGre::default();
        let stribeck = Stribeck::default();
        for simulated in [true, false] {
            assert_eq!(Search::resolve(None, &lugre, 6, simulated), Search::Staged);
            let coulomb = Search::resolve(None, &Coulomb::default(), 1, simulated);
            assert_eq!(coulomb, Search::Local);
            let asked = Some(Search::Global);
            let global = Search::resolve(asked, &Coulomb::default(), 1, simulated);
            assert_eq!(global, Search::Global);
        }
        assert_eq!(Search::resolve(None, &stribeck, 4, true), Search::Staged);
        // Along the measured motion a static law's evaluations are cheap: a wide one searches
        // globally (the Stribeck velocity's plateaus trap a single start).
        assert_eq!(Search::resolve(None, &stribeck, 4, false), Search::Global);
        let viscous_coulomb = frictionid_models::ViscousCoulomb::default();
        assert_eq!(
            Search::resolve(None, &viscous_coulomb, 2, false),
            Search::Local
        );
    }

    #[test]
    fn only_laws_with_several_elements_start_compliant_too() {
        let gms = frictionid_models::Gms::default();
        let one_element = frictionid_models::Gms::with_elements(1);
        assert!(has_several_elements(&gms));
        for law in [
            &one_element as &dyn FrictionModel,
            &LuGre::default(),
            &frictionid_models::Dahl::default(),
            &Stribeck::default(),
        ] {
            assert!(!has_several_elements(law), "{}", law.name());
        }
    }

    #[test]
    fn the_global_box_spans_two_decades_either_side_within_the_bounds() {
        let f = FreeParam {
            log: true,
            ..FreeParam::linear("s".into(), "N/m", ParamKind::Model(0), (0.0, 1e6), 1e5, 1.0)
        };
        assert!((in_box(&f, 1e5, 0.0) / 1e3 - 1.0).abs() < 1e-12);
        assert!((in_box(&f, 1e5, 1.0) / 1e6 - 1.0).abs() < 1e-12);
    }
}
