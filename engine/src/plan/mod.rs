//! Experiment design: which records to take next to pin a friction law's parameters down.
//!
//! Given the law's assumed values (or a previous fit's), the oscillator, a list of candidate
//! experiments ([`Experiment`]: release, normal force, sample rate, duration, noise, the
//! input of a driven axis) and the records already taken, [`plan`] predicts each free
//! parameter's standard error from the Fisher information of each candidate's simulated
//! record at the assumed point ([`information`]: the velocity fit's own residual Jacobian,
//! J^T W J with the noise level and its correlation), chooses the set of records that
//! minimises the criterion on the named parameters ([`design`]: D or A optimality, an
//! exhaustive or greedy search) and says which parameters no candidate brings within reach,
//! with the smallest change along the candidates' dimensions that would ([`reach`]).
//!
//! Values in, values out: the report and its writers are [`crate::report`]'s.

pub mod design;
pub mod experiment;
pub mod information;
pub mod reach;
pub mod rigid;

pub use design::{Choice, Criterion, SearchKind};
pub use experiment::{Experiment, ExperimentInput, Multisine};
pub use information::{Assumed, RecordInformation, Shared};
pub use reach::{Change, Dimension, OutOfReach, RigidEvidence};

use crate::error::EngineError;
use crate::record::Record;
use nalgebra::DMatrix;
use rayon::prelude::*;
use thiserror::Error;

/// The relative standard error above which a parameter is out of reach when not told.
pub const DEFAULT_REACH: f64 = 0.5;

/// Why a plan cannot be made.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum PlanError {
    /// No candidates.
    #[error("[plan]: no candidates")]
    NoCandidates,
    /// More records asked for than candidates.
    #[error("[plan]: choose = {choose}, but there are {candidates} candidates (list one twice to take it twice)")]
    ChooseTooMany {
        /// Records asked for.
        choose: usize,
        /// Candidates given.
        candidates: usize,
    },
    /// A setting out of its range.
    #[error("[plan]: {0}")]
    Invalid(String),
    /// A candidate cannot be simulated or differentiated.
    #[error("[plan]: candidate {index} (`{name}`): {reason}")]
    Candidate {
        /// Its 0-based index.
        index: usize,
        /// Its name.
        name: String,
        /// Why.
        reason: String,
    },
    /// A record already taken cannot be used.
    #[error("[plan]: record `{record}`: {reason}")]
    Taken {
        /// Its name.
        record: String,
        /// Why.
        reason: String,
    },
    /// The fit would free nothing.
    #[error("[plan]: the fit frees no parameter of the law or the oscillator")]
    NothingFree,
    /// A named parameter is not free.
    #[error("[plan]: parameters: `{name}` is not a free parameter{hint}; free: {free}")]
    UnknownParameter {
        /// The name given.
        name: String,
        /// "(did you mean ...)".
        hint: String,
        /// The free parameters.
        free: String,
    },
}

/// The noise of the planned records.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noise {
    /// Standard deviation of the velocity noise \[m/s\] (a candidate's own wins).
    pub velocity: Option<f64>,
    /// Lag-one correlation of the noise, in [0, 1).
    pub correlation: f64,
}

/// What a plan is made from.
pub struct PlanRequest<'a> {
    /// The assumed point and what a fit frees.
    pub assumed: Assumed<'a>,
    /// The candidate experiments.
    pub candidates: Vec<Experiment>,
    /// The records already taken (their information counts in every set).
    pub taken: Vec<Record>,
    /// The parameters whose standard errors the design minimises; `None`: every free one.
    pub targets: Option<Vec<String>>,
    /// How many records to take.
    pub choose: usize,
    /// The criterion.
    pub criterion: Criterion,
    /// The noise.
    pub noise: Noise,
    /// The relative standard error above which a parameter is out of reach.
    pub reach: f64,
    /// Whether to look for the smallest change that reaches an out-of-reach parameter
    /// (simulates the changed experiments).
    pub suggest: bool,
}

