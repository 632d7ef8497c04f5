//! What a fit compares: the [`Residuals`] trait and its implementation for the velocity
//! response ([`VelocityResponse`]: simulate the free vibration, compare the velocity).
//!
//! A residual producer says which nuisance parameters it adds to every record (a velocity
//! offset, a release-time shift, ...), what it measures and what the model predicts for it
//! at given model, oscillator and nuisance values. The fit problem
//! ([`super::problem::FitProblem`]) weighs and concatenates the residuals of all records and
//! knows nothing else of them, so a producer in the force domain (replay the measured motion,
//! compare a force) plugs in beside this one.

use super::options::FitOptions;
use super::work::WorkBudget;
use crate::error::EngineError;
use crate::oscillator::Oscillator;
use crate::record::{Channel, Record};
use crate::simulate::{simulate, simulate_velocity, Initial, SimOptions, SimStats};
use frictionid_models::{FrictionModel, GuessHint};
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicU64, Ordering};

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
        }
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
    fn predict(
        &self,
        at: &Evaluation<'_>,
        index: usize,
        record: &Record,
        nuisance: &NuisanceValues,
    ) -> Result<Vec<f64>, EngineError>;

    /// Checks a record before a fit (default: a velocity record of at least 3 samples).
    fn check_record(&self, record: &Record) -> Result<(), EngineError> {
        record.validate(3)
    }

    /// Data-driven hints for the starting values (default: from the energy analysis of the
    /// velocity, [`super::setup::guess_hint`]).
    fn hint(&self, osc: &Oscillator, records: &[Record], opts: &FitOptions) -> GuessHint {
        super::setup::guess_hint(osc, records, opts)
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

    /// Weighted residuals `sqrt(weight) (predicted - measured)` of record `index`.
    fn residuals(
        &self,
        at: &Evaluation<'_>,
        index: usize,
        record: &Record,
        nuisance: &NuisanceValues,
    ) -> Result<Vec<f64>, EngineError> {
        let mut out = self.predict(at, index, record, nuisance)?;
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
        for (p, m) in out.iter_mut().zip(measured) {
            *p = w * (*p - m);
        }
        Ok(out)
    }
}

/// The oscillator's response: simulate the free vibration from the record's release state and
/// compare the simulated velocity (plus the record's offset) with the measured one, or, for
/// records of an interferometer ([`VelocityResponse::displacement`]), the simulated
/// displacement with the measured one.
#[derive(Debug, Clone, PartialEq)]
pub struct VelocityResponse {
    nuisance: Vec<NuisanceKind>,
    compared: Channel,
}

impl VelocityResponse {
    /// A velocity response with a per-record velocity offset, release shift and/or release
    /// displacement.
    pub fn new(velocity_offset: bool, time_shift: bool, x0: bool) -> Self {
        let nuisance = NuisanceKind::ALL
            .into_iter()
            .filter(|k| match k {
                NuisanceKind::VelocityOffset => velocity_offset,
                NuisanceKind::ReleaseShift => time_shift,
                NuisanceKind::StartDisplacement => x0,
                NuisanceKind::ForceOffset => false,
            })
            .collect();
        Self {
            nuisance,
            compared: Channel::Velocity,
        }
    }

    /// The response seen by an interferometer: the simulated displacement against a measured
    /// displacement channel (relative to the spring's equilibrium), with a per-record release
    /// shift and/or release displacement.
    pub fn displacement(time_shift: bool, x0: bool) -> Self {
        Self {
            compared: Channel::Displacement,
            ..Self::new(false, time_shift, x0)
        }
    }

    /// The channel every record of a response fit is compared in: velocity when each record has
    /// one, else displacement when each has one (`None`: neither).
    pub fn common_channel(records: &[Record]) -> Option<Channel> {
        [Channel::Velocity, Channel::Displacement]
            .into_iter()
            .find(|&c| records.iter().all(|r| r.channel(c).is_some()))
    }

