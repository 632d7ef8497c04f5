//! What a fit compares: the [`Residuals`] trait. Its producers: the oscillator's simulated
//! response ([`super::SimulatedResponse`]: simulate the free vibration, compare every response
//! channel the records hold, stacked) and the force along the measured motion
//! ([`super::ForceAlongMotion`]).
//!
//! A residual producer says which nuisance parameters it adds to every record (a velocity
//! offset, a release-time shift, ...), what it measures and what the model predicts for it
//! at given model, oscillator and nuisance values. The fit problem
//! ([`super::FitProblem`]) weighs and concatenates the residuals of all records and knows
//! nothing else of them, so a producer in the force domain (replay the measured motion,
//! compare a force) plugs in beside this one.

use super::analysis_cache::{AnalysisCache, AnalysisRequest};
use super::step_allowance::StepAllowance;
use crate::energy::{EnergyAnalysis, EnergyOptions};
use crate::error::EngineError;
use crate::identify::values::{
    ForceBalance, FreeParam, FrictionLevels, NuisanceKind, NuisanceValues, SampleAxes,
    SlidingSamples, UnreliableSamples,
};
use crate::oscillator::Oscillator;
use crate::record::Record;
use crate::simulate::{SimOptions, SimStats};
use frictionid_models::{FrictionModel, GuessHint};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::Arc;

/// Step limit of a simulation per sample of its record: a bound on cost, not on stiffness.
/// With `Integrator::Auto` (`[fit.options] integrator = "auto"`) the fit integrates stiff
/// bristle and element models with Rodas4, whose steps follow the motion's accuracy whatever the stiffness (about
/// 1 000 steps for a 2 s LuGre record at sigma0 = 1e7..1e9 N/m, against 40 000 allowed): a
/// physically valid stiff start point runs. Trial points whose dynamics need more than this
/// many steps per sample interval (chattering, a runaway law) are still rejected as
/// infeasible instead of integrated for seconds.
pub const STEPS_PER_SAMPLE: u64 = 20;

/// The values a producer evaluates at: the oscillator and model of one parameter vector, the
/// simulation options, and a counter of the simulations run.
pub struct Evaluation<'a> {
    /// The oscillator.
    pub oscillator: &'a Oscillator,
    /// The friction model.
    pub model: &'a (dyn FrictionModel + 'static),
    /// Simulation options.
    pub sim: &'a SimOptions,
    simulations: &'a AtomicU64,
    allowance: Option<&'a StepAllowance>,
    failed: Option<&'a AtomicUsize>,
}

impl<'a> Evaluation<'a> {
    /// Values to evaluate at; `simulations` counts the simulations producers run.
    pub fn new(
        oscillator: &'a Oscillator,
        model: &'a (dyn FrictionModel + 'static),
        sim: &'a SimOptions,
        simulations: &'a AtomicU64,
    ) -> Self {
        Self {
            oscillator,
            model,
            sim,
            simulations,
            allowance: None,
            failed: None,
        }
    }

    /// The same, within an evaluation of several records that notes the lowest index of a
    /// record that failed in `failed` (`usize::MAX`: none).
    pub fn with_failures(self, failed: &'a AtomicUsize) -> Self {
        Self {
            failed: Some(failed),
            ..self
        }
    }

    /// Whether record `index` no longer matters to the evaluation: a record before it failed
    /// (whose error the evaluation reports whatever the later records do), and its step
    /// allowance is set (a record's first simulation, which sets it, always runs in full).
    pub fn superseded(&self, index: usize) -> bool {
        let failed_before = self
            .failed
            .is_some_and(|f| f.load(Ordering::Relaxed) < index);
        failed_before && self.allowance.is_some_and(|w| w.cap(index, 1).is_some())
    }

    /// The same, with simulations held to `allowance` ([`super::step_allowance`]).
    pub fn with_step_allowance(self, allowance: &'a StepAllowance) -> Self {
        Self {
            allowance: Some(allowance),
            ..self
        }
    }

    /// `sim` with its step limit lowered to `base` and to record `index`'s step allowance.
    pub fn capped(&self, index: usize, samples: usize, base: u64) -> SimOptions {
        let allowed = self.allowance.and_then(|w| w.cap(index, samples));
        SimOptions {
            max_steps: self
                .sim
                .max_steps
                .min(base)
                .min(allowed.unwrap_or(u64::MAX)),
            ..*self.sim
        }
    }

    /// Records the work of a simulation of record `index` (the first sets its allowance).
    pub fn record_work(&self, index: usize, stats: &SimStats, samples: usize) {
        if let Some(w) = self.allowance {
            w.record(index, stats, samples);
        }
    }

    /// Records that one simulation was run.
    pub fn count_simulation(&self) {
        self.simulations.fetch_add(1, Ordering::Relaxed);
    }
}

