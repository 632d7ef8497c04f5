//! The force domain's residuals: the model's friction force along the measured motion against a
//! target force ([`ForceAlongMotion`]).
//!
//! The measured motion is replayed, not simulated: the model's internal states travel the
//! measured displacement's increments between samples where a record has a displacement
//! channel, else the velocity channel's (`[fit.options] replay_path`, the conventions of
//! [`crate::energy::model_force`]), under the record's normal force (its channel where there
//! is one); the laws' rate-dependent terms and the force read the velocity channel (or the
//! differentiated displacement when only a displacement is measured). The target is, per
//! record,
//!
//! - the measured `force` channel (a tribometer, a driven rig), optionally with a constant
//!   offset per record (a load cell's zero, [`NuisanceKind::ForceOffset`]); or
//! - the energy-based force of Eq. 7 ([`crate::energy::analyze_record`]), masked near v = 0
//!   and after the final stop: the paper's own route, with no force sensor. It needs m, c
//!   and k; a measured force needs none of them; or
//! - the measured input force u of a driven axis (inverse dynamics, [`super::inverse_dynamics`]):
//!   the prediction is then J a + c v + R(q) + F + offset, with the oscillator properties
//!   named in `[fit.options] oscillator` fitted with the law.
//!
//! Without a normal force (neither `[oscillator] normal_force` nor a record's), the levels
//! are forces ([`FrictionLevels`]): N = 1 and their bounds from the largest force compared.
//!
//! With `[fit.options] min_speed`, only the samples where the motion slides (|v| >=
//! min_speed) are compared: the stick phases at reversals hold a force below the sliding
//! level that a static law cannot follow, and would drag its level down.
//!
//! Residuals are `sqrt(weight) (model + offset - target) / sigma`, with sigma the record's
//! noise level estimated from the target ([`crate::record::noise::noise_floor_level`] of its first differences), so records of different noise
//! weigh as they should in a joint fit. Nothing is simulated, so a force-domain fit costs a
//! few milliseconds per evaluation and has no phase errors to trap the optimiser: it is also
//! the prefit of velocity fits of dynamic models (run by [`crate::identify::fit::fit`]).

mod checks;
mod guards;
mod track;

pub use checks::check_force_domain;
pub use guards::{require_mechanics, require_oscillator};
use track::target_source;

use super::inverse_dynamics::{linear_start, Balance, BalanceSamples, LinearStart};
use super::residuals::{Evaluation, JacobianColumns, RecordCase, Residuals, Segment};
use super::state_cache::StateCache;
use crate::energy::model_force::{force_derivatives_checked, states_along_checked};
use crate::energy::EnergyOptions;
use crate::energy::{forces_in, ForceDerivatives};
use crate::error::EngineError;
use crate::identify::values::fit_options::FitOptions;
use crate::identify::values::layout::{FreeParam, ParamKind};
use crate::identify::values::levels::FrictionLevels;
use crate::identify::values::nuisance::NuisanceKind;
use crate::identify::values::result::{
    ForceBalance, SampleAxes, SlidingSamples, UnreliableSamples,
};
use crate::identify::values::target_options::ForceTarget;
use crate::oscillator::{Oscillator, OscillatorProperty};
use crate::record::{ConditionSource, NormalForce, Record};
use frictionid_models::{FrictionModel, GuessHint};
use std::sync::Arc;

/// Where a record's target force comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TargetSource {
    /// The measured `force` channel.
    Measured,
    /// The energy-based force of Eq. 7.
    EnergyBased,
    /// The measured input force, against the balance of inverse dynamics.
    InverseDynamics,
}

/// One record's motion, normal force and target, prepared once per fit.
#[derive(Debug, Clone)]
pub struct ForceTrack {
    /// Where the target comes from.
    pub source: TargetSource,
    time: Vec<f64>,
    velocity: Vec<f64>,
    displacement: Vec<f64>,
    /// Whether the replay travels the displacement's increments (`[fit.options]
    /// replay_path`), else the velocity's.
    follows_displacement: bool,
    normal: NormalForce,
    /// Indices of the compared samples (all, or those where Eq. 7 is defined).
    used: Vec<usize>,
    /// The target force at the compared samples \[N\].
    target: Vec<f64>,
    /// The samples kept by `min_speed`, when it is given.
    sliding: Option<SlidingSamples>,
    /// The sliding samples left out because their target is unreliable.
    unreliable: Option<UnreliableSamples>,
    /// Noise level of the target \[N\].
    pub noise: f64,
    /// The oscillator's terms of an inverse-dynamics target.
    balance: Option<Balance>,
    /// What a law's conditions read along the record (x, a, u, named channels).
    conditions: ConditionSource,
    /// The replay's intervals along the motion (`CheckedMotion::intervals`): every
    /// evaluation of a fit replays the same motion.
    intervals: Vec<frictionid_models::Interval>,
}

