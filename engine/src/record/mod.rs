//! Measured records: a time base and named channels ([`Channel`]) sampled on it, the release
//! state, and the normal force of the contact (constant or sampled).
//!
//! - [`time`]: the [`TimeBase`] and the one check of time stamps used everywhere.
//! - [`channel`]: the [`Channel`] names and the [`NormalForce`].
//! - [`conditions`]: the values a law's conditions (x, a, u, named channels) take along a
//!   record.
//! - [`noise`]: a channel's white-noise level estimated from its samples.
//! - [`release`]: the release instant, given or found in the pre-trigger rest.
//! - [`sanity`]: units checked against the oscillator (mm/s, milliseconds, x0 in mm).

pub(crate) mod channel;
pub(crate) mod checked;
pub mod conditions;
pub(crate) mod noise;
pub(crate) mod release;
pub(crate) mod sanity;
pub(crate) mod time;

pub use channel::{Channel, NormalForce};
pub use conditions::{ConditionColumns, ConditionSource};
pub use release::{detect_release, Release};
pub use sanity::{check_scales, ScaleError};
pub use time::{check_sorted, check_time, TimeBase, TimeError};

use crate::error::EngineError;
use crate::oscillator::Oscillator;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::sync::Arc;

/// One measured record: time stamps, the channels sampled on them and the known release state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// A name for messages and reports (usually the file name).
    pub name: String,
    /// Time stamps [s], strictly increasing.
    time: TimeBase,
    /// Sampled channels other than the normal force, each as long as the time base; shared
    /// by the record's clones (a fit, each model of a comparison and each stage of a search
    /// clones its records) until one of them changes its samples.
    channels: BTreeMap<Channel, Arc<Vec<f64>>>,
    /// Named channels besides those (`[[records]] channels = { load = "..." }`): conditions a
    /// law may read (a load torque, a temperature), each as long as the time base, in the SI
    /// unit its scale gave it.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    named: BTreeMap<String, Arc<Vec<f64>>>,
    /// The contact's normal force; `None`: the oscillator's.
    normal_force: Option<NormalForce>,
    /// Noise levels given for channels (`<channel>_noise`), in the channel's unit.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    noise: BTreeMap<Channel, f64>,
    /// Displacement at the first time stamp (release) [m].
    pub x0: f64,
    /// Where `x0` comes from: given, the first displacement sample, or unknown (0 stands in).
    #[serde(default, skip_serializing_if = "X0Source::is_given")]
    pub x0_source: X0Source,
    /// Velocity at release [m/s] (0 for a release from rest).
    pub v0: f64,
    /// Weight of this record in a joint fit.
    pub weight: f64,
    /// The release instant \[s\] when the record was cut at its release (`release = "auto"`
    /// found it, or `release = <s>` gave it); the record then starts at the last sample at or
    /// before it. `None`: the record starts at release.
    #[serde(default)]
    pub release_time: Option<f64>,
    /// Whether `release_time` was found in the samples (`release = "auto"`), not given: a
    /// fit then fits the release instant too (`time_shift`), since the samples' noise sets
    /// the instant found only to a part of a sample.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub release_found: bool,
    /// How many first samples only drive a replay along the measured motion (a law's states)
    /// and are compared with nothing: a force-domain fit of a piece whose states must enter it
    /// as the samples before it left them. 0 for a record read from a file.
    #[serde(skip)]
    pub run_in: usize,
    /// What was worked out from the samples (noise levels, checks), kept until they change.
    #[serde(skip)]
    derived: SampleFacts,
}

/// Where a record's release displacement `x0` comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum X0Source {
    /// Given (a configuration's `x0`, or the record's maker).
    #[default]
    Given,
    /// The first sample of the displacement channel (relative to the equilibrium).
    FirstDisplacement,
    /// Neither given nor measured: `x0` is 0 in its place, and what needs it refuses the
    /// record ([`Record::require_x0`]).
    Unknown,
    /// Not needed: the axis has no restoring law, so the position enters no equation (0
    /// stands in).
    Unused,
}

impl X0Source {
    fn is_given(&self) -> bool {
        *self == X0Source::Given
    }
}

