//! A law's conditions during a simulation ([`frictionid_models::Condition`]): the simulated
//! displacement, the measured input driving the axis, and named channels (a load, a
//! temperature) linear in time between the samples of the record being simulated.
//!
//! The motion gives x itself; a channel the motion does not give comes from the record, as
//! [`ChannelSeries`]. The acceleration cannot be a condition here: the friction would then
//! depend on the acceleration it produces, so a law that reads `a` is fitted along the
//! measured motion (`domain = "force"`). [`BoundConditions::bind`] refuses it, a channel the
//! record lacks (naming the record and the channel) and an input force in free vibration.

use super::Input;
use crate::error::EngineError;
use crate::record::conditions::missing_channel_reason;
use crate::record::Record;
use frictionid_models::{Condition, FrictionModel};
use std::collections::BTreeMap;

/// At most this many conditions per law in a simulation (their values live on the stack).
pub const MAX_SIMULATED_CONDITIONS: usize = 16;

/// Named channels a simulation reads, each linear between its samples and held beyond them,
/// on the simulation's clock (t = 0 at the release).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ChannelSeries {
    /// The record's name, for messages.
    record: String,
    named: BTreeMap<String, Input>,
}

impl ChannelSeries {
    /// No channels yet, for the record named `record`.
    pub fn new(record: impl Into<String>) -> Self {
        Self {
            record: record.into(),
            named: BTreeMap::new(),
        }
    }

    /// With channel `name` sampled at `time` (strictly increasing, on the simulation's clock)
    /// with `values`.
    pub fn with_channel(
        mut self,
        name: impl Into<String>,
        time: Vec<f64>,
        values: Vec<f64>,
    ) -> Result<Self, EngineError> {
        let name = name.into();
        let series = Input::new(time, values).map_err(|e| EngineError::Record {
            record: self.record.clone(),
            reason: format!(
                "channel `{name}`: {}",
                e.to_string().replace("input force: ", "")
            ),
        })?;
        self.named.insert(name, series);
        Ok(self)
    }

    /// The named channels of `record` that `model` reads, on the clock of a simulation
    /// released at `release` (the record's time of t = 0); `None` when the law reads no
    /// named channel. A channel the record lacks is left out: binding the law names it.
    pub fn of_record(
        record: &Record,
        model: &dyn FrictionModel,
        release: f64,
    ) -> Result<Option<Self>, EngineError> {
        let wanted: Vec<String> = model
            .conditions()
            .into_iter()
            .filter_map(|c| match c {
                Condition::Channel(name) => Some(name),
                _ => None,
            })
            .collect();
        if wanted.is_empty() {
            return Ok(None);
        }
        let time: Vec<f64> = record.time().iter().map(|&t| t - release).collect();
        let mut series = Self::new(record.name.clone());
        for name in wanted {
            if let Some(values) = record.named_channel(&name) {
                series = series.with_channel(name, time.clone(), values.to_vec())?;
            }
        }
        Ok(Some(series))
    }

    /// The channels' names, in alphabetical order.
    pub fn names(&self) -> Vec<&str> {
        self.named.keys().map(String::as_str).collect()
    }

    fn missing(&self, name: &str) -> EngineError {
        missing_channel(&self.record, name, &self.names())
    }
}

/// The error of a law reading channel `name`, which record `record` (with named channels
/// `named`) lacks.
fn missing_channel(record: &str, name: &str, named: &[&str]) -> EngineError {
    EngineError::Record {
        record: record.to_string(),
        reason: missing_channel_reason(name, named),
    }
}