/// The force-domain residual producer.
#[derive(Debug, Clone)]
pub struct ForceAlongMotion {
    tracks: Vec<ForceTrack>,
    nuisance: Vec<NuisanceKind>,
    /// Whether the law's levels are coefficients or forces (no normal force given).
    levels: FrictionLevels,
    /// The linear inverse-dynamics estimate (inverse dynamics only).
    start: Option<LinearStart>,
    /// States of recent predictions: a force-only parameter's column reuses them.
    states: StateCache,
}

impl ForceAlongMotion {
    /// The producer for `records` under `opts` (`force_target`, `force_offset`, the energy
    /// options for Eq. 7, the oscillator keys not given and, for inverse dynamics, the
    /// oscillator properties fitted).
    pub fn new(
        records: &[Record],
        osc: &Oscillator,
        opts: &FitOptions,
    ) -> Result<Self, EngineError> {
        let unit_normal = FrictionLevels::read_as_forces(&opts.target.unknown_oscillator, records);
        let mut tracks = Vec::with_capacity(records.len());
        for record in records {
            let err = |reason: String| EngineError::Record {
                record: record.name.clone(),
                reason,
            };
            let source = target_source(record, opts.target.force_target).map_err(err)?;
            if opts.target.force_offset && source == TargetSource::EnergyBased {
                return Err(err(
                    "[fit.options] force_offset = true needs a measured force channel or \
                     force_target = \"inverse_dynamics\" (this record is fitted to the \
                     energy-based force)"
                        .into(),
                ));
            }
            tracks.push(ForceTrack::new(record, source, osc, opts, unit_normal)?);
        }
        let nuisance = if opts.target.force_offset {
            vec![NuisanceKind::ForceOffset]
        } else {
            Vec::new()
        };
        let mut producer = Self {
            tracks,
            nuisance,
            levels: FrictionLevels::Coefficients,
            start: None,
            states: StateCache::default(),
        };
        if opts.target.force_target == ForceTarget::InverseDynamics {
            producer.start = producer.linear_start(osc, &opts.params.oscillator);
        }
        if unit_normal {
            let at = producer.start.as_ref().map_or(osc, |s| &s.oscillator);
            producer.levels = FrictionLevels::Forces {
                largest: producer.largest_friction(at),
            };
        }
        Ok(producer)
    }

    /// Every record gives `model` the conditions it reads (x, a, u, its named channels): an
    /// error naming the first record and condition that does not.
    pub fn check_conditions(&self, model: &dyn FrictionModel) -> Result<(), EngineError> {
        let wanted = model.conditions();
        for track in &self.tracks {
            track.conditions.bind(&wanted)?;
        }
        Ok(())
    }

    /// The prepared record `index`.
    pub fn track(&self, index: usize) -> Option<&ForceTrack> {
        self.tracks.get(index)
    }

    /// The mean normal force over every record \[N\].
    pub fn mean_normal_force(&self) -> f64 {
        let sum: f64 = self.tracks.iter().map(|t| t.normal.mean()).sum();
        sum / self.tracks.len().max(1) as f64
    }

    /// Whether the law's levels are coefficients or forces.
    pub fn levels(&self) -> FrictionLevels {
        self.levels
    }

    /// The oscillator an inverse-dynamics fit starts from: `osc` with the properties in
    /// `fitted` at the linear estimate (`osc` itself without one).
    pub fn starting_oscillator(
        &self,
        osc: &Oscillator,
        fitted: &[OscillatorProperty],
    ) -> Oscillator {
        let Some(start) = &self.start else {
            return *osc;
        };
        let mut out = *osc;
        for p in fitted {
            if let Some(value) = p.value(&start.oscillator) {
                p.set(&mut out, value);
            }
        }
        out
    }

    /// The linear inverse-dynamics estimate over every record (see
    /// [`super::inverse_dynamics::linear_start`]).
    fn linear_start(&self, osc: &Oscillator, fitted: &[OscillatorProperty]) -> Option<LinearStart> {
        let samples: Vec<BalanceSamples<'_>> = self
            .tracks
            .iter()
            .filter_map(|t| {
                let balance = t.balance.as_ref()?;
                Some(BalanceSamples {
                    used: &t.used,
                    input: &t.target,
                    motion: [&balance.acceleration, &t.velocity, &t.displacement],
                    restoring: balance.restoring,
                })
            })
            .collect();
        linear_start(&samples, osc, fitted)
    }