    /// The simulated response of `record` in the compared channel (see [`Self::simulate`]).
    fn simulate_compared(
        &self,
        at: &Evaluation<'_>,
        index: usize,
        record: &Record,
        nuisance: &NuisanceValues,
    ) -> Result<Vec<f64>, EngineError> {
        match self.compared {
            Channel::Displacement => self.simulate_displacement(at, index, record, nuisance),
            _ => self.simulate(at, index, record, nuisance),
        }
    }

    /// The simulated displacement of `record` at its time stamps (as [`Self::simulate`]; the
    /// samples before the release see the release displacement).
    fn simulate_displacement(
        &self,
        at: &Evaluation<'_>,
        index: usize,
        record: &Record,
        nuisance: &NuisanceValues,
    ) -> Result<Vec<f64>, EngineError> {
        let (first, times) = Self::simulation_clock(record, nuisance);
        let x0 = nuisance.x0_of(record);
        let mut x = vec![x0; first];
        if let Some(&t_end) = times.last() {
            at.count_simulation();
            let init = Initial {
                x0,
                v0: record.v0,
                z0: None,
            };
            let base = STEPS_PER_SAMPLE * (record.len() as u64).max(100);
            let opts = at.capped(index, times.len(), base);
            let traj = simulate(at.oscillator, at.model, &init, t_end, &times, &opts)?;
            at.record_work(index, &traj.stats, times.len());
            x.extend_from_slice(&traj.x);
        }
        Ok(x)
    }

    /// The number of samples before the release (shifted by the nuisance `shift`) and the
    /// remaining sample times on the simulation clock (0 at the release).
    fn simulation_clock(record: &Record, nuisance: &NuisanceValues) -> (usize, Vec<f64>) {
        let t0 = record.time().first().copied().unwrap_or(0.0);
        let release = record.release_time.unwrap_or(t0) + nuisance.shift;
        let first = record.time().partition_point(|&t| t < release);
        let times = record.time()[first..]
            .iter()
            .map(|&t| t - release)
            .collect();
        (first, times)
    }

    /// The simulated velocity of `record` at its time stamps, released from the nuisance
    /// values' x0 `shift` seconds after its release instant (the one found or given when the
    /// record was cut at its release, which may lie between samples; else its first time
    /// stamp). Samples before the release see the release velocity; no offset. `index` is the
    /// record's place in the fit (for its work budget).
    pub fn simulate(
        &self,
        at: &Evaluation<'_>,
        index: usize,
        record: &Record,
        nuisance: &NuisanceValues,
    ) -> Result<Vec<f64>, EngineError> {
        // Samples before the release see the initial state.
        let (first, times) = Self::simulation_clock(record, nuisance);
        let mut v = vec![record.v0; first];
        if let Some(&t_end) = times.last() {
            at.count_simulation();
            let init = Initial {
                x0: nuisance.x0_of(record),
                v0: record.v0,
                z0: None,
            };
            let mut sim = Vec::with_capacity(times.len());
            let base = STEPS_PER_SAMPLE * (record.len() as u64).max(100);
            let opts = at.capped(index, times.len(), base);
            let stats = simulate_velocity(
                at.oscillator,
                at.model,
                &init,
                t_end,
                &times,
                &opts,
                &mut sim,
            )?;
            at.record_work(index, &stats, times.len());
            v.extend_from_slice(&sim);
        }
        Ok(v)
    }
}