/// Checks that a simulation of each of `records` can give `model` every condition it reads:
/// x always; the input force where the record has one; a named channel where the record
/// has it; never the acceleration. The first condition one cannot give is an error naming
/// the record and the condition.
pub fn require_simulable_conditions(
    model: &dyn FrictionModel,
    records: &[Record],
) -> Result<(), EngineError> {
    let conditions = model.conditions();
    if conditions.is_empty() {
        return Ok(());
    }
    for record in records {
        for condition in &conditions {
            let given = match condition {
                Condition::Displacement => true,
                Condition::Acceleration => false,
                Condition::InputForce => {
                    record.channel(crate::record::Channel::InputForce).is_some()
                }
                Condition::Channel(name) => record.named_channel(name).is_some(),
            };
            if given {
                continue;
            }
            return Err(match condition {
                Condition::Channel(name) => {
                    missing_channel(&record.name, name, &record.named_channels())
                }
                other => match source(model, other, None, None) {
                    Err(EngineError::InvalidInput(reason)) => EngineError::Record {
                        record: record.name.clone(),
                        reason,
                    },
                    Err(e) => e,
                    Ok(_) => continue,
                },
            });
        }
    }
    Ok(())
}

/// Checks that a simulation without record channels (a planned experiment) can give `model`
/// every condition it reads: x and the input force, not the acceleration nor a named
/// channel.
pub fn require_motion_conditions(model: &dyn FrictionModel) -> Result<(), EngineError> {
    for condition in model.conditions() {
        match condition {
            Condition::Displacement | Condition::InputForce => {}
            other => {
                source(model, &other, None, None)?;
            }
        }
    }
    Ok(())
}

/// Where one condition's value comes from in a simulation.
#[derive(Debug, Clone, Copy)]
enum Source<'a> {
    /// The simulated displacement.
    Displacement,
    /// A series in time: the measured input or a named channel.
    Series(&'a Input),
}

/// One law's conditions, bound to what a simulation has: in the law's order.
#[derive(Debug, Clone)]
pub(crate) struct BoundConditions<'a> {
    sources: Vec<Source<'a>>,
}

impl<'a> BoundConditions<'a> {
    /// The sources of `model`'s conditions under `input` and `channels`; `None` when the
    /// law reads none. What a simulation cannot give is an error: the acceleration, the
    /// input force of a free vibration, a channel the record lacks.
    pub(crate) fn bind(
        model: &dyn FrictionModel,
        input: Option<&'a Input>,
        channels: Option<&'a ChannelSeries>,
    ) -> Result<Option<Self>, EngineError> {
        let conditions = model.conditions();
        if conditions.is_empty() {
            return Ok(None);
        }
        if conditions.len() > MAX_SIMULATED_CONDITIONS {
            return Err(EngineError::InvalidInput(format!(
                "model `{}` reads {} conditions; a simulation hands a law at most \
                 {MAX_SIMULATED_CONDITIONS}",
                model.name(),
                conditions.len()
            )));
        }
        let sources = conditions
            .iter()
            .map(|c| source(model, c, input, channels))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Some(Self { sources }))
    }

    /// The conditions' values at time `t` and displacement `x`, in the law's order.
    #[inline]
    pub(crate) fn values(&self, t: f64, x: f64) -> ConditionValues {
        let mut out = ConditionValues {
            values: [0.0; MAX_SIMULATED_CONDITIONS],
            len: self.sources.len(),
        };
        for (o, s) in out.values.iter_mut().zip(&self.sources) {
            *o = match s {
                Source::Displacement => x,
                Source::Series(series) => series.at(t),
            };
        }
        out
    }

    /// Whether a condition is the displacement (the force then varies with x at fixed v).
    pub(crate) fn reads_displacement(&self) -> bool {
        self.sources
            .iter()
            .any(|s| matches!(s, Source::Displacement))
    }

    /// The first sample time of any series later than `after` by more than `gap`: the
    /// conditions are linear in time between consecutive ones.
    pub(crate) fn next_knot(&self, after: f64, gap: f64) -> Option<f64> {
        self.sources
            .iter()
            .filter_map(|s| match s {
                Source::Series(series) => series.next_knot(after, gap),
                Source::Displacement => None,
            })
            .reduce(f64::min)
    }
}

/// The values of a law's conditions at one instant.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ConditionValues {
    values: [f64; MAX_SIMULATED_CONDITIONS],
    len: usize,
}

impl ConditionValues {
    /// The values, in the law's order.
    #[inline]
    pub(crate) fn as_slice(&self) -> &[f64] {
        &self.values[..self.len.min(MAX_SIMULATED_CONDITIONS)]
    }
}