    /// The largest |friction force| compared: the target, less the oscillator's terms at
    /// `osc` for inverse dynamics.
    fn largest_friction(&self, osc: &Oscillator) -> f64 {
        self.tracks
            .iter()
            .flat_map(|t| t.friction_target(osc))
            .fold(0.0, |m, f| m.max(f.abs()))
    }

    /// The model's states along track `index` (a dynamic model), from the cache when the
    /// model's parameters were evaluated last time.
    fn states_of(
        &self,
        index: usize,
        at: &Evaluation<'_>,
        track: &ForceTrack,
    ) -> Result<Arc<Vec<f64>>, EngineError> {
        self.states.states(index, at.model, || {
            at.count_simulation();
            states_along_checked(at.model, track.motion())
        })
    }

    fn track_of(&self, index: usize, record: &Record) -> Result<&ForceTrack, EngineError> {
        self.tracks.get(index).ok_or_else(|| EngineError::Record {
            record: record.name.clone(),
            reason: format!("no prepared force track {index}"),
        })
    }

    /// The friction law's force at the compared samples of track `index`.
    fn friction_at(
        &self,
        at: &Evaluation<'_>,
        index: usize,
        record: &Record,
    ) -> Result<Vec<f64>, EngineError> {
        let track = self.track_of(index, record)?;
        let states = if at.model.n_states() == 0 {
            at.count_simulation();
            Arc::new(Vec::new())
        } else {
            self.states_of(index, at, track)
                .map_err(|e| EngineError::Record {
                    record: record.name.clone(),
                    reason: e.to_string(),
                })?
        };
        let conditions = track.conditions.bind(&at.model.conditions())?;
        Ok(forces_in(
            at.model,
            &track.velocity,
            &track.normal,
            &states,
            track.used.iter().copied(),
            &conditions,
        ))
    }

    /// The law's force and its parameter derivatives at the compared samples of `track`, from
    /// one replay with sensitivities (`None`: the law has no gradient, or the replay failed).
    fn law_derivatives(
        &self,
        at: &Evaluation<'_>,
        track: &ForceTrack,
    ) -> Result<Option<ForceDerivatives>, EngineError> {
        let conditions = track.conditions.bind(&at.model.conditions())?;
        let law = force_derivatives_checked(at.model, track.motion(), &track.used, &conditions);
        if law.is_some() && at.model.n_states() > 0 {
            at.count_simulation();
        }
        Ok(law)
    }

    /// The prediction of record `case` from the law's `force` at its compared samples: plus
    /// the offset and, for inverse dynamics, J a + c v + R(q) at the evaluated oscillator.
    fn completed(
        &self,
        at: &Evaluation<'_>,
        case: RecordCase<'_>,
        mut force: Vec<f64>,
    ) -> Result<Vec<f64>, EngineError> {
        let nuisance = case.nuisance;
        let track = self.track_of(case.index, case.record)?;
        if let Some(balance) = &track.balance {
            for (f, &i) in force.iter_mut().zip(&track.used) {
                *f +=
                    balance.axis_force(at.oscillator, i, track.velocity[i], track.displacement[i]);
            }
        }
        if nuisance.force_offset != 0.0 {
            force.iter_mut().for_each(|f| *f += nuisance.force_offset);
        }
        Ok(force)
    }
}

