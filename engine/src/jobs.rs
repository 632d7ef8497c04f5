//! The commands as library calls: a [`Spec`] and records in, a report value out.
//!
//! Each job is what a front end runs for one command (the CLI's `simulate`, `fit`, `compare`,
//! `energy`); the front end then names the source (`config`), writes plots and files, lists
//! them in the report's `files`, and hands the report to its writers.

use crate::campaign::table::FitSummary;
use crate::campaign::{CampaignRow, CampaignSpec, GroupResult, GroupTask, RowVerdict};
use crate::energy::{
    analyze_record, forces_in, mean_abs_where_defined, model_force_along, percent_difference,
    states_along, EnergyAnalysis, EnergyOptions, MeasuredMotion,
};
use crate::error::EngineError;
use crate::identify::{
    compare, fit, require_mechanics, require_oscillator, Check, Finding, FitResult,
    PropertyUncertainty, Status,
};
use crate::oscillator::Oscillator;
use crate::record::{channel_list, Channel, ConditionSource, NormalForce, Record};
use crate::report::{
    CompareReport, EnergyRecord, EnergyReport, FitReport, GroupReport, InputSeries, SimulateReport,
};
use crate::simulate::{
    require_motion_conditions, simulate_driven, ChannelSeries, Initial, Input, RunInputs,
    SampleGrid, Trajectory,
};
use crate::spec::{Hooks, SimulationSpec, Spec, SpecError};
use crate::synthetic::{add_gaussian_noise, uniform_times};
use frictionid_models::{Coulomb, FrictionModel};
use std::time::Instant;
use thiserror::Error;

