//! The oscillator's response as a fit compares it ([`SimulatedResponse`]): simulate the free
//! vibration from each record's release state and compare every response channel the record
//! holds (velocity, displacement, acceleration), stacked.
//!
//! Each channel's residuals are weighted by its own noise level (the record's
//! `<channel>_noise`, else estimated from its third differences, [`crate::record::noise`]).
//! The fit keeps the unit of its primary channel (the first of velocity, displacement,
//! acceleration that any record holds): a record's primary-channel residuals are in that
//! unit as they always were, every other channel's are scaled by sigma_primary / sigma_channel,
//! so a velocity-only fit is unchanged and a joint fit weighs each sample by 1 / sigma^2. A
//! record without the primary channel is scaled by the median primary noise of the others.
//!
//! The nuisance parameters stay coherent over the channels: one simulation per record from
//! the fitted x0 and release shift feeds all of them; the velocity offset applies to the
//! velocity channel (and needs one in every record).

use super::analysis_cache::{AnalysisCache, AnalysisRequest};
use super::residuals::{
    Evaluation, JacobianColumns, RecordCase, Residuals, Segment, STEPS_PER_SAMPLE,
};
use crate::energy::{record_motion, EnergyOptions};
use crate::error::EngineError;
use crate::identify::values::layout::FreeParam;
use crate::identify::values::levels::{FrictionLevels, UNIT_NORMAL_FORCE};
use crate::identify::values::nuisance::{NuisanceKind, NuisanceValues};
use crate::oscillator::{Oscillator, OscillatorProperty};
use crate::record::{channel_list, Channel, Record};
use crate::simulate::{
    simulate_driven, simulate_velocity_watched, ChannelSeries, Initial, Input, RunInputs,
    SampleGrid, SimOptions, SimStats, VelocityRun,
};
use frictionid_models::GuessHint;
use std::borrow::Cow;

mod sensitivity;

/// The response channels, in the order they are stacked.
const RESPONSE: [Channel; 3] = [
    Channel::Velocity,
    Channel::Displacement,
    Channel::Acceleration,
];

/// One compared channel of a record.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Stacked {
    channel: Channel,
    noise: f64,
    scale: f64,
}

/// A record's compared channels and their measured samples, concatenated.
#[derive(Debug, Clone, PartialEq)]
struct ResponseTrack {
    stacked: Vec<Stacked>,
    measured: Vec<f64>,
}

/// The response producer. Built by [`SimulatedResponse::for_records`] it compares every
/// response channel; built by [`SimulatedResponse::new`] (no records) it compares the velocity
/// channel alone, unweighted.
#[derive(Debug, Clone, PartialEq)]
pub struct SimulatedResponse {
    nuisance: Vec<NuisanceKind>,
    tracks: Vec<ResponseTrack>,
    primary: Channel,
    /// The records' energy analyses: the guess's, kept for the energy check.
    analyses: AnalysisCache,
    /// Whether the law's levels are coefficients or forces (no normal force given).
    levels: FrictionLevels,
}