impl Residuals for VelocityResponse {
    fn channel(&self) -> &'static str {
        self.compared.name()
    }

    fn unit(&self) -> &'static str {
        match self.compared {
            Channel::Displacement => "m",
            _ => "m/s",
        }
    }

    fn nuisance(&self) -> &[NuisanceKind] {
        &self.nuisance
    }

    fn measured<'a>(&'a self, _index: usize, record: &'a Record) -> &'a [f64] {
        record.channel(self.compared).unwrap_or_default()
    }

    fn check_record(&self, record: &Record) -> Result<(), EngineError> {
        match self.compared {
            Channel::Displacement => record.validate_channels(3),
            _ => record.validate(3),
        }
    }

    /// Displacement records: the hints of their motion's velocity (the differentiated
    /// displacement, as the force domain takes it).
    fn hint(&self, osc: &Oscillator, records: &[Record], opts: &FitOptions) -> GuessHint {
        if self.compared == Channel::Velocity {
            return super::setup::guess_hint(osc, records, opts);
        }
        let with_velocity: Vec<Record> = records
            .iter()
            .map(|r| match super::force::motion(r) {
                Some((v, _)) => r.clone().with_channel(Channel::Velocity, v),
                None => r.clone(),
            })
            .collect();
        super::setup::guess_hint(osc, &with_velocity, opts)
    }

    /// The energy-balance check and the residual-structure diagnostic read the velocity: they
    /// apply to velocity records only.
    fn simulates_response(&self) -> bool {
        self.compared == Channel::Velocity
    }

    fn predict(
        &self,
        at: &Evaluation<'_>,
        index: usize,
        record: &Record,
        nuisance: &NuisanceValues,
    ) -> Result<Vec<f64>, EngineError> {
        let mut v = self.simulate_compared(at, index, record, nuisance)?;
        for x in &mut v {
            *x += nuisance.offset;
        }
        Ok(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::coulomb_free_vibration;
    use frictionid_models::Coulomb;

    /// The velocity response of a Coulomb oscillator against the exact piecewise solution:
    /// residuals are sqrt(w) (exact + offset - measured).
    #[test]
    fn velocity_residuals_match_the_exact_coulomb_solution() {
        let osc = Oscillator::fmm();
        let model = Coulomb { mu: 0.24 };
        let time: Vec<f64> = (0..400).map(|i| i as f64 * 2e-3).collect();
        let exact = coulomb_free_vibration(&osc, 0.24 * osc.normal_force, 0.014, &time)
            .unwrap()
            .v;
        let mut record = Record::new("r", time, vec![0.0; 400], 0.014);
        record.weight = 4.0;
        let producer = VelocityResponse::new(true, false, false);
        assert_eq!(producer.nuisance(), &[NuisanceKind::VelocityOffset]);
        let counter = AtomicU64::new(0);
        let sim = SimOptions::default();
        let at = Evaluation::new(&osc, &model, &sim, &counter);
        let nuisance = NuisanceValues {
            offset: 1e-3,
            ..NuisanceValues::default()
        };
        let r = producer.residuals(&at, 0, &record, &nuisance).unwrap();
        assert_eq!(counter.load(Ordering::Relaxed), 1);
        for (ri, e) in r.iter().zip(&exact) {
            assert!((ri - 2.0 * (e + 1e-3)).abs() < 1e-7, "{ri} vs {e}");
        }
    }

    #[test]
    fn samples_before_a_shifted_release_see_the_release_velocity() {
        let osc = Oscillator::fmm();
        let model = Coulomb { mu: 0.24 };
        let time: Vec<f64> = (0..100).map(|i| i as f64 * 1e-3).collect();
        let record = Record::new("r", time.clone(), vec![0.0; 100], 0.01);
        let counter = AtomicU64::new(0);
        let sim = SimOptions::default();
        let at = Evaluation::new(&osc, &model, &sim, &counter);
        let shifted = NuisanceValues {
            shift: 0.0305,
            ..NuisanceValues::default()
        };
        let v = VelocityResponse::new(false, true, false)
            .simulate(&at, 0, &record, &shifted)
            .unwrap();
        assert!(v[..31].iter().all(|&x| x == 0.0));
        let shifted: Vec<f64> = time[31..].iter().map(|t| t - 0.0305).collect();
        let exact = coulomb_free_vibration(&osc, 0.24 * osc.normal_force, 0.01, &shifted)
            .unwrap()
            .v;
        for (got, e) in v[31..].iter().zip(&exact) {
            assert!((got - e).abs() < 1e-8, "{got} vs {e}");
        }
    }

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