impl Residuals for ForceAlongMotion {
    fn channel(&self) -> &'static str {
        "force"
    }

    /// `force` for a measured force, `energy_based_force` for Eq. 7, `input_force` for
    /// inverse dynamics.
    fn record_channel(&self, index: usize) -> &'static str {
        match self.tracks.get(index).map(|t| t.source) {
            Some(TargetSource::EnergyBased) => "energy_based_force",
            Some(TargetSource::InverseDynamics) => "input_force",
            _ => "force",
        }
    }

    fn unit(&self) -> &'static str {
        "N"
    }

    fn nuisance(&self) -> &[NuisanceKind] {
        &self.nuisance
    }

    fn measured<'a>(&'a self, index: usize, _record: &'a Record) -> &'a [f64] {
        self.tracks
            .get(index)
            .map(|t| t.target.as_slice())
            .unwrap_or_default()
    }

    /// The law's force plus the offset; for inverse dynamics plus J a + c v + R(q) at the
    /// evaluated oscillator, so that the oscillator properties' columns are the balance's.
    fn predict(&self, at: &Evaluation<'_>, case: RecordCase<'_>) -> Result<Vec<f64>, EngineError> {
        let friction = self.friction_at(at, case.index, case.record)?;
        self.completed(at, case, friction)
    }

    fn friction_levels(&self) -> FrictionLevels {
        self.levels
    }

    /// The balance's terms at the fitted values (inverse dynamics only).
    fn force_balance(
        &self,
        at: &Evaluation<'_>,
        case: RecordCase<'_>,
    ) -> Result<Option<ForceBalance>, EngineError> {
        let track = self.track_of(case.index, case.record)?;
        let Some(balance) = &track.balance else {
            return Ok(None);
        };
        let osc = at.oscillator;
        let offset = case.nuisance.force_offset;
        let pick = |f: &dyn Fn(usize) -> f64| track.used.iter().map(|&i| f(i)).collect();
        let inertia: Vec<f64> = pick(&|i| osc.mass * balance.acceleration[i]);
        let damping: Vec<f64> = pick(&|i| osc.damping * track.velocity[i]);
        let restoring: Vec<f64> = pick(&|i| balance.restoring_at(osc, track.displacement[i]));
        let friction_balance = (0..track.used.len())
            .map(|k| track.target[k] - inertia[k] - damping[k] - restoring[k] - offset)
            .collect();
        Ok(Some(ForceBalance {
            input: track.target.clone(),
            inertia,
            damping,
            restoring,
            offset,
            friction_fitted: self.friction_at(at, case.index, case.record)?,
            friction_balance,
        }))
    }

    /// One segment, weighted by the target's noise level: records of different noise weigh
    /// as they should in a joint fit.
    fn segments(&self, index: usize, record: &Record) -> Vec<Segment> {
        let noise = self.tracks.get(index).map_or(1.0, |t| t.noise);
        vec![self.record_segment(index, record, Some(noise))]
    }

    fn check_record(&self, record: &Record) -> Result<(), EngineError> {
        record.validate_channels(3)
    }

    fn has_jacobian(&self) -> bool {
        true
    }

    /// The law's columns from one replay with sensitivities (where the law has exact steps
    /// and a parameter gradient: `energy::model_force::force_derivatives_along`), the offset's
    /// and the balance's linear terms; each weighted as the residuals are.
    fn jacobian_columns(
        &self,
        at: &Evaluation<'_>,
        case: RecordCase<'_>,
        layout: &[FreeParam],
    ) -> Result<JacobianColumns, EngineError> {
        let track = self.track_of(case.index, case.record)?;
        let law = if asks_for_the_law(layout) {
            self.law_derivatives(at, track)?
        } else {
            None
        };
        Ok(track.columns(at, case, layout, law.as_ref()))
    }

    /// For a law with states, the residuals and the columns from the one replay with
    /// sensitivities the columns need: the replay's forces are the prediction's friction.
    fn residuals_with_columns(
        &self,
        at: &Evaluation<'_>,
        case: RecordCase<'_>,
        layout: &[FreeParam],
    ) -> Result<Option<(Vec<f64>, JacobianColumns)>, EngineError> {
        if at.model.n_states() == 0 || !asks_for_the_law(layout) {
            return Ok(None);
        }
        let track = self.track_of(case.index, case.record)?;
        let Some(law) = self.law_derivatives(at, track)? else {
            return Ok(None);
        };
        let columns = track.columns(at, case, layout, Some(&law));
        let predicted = self.completed(at, case, law.force)?;
        let residuals = self.weighted(case.index, case.record, predicted)?;
        Ok(Some((residuals, columns)))
    }

    /// The friction level from the target (mean |F| over the compared samples over the mean
    /// normal force; for inverse dynamics the linear estimate's Coulomb level), the typical
    /// speed from the motion.
    fn hint(&self, osc: &Oscillator, _records: &[Record], _energy: &EnergyOptions) -> GuessHint {
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        let levels: Vec<f64> = match &self.start {
            Some(start) => vec![start.coulomb],
            None => self
                .tracks
                .iter()
                .map(|t| mean(&t.target.iter().map(|f| f.abs()).collect::<Vec<_>>()))
                .collect(),
        };
        let speeds: Vec<f64> = self
            .tracks
            .iter()
            .map(|t| 0.5 * t.velocity.iter().fold(0.0f64, |m, v| m.max(v.abs())))
            .collect();
        let n = self.mean_normal_force();
        let mu = mean(&levels) / n;
        GuessHint {
            mu: if mu.is_finite() && mu > 0.0 {
                self.levels.clamp_guess(mu)
            } else {
                0.2
            },
            typical_velocity: Some(mean(&speeds)).filter(|s| *s > 0.0).unwrap_or(0.05),
            normal_force: n,
            stiffness: osc.stiffness,
            mass: osc.mass,
        }
    }

    fn simulates_response(&self) -> bool {
        false
    }

    fn measures_friction(&self, index: usize) -> bool {
        self.tracks
            .get(index)
            .is_some_and(|t| t.source == TargetSource::Measured && t.sliding.is_none())
    }

    fn sliding_samples(&self, index: usize) -> Option<SlidingSamples> {
        self.tracks.get(index).and_then(|t| t.sliding)
    }

    fn unreliable_samples(&self, index: usize) -> Option<UnreliableSamples> {
        self.tracks.get(index).and_then(|t| t.unreliable.clone())
    }

    fn sample_axes(&self, index: usize, record: &Record) -> SampleAxes {
        let Some(t) = self.tracks.get(index) else {
            return SampleAxes {
                time: record.time().to_vec(),
                ..SampleAxes::default()
            };
        };
        let pick = |v: &[f64]| t.used.iter().map(|&i| v[i]).collect();
        SampleAxes {
            time: pick(&t.time),
            displacement: pick(&t.displacement),
            velocity: pick(&t.velocity),
        }
    }
}