/// One free parameter of the plan.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedParam {
    /// Its name.
    pub name: String,
    /// Its unit.
    pub unit: String,
    /// Its assumed value.
    pub value: f64,
    /// Whether the design minimises its standard error.
    pub target: bool,
}

/// One candidate's prediction.
#[derive(Debug, Clone, PartialEq)]
pub struct CandidatePrediction {
    /// The experiment.
    pub experiment: Experiment,
    /// The velocity noise it was planned with \[m/s\].
    pub velocity_noise: f64,
    /// Each parameter's predicted standard error from this record and those already taken
    /// (`None`: not identifiable), in the plan's parameter order.
    pub predicted_std: Vec<Option<f64>>,
}

/// The plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The free parameters (law, then oscillator).
    pub parameters: Vec<PlannedParam>,
    /// Every candidate with its prediction.
    pub candidates: Vec<CandidatePrediction>,
    /// The recommended set (candidate indices).
    pub recommended: Vec<usize>,
    /// Each parameter's predicted standard error from the recommended set and the records
    /// already taken.
    pub predicted_std: Vec<Option<f64>>,
    /// From the records already taken alone (`None` when there are none).
    pub taken_std: Option<Vec<Option<f64>>>,
    /// The names of the records already taken.
    pub taken: Vec<String>,
    /// The criterion.
    pub criterion: Criterion,
    /// How the set was found.
    pub search: SearchKind,
    /// Sets evaluated.
    pub evaluated: usize,
    /// The reach.
    pub reach: f64,
    /// The noise's lag-one correlation.
    pub correlation: f64,
    /// The parameters out of reach.
    pub out_of_reach: Vec<OutOfReach>,
}

impl Plan {
    /// The relative standard error of parameter `i` in `std` (`None`: unbounded).
    pub fn relative(&self, std: &[Option<f64>], i: usize) -> Option<f64> {
        relative_of(std, &self.parameters, i)
    }
}

fn relative_of(std: &[Option<f64>], params: &[PlannedParam], i: usize) -> Option<f64> {
    let s = std.get(i).copied().flatten()?;
    let v = params.get(i)?.value.abs();
    Some(if v > 0.0 { s / v } else { s })
}

/// Makes the plan.
pub fn plan(request: &PlanRequest<'_>) -> Result<Plan, PlanError> {
    check(request)?;
    let infos = candidate_informations(request, &request.candidates)?;
    let shared = infos[0].shared.clone();
    let taken = taken_information(request, &shared)?;
    let targets = target_indices(&shared, request.targets.as_deref())?;
    let matrices: Vec<DMatrix<f64>> = infos.into_iter().map(|i| i.matrix).collect();
    let base = taken.clone().unwrap_or_else(|| zeros(&shared));
    let values = shared.values.clone();
    let score = |f: &DMatrix<f64>| design::criterion_value(request.criterion, f, &values, &targets);
    let choice = design::choose(&matrices, &base, request.choose, &score);
    let set_info = sum_of(&base, &matrices, &choice.indices);
    let parameters = planned_params(&shared, &targets);
    let candidates = request
        .candidates
        .iter()
        .zip(&matrices)
        .map(|(e, m)| CandidatePrediction {
            experiment: e.clone(),
            velocity_noise: sigma_of(request, e).unwrap_or(f64::NAN),
            predicted_std: design::predicted_std(&(&base + m), &values),
        })
        .collect();
    let all = (0..matrices.len()).collect::<Vec<_>>();
    let all_std = design::predicted_std(&sum_of(&base, &matrices, &all), &values);
    let mut out = Plan {
        predicted_std: design::predicted_std(&set_info, &values),
        taken_std: taken.as_ref().map(|t| design::predicted_std(t, &values)),
        taken: request.taken.iter().map(|r| r.name.clone()).collect(),
        parameters,
        candidates,
        recommended: choice.indices,
        criterion: request.criterion,
        search: choice.search,
        evaluated: choice.evaluated,
        reach: request.reach,
        correlation: request.noise.correlation,
        out_of_reach: Vec::new(),
    };
    out.out_of_reach = out_of_reach(request, &out, &all_std, &base)?;
    Ok(out)
}

