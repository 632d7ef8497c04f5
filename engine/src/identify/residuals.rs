//! What a fit compares: the [`Residuals`] trait. Its producers: the oscillator's response
//! ([`VelocityResponse`] in `response.rs`: simulate the free vibration, compare every response
//! channel) and the force along the measured motion (`force.rs`).
//!
//! A residual producer says which nuisance parameters it adds to every record (a velocity
//! offset, a release-time shift, ...), what it measures and what the model predicts for it
//! at given model, oscillator and nuisance values. The fit problem
//! ([`super::problem::FitProblem`]) weighs and concatenates the residuals of all records and
//! knows nothing else of them, so a producer in the force domain (replay the measured motion,
//! compare a force) plugs in beside this one.

use super::options::FitOptions;
use super::work::WorkBudget;
use crate::energy::{analyze_record, EnergyAnalysis, EnergyOptions};
use crate::error::EngineError;
use crate::oscillator::Oscillator;
use crate::record::Record;
use crate::simulate::{SimOptions, SimStats};
use frictionid_models::{FrictionModel, GuessHint};
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::Arc;

pub use super::response::VelocityResponse;

/// Step budget of a simulation per sample of its record: a bound on cost, not on stiffness.
/// With `Integrator::Auto` (`[fit.options] integrator = "auto"`) the fit integrates stiff
/// bristle and element models with Rodas4, whose steps follow the motion's accuracy whatever the stiffness (about
/// 1 000 steps for a 2 s LuGre record at sigma0 = 1e7..1e9 N/m, against 40 000 allowed): a
/// physically valid stiff start point runs. Trial points whose dynamics need more than this
/// many steps per sample interval (chattering, a runaway law) are still rejected as
/// infeasible instead of integrated for seconds.
pub const STEPS_PER_SAMPLE: u64 = 20;

/// A per-record parameter that is not part of the friction law or the oscillator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NuisanceKind {
    /// A constant added to the predicted velocity (an instrument's DC offset) [m/s].
    VelocityOffset,
    /// The release instant relative to the record's release time (its first time stamp unless
    /// it was cut at a release found or given between samples) [s].
    ReleaseShift,
    /// The displacement at release [m], when the record's x0 is known only approximately.
    StartDisplacement,
    /// A constant added to the predicted force (a load cell's zero) \[N\].
    ForceOffset,
}

impl NuisanceKind {
    /// The key of its bounds in `FitOptions::bounds` and the prefix of its reported name
    /// (`offset[x14mm.csv]`).
    pub fn key(self) -> &'static str {
        match self {
            Self::VelocityOffset => "offset",
            Self::ReleaseShift => "shift",
            Self::StartDisplacement => "x0",
            Self::ForceOffset => "force_offset",
        }
    }

    /// SI unit.
    pub fn unit(self) -> &'static str {
        match self {
            Self::VelocityOffset => "m/s",
            Self::ReleaseShift => "s",
            Self::StartDisplacement => "m",
            Self::ForceOffset => "N",
        }
    }

    /// The scale of its internal coordinate when its start value is 0.
    pub fn typical(self) -> f64 {
        match self {
            Self::VelocityOffset => 1e-4,
            Self::ReleaseShift => 1e-3,
            Self::StartDisplacement => 1e-3,
            Self::ForceOffset => 1e-2,
        }
    }

    /// Bounds when the options give none: no bound for an offset; a quarter of the natural
    /// period either way for a release shift (a later release is the next turning point's
    /// business); x0 within 20 % of the record's value.
    pub fn default_bounds(self, record: &Record, osc: &Oscillator) -> (f64, f64) {
        match self {
            Self::VelocityOffset | Self::ForceOffset => (f64::NEG_INFINITY, f64::INFINITY),
            Self::ReleaseShift => {
                let quarter = 0.5 * std::f64::consts::PI / osc.omega_n();
                (-quarter, quarter)
            }
            Self::StartDisplacement => {
                let half_width = X0_RELATIVE_BOUND * record.x0.abs();
                (record.x0 - half_width, record.x0 + half_width)
            }
        }
    }

    /// The value a fit starts from (before clipping to the bounds): 0, or the record's x0.
    pub fn start(self, record: &Record) -> f64 {
        match self {
            Self::VelocityOffset | Self::ReleaseShift | Self::ForceOffset => 0.0,
            Self::StartDisplacement => record.x0,
        }
    }

    /// Every kind, in the order a record's nuisance parameters are laid out.
    pub const ALL: [NuisanceKind; 4] = [
        Self::VelocityOffset,
        Self::ReleaseShift,
        Self::StartDisplacement,
        Self::ForceOffset,
    ];
}

