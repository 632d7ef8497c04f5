//! The per-record side of a finished fit: each record's residuals by channel, its measured
//! and fitted series and the energy-based force check along it.

use super::diagnostics;
use super::down_weighted::{down_weighted_finding, robust_weights};
use super::energy_check::{
    energy_force_check, skip_ill_conditioned, FittedDamping, ForceReference,
};
use crate::axis::Axis;
use crate::energy::{
    analyze_record, forces_from_states, forces_in, states_along, EnergyOptions, MeasuredMotion,
};
use crate::error::EngineError;
use crate::identify::problem::inverse_dynamics::unreliable_target_finding;
use crate::identify::problem::{
    AnalysisRequest, FitProblem, Realised, RecordCase, Residuals, Segment,
};
use crate::identify::values::{
    ChannelFit, Check, EnergyForce, Finding, FitSeries, NuisanceValues, RecordFit,
};
use crate::record::{Channel, ConditionSource, NormalForce, Record};
use std::sync::Arc;

/// The per-record fits and what they add up to.
pub(crate) struct RecordFits {
    /// Each record's fit.
    pub records: Vec<RecordFit>,
    /// Sum of squared residuals of every record's first channel.
    pub sum_sq: f64,
    /// Samples of every record's first channel.
    pub n_total: usize,
    /// The energy-balance finding of each record.
    pub findings: Vec<Finding>,
}

/// Per-record residuals, fitted series and the energy-based force check (one record after
/// the other: on rayon's pool the Coulomb fit on three records took 15-30 % longer).
pub(crate) fn record_fits<R: Residuals>(
    problem: &FitProblem<R>,
    world: &Realised,
    energy: &EnergyOptions,
    damping: Option<FittedDamping>,
) -> Result<RecordFits, EngineError> {
    let mut out = RecordFits {
        records: Vec::new(),
        sum_sq: 0.0,
        n_total: 0,
        findings: Vec::new(),
    };
    for (ri, rec) in problem.records.iter().enumerate() {
        let (record, sum_sq, finding) = record_fit(problem, world, (energy, damping), ri, rec)?;
        out.sum_sq += sum_sq;
        out.n_total += record.series.measured.len();
        out.findings.extend(finding);
        out.findings.extend(
            record
                .unreliable_target
                .as_ref()
                .and_then(|u| unreliable_target_finding(&record.file, u)),
        );
        out.findings.extend(
            record
                .robust_weights
                .as_ref()
                .and_then(|w| down_weighted_finding(&record.file, w)),
        );
        out.records.push(record);
    }
    Ok(out)
}

/// The fit of record `ri`: residuals, fitted series and the energy-based force check (with
/// its finding), and the sum of squared residuals of its first channel.
fn record_fit<R: Residuals>(
    problem: &FitProblem<R>,
    world: &Realised,
    energy: (&EnergyOptions, Option<FittedDamping>),
    ri: usize,
    rec: &Record,
) -> Result<(RecordFit, f64, Option<Finding>), EngineError> {
    // The energy check first: its analysis is freed before the fitted series are made (on a
    // long record each is as large as the record).
    let checked = record_energy_check(problem, world, energy, ri, rec);
    let mut predicted = problem.predict_record(world, ri)?;
    let stacked = problem.residuals.measured(ri, rec);
    let segments = problem.residuals.segments(ri, rec);
    let channels = channel_fits(&segments, &predicted, stacked, world.oscillator.axis);
    // The record's first channel is what its `measured` and `fitted` series hold.
    let first = channels.first().map_or(0, |c| c.samples);
    predicted.truncate(first);
    let measured = &stacked[..first];
    let sum_sq = channels.first().map_or(0.0, |c| c.rms_residual.powi(2)) * first as f64;
    let nuisance = &world.nuisance[ri];
    let axes = problem.residuals.sample_axes(ri, rec);
    let case = RecordCase {
        index: ri,
        record: rec,
        nuisance,
    };
    let balance = problem
        .residuals
        .force_balance(&problem.evaluation(world), case)?;
    let weights = record_weights(problem, world, case, (&axes.time, first))?;
    let record = RecordFit {
        file: rec.name.clone(),
        x0: nuisance.x0_of(rec),
        release_time: rec.release_time,
        samples: rec.len(),
        sliding: problem.residuals.sliding_samples(ri),
        unreliable_target: problem.residuals.unreliable_samples(ri),
        robust_weights: weights,
        channel: problem.residuals.record_channel(ri).to_string(),
        rms_residual: (sum_sq / measured.len() as f64).sqrt(),
        channels,
        energy_force: checked.energy_force,
        axes,
        series: FitSeries {
            measured: measured.to_vec(),
            fitted: predicted,
            energy_based_force: checked.energy_based_force,
            model_force: checked.model_force,
            balance,
        },
    };
    Ok((record, sum_sq, checked.finding))
}

/// The robust loss's weights of the record's first `first` residuals (its first channel), at
/// `time`; `None` under least squares.
fn record_weights<R: Residuals>(
    problem: &FitProblem<R>,
    world: &Realised,
    case: RecordCase<'_>,
    (time, first): (&[f64], usize),
) -> Result<Option<crate::identify::values::RobustWeights>, EngineError> {
    if problem.loss().is_linear() {
        return Ok(None);
    }
    let r = problem
        .residuals
        .residuals(&problem.evaluation(world), case)?;
    let r = &r[..first.min(r.len())];
    Ok(robust_weights(
        problem.loss(),
        r,
        &time[..first.min(time.len())],
    ))
}

