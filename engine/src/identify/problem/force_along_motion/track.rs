//! One record of the force domain: its motion, normal force and target force, the samples
//! compared, and the inverse-dynamics balance where the target is the input.

use super::super::inverse_dynamics::{sliding_samples, Balance};
use super::super::residuals::{Evaluation, JacobianColumns, RecordCase};
use super::guards::require_mechanics;
use super::{ForceTrack, TargetSource};
use crate::energy::model_force::{check_displacement, check_motion, CheckedMotion};
use crate::energy::{
    analyze_record, central_difference, record_motion, EnergyOptions, ForceDerivatives,
    SeriesSource,
};
use crate::error::EngineError;
use crate::identify::values::fit_options::FitOptions;
use crate::identify::values::layout::{FreeParam, ParamKind};
use crate::identify::values::levels::FrictionLevels;
use crate::identify::values::nuisance::NuisanceKind;
use crate::identify::values::result::SlidingSamples;
use crate::identify::values::target_options::{ForceTarget, ReplayPath};
use crate::oscillator::{Oscillator, OscillatorProperty};
use crate::record::noise::noise_floor_level;
use crate::record::{channel_list, Channel, ConditionSource, Record};

impl ForceTrack {
    /// Prepares `record`: its motion, its normal force (1 N when `unit_normal`: no normal
    /// force given anywhere) and its target from `source`.
    pub(super) fn new(
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
        let follows_displacement =
            follows_displacement(record, motion.displacement, opts.target.replay_path)
                .map_err(err)?;
        if follows_displacement {
            check_displacement(record.time(), &motion.x).map_err(|e| err(e.to_string()))?;
        }
        let (used, target) = after_run_in(used, target, record.run_in);
        let (used, target, sliding) =
            enough_compared(used, target, &motion.v, osc, opts).map_err(err)?;
        let noise_channel = match source {
            TargetSource::Measured => Some(Channel::Force),
            TargetSource::InverseDynamics => Some(Channel::InputForce),
            TargetSource::EnergyBased => None,
        };
        let conditions = track_conditions(record, &motion.v, &motion.x, balance.as_ref());
        let mut track = Self {
            source,
            conditions,
            time: record.time().to_vec(),
            velocity: motion.v,
            displacement: motion.x,
            follows_displacement,
            normal,
            noise: noise_channel
                .and_then(|c| record.given_noise(c))
                .unwrap_or_else(|| noise_floor_level(&target, 1)),
            used,
            target,
            balance,
            sliding,
            unreliable,
            intervals: Vec::new(),
        };
        track.intervals = track.unkept_motion().intervals();
        Ok(track)
    }

    /// The record's motion and normal force, checked when the track was prepared, the
    /// displacement it travels where it follows one, and its replay intervals, computed then.
    pub(super) fn motion(&self) -> CheckedMotion<'_> {
        CheckedMotion {
            intervals: Some(&self.intervals),
            ..self.unkept_motion()
        }
    }

    /// [`ForceTrack::motion`] without its kept intervals.
    fn unkept_motion(&self) -> CheckedMotion<'_> {
        CheckedMotion {
            time: &self.time,
            v: &self.velocity,
            normal: &self.normal,
            displacement: self
                .follows_displacement
                .then_some(self.displacement.as_slice()),
            intervals: None,
        }
    }

    /// Whether the replay travels the measured displacement's increments.
    pub fn follows_displacement(&self) -> bool {
        self.follows_displacement
    }

    /// Record `case`'s Jacobian columns, one per free parameter of `layout`, weighted as its
    /// residuals are: the law's from its derivatives `law` where they are given, the offset's
    /// and the balance's linear terms; `None` for the fit's difference quotients.
    pub(super) fn columns(
        &self,
        at: &Evaluation<'_>,
        case: RecordCase<'_>,
        layout: &[FreeParam],
        law: Option<&ForceDerivatives>,
    ) -> JacobianColumns {
        let weight = case.record.weight.sqrt() / self.noise;
        let mut law_columns = law.map_or_else(Vec::new, |d| d.columns(self.used.len()));
        let column = |f: &FreeParam, law_columns: &mut Vec<Option<Vec<f64>>>| match f.kind {
            ParamKind::Model(j) => law_columns.get_mut(j).and_then(Option::take),
            kind => self.balance_column(kind, case.index, at.oscillator),
        };
        let weighted = |c: Vec<f64>| c.into_iter().map(|x| weight * x).collect();
        layout
            .iter()
            .map(|f| column(f, &mut law_columns).map(weighted))
            .collect()
    }

    /// The derivative of the prediction at the compared samples with respect to the
    /// oscillator property or nuisance parameter `kind` at `osc`: the balance's terms are
    /// linear in J, c, the input offset and a linear spring's k, the force offset adds
    /// itself to record `index` only. `None` for what is not that simple (a restoring law's
    /// own parameters, another law's stiffness).
    pub(super) fn balance_column(
        &self,
        kind: ParamKind,
        index: usize,
        osc: &Oscillator,
    ) -> Option<Vec<f64>> {
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
    pub(super) fn friction_target(&self, osc: &Oscillator) -> Vec<f64> {
        let axis = self.axis_forces(osc);
        if axis.is_empty() {
            return self.target.clone();
        }
        self.target.iter().zip(&axis).map(|(u, a)| u - a).collect()
    }
}

