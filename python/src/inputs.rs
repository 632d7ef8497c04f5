//! The engine's inputs from Python: the [`Spec`] from dicts (the configuration's tables) and
//! [`Record`]s from dicts of arrays.

use crate::convert::{to_f64_vec, to_json};
use crate::errors::value_error;
use frictionid_engine::record::{Channel, NormalForce, TimeBase};
use frictionid_engine::spec::{EnergySpec, FitSpec, ModelSpec, OscillatorSpec};
use frictionid_engine::{Record, Spec};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use serde::de::DeserializeOwned;

/// A table deserialized as the configuration's `[table]` would be; `None` gives the default.
fn table<T: DeserializeOwned + Default>(obj: Option<&Bound<'_, PyAny>>, name: &str) -> PyResult<T> {
    match obj {
        Some(o) if !o.is_none() => {
            let json = to_json(o, name)?;
            serde_json::from_value(json).map_err(|e| value_error(format!("[{name}]: {e}")))
        }
        _ => Ok(T::default()),
    }
}

/// `[oscillator]`: mass, damping, stiffness, normal_force and, optionally, their standard
/// deviations `mass_std`, `damping_std`, `stiffness_std`, `normal_force_std`.
pub fn oscillator(obj: &Bound<'_, PyAny>) -> PyResult<OscillatorSpec> {
    let json = to_json(obj, "oscillator")?;
    serde_json::from_value(json).map_err(|e| {
        let msg = e.to_string();
        // Range errors already name the table; serde's own (unknown or missing keys) do not.
        value_error(if msg.starts_with("[oscillator]") {
            msg
        } else {
            format!("[oscillator]: {msg}")
        })
    })
}

/// A model: a `[model]` table (`{"type": "lugre", "sigma0": 2e5}`) or just its name.
pub fn model(obj: &Bound<'_, PyAny>) -> PyResult<ModelSpec> {
    let json = match obj.cast::<PyString>() {
        Ok(name) => serde_json::json!({ "type": name.extract::<String>()? }),
        Err(_) => to_json(obj, "model")?,
    };
    ModelSpec::from_json(&json).map_err(|e| value_error(format!("[model]: {e}")))
}

/// `[fit]` with its `options`.
pub fn fit_spec(obj: Option<&Bound<'_, PyAny>>) -> PyResult<FitSpec> {
    table(obj, "fit")
}

/// `[energy]`.
pub fn energy_spec(obj: Option<&Bound<'_, PyAny>>) -> PyResult<EnergySpec> {
    table(obj, "energy")
}

/// The checked spec (the `[fit]` names are checked against the model).
pub fn spec(
    oscillator: OscillatorSpec,
    model: Option<ModelSpec>,
    fit: FitSpec,
    energy: EnergySpec,
) -> PyResult<Spec> {
    Spec::new(oscillator, model, fit, None, energy).map_err(value_error)
}

/// The keys a record dict may have besides its channels.
const RECORD_KEYS: [&str; 8] = [
    "name",
    "t",
    "time",
    "x0",
    "v0",
    "weight",
    "release_time",
    "channels",
];

/// The channel a record dict's key names (`v`, `x`, `a` as short names).
fn channel_of(key: &str) -> Option<Channel> {
    match key {
        "v" => Some(Channel::Velocity),
        "x" => Some(Channel::Displacement),
        "a" => Some(Channel::Acceleration),
        other => Channel::from_name(other),
    }
}

/// An optional float key of a record dict.
fn float_key(dict: &Bound<'_, PyDict>, key: &str, what: &str) -> PyResult<Option<f64>> {
    match dict.get_item(key)? {
        Some(v) if !v.is_none() => v
            .extract::<f64>()
            .map(Some)
            .map_err(|_| value_error(format!("{what}: `{key}` must be a number"))),
        _ => Ok(None),
    }
}

/// The time stamps of a record dict (`t` or `time`), checked by the engine's time base.
fn time_base(dict: &Bound<'_, PyDict>, what: &str) -> PyResult<TimeBase> {
    let t = match (dict.get_item("t")?, dict.get_item("time")?) {
        (Some(t), _) | (None, Some(t)) => t,
        (None, None) => return Err(value_error(format!("{what}: missing `t` (time stamps, s)"))),
    };
    TimeBase::new(to_f64_vec(&t, &format!("{what}: t"))?)
        .map_err(|e| value_error(format!("{what}: {e}")))
}

