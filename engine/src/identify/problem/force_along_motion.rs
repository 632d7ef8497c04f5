//! The force domain's residuals: the model's friction force along the measured motion against a
//! target force ([`ForceAlongMotion`]).
//!
//! The measured motion is replayed, not simulated: the velocity channel (or the differentiated
//! displacement when only a displacement is measured) drives the model's internal states,
//! integrated along it by [`crate::energy::model_force_with_normal`] under the record's normal
//! force (its channel where there is one). The target is, per record,
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

use super::inverse_dynamics::{
    linear_start, sliding_samples, Balance, BalanceSamples, LinearStart,
};
use super::residuals::{Evaluation, JacobianColumns, RecordCase, Residuals, Segment};
use super::state_cache::StateCache;
use crate::axis::Axis;
use crate::energy::forces_at;
use crate::energy::model_force::{
    check_motion, force_derivatives_checked, states_along_checked, CheckedMotion,
};
use crate::energy::{analyze_record, record_motion, EnergyOptions};
use crate::error::EngineError;
use crate::identify::values::fit_options::FitOptions;
use crate::identify::values::layout::{FreeParam, ParamKind};
use crate::identify::values::levels::FrictionLevels;
use crate::identify::values::nuisance::NuisanceKind;
use crate::identify::values::result::{
    ForceBalance, SampleAxes, SlidingSamples, UnreliableSamples,
};
use crate::identify::values::target_options::{FitDomain, ForceTarget};
use crate::oscillator::{Oscillator, OscillatorProperty};
use crate::record::noise::noise_floor_level;
use crate::record::{channel_list, Channel, NormalForce, Record};
use frictionid_models::GuessHint;
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

/// The oscillator properties a force-domain fit on the energy-based force, a velocity fit or
/// an energy analysis needs, and the message (naming them on `axis`) when `missing` holds
/// any of them. The one place of this rule.
pub fn require_mechanics(
    missing: &[OscillatorProperty],
    axis: Axis,
    purpose: &str,
) -> Result<(), EngineError> {
    use OscillatorProperty::{Damping, Mass, Stiffness};
    require_properties(missing, axis, &[Mass, Damping, Stiffness], purpose)
}

/// Every oscillator property, the normal force included, is given: what a simulation of the
/// oscillator needs (a placeholder N = 0 would silently simulate no friction at all).
pub fn require_oscillator(
    missing: &[OscillatorProperty],
    axis: Axis,
    purpose: &str,
) -> Result<(), EngineError> {
    use OscillatorProperty::{Damping, Mass, NormalForce, Stiffness};
    require_properties(
        missing,
        axis,
        &[Mass, Damping, Stiffness, NormalForce],
        purpose,
    )
}

/// `a, b and c`.
fn spoken_list(items: &[&str]) -> String {
    match items.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => items.join(""),
    }
}

/// None of the `needed` properties is among the `missing` ones; otherwise an error naming
/// those that are, as `axis` names them.
fn require_properties(
    missing: &[OscillatorProperty],
    axis: Axis,
    needed: &[OscillatorProperty],
    purpose: &str,
) -> Result<(), EngineError> {
    let absent: Vec<&str> = needed
        .iter()
        .filter(|p| missing.contains(p))
        .map(|p| p.name_on(axis))
        .collect();
    if absent.is_empty() {
        return Ok(());
    }
    let needed: Vec<&str> = needed.iter().map(|p| p.name_on(axis)).collect();
    Err(EngineError::InvalidInput(format!(
        "[oscillator]: {purpose} needs {}; `{}` not given (only a force-domain fit on a \
         measured force channel does without mass, damping and stiffness)",
        spoken_list(&needed),
        absent.join("`, `")
    )))
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
        Ok(forces_at(
            at.model,
            &track.velocity,
            &track.normal,
            &states,
            track.used.iter().copied(),
        ))
    }
}