/// What is worked out from a record's samples and kept until they change: clones carry it
/// (they have the same samples), equality and serialisation ignore it (bookkeeping, not
/// data), and every change of the samples forgets it ([`Record::samples_changed`]).
#[derive(Debug, Default, Clone)]
struct SampleFacts {
    /// Noise levels estimated from the samples, each computed once.
    noise: noise::NoiseCache,
    /// Whether the samples passed their checks.
    checked: checked::SampleCheck,
}

impl SampleFacts {
    fn clear(&mut self) {
        self.noise.clear();
        self.checked.clear();
    }
}

impl PartialEq for SampleFacts {
    /// Records are equal whatever they remember.
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

impl Record {
    /// A velocity record released from rest with unit weight. The samples are checked by
    /// [`Record::validate`] (which every analysis calls), not here.
    pub fn new(name: impl Into<String>, time: Vec<f64>, velocity: Vec<f64>, x0: f64) -> Self {
        Self::from_time_base(name, TimeBase::unchecked(time))
            .with_channel(Channel::Velocity, velocity)
            .with_x0(x0)
    }

    /// A record with no channels yet on a time base, released from rest at x0 = 0 with unit
    /// weight; add channels with [`Record::with_channel`].
    pub fn from_time_base(name: impl Into<String>, time: TimeBase) -> Self {
        Self {
            name: name.into(),
            time,
            channels: BTreeMap::new(),
            named: BTreeMap::new(),
            normal_force: None,
            noise: BTreeMap::new(),
            x0: 0.0,
            x0_source: X0Source::Given,
            v0: 0.0,
            weight: 1.0,
            release_time: None,
            release_found: false,
            run_in: 0,
            derived: SampleFacts::default(),
        }
    }

    /// The record with `values` as its `channel` (replacing one already there). A
    /// [`Channel::NormalForce`] becomes the sampled [`NormalForce`].
    pub fn with_channel(mut self, channel: Channel, values: Vec<f64>) -> Self {
        self.samples_changed();
        match channel {
            Channel::NormalForce => self.normal_force = Some(NormalForce::Sampled(values)),
            other => {
                self.channels.insert(other, Arc::new(values));
            }
        }
        self
    }

    /// The record with `values` as its named channel `name` (replacing one already there).
    pub fn with_named_channel(mut self, name: impl Into<String>, values: Vec<f64>) -> Self {
        self.samples_changed();
        self.named.insert(name.into(), Arc::new(values));
        self
    }

    /// The samples of the named channel `name`, if the record has it.
    pub fn named_channel(&self, name: &str) -> Option<&[f64]> {
        self.named.get(name).map(|v| v.as_slice())
    }

    /// The named channel `name`, shared (no copy), if the record has it.
    pub fn named_channel_shared(&self, name: &str) -> Option<Arc<Vec<f64>>> {
        self.named.get(name).cloned()
    }

    /// The names of the record's named channels, in alphabetical order.
    pub fn named_channels(&self) -> Vec<&str> {
        self.named.keys().map(String::as_str).collect()
    }

    fn with_x0(mut self, x0: f64) -> Self {
        self.x0 = x0;
        self
    }
    /// Sets the release displacement by the one rule for it: `given` when there is one
    /// (a configuration's or a dict's `x0`), else the first sample of the displacement
    /// channel (relative to the equilibrium), else unknown (0 stands in, and what needs x0
    /// refuses the record: [`Record::require_x0`]).
    pub fn set_release_displacement(&mut self, given: Option<f64>) {
        let first = self
            .channel(Channel::Displacement)
            .and_then(|x| x.first().copied());
        (self.x0, self.x0_source) = match (given, first) {
            (Some(x0), _) => (x0, X0Source::Given),
            (None, Some(x0)) => (x0, X0Source::FirstDisplacement),
            (None, None) => (0.0, X0Source::Unknown),
        };
    }

    /// The record's x0 is known (given or measured), as `purpose` needs it: a velocity-only
    /// record is simulated from rest at x0 or has its velocity integrated from it. A record
    /// read without `x0` and without a displacement channel is refused, with the key to give.
    pub fn require_x0(&self, purpose: &str) -> Result<(), EngineError> {
        if self.x0_source != X0Source::Unknown {
            return Ok(());
        }
        Err(EngineError::Record {
            record: self.name.clone(),
            reason: format!(
                "missing `x0` (the release displacement, m): {purpose} needs it for a record \
                 without a displacement channel"
            ),
        })
    }

    /// The time stamps \[s\].
    pub fn time(&self) -> &[f64] {
        self.time.as_slice()
    }