/// What a law's conditions read along `record`: its displacement `x`, its acceleration (the
/// record's channel, else the balance's of inverse dynamics, else the central difference of
/// the velocity `v`), its input force and named channels.
fn track_conditions(
    record: &Record,
    v: &[f64],
    x: &[f64],
    balance: Option<&Balance>,
) -> ConditionSource {
    let acceleration = match (record.channel(Channel::Acceleration), balance) {
        (Some(a), _) => a.to_vec(),
        (None, Some(b)) => b.acceleration.clone(),
        (None, None) => central_difference(record.time(), v),
    };
    ConditionSource::of_record(record, x.to_vec(), acceleration)
}

/// The compared samples `used` (with their `target`) from sample `run_in` on (the samples
/// before only drive the states).
fn after_run_in(used: Vec<usize>, target: Vec<f64>, run_in: usize) -> (Vec<usize>, Vec<f64>) {
    if run_in == 0 {
        return (used, target);
    }
    used.into_iter()
        .zip(target)
        .filter(|(i, _)| *i >= run_in)
        .unzip()
}

/// The compared samples, their target values, and what `min_speed` kept of them.
type Compared = (Vec<usize>, Vec<f64>, Option<SlidingSamples>);

/// The compared samples kept by `[fit.options] min_speed` (and how many it kept), refused
/// with the reason when fewer than two remain.
fn enough_compared(
    used: Vec<usize>,
    target: Vec<f64>,
    velocity: &[f64],
    osc: &Oscillator,
    opts: &FitOptions,
) -> Result<Compared, String> {
    let (used, target, sliding) = keep_sliding(used, target, velocity, opts.target.min_speed);
    if sliding.is_some_and(|s| s.kept < 2) {
        return Err(format!(
            "{} samples slide with |v| >= [fit.options] min_speed = {} {}; lower it",
            target.len(),
            opts.target.min_speed.unwrap_or_default(),
            osc.axis.unit("m/s")
        ));
    }
    if target.len() < 2 {
        return Err(format!(
            "{} samples to compare the model force with (Eq. 7 and the inverse-dynamics \
             force are masked where |v| <= [energy] velocity_threshold = {} {})",
            target.len(),
            opts.energy.velocity_threshold,
            osc.axis.unit("m/s")
        ));
    }
    Ok((used, target, sliding))
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

/// Whether the replay of `record` travels its displacement channel's increments under
/// `replay_path` (`displacement`: where its displacement came from).
fn follows_displacement(
    record: &Record,
    displacement: SeriesSource,
    replay_path: ReplayPath,
) -> Result<bool, String> {
    let measured = displacement == SeriesSource::Measured;
    match replay_path {
        ReplayPath::Auto => Ok(measured),
        ReplayPath::Velocity => Ok(false),
        ReplayPath::Displacement if measured => Ok(true),
        ReplayPath::Displacement => Err(format!(
            "[fit.options] replay_path = \"displacement\" but the record has no displacement \
             channel (it has: {}; name its column with `displacement_column`)",
            channel_list(&record.channels())
        )),
    }
}

/// The target of a record under `force_target`.
pub(super) fn target_source(record: &Record, wanted: ForceTarget) -> Result<TargetSource, String> {
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