impl SimulatedResponse {
    /// A velocity-only response with a per-record velocity offset, release shift and/or
    /// release displacement.
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
            tracks: Vec::new(),
            primary: Channel::Velocity,
            analyses: AnalysisCache::default(),
            levels: FrictionLevels::Coefficients,
        }
    }

    /// The same, reading the law's levels as `levels` (see [`simulated_levels`]).
    pub fn with_levels(self, levels: FrictionLevels) -> Self {
        Self { levels, ..self }
    }

    /// The response of `records` over every response channel each holds, with the nuisance
    /// parameters of [`SimulatedResponse::new`]. Errors: a record without a response channel;
    /// a velocity offset asked for a record without velocity.
    pub fn for_records(
        records: &[Record],
        velocity_offset: bool,
        time_shift: bool,
        x0: bool,
    ) -> Result<Self, EngineError> {
        let mut out = Self::new(velocity_offset, time_shift, x0);
        let present = |c: Channel| records.iter().any(|r| r.channel(c).is_some());
        out.primary = RESPONSE
            .into_iter()
            .find(|&c| present(c))
            .unwrap_or(Channel::Velocity);
        let reference = median_noise(records, out.primary);
        for record in records {
            record.require_x0("a velocity-domain fit (it simulates the record from rest)")?;
            check_response_channels(record, velocity_offset)?;
            out.tracks.push(track(record, out.primary, reference));
        }
        Ok(out)
    }

    /// The simulated velocity of `record` at its time stamps, released from the nuisance
    /// values' x0 `shift` seconds after its release instant (the one found or given when the
    /// record was cut at its release, which may lie between samples; else its first time
    /// stamp). Samples before the release see the release velocity; no offset. `index` is the
    /// record's place in the fit (for its step allowance, [`super::step_allowance`]).
    pub fn simulate(
        &self,
        at: &Evaluation<'_>,
        case: RecordCase<'_>,
    ) -> Result<Vec<f64>, EngineError> {
        let (record, nuisance) = (case.record, case.nuisance);
        let clock = ReleaseClock::new(record, nuisance);
        let mut v = vec![record.v0; clock.before];
        if let Some(&t_end) = clock.times.last() {
            let sim = simulated_from_release((at, self.levels), case, &clock, t_end, |inputs| {
                let mut sim = Vec::with_capacity(clock.times.len());
                let mut superseded = |_: usize| at.superseded(case.index);
                let run = VelocityRun {
                    v_out: &mut sim,
                    watch: &mut superseded,
                };
                let stats = simulate_velocity_watched(inputs, run)?;
                Ok((sim, stats))
            })?;
            if v.is_empty() {
                return Ok(sim);
            }
            v.extend_from_slice(&sim);
        }
        Ok(v)
    }

    /// The simulated `channels` of `record` (as [`SimulatedResponse::simulate`]; before the
    /// release: x0, v0 and no acceleration), concatenated in the order given.
    fn simulate_channels(
        &self,
        at: &Evaluation<'_>,
        case: RecordCase<'_>,
        channels: &[Channel],
    ) -> Result<Vec<f64>, EngineError> {
        let (record, nuisance) = (case.record, case.nuisance);
        let clock = ReleaseClock::new(record, nuisance);
        let x0 = nuisance.x0_of(record);
        let trajectory = match clock.times.last() {
            Some(&t_end) => Some(simulated_from_release(
                (at, self.levels),
                case,
                &clock,
                t_end,
                |inputs| {
                    let trajectory = simulate_driven(inputs)?;
                    let stats = trajectory.stats;
                    Ok((trajectory, stats))
                },
            )?),
            None => None,
        };
        let mut out = Vec::with_capacity(channels.len() * record.len());
        for &channel in channels {
            let (held, series) = match channel {
                Channel::Displacement => (x0, trajectory.as_ref().map(|t| &t.x)),
                Channel::Acceleration => (0.0, trajectory.as_ref().map(|t| &t.a)),
                _ => (record.v0, trajectory.as_ref().map(|t| &t.v)),
            };
            out.extend(std::iter::repeat_n(held, clock.before));
            out.extend(series.into_iter().flatten());
        }
        Ok(out)
    }

    fn track_of(&self, index: usize) -> Option<&ResponseTrack> {
        self.tracks.get(index)
    }

    /// The channels compared in record `index`.
    fn channels_of(&self, index: usize) -> Vec<Channel> {
        match self.track_of(index) {
            Some(t) => t.stacked.iter().map(|s| s.channel).collect(),
            None => vec![Channel::Velocity],
        }
    }
}

/// How a velocity fit of `records` reads the law's levels, and the oscillator it simulates:
/// without a normal force in the configuration (`unknown` names `normal_force`) or any record
/// ([`FrictionLevels::read_as_forces`]), the levels are forces bounded by the largest friction
/// force the records can hold ([`super::guess::largest_friction_bound`]) and `osc` carries
/// N = 1; otherwise they are coefficients and every record needs a normal force, its own or
/// the oscillator's (an error naming the record without one).
pub fn simulated_levels(
    records: &[Record],
    osc: &Oscillator,
    unknown: &[OscillatorProperty],
) -> Result<(FrictionLevels, Oscillator), EngineError> {
    let as_forces = FrictionLevels::read_as_forces(unknown, records);
    for record in records {
        FrictionLevels::record_normal_force(record, osc, unknown, as_forces).map_err(|reason| {
            EngineError::Record {
                record: record.name.clone(),
                reason,
            }
        })?;
    }
    if !as_forces {
        return Ok((FrictionLevels::Coefficients, *osc));
    }
    let simulated = Oscillator {
        normal_force: UNIT_NORMAL_FORCE,
        ..*osc
    };
    let largest = super::guess::largest_friction_bound(records, &simulated);
    Ok((FrictionLevels::Forces { largest }, simulated))
}