    /// The time base.
    pub fn time_base(&self) -> &TimeBase {
        &self.time
    }

    /// The velocity samples [m/s]; empty when the record has no velocity channel
    /// ([`Record::validate`] rejects such a record).
    pub fn velocity(&self) -> &[f64] {
        self.channel(Channel::Velocity).unwrap_or_default()
    }

    /// The velocity samples, mutable (empty when there is no velocity channel).
    pub fn velocity_mut(&mut self) -> &mut [f64] {
        self.channel_mut(Channel::Velocity).unwrap_or_default()
    }

    /// The samples of `channel`, if the record has it.
    pub fn channel(&self, channel: Channel) -> Option<&[f64]> {
        match channel {
            Channel::NormalForce => match &self.normal_force {
                Some(NormalForce::Sampled(values)) => Some(values),
                _ => None,
            },
            other => self.channels.get(&other).map(|v| v.as_slice()),
        }
    }

    /// Forgets what was worked out from the samples (noise levels, checks): they change.
    fn samples_changed(&mut self) {
        self.derived.clear();
    }

    /// The samples of `channel`, mutable, if the record has it.
    pub fn channel_mut(&mut self, channel: Channel) -> Option<&mut [f64]> {
        self.samples_changed();
        match channel {
            Channel::NormalForce => match &mut self.normal_force {
                Some(NormalForce::Sampled(values)) => Some(values),
                _ => None,
            },
            other => self
                .channels
                .get_mut(&other)
                .map(|v| Arc::make_mut(v).as_mut_slice()),
        }
    }

    /// The channels the record holds, in [`Channel::ALL`] order.
    pub fn channels(&self) -> Vec<Channel> {
        Channel::ALL
            .into_iter()
            .filter(|&c| self.channel(c).is_some())
            .collect()
    }

    /// The record's own normal force, constant or sampled; `None`: the oscillator's applies.
    pub fn normal_force(&self) -> Option<&NormalForce> {
        self.normal_force.as_ref()
    }

    /// The normal force acting on this record: its own (sampled or constant), else the
    /// oscillator's `normal_force` as a constant.
    pub fn normal_force_with(&self, osc: &Oscillator) -> NormalForce {
        self.normal_force
            .clone()
            .unwrap_or(NormalForce::Constant(osc.normal_force))
    }

    /// `osc` under this record's own normal force, as a simulation of the record needs it:
    /// its constant (`[[records]] normal_force`) or the mean of its normal-force channel (a
    /// simulation holds N constant); `osc` itself without one.
    pub fn oscillator_for(&self, osc: &Oscillator) -> Oscillator {
        match &self.normal_force {
            Some(n) => Oscillator {
                normal_force: n.mean(),
                ..*osc
            },
            None => *osc,
        }
    }

    /// Sets (or with `None` removes) the record's own normal force.
    pub fn set_normal_force(&mut self, normal_force: Option<NormalForce>) {
        self.samples_changed();
        self.normal_force = normal_force;
    }

    /// The record from sample `first` on: the same channels, release state and weight.
    pub fn starting_at(&self, first: usize) -> Self {
        Self {
            run_in: self.run_in.saturating_sub(first),
            ..self.cut_to(self.time.tail(first), |v| {
                v.get(first..).unwrap_or_default().to_vec()
            })
        }
    }

    /// The record's first `len` samples: the same channels, release state and weight.
    pub fn ending_at(&self, len: usize) -> Self {
        self.cut_to(self.time.head(len), |v| v[..len.min(v.len())].to_vec())
    }

    /// The record on the time base `time`, every sampled series (channels, named channels, a
    /// sampled normal force) cut by `cut`, its derived facts cleared.
    fn cut_to(&self, time: TimeBase, cut: impl Fn(&[f64]) -> Vec<f64>) -> Self {
        Self {
            name: self.name.clone(),
            time,
            channels: self
                .channels
                .iter()
                .map(|(&c, v)| (c, Arc::new(cut(v))))
                .collect(),
            named: self
                .named
                .iter()
                .map(|(c, v)| (c.clone(), Arc::new(cut(v))))
                .collect(),
            normal_force: self.normal_force.as_ref().map(|n| match n {
                NormalForce::Sampled(v) => NormalForce::Sampled(cut(v)),
                constant => constant.clone(),
            }),
            noise: self.noise.clone(),
            x0: self.x0,
            x0_source: self.x0_source,
            v0: self.v0,
            weight: self.weight,
            release_time: self.release_time,
            release_found: self.release_found,
            run_in: self.run_in,
            derived: SampleFacts::default(),
        }
    }