/// Adds the channel under `key` to `record` (a number is a constant normal force).
fn add_channel(
    record: Record,
    key: &str,
    value: &Bound<'_, PyAny>,
    what: &str,
) -> PyResult<Record> {
    let channel = channel_of(key).ok_or_else(|| {
        let known = Channel::ALL.map(Channel::name).join(", ");
        value_error(format!(
            "{what}: unknown key `{key}`; a record has t, x0, v0, name, weight, release_time \
             and channels (v, x, a or {known})"
        ))
    })?;
    if channel == Channel::NormalForce {
        if let Ok(n) = value.extract::<f64>() {
            let mut record = record;
            record.set_normal_force(Some(NormalForce::Constant(n)));
            return Ok(record);
        }
    }
    let values = to_f64_vec(value, &format!("{what}: {key}"))?;
    Ok(record.with_channel(channel, values))
}

/// The named channels of a record dict (`channels = {"load": [...], "temperature": [...]}`):
/// the conditions a law beyond speed reads, each an array of one value per sample.
fn named_channels(dict: &Bound<'_, PyDict>, mut record: Record, what: &str) -> PyResult<Record> {
    let Some(channels) = dict.get_item("channels")? else {
        return Ok(record);
    };
    if channels.is_none() {
        return Ok(record);
    }
    let channels = channels.cast::<PyDict>().map_err(|_| {
        value_error(format!(
            "{what}: `channels` must be a dict of named arrays (e.g. {{\"load\": [...]}})"
        ))
    })?;
    for (name, values) in channels.iter() {
        let name: String = name.extract()?;
        let values = to_f64_vec(&values, &format!("{what}: channels.{name}"))?;
        record = record.with_named_channel(name, values);
    }
    Ok(record)
}

/// One record from a dict: `t` and channels as arrays, optional `x0`, `name`, `v0`, `weight`,
/// `release_time`, `<channel>_noise` levels and named `channels` (a dict of arrays). `x0` follows the configuration's rule
/// ([`Record::set_release_displacement`]): given, else the first displacement sample, else
/// unknown, which whatever simulates the record from rest refuses with a message naming it.
pub fn record(obj: &Bound<'_, PyAny>, index: usize) -> PyResult<Record> {
    let default_name = format!("record {}", index + 1);
    let dict = obj
        .cast::<PyDict>()
        .map_err(|_| value_error(format!("{default_name}: expected a dict")))?;
    let name = match dict.get_item("name")? {
        Some(n) if !n.is_none() => n.str()?.to_string(),
        _ => default_name,
    };
    let x0 = float_key(dict, "x0", &name)?;
    let mut record = Record::from_time_base(name.clone(), time_base(dict, &name)?);
    record.v0 = float_key(dict, "v0", &name)?.unwrap_or(0.0);
    record.weight = float_key(dict, "weight", &name)?.unwrap_or(1.0);
    record.release_time = float_key(dict, "release_time", &name)?;
    for (key, value) in dict.iter() {
        let key: String = key.extract()?;
        if RECORD_KEYS.contains(&key.as_str()) {
            continue;
        }
        record = match key.strip_suffix("_noise") {
            Some(channel) => {
                let (channel, sigma) = noise_level(channel, &value, &name)?;
                record.with_noise(channel, sigma)
            }
            None => add_channel(record, &key, &value, &name)?,
        };
    }
    let mut record = named_channels(dict, record, &name)?;
    record.set_release_displacement(x0);
    Ok(record)
}

/// The channel and noise level of a `<channel>_noise` key (a positive number in the
/// channel's SI unit); without one a fit estimates the level from the channel.
fn noise_level(channel: &str, value: &Bound<'_, PyAny>, what: &str) -> PyResult<(Channel, f64)> {
    let key = format!("{channel}_noise");
    let channel = channel_of(channel).ok_or_else(|| {
        value_error(format!(
            "{what}: unknown key `{key}`: `{channel}` is not a channel"
        ))
    })?;
    match value.extract::<f64>() {
        Ok(sigma) if sigma > 0.0 && sigma.is_finite() => Ok((channel, sigma)),
        _ => Err(value_error(format!(
            "{what}: `{key}` must be a number > 0 (the channel's noise level in SI units)"
        ))),
    }
}

/// Records from a list of dicts (at least one).
pub fn records(obj: &Bound<'_, PyAny>) -> PyResult<Vec<Record>> {
    let list = non_empty_list(
        obj,
        "records: expected a list of dicts",
        "records: no records given",
    )?;
    list.iter().enumerate().map(|(i, r)| record(r, i)).collect()
}

/// The items of the Python iterable `obj`: a ValueError `not_a_list` when it is not iterable,
/// `empty` when it has no items.
pub fn non_empty_list<'py>(
    obj: &Bound<'py, PyAny>,
    not_a_list: &str,
    empty: &str,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let items: Vec<Bound<'py, PyAny>> = obj
        .try_iter()
        .map_err(|_| value_error(not_a_list))?
        .collect::<PyResult<_>>()?;
    if items.is_empty() {
        return Err(value_error(empty));
    }
    Ok(items)
}