/// A record's energy-based force check: its figures, Eq. 7's force and the model's along the
/// measured motion, and its finding (none where the check does not apply).
#[derive(Default)]
struct CheckedRecord {
    energy_force: Option<EnergyForce>,
    energy_based_force: Vec<f64>,
    model_force: Vec<f64>,
    finding: Option<Finding>,
}

/// The energy check of record `ri` where it applies: a fit of the free response (a driven
/// record is skipped with the reason), not one along the measured motion.
fn record_energy_check<R: Residuals>(
    problem: &FitProblem<R>,
    world: &Realised,
    (energy, damping): (&EnergyOptions, Option<FittedDamping>),
    ri: usize,
    rec: &Record,
) -> CheckedRecord {
    if !problem.residuals.simulates_response() {
        return CheckedRecord::default();
    }
    let driven = rec.channel(Channel::InputForce).is_some() || world.oscillator.input_offset != 0.0;
    if driven {
        return CheckedRecord {
            finding: Some(driven_skip(&rec.name)),
            ..CheckedRecord::default()
        };
    }
    let nuisance = &world.nuisance[ri];
    match energy_check(
        problem.residuals.as_ref(),
        ri,
        rec,
        nuisance,
        world,
        (energy, damping),
    ) {
        Ok((ef, ebf, mf)) => CheckedRecord {
            finding: Some(diagnostics::energy_balance(
                &rec.name,
                &ef,
                world.oscillator.axis,
            )),
            energy_force: Some(ef),
            energy_based_force: ebf,
            model_force: mf,
        },
        Err(e) => {
            let message = format!("record `{}`: no energy-based force check: {e}", rec.name);
            let finding = match e {
                // The model's force along the measured motion could not be computed: the
                // check has nothing to judge the fit with.
                EngineError::StateIntegration { .. } => {
                    Finding::skipped(Check::EnergyBalance, message)
                }
                _ => Finding::warn(Check::EnergyBalance, None, message),
            };
            CheckedRecord {
                finding: Some(finding),
                ..CheckedRecord::default()
            }
        }
    }
}

/// The fit of each compared channel of a record: its RMS residual and noise level, from the
/// record's stacked `predicted` and `measured` series cut at `segments`, in the units of
/// `axis`.
fn channel_fits(
    segments: &[Segment],
    predicted: &[f64],
    measured: &[f64],
    axis: Axis,
) -> Vec<ChannelFit> {
    let mut start = 0;
    segments
        .iter()
        .map(|s| {
            let end = (start + s.len).min(predicted.len()).min(measured.len());
            let ss: f64 = predicted[start..end]
                .iter()
                .zip(&measured[start..end])
                .map(|(p, m)| (p - m).powi(2))
                .sum();
            let samples = end - start;
            start = end;
            ChannelFit {
                channel: s.channel.to_string(),
                unit: axis.unit(s.unit),
                samples,
                rms_residual: (ss / samples.max(1) as f64).sqrt(),
                noise: s.noise,
            }
        })
        .collect()
}

/// The energy check of record `index` (`rec`), its energy-based force and the model force
/// along it.
/// The energy-balance finding of a driven record: Eq. 7 and the half-cycle energies hold the
/// free vibration's balance, which an input (or a constant force) breaks, so the check
/// cannot judge the fit there.
fn driven_skip(record: &str) -> Finding {
    Finding::skipped(
        Check::EnergyBalance,
        format!(
            "record `{record}`: the energy balance (Eq. 7) holds for free vibration; the record is \
             driven by an input, so the check cannot judge it (inverse dynamics compares the \
             force balance instead)"
        ),
    )
}

fn energy_check<R: Residuals + ?Sized>(
    residuals: &R,
    index: usize,
    rec: &Record,
    nuisance: &NuisanceValues,
    world: &Realised,
    (energy, damping): (&EnergyOptions, Option<FittedDamping>),
) -> Result<(EnergyForce, Vec<f64>, Vec<f64>), EngineError> {
    // The energy analysis sees the measured velocity corrected by the fitted offset, from the
    // fitted release displacement.
    let osc = &world.oscillator;
    let x0 = nuisance.x0_of(rec);
    let analysis = if nuisance.offset == 0.0 && x0 == rec.x0 {
        // The record as measured: the analysis the guess made, when m, c and k are those it
        // was made with (the check is its last reader).
        residuals.last_energy_analysis(AnalysisRequest {
            index,
            record: rec,
            osc,
            options: energy,
        })?
    } else {
        let mut corrected = rec.clone();
        corrected.x0 = x0;
        for v in corrected.velocity_mut() {
            *v -= nuisance.offset;
        }
        Arc::new(analyze_record(&corrected, osc, energy)?)
    };
    let model = world.model.as_ref();
    let normal = NormalForce::Constant(rec.oscillator_for(osc).normal_force);
    let motion = MeasuredMotion {
        time: &analysis.time,
        v: &analysis.v,
        normal: &normal,
    };
    let states = states_along(model, motion)?;
    let model_force = if model.conditions().is_empty() {
        forces_from_states(model, &analysis.v, &normal, &states)
    } else {
        let source = ConditionSource::of_record(rec, analysis.x.clone(), analysis.a.clone());
        let conditions = source.bind(&model.conditions())?;
        let all = 0..analysis.v.len();
        forces_in(model, &analysis.v, &normal, &states, all, &conditions)
    };
    let mut ef = energy_force_check(&analysis, ForceReference::ModelForce(&model_force))?;
    if let Some(damping) = damping {
        skip_ill_conditioned(&mut ef, &analysis, damping);
    }
    drop(states);
    // The analysis is the check's own unless a cache still shares it: its force is moved out.
    let friction = match Arc::try_unwrap(analysis) {
        Ok(own) => own.friction,
        Err(shared) => shared.friction.clone(),
    };
    Ok((ef, friction, model_force))
}