/// Why a job could not produce its report.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum JobError {
    /// The spec lacks something the job needs, or is inconsistent.
    #[error(transparent)]
    Spec(#[from] SpecError),
    /// The simulation failed.
    #[error("simulation failed: {0}")]
    Simulation(EngineError),
    /// A record cannot be analysed.
    #[error("record `{record}`: {source}")]
    Record {
        /// The record's name.
        record: String,
        /// Why.
        source: EngineError,
    },
    /// No reference was given and the Coulomb fit that would provide one failed.
    #[error("no [model] or reference_force, and the Coulomb fit for a reference failed: {0}")]
    ReferenceFit(EngineError),
    /// The identifier could not run.
    #[error(transparent)]
    Fit(EngineError),
    /// The plan cannot be made.
    #[error(transparent)]
    Plan(#[from] crate::plan::PlanError),
    /// Every model of a comparison failed; the reasons, one per model.
    #[error("no model could be fitted ({})", .0.join("; "))]
    NothingFitted(Vec<String>),
}

/// Rate of change of the mechanical energy along exact states of `osc`:
/// dE/dt = v (J a + R(q)) = (u - F_0 - c v - F) v (u = 0 in free vibration).
pub fn energy_rate(osc: &Oscillator, x: &[f64], v: &[f64], a: &[f64]) -> Vec<f64> {
    x.iter()
        .zip(v)
        .zip(a)
        .map(|((&x, &v), &a)| v * (osc.mass * a + osc.restoring_force(x)))
        .collect()
}

/// Final displacement and rest time: at rest if the mass stuck for good, else at the end.
fn final_state(traj: &Trajectory) -> (f64, Option<f64>) {
    match &traj.rest {
        Some(r) => (r.displacement, Some(r.time)),
        None => (traj.x.last().copied().unwrap_or(f64::NAN), None),
    }
}

/// The simulate report of a trajectory from `init` (duration and sample rate taken from its
/// sample times; no noise). Shared by [`simulate_job`] and the Python module.
pub fn simulate_report(
    osc: Oscillator,
    model: Box<dyn FrictionModel>,
    init: &Initial,
    traj: Trajectory,
    wall_time_s: f64,
) -> SimulateReport {
    let (final_displacement, rest_time) = final_state(&traj);
    let duration = traj.time.last().copied().unwrap_or(0.0);
    let samples = traj.time.len();
    SimulateReport {
        command: "simulate".into(),
        config: String::new(),
        oscillator: osc,
        model,
        x0: init.x0,
        v0: init.v0,
        duration,
        sample_rate: samples.saturating_sub(1) as f64 / duration,
        samples,
        final_displacement,
        rest_time,
        half_cycles: traj.half_cycles(),
        events: traj.events.clone(),
        stats: traj.stats,
        wall_time_s,
        noise: None,
        seed: None,
        files: Vec::new(),
        energy_rate: energy_rate(&osc, &traj.x, &traj.v, &traj.a),
        trajectory: traj,
        noisy_velocity: None,
        input: None,
    }
}

/// `simulate`: one motion of the spec's model from `[simulation]`, free or driven by the
/// input-force channel of `input` (the record `[simulation] input` names, read by the front
/// end), with a noisy velocity record when the spec asks for noise.
pub fn simulate_job(spec: &Spec, input: Option<&Record>) -> Result<SimulateReport, JobError> {
    let model = &spec.require_model("simulate")?.model;
    require_oscillator(&spec.unknown_oscillator, spec.oscillator.axis, "simulate")
        .map_err(JobError::Fit)?;
    let sim: &SimulationSpec = spec.require_simulation("simulate")?;
    let times = uniform_times(sim.duration, sim.sample_rate);
    let init = Initial {
        x0: sim.x0,
        v0: sim.v0,
        z0: sim.z0.clone(),
    };
    let osc = &spec.oscillator;
    let channels = input
        .map(|record| ChannelSeries::of_record(record, model.as_ref(), record_start(record)))
        .transpose()
        .map_err(JobError::Simulation)?
        .flatten();
    // A record that only carries the channels a law reads (a temperature beside a free
    // vibration) drives nothing.
    let drives =
        |record: &&Record| record.channel(Channel::InputForce).is_some() || channels.is_none();
    let driving = input.filter(drives).map(driving_input).transpose()?;
    let started = Instant::now();
    let traj = simulate_driven(RunInputs {
        osc,
        model: model.as_ref(),
        init: &init,
        input: driving.as_ref().map(|d| &d.input),
        channels: channels.as_ref(),
        grid: SampleGrid {
            t_end: sim.duration,
            sample_times: &times,
        },
        opts: &sim.sim_options(),
    })
    .map_err(JobError::Simulation)?;
    let wall_time_s = started.elapsed().as_secs_f64();
    let noisy_velocity = sim.noise.map(|sigma| {
        let mut noisy = traj.v.clone();
        add_gaussian_noise(&mut noisy, sigma, sim.seed);
        noisy
    });
    let mut report = simulate_report(*osc, model.clone(), &init, traj, wall_time_s);
    report.sample_rate = sim.sample_rate;
    report.duration = sim.duration;
    report.noise = sim.noise;
    report.seed = sim.noise.map(|_| sim.seed);
    report.noisy_velocity = noisy_velocity;
    report.input = driving.map(|d| d.series);
    Ok(report)
}

/// The first sample time of `record`: t = 0 of a simulation it drives.
fn record_start(record: &Record) -> f64 {
    record.time().first().copied().unwrap_or(0.0)
}

/// The input of a simulation and the series it was read from.
struct Driving {
    input: Input,
    series: InputSeries,
}

/// The input-force channel of `record` on its own clock (its first sample at t = 0 of the
/// simulation); an error naming the record without one.
fn driving_input(record: &Record) -> Result<Driving, JobError> {
    let err = |reason: String| {
        JobError::Spec(SpecError::Simulation(format!(
            "input (`{}`): {reason}",
            record.name
        )))
    };
    let Some(u) = record.channel(Channel::InputForce) else {
        return Err(err(format!(
            "no input force channel (the file has: {}); name its column with \
             `input_force_column`",
            channel_list(&record.channels())
        )));
    };
    let t0 = record_start(record);
    let time: Vec<f64> = record.time().iter().map(|t| t - t0).collect();
    let input = Input::new(time.clone(), u.to_vec()).map_err(|e| err(e.to_string()))?;
    Ok(Driving {
        input,
        series: InputSeries {
            file: record.name.clone(),
            time,
            values: u.to_vec(),
        },
    })
}

/// `fit`: the spec's model fitted to `records`; parameters the model table gives start from
/// their given values.
pub fn fit_job(spec: &Spec, records: &[Record], hooks: &Hooks) -> Result<FitReport, JobError> {
    let model = spec.require_model("fit")?;
    let mut opts = spec.fit_options(&model.given, hooks);
    opts.params.time_shift |= release_found(records);
    let mut fit =
        fit(&spec.oscillator, model.model.as_ref(), records, &opts).map_err(JobError::Fit)?;
    state_assumptions(spec, &mut fit);
    Ok(FitReport {
        config: String::new(),
        fit,
        files: Vec::new(),
    })
}

/// Adds what the spec assumed for keys it was not given (damping 0) to the fit's findings,
/// so every writer says what its numbers rest on.
fn state_assumptions(spec: &Spec, fit: &mut FitResult) {
    fit.diagnostics.extend(
        spec.assumptions()
            .into_iter()
            .map(|text| Finding::new(Check::Assumption, Status::Pass, None, text)),
    );
}

/// Whether a record's release was found in its samples (`release = "auto"`): the fit then
/// fits the release instant (`time_shift`), which the whole motion sets far better than the
/// few samples of the rise.
fn release_found(records: &[Record]) -> bool {
    records.iter().any(|r| r.release_found)
}

/// `compare`: every model of `models` (see [`Spec::models_to_compare`]) fitted to `records`
/// and ranked by AIC; an error when none could be fitted.
pub fn compare_job(
    spec: &Spec,
    models: &[Box<dyn FrictionModel>],
    records: &[Record],
    hooks: &Hooks,
) -> Result<CompareReport, JobError> {
    // Options common to every model; per-model free lists and bounds are filtered by the
    // identifier to the parameters each model has.
    let mut opts = spec.fit_options(&[], hooks);
    opts.params.time_shift |= release_found(records);
    let mut comparison =
        compare(&spec.oscillator, models, records, &opts).map_err(JobError::Fit)?;
    comparison
        .ranking
        .iter_mut()
        .for_each(|fit| state_assumptions(spec, fit));
    if comparison.ranking.is_empty() {
        let why = comparison
            .failed
            .iter()
            .map(|f| format!("{}: {}", f.model, f.error))
            .collect();
        return Err(JobError::NothingFitted(why));
    }
    Ok(CompareReport {
        config: String::new(),
        comparison,
        records: records.len(),
        files: Vec::new(),
    })
}

/// The model whose force is the energy analysis's reference: the spec's `[model]` as given;
/// none when a `reference_force` is given instead; else Coulomb friction fitted to the same
/// records (the paper's procedure: fit mu, then compare with mu N).
pub fn reference_model(
    spec: &Spec,
    records: &[Record],
    hooks: &Hooks,
) -> Result<Option<Box<dyn FrictionModel>>, JobError> {
    if let Some(m) = &spec.model {
        return Ok(Some(m.model.clone()));
    }
    if spec.energy.reference_force.is_some() {
        return Ok(None);
    }
    let coulomb = Coulomb::default();
    // Only the fitted values are used: no uncertainty budget.
    let mut opts = spec.fit_options(&[], hooks);
    opts.uncertainty = PropertyUncertainty::default();
    let fitted: FitResult =
        fit(&spec.oscillator, &coulomb, records, &opts).map_err(JobError::ReferenceFit)?;
    Ok(Some(fitted.fitted_model))
}

/// The reference force of one record: `given`, else the model's mean |force| over the samples
/// the energy estimate uses (mu N for Coulomb friction), else NaN.
pub fn record_reference(given: Option<f64>, model_force: Option<&[f64]>, friction: &[f64]) -> f64 {
    match (given, model_force) {
        (Some(r), _) => r,
        (None, Some(f)) => mean_abs_where_defined(f, friction),
        (None, None) => f64::NAN,
    }
}

/// The force of `model` along the analysed motion of `record`; a law that reads conditions
/// takes them from the analysis (x, a) and the record (u, named channels).
fn analysed_model_force(
    model: &dyn FrictionModel,
    osc: &Oscillator,
    record: &Record,
    analysis: &EnergyAnalysis,
) -> Result<Vec<f64>, EngineError> {
    let conditions = model.conditions();
    if conditions.is_empty() {
        return model_force_along(model, osc, &analysis.time, &analysis.v);
    }
    let source = ConditionSource::of_record(record, analysis.x.clone(), analysis.a.clone());
    let bound = source.bind(&conditions)?;
    let normal = NormalForce::Constant(osc.normal_force);
    let motion = MeasuredMotion {
        time: &analysis.time,
        v: &analysis.v,
        normal: &normal,
    };
    let states = states_along(model, motion)?;
    let all = 0..analysis.v.len();
    Ok(forces_in(model, &analysis.v, &normal, &states, all, &bound))
}

/// The energy analysis of one record against its reference.
fn energy_record(
    record: &Record,
    osc: &Oscillator,
    opts: &EnergyOptions,
    model: Option<&dyn FrictionModel>,
    given: Option<f64>,
) -> Result<EnergyRecord, JobError> {
    let in_record = |source| JobError::Record {
        record: record.name.clone(),
        source,
    };
    let analysis: EnergyAnalysis = analyze_record(record, osc, opts).map_err(in_record)?;
    let model_force = model
        .map(|m| analysed_model_force(m, osc, record, &analysis))
        .transpose()
        .map_err(in_record)?;
    let reference = record_reference(given, model_force.as_deref(), &analysis.friction);
    Ok(EnergyRecord {
        file: record.name.clone(),
        release_time: record.release_time,
        mean_abs_force: analysis.mean_abs_force,
        reference,
        percent_difference: percent_difference(analysis.mean_abs_force, reference),
        half_cycle_forces: analysis.half_cycles.iter().map(|h| h.force).collect(),
        half_cycle_mean: analysis.half_cycle_mean,
        half_cycle_std: analysis.half_cycle_std,
        half_cycles: analysis.half_cycles.clone(),
        masked: analysis.masked,
        samples: analysis.time.len(),
        sources: analysis.sources,
        analysis,
        model_force,
    })
}

/// `energy`: the energy-based friction force of every record (the paper's Eq. 7) against the
/// reference of [`reference_model`] / [`record_reference`].
pub fn energy_job(
    spec: &Spec,
    records: &[Record],
    hooks: &Hooks,
) -> Result<EnergyReport, JobError> {
    require_mechanics(
        &spec.unknown_oscillator,
        spec.oscillator.axis,
        "the energy analysis",
    )
    .map_err(JobError::Fit)?;
    let opts = spec.energy.options();
    let model = reference_model(spec, records, hooks)?;
    let analysed = records
        .iter()
        .map(|r| {
            energy_record(
                r,
                &spec.oscillator,
                &opts,
                model.as_deref(),
                spec.energy.reference_force,
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(EnergyReport {
        command: "energy".into(),
        config: String::new(),
        oscillator: spec.oscillator,
        model: spec.model.as_ref().map(|m| m.model.clone()),
        options: opts,
        records: analysed,
        files: Vec::new(),
        reference_model: model.map(|m| m.name().to_string()),
    })
}

/// The models a campaign fits in each group: `Some` models compared (`[campaign] models`),
/// or `None` for the `[model]` fitted alone (an error when there is none).
pub fn campaign_models(
    spec: &Spec,
    campaign: &CampaignSpec,
) -> Result<Option<Vec<Box<dyn FrictionModel>>>, SpecError> {
    match &campaign.models {
        Some(names) => spec.models_to_compare(Some(names)).map(Some),
        None => spec.require_model("campaign").map(|_| None),
    }
}

/// The names of the models a campaign fits in each group (see [`campaign_models`]).
pub fn campaign_model_names(spec: &Spec, models: Option<&[Box<dyn FrictionModel>]>) -> Vec<String> {
    match models {
        Some(list) => list.iter().map(|m| m.name().to_string()).collect(),
        None => spec
            .model
            .iter()
            .map(|m| m.model.name().to_string())
            .collect(),
    }
}

/// What fitting one group gave: its result (rows and summaries) and the report `fit` or
/// `compare` gives for its records (`None` when they could not be read or nothing fitted).
#[derive(Debug, Clone)]
pub struct GroupRun {
    /// The group's rows.
    pub result: GroupResult,
    /// Its own report.
    pub report: Option<GroupReport>,
}

/// One group of a campaign: its records read as `fit` reads a configuration's, then
/// [`fit_job`] (no `models`) or [`compare_job`] on them. A record that cannot be read or a
/// fit that fails gives rows with the reason, never an error.
pub fn campaign_group_job(
    spec: &Spec,
    models: Option<&[Box<dyn FrictionModel>]>,
    task: &GroupTask,
    hooks: &Hooks,
) -> GroupRun {
    let names = campaign_model_names(spec, models);
    let failed = |error: String| GroupRun {
        result: GroupResult::failed(task, &names, &error),
        report: None,
    };
    let records = match load_group(spec, task) {
        Ok(records) => records,
        Err(e) => return failed(e),
    };
    let task = &task.with_channel_means(&records);
    let report = match models {
        Some(list) => {
            compare_job(spec, list, &records, hooks).map(|r| GroupReport::Compare(Box::new(r)))
        }
        None => fit_job(spec, &records, hooks).map(|r| GroupReport::Fit(Box::new(r))),
    };
    match report {
        Ok(report) => GroupRun {
            result: group_result(task, &names, &report),
            report: Some(report),
        },
        Err(e) => failed(e.to_string()),
    }
}

/// A group's records, read and checked as a configuration's `[[records]]` are.
fn load_group(spec: &Spec, task: &GroupTask) -> Result<Vec<Record>, String> {
    task.sources
        .iter()
        .zip(&task.lines)
        .map(|(source, &line)| {
            let resolved = source
                .resolve_for(line, &task.base_dir, spec.record_use())
                .map_err(|e| e.to_string())?;
            let record = resolved.load().map_err(|e| e.to_string())?;
            spec.check_units(&record).map_err(|e| e.to_string())?;
            spec.check_law_on(&record).map_err(|e| e.to_string())?;
            Ok(record)
        })
        .collect()
}

/// The rows of a group's report, one per model in `names` order.
fn group_result(task: &GroupTask, names: &[String], report: &GroupReport) -> GroupResult {
    let (fits, failures, best): (Vec<&FitResult>, Vec<(String, String)>, Option<&FitResult>) =
        match report {
            GroupReport::Fit(r) => (vec![&r.fit], Vec::new(), Some(&r.fit)),
            GroupReport::Compare(r) => (
                r.comparison.ranking.iter().collect(),
                r.comparison
                    .failed
                    .iter()
                    .map(|f| (f.model.clone(), f.error.clone()))
                    .collect(),
                r.best(),
            ),
        };
    let rows = names
        .iter()
        .map(|name| match fits.iter().find(|f| &f.model == name) {
            Some(fit) => CampaignRow::from_fit(task, fit),
            None => {
                let why = failures
                    .iter()
                    .find(|(m, _)| m == name)
                    .map_or("not fitted", |(_, e)| e);
                CampaignRow::failed(task, name, why)
            }
        })
        .collect();
    GroupResult {
        task: task.clone(),
        verdict: best.map_or(RowVerdict::Failed, |b| b.verdict().into()),
        rows,
        fits: fits.into_iter().map(FitSummary::of).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::coulomb_free_vibration;

    /// The energy rate from the states equals the power of the dissipative forces,
    /// -(c v + mu N sgn v) v, on the exact Coulomb solution.
    #[test]
    fn energy_rate_is_the_dissipated_power() {
        let osc = Oscillator::fmm();
        let f = 0.24 * osc.normal_force;
        let t: Vec<f64> = (0..500).map(|i| i as f64 * 1e-3 + 1e-4).collect();
        let s = coulomb_free_vibration(&osc, f, 0.014, &t).unwrap();
        let rate = energy_rate(&osc, &s.x, &s.v, &s.a);
        for i in 0..t.len() {
            let v = s.v[i];
            let expect = -(osc.damping * v + f * v.signum()) * v;
            let expect = if v == 0.0 { 0.0 } else { expect };
            assert!(
                (rate[i] - expect).abs() < 1e-9,
                "t = {}: {} vs {expect}",
                t[i],
                rate[i]
            );
        }
    }

    #[test]
    fn a_given_reference_wins_over_the_model_force() {
        let friction = [f64::NAN, 1.0, -1.0];
        let model = [9.0, 2.0, -4.0];
        assert_eq!(record_reference(Some(5.0), Some(&model), &friction), 5.0);
        assert_eq!(record_reference(None, Some(&model), &friction), 3.0);
        assert!(record_reference(None, None, &friction).is_nan());
    }
}

/// What `plan` reads besides the spec: the records already taken, each candidate's input
/// record (`None` where it names no file), the record whose noise level the candidates take,
/// and a previous fit's law with the report's name (instead of `[model]`).
#[derive(Default)]
pub struct PlanInputs<'a> {
    /// The `[[records]]` already taken.
    pub taken: &'a [Record],
    /// Each candidate's input record.
    pub candidate_inputs: &'a [Option<Record>],
    /// `[plan] noise_record`, read.
    pub noise_record: Option<&'a Record>,
    /// `[plan] prior`: the fitted law and where it comes from.
    pub prior: Option<(Box<dyn FrictionModel>, String)>,
}

/// `plan`: the records to take next ([`crate::plan::plan`]) from `[plan]`, the oscillator,
/// the assumed law (`[model]` or the prior) and what `[fit]` frees.
pub fn plan_job(
    spec: &Spec,
    plan_spec: &crate::spec::PlanSpec,
    inputs: PlanInputs<'_>,
) -> Result<crate::report::PlanReport, JobError> {
    use crate::plan::{plan, Assumed, Noise, PlanRequest};
    let (model, from) = match inputs.prior {
        Some((law, source)) => (law, format!("the prior `{source}`")),
        None => (
            spec.require_model("plan")?.model.clone(),
            "[model]".to_string(),
        ),
    };
    let estimated = inputs
        .noise_record
        .and_then(|r| r.noise_level(Channel::Velocity));
    if inputs.noise_record.is_some() && estimated.is_none() {
        return Err(SpecError::Plan(
            "noise_record: no velocity noise level can be estimated".into(),
        )
        .into());
    }
    require_motion_conditions(model.as_ref()).map_err(JobError::Fit)?;
    let options = spec.fit_options(&[], &Hooks::default());
    let request = PlanRequest {
        assumed: Assumed {
            oscillator: spec.oscillator,
            model: model.as_ref(),
            params: options.params,
            sim: options.sim,
        },
        candidates: plan_spec.experiments(inputs.candidate_inputs)?,
        taken: inputs.taken.to_vec(),
        targets: Some(plan_spec.parameters.clone()),
        choose: plan_spec.choose,
        criterion: plan_spec.criterion,
        noise: Noise {
            velocity: plan_spec.velocity_noise.or(estimated),
            correlation: plan_spec.noise_correlation,
        },
        reach: plan_spec.reach,
        suggest: plan_spec.suggest,
    };
    let made = plan(&request)?;
    Ok(crate::report::PlanReport::new(
        made,
        model.name(),
        &from,
        plan_spec.choose,
    ))
}