/// The request's settings in range.
fn check(request: &PlanRequest<'_>) -> Result<(), PlanError> {
    let n = request.candidates.len();
    if n == 0 {
        return Err(PlanError::NoCandidates);
    }
    if request.choose == 0 || request.choose > n {
        return Err(PlanError::ChooseTooMany {
            choose: request.choose,
            candidates: n,
        });
    }
    let rho = request.noise.correlation;
    if !(0.0..1.0).contains(&rho) {
        return Err(PlanError::Invalid(format!(
            "noise_correlation = {rho} must be in [0, 1)"
        )));
    }
    if !(request.reach.is_finite() && request.reach > 0.0) {
        return Err(PlanError::Invalid(format!(
            "reach = {} must be > 0",
            request.reach
        )));
    }
    if let Some(s) = request.noise.velocity {
        if !(s.is_finite() && s > 0.0) {
            return Err(PlanError::Invalid(format!(
                "velocity_noise = {s} must be > 0"
            )));
        }
    }
    for (index, e) in request.candidates.iter().enumerate() {
        let fail = |reason: String| PlanError::Candidate {
            index,
            name: e.name.clone(),
            reason,
        };
        e.validate().map_err(fail)?;
        sigma_of(request, e).ok_or_else(|| {
            fail("no velocity noise: give [plan] velocity_noise, noise_record or the candidate's own".into())
        })?;
    }
    Ok(())
}

/// The velocity noise a candidate is planned with.
fn sigma_of(request: &PlanRequest<'_>, e: &Experiment) -> Option<f64> {
    e.velocity_noise.or(request.noise.velocity)
}

/// Each experiment's information, in parallel.
fn candidate_informations(
    request: &PlanRequest<'_>,
    experiments: &[Experiment],
) -> Result<Vec<RecordInformation>, PlanError> {
    let one = |(index, e): (usize, &Experiment)| {
        information_of(request, e).map_err(|err| PlanError::Candidate {
            index,
            name: e.name.clone(),
            reason: err.to_string(),
        })
    };
    let infos = experiments
        .par_iter()
        .enumerate()
        .map(one)
        .collect::<Result<Vec<_>, _>>()?;
    if infos.first().is_none_or(|i| i.shared.params.is_empty()) {
        return Err(PlanError::NothingFree);
    }
    Ok(infos)
}

/// One experiment's information.
fn information_of(
    request: &PlanRequest<'_>,
    e: &Experiment,
) -> Result<RecordInformation, EngineError> {
    let assumed = &request.assumed;
    let sigma = sigma_of(request, e).unwrap_or(f64::NAN);
    let record = e.record(&assumed.oscillator, assumed.model, &assumed.sim, sigma)?;
    information::record_information(assumed, record, request.noise.correlation)
}

/// The records already taken: their summed information, `None` when there are none.
fn taken_information(
    request: &PlanRequest<'_>,
    shared: &Shared,
) -> Result<Option<DMatrix<f64>>, PlanError> {
    let mut sum: Option<DMatrix<f64>> = None;
    for record in &request.taken {
        let fail = |reason: String| PlanError::Taken {
            record: record.name.clone(),
            reason,
        };
        let info = information::record_information(
            &request.assumed,
            record.clone(),
            request.noise.correlation,
        )
        .map_err(|e| fail(e.to_string()))?;
        if info.shared.params.len() != shared.params.len() {
            return Err(fail(
                "its free parameters differ from the candidates'".into(),
            ));
        }
        sum = Some(match sum {
            Some(s) => s + info.matrix,
            None => info.matrix,
        });
    }
    Ok(sum)
}