impl ForceTrack {
    /// Prepares `record`: its motion, its normal force (1 N when `unit_normal`: no normal
    /// force given anywhere) and its target from `source`.
    fn new(
        record: &Record,
        source: TargetSource,
        osc: &Oscillator,
        opts: &FitOptions,
        unit_normal: bool,
    ) -> Result<Self, EngineError> {
        let err = |reason: String| EngineError::Record {
            record: record.name.clone(),
            reason,
        };
        record.validate_channels(3)?;
        let motion = record_motion(record).ok_or_else(|| {
            err(format!(
                "a force-domain fit needs the motion: a velocity or displacement channel (the \
                 record has: {}); name its column with `velocity_column` or \
                 `displacement_column`",
                channel_list(&record.channels())
            ))
        })?;
        let normal = FrictionLevels::record_normal_force(
            record,
            osc,
            &opts.target.unknown_oscillator,
            unit_normal,
        )
        .map_err(err)?;
        let mut balance = None;
        let mut unreliable = None;
        let (used, target) = match source {
            TargetSource::Measured => {
                let f = record.channel(Channel::Force).unwrap_or_default().to_vec();
                ((0..f.len()).collect(), f)
            }
            TargetSource::EnergyBased => {
                require_mechanics(
                    &opts.target.unknown_oscillator,
                    osc.axis,
                    "the energy-based force (Eq. 7)",
                )?;
                energy_target(record, osc, &opts.energy)?
            }
            TargetSource::InverseDynamics => {
                let threshold = opts.energy.velocity_threshold;
                let axis = Balance::new(record, &motion.v, has_restoring(osc, opts))
                    .map_err(|e| err(e.to_string()))?;
                let u = record.channel(Channel::InputForce).unwrap_or_default();
                let sliding = sliding_samples(&motion.v, threshold);
                unreliable = axis.left_out(&sliding, record.time());
                let used = axis.reliable(sliding);
                balance = Some(axis);
                let target = used.iter().map(|&i| u[i]).collect();
                (used, target)
            }
        };
        check_motion(record.time(), &motion.v, &normal).map_err(|e| err(e.to_string()))?;
        let (used, target, sliding) = keep_sliding(used, target, &motion.v, opts.target.min_speed);
        if sliding.is_some_and(|s| s.kept < 2) {
            return Err(err(format!(
                "{} samples slide with |v| >= [fit.options] min_speed = {} m/s; lower it",
                target.len(),
                opts.target.min_speed.unwrap_or_default()
            )));
        }
        if target.len() < 2 {
            return Err(err(format!(
                "{} samples to compare the model force with (Eq. 7 and the inverse-dynamics \
                 force are masked where |v| <= [energy] velocity_threshold = {} m/s)",
                target.len(),
                opts.energy.velocity_threshold
            )));
        }
        let noise_channel = match source {
            TargetSource::Measured => Some(Channel::Force),
            TargetSource::InverseDynamics => Some(Channel::InputForce),
            TargetSource::EnergyBased => None,
        };
        Ok(Self {
            source,
            time: record.time().to_vec(),
            velocity: motion.v,
            displacement: motion.x,
            normal,
            noise: noise_channel
                .and_then(|c| record.given_noise(c))
                .unwrap_or_else(|| noise_floor_level(&target, 1)),
            used,
            target,
            balance,
            sliding,
            unreliable,
        })
    }