/// Default half-width of the bounds of a fitted x0, relative to the record's value.
pub const X0_RELATIVE_BOUND: f64 = 0.2;

/// The nuisance values of one record (0, or the record's own x0, for those not fitted).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct NuisanceValues {
    /// Velocity offset [m/s].
    pub offset: f64,
    /// Release-time shift [s].
    pub shift: f64,
    /// Fitted displacement at release [m] (`None`: the record's x0).
    pub x0: Option<f64>,
    /// Force offset \[N\].
    pub force_offset: f64,
}

impl NuisanceValues {
    /// The value of `kind` (`None` for an x0 that is not fitted).
    pub fn get(&self, kind: NuisanceKind) -> Option<f64> {
        match kind {
            NuisanceKind::VelocityOffset => Some(self.offset),
            NuisanceKind::ReleaseShift => Some(self.shift),
            NuisanceKind::StartDisplacement => self.x0,
            NuisanceKind::ForceOffset => Some(self.force_offset),
        }
    }

    /// Sets the value of `kind`.
    pub fn set(&mut self, kind: NuisanceKind, value: f64) {
        match kind {
            NuisanceKind::VelocityOffset => self.offset = value,
            NuisanceKind::ReleaseShift => self.shift = value,
            NuisanceKind::StartDisplacement => self.x0 = Some(value),
            NuisanceKind::ForceOffset => self.force_offset = value,
        }
    }

    /// The release displacement of `record` with these values.
    pub fn x0_of(&self, record: &Record) -> f64 {
        self.x0.unwrap_or(record.x0)
    }
}

/// The values a producer evaluates at: the oscillator and model of one parameter vector, the
/// simulation options, and a counter of the simulations run.
pub struct Evaluation<'a> {
    /// The oscillator.
    pub oscillator: &'a Oscillator,
    /// The friction model.
    pub model: &'a dyn FrictionModel,
    /// Simulation options.
    pub sim: &'a SimOptions,
    simulations: &'a AtomicU64,
    work: Option<&'a WorkBudget>,
    failed: Option<&'a AtomicUsize>,
}