/// The indices of the named parameters (every one when none are named).
fn target_indices(shared: &Shared, names: Option<&[String]>) -> Result<Vec<usize>, PlanError> {
    let free: Vec<&str> = shared.params.iter().map(|p| p.name.as_str()).collect();
    let Some(names) = names.filter(|n| !n.is_empty()) else {
        return Ok((0..free.len()).collect());
    };
    names
        .iter()
        .map(|name| {
            free.iter()
                .position(|f| f == name)
                .ok_or_else(|| PlanError::UnknownParameter {
                    name: name.clone(),
                    hint: frictionid_models::suggest::did_you_mean(name, free.iter().copied()),
                    free: free.join(", "),
                })
        })
        .collect()
}

fn zeros(shared: &Shared) -> DMatrix<f64> {
    let n = shared.params.len();
    DMatrix::zeros(n, n)
}

fn sum_of(base: &DMatrix<f64>, each: &[DMatrix<f64>], set: &[usize]) -> DMatrix<f64> {
    set.iter().fold(base.clone(), |acc, &i| acc + &each[i])
}

fn planned_params(shared: &Shared, targets: &[usize]) -> Vec<PlannedParam> {
    shared
        .params
        .iter()
        .zip(&shared.values)
        .enumerate()
        .map(|(i, (p, &value))| PlannedParam {
            name: p.name.clone(),
            unit: p.unit.clone(),
            value,
            target: targets.contains(&i),
        })
        .collect()
}

/// The parameters above the reach with the recommended records, and for each the smallest
/// change that reaches it (when the request asks to look).
fn out_of_reach(
    request: &PlanRequest<'_>,
    plan: &Plan,
    all_std: &[Option<f64>],
    base: &DMatrix<f64>,
) -> Result<Vec<OutOfReach>, PlanError> {
    let reach = request.reach;
    let beyond = |r: Option<f64>| r.is_none_or(|r| r > reach);
    let mut found: Vec<(usize, OutOfReach)> = (0..plan.parameters.len())
        .filter(|&i| beyond(plan.relative(&plan.predicted_std, i)))
        .map(|i| {
            (
                i,
                OutOfReach {
                    parameter: plan.parameters[i].name.clone(),
                    relative_std: plan.relative(&plan.predicted_std, i),
                    all_candidates: plan.relative(all_std, i),
                    change: None,
                    alternatives: Vec::new(),
                    rigid_limit: None,
                    message: String::new(),
                },
            )
        })
        .collect();
    add_rigid_limit(request, plan, &mut found)?;
    if request.suggest && !found.is_empty() {
        find_changes(request, plan, base, &mut found);
    }
    Ok(found
        .into_iter()
        .map(|(_, mut o)| {
            o.describe(reach, request.suggest);
            o
        })
        .collect())
}

/// The names of the plan's parameters.
fn names(plan: &Plan) -> Vec<String> {
    plan.parameters.iter().map(|p| p.name.clone()).collect()
}

/// The records of `experiments`, noise-free, with their planned noise declared.
fn planned_records(request: &PlanRequest<'_>, experiments: &[&Experiment]) -> Option<Vec<Record>> {
    let a = &request.assumed;
    experiments
        .iter()
        .map(|e| {
            let sigma = sigma_of(request, e)?;
            e.record(&a.oscillator, a.model, &a.sim, sigma).ok()
        })
        .collect()
}

/// The records already taken and those of `experiments`: whether they would reject the
/// law's rigid limit ([`rigid::separation`]); `None` when the law has none.
fn separation_of(
    request: &PlanRequest<'_>,
    plan: &Plan,
    experiments: &[&Experiment],
) -> Option<rigid::Separation> {
    let mut records = request.taken.clone();
    records.extend(planned_records(request, experiments)?);
    rigid::separation(&request.assumed, &records, &names(plan))
}