    /// The record's motion and normal force, checked when the track was prepared.
    fn motion(&self) -> CheckedMotion<'_> {
        CheckedMotion {
            time: &self.time,
            v: &self.velocity,
            normal: &self.normal,
        }
    }

    /// The derivative of the prediction at the compared samples with respect to the
    /// oscillator property or nuisance parameter `kind` at `osc`: the balance's terms are
    /// linear in J, c, the input offset and a linear spring's k, the force offset adds
    /// itself to record `index` only. `None` for what is not that simple (a restoring law's
    /// own parameters, another law's stiffness).
    fn balance_column(&self, kind: ParamKind, index: usize, osc: &Oscillator) -> Option<Vec<f64>> {
        let pick = |f: &dyn Fn(usize) -> f64| Some(self.used.iter().map(|&i| f(i)).collect());
        let zeros = || Some(vec![0.0; self.used.len()]);
        match (kind, &self.balance) {
            (
                ParamKind::Nuisance {
                    kind: NuisanceKind::ForceOffset,
                    record,
                },
                _,
            ) => {
                if record == index {
                    Some(vec![1.0; self.used.len()])
                } else {
                    zeros()
                }
            }
            (ParamKind::Nuisance { record, .. }, _) if record != index => zeros(),
            (ParamKind::Nuisance { .. } | ParamKind::Model(_), _) => None,
            (_, None) => zeros(),
            (ParamKind::Property(p), Some(b)) if p.is_restoring() && !b.restoring => zeros(),
            (ParamKind::Property(p), Some(b)) if p.balance_column_exact(osc) => pick(&|i| {
                p.balance_column(b.acceleration[i], self.velocity[i], self.displacement[i])
            }),
            (ParamKind::Property(_), Some(_)) => None,
        }
    }

    /// The oscillator's terms J a + c v + R(q) at the compared samples (inverse dynamics;
    /// empty otherwise).
    fn axis_forces(&self, osc: &Oscillator) -> Vec<f64> {
        let Some(balance) = &self.balance else {
            return Vec::new();
        };
        self.used
            .iter()
            .map(|&i| balance.axis_force(osc, i, self.velocity[i], self.displacement[i]))
            .collect()
    }

    /// The friction force the target implies at `osc`: the target itself, or for inverse
    /// dynamics u - J a - c v - R(q).
    fn friction_target(&self, osc: &Oscillator) -> Vec<f64> {
        let axis = self.axis_forces(osc);
        if axis.is_empty() {
            return self.target.clone();
        }
        self.target.iter().zip(&axis).map(|(u, a)| u - a).collect()
    }
}

/// The compared samples `used` (with their `target`) where |v| >= `min_speed`, and how many
/// were kept; all of them without a `min_speed`.
fn keep_sliding(
    used: Vec<usize>,
    target: Vec<f64>,
    velocity: &[f64],
    min_speed: Option<f64>,
) -> (Vec<usize>, Vec<f64>, Option<SlidingSamples>) {
    let Some(min_speed) = min_speed else {
        return (used, target, None);
    };
    let of = used.len();
    let (used, target): (Vec<usize>, Vec<f64>) = used
        .into_iter()
        .zip(target)
        .filter(|&(i, _)| velocity.get(i).is_some_and(|v| v.abs() >= min_speed))
        .unzip();
    let sliding = SlidingSamples {
        min_speed,
        kept: used.len(),
        of,
    };
    (used, target, Some(sliding))
}

/// Whether an inverse-dynamics balance has a restoring force: a restoring law other than the
/// linear spring carries its own parameters; the spring needs its stiffness given or fitted
/// (an axis without a spring gives no `stiffness`).
fn has_restoring(osc: &Oscillator, opts: &FitOptions) -> bool {
    !osc.restoring.is_linear_spring()
        || opts
            .params
            .oscillator
            .contains(&OscillatorProperty::Stiffness)
        || !opts.target.is_unknown(OscillatorProperty::Stiffness)
}

/// The target of a record under `force_target`.
fn target_source(record: &Record, wanted: ForceTarget) -> Result<TargetSource, String> {
    let has_force = record.channel(Channel::Force).is_some();
    match (wanted, has_force) {
        (ForceTarget::Measured, false) => Err(format!(
            "[fit.options] force_target = \"measured\" but the record has no force channel \
             (it has: {}; name its column with `force_column`)",
            channel_list(&record.channels())
        )),
        (ForceTarget::Measured, true) | (ForceTarget::Auto, true) => Ok(TargetSource::Measured),
        (ForceTarget::Energy, _) | (ForceTarget::Auto, false) => Ok(TargetSource::EnergyBased),
        (ForceTarget::InverseDynamics, _) if record.channel(Channel::InputForce).is_none() => {
            Err(format!(
                "[fit.options] force_target = \"inverse_dynamics\" but the record has no input \
                 force channel (it has: {}; name its column with `input_force_column`)",
                channel_list(&record.channels())
            ))
        }
        (ForceTarget::InverseDynamics, _) => Ok(TargetSource::InverseDynamics),
    }
}