/// Sample times of a record on the simulation clock (from the shifted release), and how
/// many samples lie before the release.
struct ReleaseClock<'a> {
    before: usize,
    times: Cow<'a, [f64]>,
    /// The release instant on the record's clock.
    release: f64,
}

impl<'a> ReleaseClock<'a> {
    fn new(record: &'a Record, nuisance: &NuisanceValues) -> Self {
        let t0 = record.time().first().copied().unwrap_or(0.0);
        let release = record.release_time.unwrap_or(t0) + nuisance.shift;
        let before = record.time().partition_point(|&t| t < release);
        let after = &record.time()[before..];
        // Released at t = 0 (the common case): the record's own stamps, t - 0 = t.
        let times = if release == 0.0 {
            Cow::Borrowed(after)
        } else {
            Cow::Owned(after.iter().map(|&t| t - release).collect())
        };
        Self {
            before,
            times,
            release,
        }
    }

    /// The record's input channel on the simulation clock, if it has one.
    fn input(&self, record: &Record) -> Result<Option<Input>, EngineError> {
        let Some(u) = record.channel(Channel::InputForce) else {
            return Ok(None);
        };
        let time = record.time().iter().map(|&t| t - self.release).collect();
        Input::new(time, u.to_vec())
            .map(Some)
            .map_err(|e| EngineError::Record {
                record: record.name.clone(),
                reason: e.to_string(),
            })
    }
}