    /// The record with `sigma` as the given noise level of `channel` (in its unit).
    pub fn with_noise(mut self, channel: Channel, sigma: f64) -> Self {
        self.noise.insert(channel, sigma);
        self
    }

    /// The noise level given for `channel`, if any.
    pub fn given_noise(&self, channel: Channel) -> Option<f64> {
        self.noise.get(&channel).copied()
    }

    /// The noise level of `channel`: the given one, else estimated from its samples
    /// ([`noise::noise_floor_level`] of the channel's [`Channel::noise_order`] differences);
    /// `None` when the record lacks the channel.
    pub fn noise_level(&self, channel: Channel) -> Option<f64> {
        let values = self.channel(channel)?;
        Some(self.given_noise(channel).unwrap_or_else(|| {
            let estimated = self.difference_noise(channel, channel.noise_order());
            estimated.unwrap_or(0.0).max(noise::noise_floor(values))
        }))
    }

    /// [`noise::difference_noise`] of `channel`'s differences of `order`, computed once per
    /// record; `None` when the record lacks the channel.
    pub fn difference_noise(&self, channel: Channel, order: usize) -> Option<f64> {
        let values = self.channel(channel)?;
        Some(
            self.derived
                .noise
                .get_or(channel, order, || noise::difference_noise(values, order)),
        )
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// Whether the record has no samples.
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// Checks that the record has velocity, every channel as long as the time, finite values,
    /// strictly increasing time, at least `min_samples` samples and a valid release state.
    pub fn validate(&self, min_samples: usize) -> Result<(), EngineError> {
        let err = |reason: String| EngineError::Record {
            record: self.name.clone(),
            reason,
        };
        if !self.channels.contains_key(&Channel::Velocity) {
            return Err(err(format!(
                "no velocity channel (the record has: {})",
                channel_list(&self.channels())
            )));
        }
        self.validate_channels(min_samples)
    }

    /// [`Record::validate`] without requiring a velocity channel (records of a force-domain
    /// fit may hold displacement and force only).
    pub fn validate_channels(&self, min_samples: usize) -> Result<(), EngineError> {
        let err = |reason: String| EngineError::Record {
            record: self.name.clone(),
            reason,
        };
        if self.derived.checked.passed() {
            self.time
                .check_count(min_samples)
                .map_err(|e| err(e.to_string()))?;
        } else {
            self.check_lengths().map_err(err)?;
            self.check_finite().map_err(err)?;
            self.time
                .check(min_samples)
                .map_err(|e| err(e.to_string()))?;
            self.derived.checked.pass();
        }
        if !self.x0.is_finite() || !self.v0.is_finite() {
            return Err(err("x0 and v0 must be finite".into()));
        }
        if !(self.weight.is_finite() && self.weight > 0.0) {
            return Err(err(format!("weight must be > 0, got {}", self.weight)));
        }
        if let Some((c, sigma)) = self
            .noise
            .iter()
            .find(|(_, s)| !(s.is_finite() && **s > 0.0))
        {
            return Err(err(format!("{c}_noise must be > 0, got {sigma}")));
        }
        Ok(())
    }

    fn check_lengths(&self) -> Result<(), String> {
        let n = self.time.len();
        for channel in self.channels() {
            let len = self.channel(channel).map_or(0, <[f64]>::len);
            if len != n {
                let what = match channel {
                    Channel::Velocity => "velocities".to_string(),
                    other => format!("{other} samples"),
                };
                return Err(format!("{n} time stamps but {len} {what}"));
            }
        }
        for (name, values) in &self.named {
            if values.len() != n {
                return Err(format!(
                    "{n} time stamps but {} samples of channel `{name}`",
                    values.len()
                ));
            }
        }
        Ok(())
    }

    /// Time and velocity are checked together (the message shows both), then the others.
    fn check_finite(&self) -> Result<(), String> {
        let time = self.time();
        let v = self.velocity();
        let finite = |i: usize| time[i].is_finite() && v.get(i).is_none_or(|x| x.is_finite());
        // The common case first, in one pass the compiler can vectorise; the search for the
        // offending sample only when there is one.
        let all_finite = time.iter().chain(v).all(|x| x.is_finite());
        let offending = || (0..time.len()).find(|&i| !finite(i));
        if let Some(i) = if all_finite { None } else { offending() } {
            return Err(match v.get(i) {
                Some(vi) => format!("sample {i} is not finite (t = {}, v = {vi})", time[i]),
                None => format!("time stamp {i} is not finite (t = {})", time[i]),
            });
        }
        for channel in self.channels() {
            let values = self.channel(channel).unwrap_or_default();
            if let Some(i) = values.iter().position(|x| !x.is_finite()) {
                return Err(format!(
                    "{channel} sample {i} is {} (values must be finite)",
                    values[i]
                ));
            }
        }
        for (name, values) in &self.named {
            if let Some(i) = values.iter().position(|x| !x.is_finite()) {
                return Err(format!(
                    "channel `{name}` sample {i} is {} (values must be finite)",
                    values[i]
                ));
            }
        }
        Ok(())
    }
}

/// `a, b, c`, or `none`.
pub(crate) fn channel_list(channels: &[Channel]) -> String {
    if channels.is_empty() {
        return "none".into();
    }
    channels
        .iter()
        .map(|c| c.name())
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cached noise level follows every change of the samples and never makes records
    /// differ.
    #[test]
    fn the_estimated_noise_is_cached_until_the_samples_change() {
        let n = 2000;
        let time: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
        let mut v: Vec<f64> = time.iter().map(|t| 0.1 * (13.8 * t).sin()).collect();
        crate::synthetic::add_gaussian_noise(&mut v, 2e-4, 5);
        let mut rec = Record::new("r", time, v.clone(), 0.0);
        let level = rec.noise_level(Channel::Velocity).unwrap();
        assert_eq!(
            level,
            noise::noise_floor_level(&v, Channel::Velocity.noise_order())
        );
        let twin = rec.clone();
        assert_eq!(twin.noise_level(Channel::Velocity), Some(level));
        rec.velocity_mut().iter_mut().for_each(|x| *x *= 10.0);
        let scaled = rec.noise_level(Channel::Velocity).unwrap();
        assert!(
            (scaled / level - 10.0).abs() < 1e-9,
            "{scaled} against {level}"
        );
        let rebuilt = Record::new("r", twin.time().to_vec(), rec.velocity().to_vec(), 0.0);
        assert_eq!(rec, rebuilt);
        let replaced = rec.with_channel(Channel::Velocity, v);
        assert_eq!(replaced.noise_level(Channel::Velocity), Some(level));
    }

    /// A check that passed is remembered only while the samples stay: a sample made
    /// non-finite afterwards, or a record too short for a larger count, still fails.
    #[test]
    fn passed_checks_are_forgotten_when_the_samples_change() {
        let mut rec = record();
        assert!(rec.validate(2).is_ok());
        assert!(rec.validate(4).is_ok());
        assert!(rec.validate(5).is_err(), "four samples are fewer than five");
        let twin = rec.clone();
        rec.velocity_mut()[2] = f64::NAN;
        let err = rec.validate(2).unwrap_err().to_string();
        assert!(err.contains("sample 2 is not finite"), "{err}");
        assert!(twin.validate(4).is_ok());
        let bad_time = Record::new("r", vec![0.0, 0.2, 0.1, 0.3], vec![0.0; 4], 0.0);
        assert!(bad_time.validate(2).is_err());
        assert!(
            bad_time.validate(2).is_err(),
            "a failed check is not remembered"
        );
    }

    fn record() -> Record {
        Record::new(
            "r",
            vec![0.0, 0.1, 0.2, 0.3],
            vec![0.0, 1.0, 0.5, -0.2],
            0.01,
        )
    }

    #[test]
    fn new_keeps_the_velocity_record_of_old() {
        let r = record();
        assert_eq!(r.time(), &[0.0, 0.1, 0.2, 0.3]);
        assert_eq!(r.velocity(), &[0.0, 1.0, 0.5, -0.2]);
        assert_eq!((r.x0, r.v0, r.weight), (0.01, 0.0, 1.0));
        assert_eq!(r.channels(), vec![Channel::Velocity]);
        assert!(r.normal_force().is_none());
        r.validate(4).unwrap();
    }

    /// A clone shares the samples (a fit and each model of a comparison clone their
    /// records) until one of them changes its own: the other keeps its values.
    #[test]
    fn clones_share_the_samples_until_one_changes_them() {
        let time: Vec<f64> = (0..100).map(|i| i as f64 * 1e-3).collect();
        let v: Vec<f64> = time.iter().map(|t| (10.0 * t).sin()).collect();
        let original = Record::new("r", time, v.clone(), 0.01);
        let mut copy = original.clone();
        assert!(std::ptr::eq(copy.time(), original.time()));
        assert!(std::ptr::eq(copy.velocity(), original.velocity()));
        copy.velocity_mut()[3] = 7.0;
        assert_eq!(copy.velocity()[3], 7.0);
        assert_eq!(original.velocity(), v.as_slice());
        assert!(std::ptr::eq(copy.time(), original.time()));
    }

    #[test]
    fn channels_and_sampled_normal_force() {
        let r = record()
            .with_channel(Channel::Force, vec![1.0; 4])
            .with_channel(Channel::NormalForce, vec![5.0, 5.0, 6.0, 6.0]);
        assert_eq!(
            r.channels(),
            vec![Channel::Velocity, Channel::Force, Channel::NormalForce]
        );
        assert_eq!(r.normal_force().map(|n| n.mean()), Some(5.5));
        let osc = crate::oscillator::Oscillator::fmm();
        assert_eq!(r.normal_force_with(&osc).at(2), 6.0);
        assert_eq!(
            record().normal_force_with(&osc),
            NormalForce::Constant(14.5)
        );
        let tail = r.starting_at(2);
        assert_eq!(tail.time(), &[0.2, 0.3]);
        assert_eq!(tail.channel(Channel::NormalForce), Some(&[6.0, 6.0][..]));
        assert_eq!(tail.velocity(), &[0.5, -0.2]);
    }

    /// Named channels are cut with the record, checked like the others and listed by name.
    #[test]
    fn named_channels_follow_the_cuts_and_the_checks() {
        let r = record().with_named_channel("load", vec![1.0, 2.0, 3.0, 4.0]);
        assert_eq!(r.named_channels(), vec!["load"]);
        assert_eq!(
            r.starting_at(1).named_channel("load"),
            Some(&[2.0, 3.0, 4.0][..])
        );
        assert_eq!(r.ending_at(2).named_channel("load"), Some(&[1.0, 2.0][..]));
        assert_eq!(r.named_channel("temperature"), None);
        r.validate(4).unwrap();
        let short = record().with_named_channel("load", vec![1.0]);
        assert_eq!(
            short.validate(2).unwrap_err().to_string(),
            "record `r`: 4 time stamps but 1 samples of channel `load`"
        );
        let nan = record().with_named_channel("load", vec![1.0, f64::NAN, 0.0, 0.0]);
        assert_eq!(
            nan.validate(2).unwrap_err().to_string(),
            "record `r`: channel `load` sample 1 is NaN (values must be finite)"
        );
    }

    #[test]
    fn validate_names_what_is_wrong() {
        let msg = |r: &Record| r.validate(3).unwrap_err().to_string();
        let short = Record::new("r", vec![0.0, 0.1, 0.2], vec![0.0; 2], 0.0);
        assert_eq!(msg(&short), "record `r`: 3 time stamps but 2 velocities");
        let repeated = Record::new("r", vec![0.0, 0.1, 0.1], vec![0.0; 3], 0.0);
        assert_eq!(
            msg(&repeated),
            "record `r`: time is not strictly increasing at sample 2 (t = 0.1 then 0.1)"
        );
        let nan = Record::new("r", vec![0.0, 0.1, 0.2], vec![0.0, f64::NAN, 0.0], 0.0);
        assert_eq!(
            msg(&nan),
            "record `r`: sample 1 is not finite (t = 0.1, v = NaN)"
        );
        let force_only = Record::from_time_base("r", TimeBase::new(vec![0.0, 1.0]).unwrap())
            .with_channel(Channel::Force, vec![0.0, 1.0]);
        assert_eq!(
            msg(&force_only),
            "record `r`: no velocity channel (the record has: force)"
        );
        let few = record();
        assert_eq!(
            few.validate(5).unwrap_err().to_string(),
            "record `r`: 4 samples, at least 5 needed"
        );
    }
}