/// Whether any of the free parameters `layout` is the law's (its columns need the replay).
fn asks_for_the_law(layout: &[FreeParam]) -> bool {
    layout.iter().any(|f| matches!(f.kind, ParamKind::Model(_)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::values::target_options::{FitDomain, TargetOptions};
    use crate::record::Channel;
    use crate::record::TimeBase;

    fn record(channels: &[(Channel, Vec<f64>)]) -> Record {
        let time = TimeBase::new((0..50).map(|i| i as f64 * 1e-2).collect()).unwrap();
        channels
            .iter()
            .fold(Record::from_time_base("r", time), |r, (c, v)| {
                r.with_channel(*c, v.clone())
            })
    }

    #[test]
    fn targets_follow_the_channels_and_the_request() {
        let x: Vec<f64> = (0..50).map(|i| 1e-3 * (i as f64 * 0.1).sin()).collect();
        let with_force = record(&[
            (Channel::Displacement, x.clone()),
            (Channel::Force, vec![1.0; 50]),
        ]);
        let osc = Oscillator::fmm();
        let opts = FitOptions {
            target: TargetOptions {
                domain: FitDomain::Force,
                ..TargetOptions::default()
            },
            ..FitOptions::default()
        };
        let t = ForceAlongMotion::new(std::slice::from_ref(&with_force), &osc, &opts)
            .unwrap()
            .tracks
            .remove(0);
        assert_eq!(t.source, TargetSource::Measured);
        // The velocity is the central difference of the displacement.
        let v = crate::energy::central_difference(with_force.time(), &x);
        assert_eq!(t.velocity, v);
        let bare = record(&[(Channel::Displacement, x)]);
        let measured = FitOptions {
            target: TargetOptions {
                force_target: ForceTarget::Measured,
                ..opts.target.clone()
            },
            ..opts.clone()
        };
        let e = ForceAlongMotion::new(std::slice::from_ref(&bare), &osc, &measured).unwrap_err();
        assert_eq!(
            e.to_string(),
            "record `r`: [fit.options] force_target = \"measured\" but the record has no force \
             channel (it has: displacement; name its column with `force_column`)"
        );
        let no_mechanics = FitOptions {
            target: TargetOptions {
                unknown_oscillator: vec![OscillatorProperty::Mass, OscillatorProperty::Stiffness],
                ..opts.target.clone()
            },
            ..opts.clone()
        };
        let e = ForceAlongMotion::new(std::slice::from_ref(&bare), &osc, &no_mechanics)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("[oscillator]: the energy-based force (Eq. 7) needs mass, damping and stiffness; `mass`, `stiffness` not given"),
            "{e}"
        );
        let no_motion = record(&[(Channel::Force, vec![1.0; 50])]);
        let e = ForceAlongMotion::new(&[no_motion], &osc, &opts)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(
                "needs the motion: a velocity or displacement channel (the record has: force)"
            ),
            "{e}"
        );
    }
}