impl<'a> Evaluation<'a> {
    /// Values to evaluate at; `simulations` counts the simulations producers run.
    pub fn new(
        oscillator: &'a Oscillator,
        model: &'a dyn FrictionModel,
        sim: &'a SimOptions,
        simulations: &'a AtomicU64,
    ) -> Self {
        Self {
            oscillator,
            model,
            sim,
            simulations,
            work: None,
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
    /// (whose error the evaluation reports whatever the later records do), and its work
    /// budget is set (a record's first simulation, which sets it, always runs in full).
    pub fn superseded(&self, index: usize) -> bool {
        let failed_before = self
            .failed
            .is_some_and(|f| f.load(Ordering::Relaxed) < index);
        failed_before && self.work.is_some_and(|w| w.cap(index, 1).is_some())
    }

    /// The same, with simulations held to `work` ([`super::work`]).
    pub fn with_work(self, work: &'a WorkBudget) -> Self {
        Self {
            work: Some(work),
            ..self
        }
    }

    /// `sim` with its step limit lowered to `base` and to record `index`'s work budget.
    pub fn capped(&self, index: usize, samples: usize, base: u64) -> SimOptions {
        let budget = self.work.and_then(|w| w.cap(index, samples));
        SimOptions {
            max_steps: self.sim.max_steps.min(base).min(budget.unwrap_or(u64::MAX)),
            ..*self.sim
        }
    }

    /// Records the work of a simulation of record `index` (the first sets its budget).
    pub fn record_work(&self, index: usize, stats: &SimStats, samples: usize) {
        if let Some(w) = self.work {
            w.record(index, stats, samples);
        }
    }

    /// Records that one simulation was run.
    pub fn count_simulation(&self) {
        self.simulations.fetch_add(1, Ordering::Relaxed);
    }
}

/// The abscissae of a record's compared samples (one value per sample).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SampleAxes {
    /// Time stamps \[s\].
    pub time: Vec<f64>,
    /// Displacement of the motion \[m\] (empty when not known).
    pub displacement: Vec<f64>,
    /// Velocity of the motion [m/s] (empty when not known).
    pub velocity: Vec<f64>,
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
    /// velocity, [`super::setup::guess_hint`]).
    fn hint(&self, osc: &Oscillator, records: &[Record], opts: &FitOptions) -> GuessHint {
        super::setup::guess_hint(osc, records, opts)
    }

    /// The energy analysis (Eq. 7) of the fit's record `index`, its velocity as measured,
    /// under `osc` (default: computed at every call; a producer may keep it for the energy
    /// check, see [`super::analysis_cache`]).
    fn energy_analysis(
        &self,
        _index: usize,
        record: &Record,
        osc: &Oscillator,
        options: &EnergyOptions,
    ) -> Result<Arc<EnergyAnalysis>, EngineError> {
        Ok(Arc::new(analyze_record(record, osc, options)?))
    }

    /// Whether the prediction is the oscillator's simulated response: then the energy-balance
    /// check and the residual-structure diagnostic apply to the fit.
    fn simulates_response(&self) -> bool {
        true
    }

    /// Where the compared samples of record `index` lie: their times, and the displacement
    /// and velocity of the motion there when the producer knows them.
    fn sample_axes(&self, _index: usize, record: &Record) -> SampleAxes {
        SampleAxes {
            time: record.time().to_vec(),
            ..SampleAxes::default()
        }
    }

    /// Number of residuals record `index` contributes.
    fn residual_count(&self, index: usize, record: &Record) -> usize {
        self.measured(index, record).len()
    }

    /// The parts of record `index`'s measured series, in order: one per compared channel
    /// (default: one part, the whole series, unscaled).
    fn segments(&self, index: usize, record: &Record) -> Vec<Segment> {
        vec![Segment {
            channel: self.record_channel(index),
            unit: self.unit(),
            len: self.measured(index, record).len(),
            noise: None,
            scale: 1.0,
        }]
    }

    /// Weighted residuals `sqrt(weight) scale (predicted - measured)` of record `index`, with
    /// the scale of each of its [`Residuals::segments`].
    fn residuals(
        &self,
        at: &Evaluation<'_>,
        case: RecordCase<'_>,
    ) -> Result<Vec<f64>, EngineError> {
        let (index, record) = (case.index, case.record);
        let mut out = self.predict(at, case)?;
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

/// One record as a producer evaluates it: its place in the fit (for the per-record state of
/// the producer and the work budget), its data and its nuisance values.
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The default bounds: a quarter of the natural period 2 pi sqrt(m/k) for a shift, 20 %
    /// of the stated x0 for x0.
    #[test]
    fn default_nuisance_bounds_come_from_the_record_and_the_oscillator() {
        let osc = Oscillator::fmm();
        let record = Record::new("r", vec![0.0, 1e-3], vec![0.0, 0.0], -0.014);
        let quarter = 0.25 * 2.0 * std::f64::consts::PI * (osc.mass / osc.stiffness).sqrt();
        let (lo, hi) = NuisanceKind::ReleaseShift.default_bounds(&record, &osc);
        assert!((hi - quarter).abs() < 1e-12 && (lo + quarter).abs() < 1e-12);
        let (lo, hi) = NuisanceKind::StartDisplacement.default_bounds(&record, &osc);
        assert!((lo + 0.0168).abs() < 1e-12 && (hi + 0.0112).abs() < 1e-12);
        assert_eq!(NuisanceKind::StartDisplacement.start(&record), -0.014);
    }
}