/// What produces a fit's residuals: a measured series per record and the model's prediction
/// of it. Residuals are `sqrt(weight) (predicted - measured)`, sample by sample.
pub trait Residuals: Send + Sync {
    /// The quantity compared, for reports (`velocity`, `force`).
    fn channel(&self) -> &'static str;

    /// The quantity compared in record `index` (default: [`Residuals::channel`]).
    fn record_channel(&self, _index: usize) -> &'static str {
        self.channel()
    }

    /// Its SI unit.
    fn unit(&self) -> &'static str;

    /// The nuisance parameters this producer adds to every record, in layout order.
    fn nuisance(&self) -> &[NuisanceKind];

    /// The measured series of record `index` that the prediction is compared with.
    fn measured<'a>(&'a self, index: usize, record: &'a Record) -> &'a [f64];

    /// The model's prediction of the measured series of record `index` (nuisance applied),
    /// one value per measured sample.
    fn predict(&self, at: &Evaluation<'_>, case: RecordCase<'_>) -> Result<Vec<f64>, EngineError>;

    /// Checks a record before a fit (default: a velocity record of at least 3 samples).
    fn check_record(&self, record: &Record) -> Result<(), EngineError> {
        record.validate(3)
    }

    /// Data-driven hints for the starting values (default: from the energy analysis of the
    /// velocity with `energy`'s options, [`super::guess::guess_hint`]).
    fn hint(&self, osc: &Oscillator, records: &[Record], energy: &EnergyOptions) -> GuessHint {
        super::guess::guess_hint(osc, records, energy)
    }

    /// Where the producer keeps the energy analyses of its records (default: nowhere, every
    /// [`Residuals::energy_analysis`] computes its own).
    fn analysis_cache(&self) -> Option<&AnalysisCache> {
        None
    }

    /// The energy analysis (Eq. 7) `request` asks for (the fit's record, its velocity as
    /// measured): from the producer's [`Residuals::analysis_cache`] when it has one, else
    /// computed.
    fn energy_analysis(
        &self,
        request: AnalysisRequest<'_>,
    ) -> Result<Arc<EnergyAnalysis>, EngineError> {
        match self.analysis_cache() {
            Some(cache) => cache.analysis(request),
            None => request.compute(),
        }
    }

    /// The same, for its last reader in a fit (the energy check): the cached analysis leaves
    /// the cache.
    fn last_energy_analysis(
        &self,
        request: AnalysisRequest<'_>,
    ) -> Result<Arc<EnergyAnalysis>, EngineError> {
        match self.analysis_cache() {
            Some(cache) => cache.take(request),
            None => request.compute(),
        }
    }

    /// Whether the law's levels are coefficients of a normal force or forces (default:
    /// coefficients).
    fn friction_levels(&self) -> FrictionLevels {
        FrictionLevels::Coefficients
    }

    /// The terms of record `index`'s force balance at the evaluated values, for an
    /// inverse-dynamics producer (default: none).
    fn force_balance(
        &self,
        _at: &Evaluation<'_>,
        _case: RecordCase<'_>,
    ) -> Result<Option<ForceBalance>, EngineError> {
        Ok(None)
    }

    /// Whether the prediction is the oscillator's simulated response: then the energy-balance
    /// check and the residual-structure diagnostic apply to the fit.
    fn simulates_response(&self) -> bool {
        true
    }

    /// Whether record `index`'s measured series ([`Residuals::measured`]) is a measured
    /// friction force at every sample along the displacement of [`Residuals::sample_axes`],
    /// so that a start can read the contact's presliding travel from it (default: `false`; a
    /// velocity, an inverse-dynamics input force, Eq. 7's force or the sliding samples alone
    /// are not).
    fn measures_friction(&self, _index: usize) -> bool {
        false
    }

    /// Where the compared samples of record `index` lie: their times, and the displacement
    /// and velocity of the motion there when the producer knows them.
    fn sample_axes(&self, _index: usize, record: &Record) -> SampleAxes {
        SampleAxes {
            time: record.time().to_vec(),
            ..SampleAxes::default()
        }
    }

    /// The sliding samples record `index` compares, when only those are (`None`: every
    /// sample the residuals define).
    fn sliding_samples(&self, _index: usize) -> Option<SlidingSamples> {
        None
    }

    /// The samples of record `index` left out because their target is unreliable (`None`:
    /// none are).
    fn unreliable_samples(&self, _index: usize) -> Option<UnreliableSamples> {
        None
    }

    /// Number of residuals record `index` contributes.
    fn residual_count(&self, index: usize, record: &Record) -> usize {
        self.measured(index, record).len()
    }

    /// The parts of record `index`'s measured series, in order: one per compared channel
    /// (default: one part, the whole series, unscaled).
    fn segments(&self, index: usize, record: &Record) -> Vec<Segment> {
        vec![self.record_segment(index, record, None)]
    }

    /// Record `index`'s measured series as one segment, its residuals weighted by `noise`
    /// where the producer knows it (scale 1 / noise) and by 1 otherwise.
    fn record_segment(&self, index: usize, record: &Record, noise: Option<f64>) -> Segment {
        Segment {
            channel: self.record_channel(index),
            unit: self.unit(),
            len: self.measured(index, record).len(),
            noise,
            scale: noise.map_or(1.0, |n| 1.0 / n),
        }
    }

    /// Whether [`Residuals::jacobian_columns`] may give any column (default: `false`, and the
    /// fit takes every column by finite differences without asking).
    fn has_jacobian(&self) -> bool {
        false
    }

    /// The derivatives of record `index`'s weighted residuals ([`Residuals::residuals`]) with
    /// respect to the physical values of the free parameters `layout`, where the producer has
    /// them without finite differences: one entry per free parameter, each a column of the
    /// record's residual count, or `None` for a parameter it leaves to the fit's difference
    /// quotients. Default: none.
    fn jacobian_columns(
        &self,
        _at: &Evaluation<'_>,
        _case: RecordCase<'_>,
        layout: &[FreeParam],
    ) -> Result<JacobianColumns, EngineError> {
        Ok(vec![None; layout.len()])
    }

    /// Record `index`'s weighted residuals ([`Residuals::residuals`]) and its Jacobian columns
    /// ([`Residuals::jacobian_columns`]) from one evaluation, where the producer has both for
    /// less than apart (a replay with sensitivities yields the prediction as well); `None`
    /// where it has not, and the fit asks for them apart. Default: `None`.
    fn residuals_with_columns(
        &self,
        _at: &Evaluation<'_>,
        _case: RecordCase<'_>,
        _layout: &[FreeParam],
    ) -> Result<Option<(Vec<f64>, JacobianColumns)>, EngineError> {
        Ok(None)
    }

    /// Weighted residuals `sqrt(weight) scale (predicted - measured)` of record `index`, with
    /// the scale of each of its [`Residuals::segments`].
    fn residuals(
        &self,
        at: &Evaluation<'_>,
        case: RecordCase<'_>,
    ) -> Result<Vec<f64>, EngineError> {
        let predicted = self.predict(at, case)?;
        self.weighted(case.index, case.record, predicted)
    }

    /// The prediction `out` of record `index`'s measured series turned into its weighted
    /// residuals ([`Residuals::residuals`]).
    fn weighted(
        &self,
        index: usize,
        record: &Record,
        mut out: Vec<f64>,
    ) -> Result<Vec<f64>, EngineError> {
        let measured = self.measured(index, record);
        if out.len() != measured.len() {
            return Err(EngineError::InvalidInput(format!(
                "record `{}`: {} predicted values for {} measured",
                record.name,
                out.len(),
                measured.len()
            )));
        }
        let w = record.weight.sqrt();
        let mut start = 0;
        for segment in self.segments(index, record) {
            let end = (start + segment.len).min(out.len());
            for (p, m) in out[start..end].iter_mut().zip(&measured[start..end]) {
                *p = w * segment.scale * (*p - m);
            }
            start = end;
        }
        Ok(out)
    }
}

/// A record's Jacobian columns, one per free parameter ([`Residuals::jacobian_columns`]).
pub type JacobianColumns = Vec<Option<Vec<f64>>>;

/// One record as a producer evaluates it: its place in the fit (for the per-record state of
/// the producer and the step allowance), its data and its nuisance values.
#[derive(Debug, Clone, Copy)]
pub struct RecordCase<'a> {
    /// The record's place in the fit.
    pub index: usize,
    /// The record.
    pub record: &'a Record,
    /// Its nuisance values at the evaluated point.
    pub nuisance: &'a NuisanceValues,
}

/// One compared channel's part of a record's measured series.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// The quantity compared (`velocity`, `displacement`, `force`, ...).
    pub channel: &'static str,
    /// Its SI unit.
    pub unit: &'static str,
    /// Number of samples.
    pub len: usize,
    /// The noise level its residuals are weighted by, in `unit` (`None`: not weighted).
    pub noise: Option<f64>,
    /// The factor on its residuals (besides sqrt(weight)): 1 for the fit's own unit, the ratio
    /// of noise levels for a channel stacked beside it.
    pub scale: f64,
}