fn energy_target(
    record: &Record,
    osc: &Oscillator,
    energy: &EnergyOptions,
) -> Result<(Vec<usize>, Vec<f64>), EngineError> {
    let analysed = analyze_record(record, osc, energy)?;
    Ok(analysed
        .friction
        .iter()
        .enumerate()
        .filter(|(_, f)| f.is_finite())
        .map(|(i, &f)| (i, f))
        .unzip())
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
        let (index, record, nuisance) = (case.index, case.record, case.nuisance);
        let mut force = self.friction_at(at, index, record)?;
        let track = self.track_of(index, record)?;
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
        vec![Segment {
            channel: self.record_channel(index),
            unit: self.unit(),
            len: self.measured(index, record).len(),
            noise: Some(noise),
            scale: 1.0 / noise,
        }]
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
        let weight = case.record.weight.sqrt() / track.noise;
        let wanted = layout.iter().any(|f| matches!(f.kind, ParamKind::Model(_)));
        let law = wanted
            .then(|| force_derivatives_checked(at.model, track.motion(), &track.used))
            .flatten();
        if law.is_some() && at.model.n_states() > 0 {
            at.count_simulation();
        }
        let columns = layout.iter().map(|f| {
            let column = match (f.kind, &law) {
                (ParamKind::Model(j), Some(d)) if d.given.get(j).copied().unwrap_or(false) => {
                    Some((0..track.used.len()).map(|k| d.at(k, j)).collect())
                }
                (ParamKind::Model(_), _) => None,
                (kind, _) => track.balance_column(kind, case.index, at.oscillator),
            };
            column.map(|c: Vec<f64>| c.into_iter().map(|x| weight * x).collect())
        });
        Ok(columns.collect())
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

/// Options that only a velocity fit has, as the `[fit.options]` keys they are.
fn velocity_only_options(opts: &FitOptions) -> Vec<&'static str> {
    let mut keys = Vec::new();
    for (on, key) in [
        (opts.params.velocity_offset, "velocity_offset"),
        (opts.params.time_shift, "time_shift"),
        (opts.params.x0, "x0"),
        (
            !opts.params.oscillator.is_empty()
                && opts.target.force_target != ForceTarget::InverseDynamics,
            "oscillator",
        ),
    ] {
        if on {
            keys.push(key);
        }
    }
    keys
}

/// The options fit the force domain: `domain = "force"`, and none of the options only a
/// velocity fit has (the oscillator properties are fitted in the force domain by inverse
/// dynamics only).
pub fn check_force_domain(opts: &FitOptions) -> Result<(), EngineError> {
    let velocity_keys = velocity_only_options(opts);
    if !velocity_keys.is_empty() {
        return Err(EngineError::InvalidInput(format!(
            "[fit.options] {} apply to velocity fits only, not with domain = \"force\"",
            velocity_keys.join(", ")
        )));
    }
    if opts.target.domain != FitDomain::Force {
        return Err(EngineError::InvalidInput(
            "fit_force needs [fit.options] domain = \"force\"".into(),
        ));
    }
    check_inverse_dynamics(opts)
}

/// Inverse dynamics knows the mass (the inertia): given in `[oscillator]` or fitted.
fn check_inverse_dynamics(opts: &FitOptions) -> Result<(), EngineError> {
    let mass_unknown = opts.target.is_unknown(OscillatorProperty::Mass)
        && !opts.params.oscillator.contains(&OscillatorProperty::Mass);
    if opts.target.force_target == ForceTarget::InverseDynamics && mass_unknown {
        return Err(EngineError::InvalidInput(
            "[oscillator]: force_target = \"inverse_dynamics\" needs the mass (the inertia): \
             give `mass`, or fit it with [fit.options] oscillator = [\"mass\"]"
                .into(),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::values::target_options::TargetOptions;
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