/// Marks the contact stiffnesses the recommended records would not tell from a rigid
/// contact (adding them to `found` when their linearised error is within reach).
fn add_rigid_limit(
    request: &PlanRequest<'_>,
    plan: &Plan,
    found: &mut Vec<(usize, OutOfReach)>,
) -> Result<(), PlanError> {
    let chosen: Vec<&Experiment> = plan
        .recommended
        .iter()
        .map(|&i| &request.candidates[i])
        .collect();
    let Some(sep) = separation_of(request, plan, &chosen) else {
        return Ok(());
    };
    if sep.rejects() {
        return Ok(());
    }
    let evidence = RigidEvidence {
        limit: sep.limit.clone(),
        chi2: sep.chi2,
        threshold: sep.threshold,
        needed: sep.needed,
    };
    for name in &sep.stiffnesses {
        let Some(i) = plan.parameters.iter().position(|p| &p.name == name) else {
            continue;
        };
        match found.iter_mut().find(|(j, _)| *j == i) {
            Some((_, o)) => o.rigid_limit = Some(evidence.clone()),
            None => found.push((
                i,
                OutOfReach {
                    parameter: name.clone(),
                    relative_std: plan.relative(&plan.predicted_std, i),
                    all_candidates: None,
                    change: None,
                    alternatives: Vec::new(),
                    rigid_limit: Some(evidence.clone()),
                    message: String::new(),
                },
            )),
        }
    }
    found.sort_by_key(|(i, _)| *i);
    Ok(())
}

/// Walks the ladder of changes on the recommended records until each parameter in `found`
/// has, along every dimension the records have, the smallest change that reaches it (or the
/// ladder ends): the first found is the smallest overall, the others its alternatives. A
/// changed experiment that cannot be simulated is a rung skipped.
fn find_changes(
    request: &PlanRequest<'_>,
    plan: &Plan,
    base: &DMatrix<f64>,
    found: &mut [(usize, OutOfReach)],
) {
    let normal = request.assumed.oscillator.normal_force;
    let chosen: Vec<&Experiment> = plan
        .recommended
        .iter()
        .map(|&i| &request.candidates[i])
        .collect();
    let values: Vec<f64> = plan.parameters.iter().map(|p| p.value).collect();
    for &(dimension, factor) in &reach::LADDER {
        if found.iter().all(|(_, o)| o.has_change_along(dimension)) {
            continue;
        }
        let changed: Option<Vec<Experiment>> = chosen
            .iter()
            .map(|e| dimension.scaled(e, factor, normal))
            .collect();
        let Some(changed) = changed else { continue };
        if changed.iter().any(|e| e.validate().is_err()) {
            continue;
        }
        let Ok(infos) = candidate_informations(request, &changed) else {
            continue;
        };
        let total = infos.iter().fold(base.clone(), |acc, i| acc + &i.matrix);
        let std = design::predicted_std(&total, &values);
        let mut rejects: Option<bool> = None;
        for (i, o) in found
            .iter_mut()
            .filter(|(_, o)| !o.has_change_along(dimension))
        {
            let Some(r) = relative_of(&std, &plan.parameters, *i) else {
                continue;
            };
            if r > request.reach {
                continue;
            }
            if o.rigid_limit.is_some() {
                let refs: Vec<&Experiment> = changed.iter().collect();
                let sep = *rejects.get_or_insert_with(|| {
                    separation_of(request, plan, &refs).is_none_or(|s| s.rejects())
                });
                if !sep {
                    continue;
                }
            }
            o.add_change(Change {
                dimension,
                factor,
                from: chosen
                    .iter()
                    .filter_map(|e| dimension.value(e, normal))
                    .collect(),
                to: changed
                    .iter()
                    .filter_map(|e| dimension.value(e, normal))
                    .collect(),
                relative_std: r,
            });
        }
    }
}