/// Simulates `case`'s record from its release up to `t_end`, sampled at `clock`'s times,
/// with `simulation` (the velocity-only or the full run, which returns what it made and its
/// statistics): from the nuisance values' release state, under the record's input and normal
/// force (the law's levels read as `levels`), within the record's step allowance; the work is
/// counted against the evaluation.
fn simulated_from_release<T>(
    (at, levels): (&Evaluation<'_>, FrictionLevels),
    case: RecordCase<'_>,
    clock: &ReleaseClock<'_>,
    t_end: f64,
    simulation: impl FnOnce(RunInputs<'_>) -> Result<(T, SimStats), EngineError>,
) -> Result<T, EngineError> {
    let (index, record) = (case.index, case.record);
    at.count_simulation();
    let init = initial(record, case.nuisance);
    let opts = within_allowance(at, index, record, clock.times.len());
    let input = clock.input(record)?;
    let channels = ChannelSeries::of_record(record, at.model, clock.release)?;
    // A record's own constant normal force reaches its simulation; levels read as forces
    // beyond a coefficient's bound run scaled.
    let mut osc = record.oscillator_for(at.oscillator);
    let scaled = levels.scaled_for_simulation(at.model);
    let model = match &scaled {
        Some((law, normal)) => {
            osc.normal_force = *normal;
            law.as_ref()
        }
        None => at.model,
    };
    let (made, stats) = simulation(RunInputs {
        osc: &osc,
        model,
        init: &init,
        input: input.as_ref(),
        channels: channels.as_ref(),
        grid: SampleGrid {
            t_end,
            sample_times: &clock.times,
        },
        opts: &opts,
    })?;
    at.record_work(index, &stats, clock.times.len());
    Ok(made)
}

/// The release state of `record` under `nuisance`.
fn initial(record: &Record, nuisance: &NuisanceValues) -> Initial {
    Initial {
        x0: nuisance.x0_of(record),
        v0: record.v0,
        z0: None,
    }
}

/// The simulation options of record `index` with `simulated` samples: within the step limit
/// of the record ([`STEPS_PER_SAMPLE`]) and the fit's step allowance
/// ([`super::step_allowance`]).
fn within_allowance(
    at: &Evaluation<'_>,
    index: usize,
    record: &Record,
    simulated: usize,
) -> SimOptions {
    let base = STEPS_PER_SAMPLE * (record.len() as u64).max(100);
    at.capped(index, simulated, base)
}

/// The record has a response channel, and velocity when a velocity offset is fitted.
fn check_response_channels(record: &Record, velocity_offset: bool) -> Result<(), EngineError> {
    let err = |reason: String| EngineError::Record {
        record: record.name.clone(),
        reason,
    };
    let has = |c: Channel| record.channel(c).is_some();
    if !RESPONSE.into_iter().any(has) {
        return Err(err(format!(
            "no response channel to fit: a velocity, displacement or acceleration channel is \
             needed (the record has: {}; a force record is fitted with [fit.options] domain = \
             \"force\")",
            channel_list(&record.channels())
        )));
    }
    if velocity_offset && !has(Channel::Velocity) {
        return Err(err(format!(
            "[fit.options] velocity_offset = true needs a velocity channel (the record has: {})",
            channel_list(&record.channels())
        )));
    }
    Ok(())
}

/// The median noise level of `channel` over the records that hold it (1 when none does).
fn median_noise(records: &[Record], channel: Channel) -> f64 {
    let mut levels: Vec<f64> = records
        .iter()
        .filter_map(|r| r.noise_level(channel))
        .collect();
    levels.sort_by(f64::total_cmp);
    levels.get(levels.len() / 2).copied().unwrap_or(1.0)
}

/// The compared channels of `record`, each scaled to the primary channel's noise (its own
/// where it has the primary channel, else `reference`).
fn track(record: &Record, primary: Channel, reference: f64) -> ResponseTrack {
    let own = record.noise_level(primary).unwrap_or(reference);
    let mut stacked = Vec::new();
    let mut measured = Vec::new();
    for channel in RESPONSE {
        let (Some(values), Some(noise)) = (record.channel(channel), record.noise_level(channel))
        else {
            continue;
        };
        let scale = if channel == primary { 1.0 } else { own / noise };
        stacked.push(Stacked {
            channel,
            noise,
            scale,
        });
        measured.extend_from_slice(values);
    }
    ResponseTrack { stacked, measured }
}

impl Residuals for SimulatedResponse {
    fn channel(&self) -> &'static str {
        self.primary.name()
    }

    /// The record's first compared channel (the one its `measured` and `fitted` series in a
    /// report hold).
    fn record_channel(&self, index: usize) -> &'static str {
        self.channels_of(index)
            .first()
            .map_or("velocity", |c| c.name())
    }

    fn unit(&self) -> &'static str {
        self.primary.unit()
    }

    fn nuisance(&self) -> &[NuisanceKind] {
        &self.nuisance
    }

    fn measured<'a>(&'a self, index: usize, record: &'a Record) -> &'a [f64] {
        match self.track_of(index) {
            Some(t) => &t.measured,
            None => record.velocity(),
        }
    }

    fn predict(&self, at: &Evaluation<'_>, case: RecordCase<'_>) -> Result<Vec<f64>, EngineError> {
        let (index, record, nuisance) = (case.index, case.record, case.nuisance);
        let channels = self.channels_of(index);
        let mut out = if channels == [Channel::Velocity] {
            self.simulate(at, case)?
        } else {
            self.simulate_channels(at, case, &channels)?
        };
        if let Some(v) = channels.iter().position(|&c| c == Channel::Velocity) {
            let n = record.len();
            for x in out.iter_mut().skip(v * n).take(n) {
                *x += nuisance.offset;
            }
        }
        Ok(out)
    }

    /// Hints from the energy analysis of the velocity; a record without one lends it the
    /// differentiated displacement ([`record_motion`]).
    fn hint(&self, osc: &Oscillator, records: &[Record], energy: &EnergyOptions) -> GuessHint {
        let with_velocity: Vec<Cow<'_, Record>> = records
            .iter()
            .map(|r| match r.channel(Channel::Velocity) {
                Some(_) => Cow::Borrowed(r),
                None => match record_motion(r) {
                    Some(motion) => Cow::Owned(r.clone().with_channel(Channel::Velocity, motion.v)),
                    None => Cow::Borrowed(r),
                },
            })
            .collect();
        // A record measured as velocity is analysed once, for the guess and the energy check
        // (the same level as the half-cycle analysis alone gives).
        let level = |index: usize, rec: &Record| {
            let analysed = records[index].channel(Channel::Velocity).and_then(|_| {
                self.energy_analysis(AnalysisRequest {
                    index,
                    record: rec,
                    osc,
                    options: energy,
                })
                .ok()
            });
            match analysed {
                Some(analysis) => super::guess::level_of_analysis(&analysis),
                None => super::guess::friction_level(rec, osc, energy),
            }
        };
        super::guess::guess_hint_with(osc, &with_velocity, self.levels, level)
    }

    fn friction_levels(&self) -> FrictionLevels {
        self.levels
    }

    fn analysis_cache(&self) -> Option<&AnalysisCache> {
        Some(&self.analyses)
    }

    /// Prepared records need a response channel (not necessarily velocity); an unprepared
    /// producer compares velocity, so needs it.
    fn check_record(&self, record: &Record) -> Result<(), EngineError> {
        if self.tracks.is_empty() {
            record.validate(3)
        } else {
            record.validate_channels(3)
        }
    }

    /// Columns from one augmented simulation per record where the law and the record allow
    /// (see [`sensitivity`]), difference quotients elsewhere.
    fn has_jacobian(&self) -> bool {
        true
    }

    fn jacobian_columns(
        &self,
        at: &Evaluation<'_>,
        case: RecordCase<'_>,
        layout: &[FreeParam],
    ) -> Result<JacobianColumns, EngineError> {
        self.sensitivity_columns(at, case, layout)
    }

    fn segments(&self, index: usize, record: &Record) -> Vec<Segment> {
        let Some(t) = self.track_of(index) else {
            return vec![Segment {
                channel: "velocity",
                unit: "m/s",
                len: record.velocity().len(),
                noise: None,
                scale: 1.0,
            }];
        };
        t.stacked
            .iter()
            .map(|s| Segment {
                channel: s.channel.name(),
                unit: s.channel.unit(),
                len: record.len(),
                noise: Some(s.noise),
                scale: s.scale,
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::coulomb_free_vibration;
    use crate::oscillator::Oscillator;
    use crate::record::TimeBase;
    use frictionid_models::Coulomb;
    use std::sync::atomic::{AtomicU64, Ordering};

    /// The first record of a fit, at `nuisance`.
    fn case<'a>(record: &'a Record, nuisance: &'a NuisanceValues) -> RecordCase<'a> {
        RecordCase {
            index: 0,
            record,
            nuisance,
        }
    }

    /// Under a fit's simulation options a record's simulations are held per sample: a
    /// 19 000-sample record may take the steps per sample a 2 000-sample one may (a fixed
    /// limit of 200 000 steps held the long one to 10.5 per sample and dropped every start
    /// of a LuGre fit to a drive record).
    #[test]
    fn a_long_record_may_take_the_steps_per_sample_of_a_short_one() {
        let osc = Oscillator::fmm();
        let sim = crate::identify::values::fit_options::fit_sim_options();
        let simulations = AtomicU64::new(0);
        let at = Evaluation::new(&osc, &Coulomb { mu: 0.2 }, &sim, &simulations);
        for samples in [2_000usize, 19_000, 200_000] {
            let time: Vec<f64> = (0..samples).map(|i| i as f64 * 1e-3).collect();
            let record = Record::new("r", time, vec![0.0; samples], 0.01);
            let cap = within_allowance(&at, 0, &record, samples).max_steps;
            assert_eq!(cap, STEPS_PER_SAMPLE * samples as u64, "{samples} samples");
        }
    }

    /// A displacement + acceleration record of the exact Coulomb solution: at the true
    /// parameters the stacked prediction is the exact x then a (to the integrator's
    /// accuracy), and the acceleration part is scaled by sigma_x / sigma_a.
    #[test]
    fn stacked_channels_match_the_exact_solution_and_are_scaled_by_their_noise() {
        let osc = Oscillator::fmm();
        let time: Vec<f64> = (0..1500).map(|i| i as f64 * 1e-3).collect();
        let exact = coulomb_free_vibration(&osc, 0.24 * osc.normal_force, 0.014, &time).unwrap();
        let mut record = Record::from_time_base("r", TimeBase::new(time).unwrap())
            .with_channel(Channel::Displacement, exact.x.clone())
            .with_channel(Channel::Acceleration, exact.a.clone())
            .with_noise(Channel::Displacement, 5e-7)
            .with_noise(Channel::Acceleration, 5e-3);
        record.x0 = 0.014;
        let producer =
            SimulatedResponse::for_records(std::slice::from_ref(&record), false, false, false)
                .unwrap();
        assert_eq!((producer.channel(), producer.unit()), ("displacement", "m"));
        let segments = producer.segments(0, &record);
        assert_eq!(segments.len(), 2);
        assert_eq!(
            (segments[1].channel, segments[1].noise),
            ("acceleration", Some(5e-3))
        );
        assert!((segments[1].scale - 1e-4).abs() < 1e-18);
        let counter = AtomicU64::new(0);
        let sim = SimOptions::default();
        let model = Coulomb { mu: 0.24 };
        let at = Evaluation::new(&osc, &model, &sim, &counter);
        let predicted = producer
            .predict(&at, case(&record, &NuisanceValues::default()))
            .unwrap();
        let (x, a) = predicted.split_at(1500);
        assert!(x.iter().zip(&exact.x).all(|(p, e)| (p - e).abs() < 1e-8));
        // Away from the reversals, where a sample may fall on either side of the jump.
        let mismatched = a
            .iter()
            .zip(&exact.a)
            .filter(|(p, e)| (*p - *e).abs() > 1e-6)
            .count();
        assert!(mismatched <= exact.half_cycles(), "{mismatched}");
        let bare = Record::from_time_base("f", TimeBase::new(vec![0.0, 1.0]).unwrap())
            .with_channel(Channel::Force, vec![0.0, 1.0]);
        let e = SimulatedResponse::for_records(&[bare], false, false, false).unwrap_err();
        assert!(e.to_string().contains("no response channel to fit"), "{e}");
        let e = SimulatedResponse::for_records(&[record], true, false, false).unwrap_err();
        assert!(
            e.to_string()
                .contains("velocity_offset = true needs a velocity channel"),
            "{e}"
        );
    }

    /// Without a normal force anywhere the levels are forces, simulated under N = 1 and
    /// bounded by the records' balance: on the exact decay from 14 mm under 3.48 N the bound
    /// lies between the spring's force at the release, k x0, and twice it plus the level. A
    /// record's own normal force keeps the levels coefficients and the oscillator as it is.
    #[test]
    fn without_a_normal_force_the_levels_are_forces_bounded_by_the_balance() {
        let osc = Oscillator {
            normal_force: 0.0,
            ..Oscillator::fmm()
        };
        let time: Vec<f64> = (0..1500).map(|i| i as f64 * 1e-3).collect();
        let exact = coulomb_free_vibration(&osc, 3.48, 0.014, &time).unwrap();
        let record = Record::new("r", time, exact.v, 0.014);
        let unknown = vec![OscillatorProperty::NormalForce];
        let (levels, simulated) =
            simulated_levels(std::slice::from_ref(&record), &osc, &unknown).unwrap();
        let FrictionLevels::Forces { largest } = levels else {
            panic!("{levels:?}");
        };
        let spring = osc.stiffness * 0.014;
        assert!(
            (spring..2.0 * spring + 3.48).contains(&largest),
            "{largest}"
        );
        assert_eq!(simulated.normal_force, UNIT_NORMAL_FORCE);
        let mut own = record;
        own.set_normal_force(Some(crate::record::NormalForce::Constant(14.5)));
        let (levels, simulated) = simulated_levels(&[own], &osc, &unknown).unwrap();
        assert_eq!(levels, FrictionLevels::Coefficients);
        assert_eq!(simulated, osc);
    }

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
        let producer = SimulatedResponse::new(true, false, false);
        assert_eq!(producer.nuisance(), &[NuisanceKind::VelocityOffset]);
        let counter = AtomicU64::new(0);
        let sim = SimOptions::default();
        let at = Evaluation::new(&osc, &model, &sim, &counter);
        let nuisance = NuisanceValues {
            offset: 1e-3,
            ..NuisanceValues::default()
        };
        let r = producer.residuals(&at, case(&record, &nuisance)).unwrap();
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
        let v = SimulatedResponse::new(false, true, false)
            .simulate(&at, case(&record, &shifted))
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
}