/// Where `condition` comes from in a simulation of `model`.
fn source<'a>(
    model: &dyn FrictionModel,
    condition: &Condition,
    input: Option<&'a Input>,
    channels: Option<&'a ChannelSeries>,
) -> Result<Source<'a>, EngineError> {
    match condition {
        Condition::Displacement => Ok(Source::Displacement),
        Condition::Acceleration => Err(EngineError::InvalidInput(format!(
            "model `{}` reads the acceleration `a`, which a simulation cannot give it (the \
             friction would depend on the acceleration it produces): fit it along the \
             measured motion with [fit.options] domain = \"force\"",
            model.name()
        ))),
        Condition::InputForce => input.map(Source::Series).ok_or_else(|| {
            EngineError::InvalidInput(format!(
                "model `{}` reads the input force `u`, and this simulation has none (a free \
                 vibration): give the record an input force (`input_force_column`) or fit \
                 it with [fit.options] domain = \"force\"",
                model.name()
            ))
        }),
        Condition::Channel(name) => match channels {
            Some(series) => series
                .named
                .get(name)
                .map(Source::Series)
                .ok_or_else(|| series.missing(name)),
            None => Err(EngineError::InvalidInput(format!(
                "model `{}` reads channel `{name}`, and this simulation was given no \
                 channels: name its column in the record's `channels`",
                model.name()
            ))),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use frictionid_models::default_model;

    fn load_series() -> ChannelSeries {
        ChannelSeries::new("r")
            .with_channel("load", vec![0.0, 1.0, 2.0], vec![0.0, 2.0, -2.0])
            .expect("a valid channel")
    }

    #[test]
    fn channels_are_linear_in_time_and_x_is_the_state() {
        let ripple = default_model("position_ripple").expect("registered");
        let bound = BoundConditions::bind(ripple.as_ref(), None, None)
            .expect("x is always given")
            .expect("the law reads x");
        assert_eq!(bound.values(0.3, 0.25).as_slice(), &[0.25]);
        assert!(bound.reads_displacement());
        let load = default_model("coulomb_load").expect("registered");
        let series = load_series();
        let bound = BoundConditions::bind(load.as_ref(), None, Some(&series))
            .expect("the channel is there")
            .expect("the law reads load");
        assert_eq!(bound.values(0.5, 9.0).as_slice(), &[1.0]);
        assert_eq!(bound.values(1.75, 9.0).as_slice(), &[-1.0]);
        assert_eq!(bound.next_knot(0.5, 0.0), Some(1.0));
        assert!(!bound.reads_displacement());
    }

    #[test]
    fn what_a_simulation_cannot_give_is_named() {
        let load = default_model("coulomb_load").expect("registered");
        let other = ChannelSeries::new("rec 3")
            .with_channel("temperature", vec![0.0, 1.0], vec![25.0, 26.0])
            .expect("a valid channel");
        let e = BoundConditions::bind(load.as_ref(), None, Some(&other))
            .expect_err("no load channel")
            .to_string();
        assert!(e.contains("rec 3") && e.contains("`load`"), "{e}");
        let e = BoundConditions::bind(load.as_ref(), None, None)
            .expect_err("no channels at all")
            .to_string();
        assert!(e.contains("`load`"), "{e}");
        let accel = frictionid_models::Expression::new(
            "m0 * a + fc * sign(v)",
            &[("m0", 1.0), ("fc", 1.0)],
        )
        .expect("a valid formula");
        let e = BoundConditions::bind(&accel, None, None)
            .expect_err("a is refused")
            .to_string();
        assert!(e.contains("`a`") && e.contains("domain = \"force\""), "{e}");
        let driven =
            frictionid_models::Expression::new("fc * sign(v) + g * u", &[("fc", 1.0), ("g", 0.1)])
                .expect("a valid formula");
        assert!(BoundConditions::bind(&driven, None, None).is_err());
        let u = Input::new(vec![0.0, 1.0], vec![0.0, 4.0]).expect("a valid input");
        let bound = BoundConditions::bind(&driven, Some(&u), None)
            .expect("u is the input")
            .expect("the law reads u");
        assert_eq!(bound.values(0.25, 0.0).as_slice(), &[1.0]);
    }
}
