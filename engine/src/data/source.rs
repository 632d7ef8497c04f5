//! One `[[records]]` entry of a configuration: where a record's file is, how to read it, and
//! the record's release state. Shared by every front end (CLI, Python).
//!
//! ```toml
//! [record_defaults]           # optional: any key below, for every record (a record's own wins)
//! velocity_scale = 1e-3
//!
//! [[records]]
//! file = "x14mm.csv"          # relative to the configuration file
//! x0 = 0.014                  # m, the release displacement (see below when it may be left out)
//! v0 = 0.0                    # m/s, optional
//! weight = 1.0                # optional, in a joint fit
//! format = "auto"             # auto | csv | whitespace | uff58 | mat (a MAT-file: each
//!                             # *_column names a variable)
//! delimiter = "auto"          # or ";", ",", "tab", "whitespace" (default: sniffed)
//! decimal = "auto"            # or "point", "comma" (default: sniffed)
//! time_column = "time"        # and time_scale (1e-3 for milliseconds)
//! velocity_column = "velocity"
//! velocity_scale = 1e-3       # the file's velocity unit in m/s (here mm/s)
//! # displacement_, acceleration_, force_, normal_force_ and input_force_ column and scale
//! # alike (input_force: the force driving the axis, a drive's motor force): a channel
//! # is read when its column is found (default: the channel's own name); a negative scale
//! # flips a sign convention
//! velocity_noise = 2e-4       # m/s, the channel's noise level (default: estimated from it);
//! # displacement_, acceleration_, force_ and input_force_noise alike, in the channel's SI unit
//! normal_force = 14.5         # N, this record's constant normal force (else the oscillator's)
//! channels = { temperature = "T [degC]", load = "Load torque [N m]", load_scale = -1.0 }
//!                             # named channels a law or a formula reads by name, each from
//!                             # its column (a unit in a column found by a name without it
//!                             # scales it, as above); `<name>_scale` the factor to SI
//! release = "auto"            # or a time in s: drop the pre-trigger rest (default: none)
//! min_samples = 10
//! sampling_tolerance = 0.01
//! ```
//!
//! `x0` is needed only where a record without a displacement channel is simulated from rest
//! or has its velocity integrated (velocity fits, the energy analysis, the energy-based force
//! of Eq. 7). A record with a displacement channel (its column named or found by its default
//! name) starts at its first sample (relative to the equilibrium); a force-domain fit on a
//! measured force uses no x0. Once read, an entry of a velocity fit without either is refused
//! ([`ResolvedSource::load`]), and [`crate::record::Record::require_x0`] refuses a record
//! whose x0 is unknown wherever else one is needed.

use super::{read_record, DataError, DataFormat, DecimalMark, Delimiter, ReadOptions};
use crate::oscillator::Oscillator;
use crate::record::{
    check_scales, detect_release, Channel, NormalForce, Record, Release, X0Source,
};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// A `[[records]]` (or `[record_defaults]`) entry as written: every key optional, unknown keys
/// rejected.
///
/// [`RecordSource::with_defaults`] fills keys from `[record_defaults]`;
/// [`RecordSource::resolve`] gives the errors a configuration reports on loading;
/// [`RecordSource::load`] reads the file.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordSource {
    /// The data file, relative to the base directory (the configuration file's) or absolute.
    pub file: Option<String>,
    /// Release displacement \[m\] (default: the first displacement sample; required for a
    /// velocity fit of a record without a displacement channel).
    pub x0: Option<f64>,
    /// Release velocity [m/s] (default 0).
    pub v0: Option<f64>,
    /// Weight in a joint fit (default 1).
    pub weight: Option<f64>,
    /// File format (default: from the extension).
    pub format: Option<DataFormat>,
    /// How a text file's fields are separated (default: sniffed from the file).
    pub delimiter: Option<Delimiter>,
    /// The decimal mark of a text file's numbers (default: sniffed from the file).
    pub decimal: Option<DecimalMark>,
    /// Header name of the time column (default `time`).
    pub time_column: Option<String>,
    /// Factor from the file's time unit to s (default 1; 1e-3 for milliseconds).
    pub time_scale: Option<f64>,
    /// Header name of the velocity column (default `velocity`).
    pub velocity_column: Option<String>,
    /// Factor from the file's velocity unit to m/s (default 1).
    pub velocity_scale: Option<f64>,
    /// Header name of the displacement column (default `displacement`).
    pub displacement_column: Option<String>,
    /// Factor from the file's displacement unit to m (default 1).
    pub displacement_scale: Option<f64>,
    /// Header name of the acceleration column (default `acceleration`).
    pub acceleration_column: Option<String>,
    /// Factor from the file's acceleration unit to m/s^2 (default 1).
    pub acceleration_scale: Option<f64>,
    /// Header name of the friction-force column (default `force`).
    pub force_column: Option<String>,
    /// Factor from the file's force unit to N (default 1; negative for the opposite sign
    /// convention).
    pub force_scale: Option<f64>,
    /// Header name of the normal-force column (default `normal_force`).
    pub normal_force_column: Option<String>,
    /// Factor from the file's normal-force unit to N (default 1).
    pub normal_force_scale: Option<f64>,
    /// Header name of the input-force column (default `input_force`): the force (torque)
    /// that drives the axis.
    pub input_force_column: Option<String>,
    /// Factor from the file's input unit to N (N m on a rotary axis) (default 1).
    pub input_force_scale: Option<f64>,
    /// This record's constant normal force \[N\] (default: the oscillator's, or the channel).
    pub normal_force: Option<f64>,
    /// Noise level of the velocity channel [m/s] (default: estimated from the record).
    pub velocity_noise: Option<f64>,
    /// Noise level of the displacement channel \[m\] (default: estimated).
    pub displacement_noise: Option<f64>,
    /// Noise level of the acceleration channel [m/s^2] (default: estimated).
    pub acceleration_noise: Option<f64>,
    /// Noise level of the force channel \[N\] (default: estimated).
    pub force_noise: Option<f64>,
    /// Noise level of the input-force channel \[N\] (default: estimated).
    pub input_force_noise: Option<f64>,
    /// Named channels: each name's column, and `<name>_scale` its factor to SI (default 1).
    pub channels: Option<BTreeMap<String, NamedEntry>>,
    /// Where the free vibration starts (default: at the first sample).
    pub release: Option<Release>,
    /// Fewest samples accepted (default 10).
    pub min_samples: Option<usize>,
    /// Largest relative deviation of a time step from the median step (default 0.01).
    pub sampling_tolerance: Option<f64>,
}

/// One value of a `channels` table: a column name, or the `<name>_scale` of one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum NamedEntry {
    /// The channel's column (delimited text) or variable (MAT-file).
    Column(String),
    /// A `<name>_scale`: the factor from the file's unit to SI.
    Scale(f64),
}

/// Why a `[[records]]` entry cannot be used. `index` is the entry's 1-based position.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RecordSourceError {
    /// No `file` key.
    #[error("[[records]] entry {index}: missing `file` (the record's data file)")]
    MissingFile { index: usize },
    /// No `x0` key.
    #[error("[[records]] entry {index} (`{file}`): missing `x0` (the release displacement, m)")]
    MissingX0 { index: usize, file: String },
    /// A value that must be finite is not.
    #[error("[[records]] entry {index} (`{file}`): `{key}` must be finite, got {value}")]
    NotFinite {
        index: usize,
        file: String,
        key: &'static str,
        value: f64,
    },
    /// A weight that is not a positive number.
    #[error("[[records]] entry {index} (`{file}`): `weight` must be > 0, got {value}")]
    BadWeight {
        index: usize,
        file: String,
        value: f64,
    },
    /// A noise level that is not a positive number.
    #[error("[[records]] entry {index} (`{file}`): `{key}` must be > 0 (the channel's noise level in SI units), got {value}")]
    BadNoise {
        index: usize,
        file: String,
        key: String,
        value: f64,
    },
    /// A negative constant normal force.
    #[error("[[records]] entry {index} (`{file}`): `normal_force` must be >= 0, got {value}")]
    BadNormalForce {
        index: usize,
        file: String,
        value: f64,
    },
    /// A `channels` table that names a channel wrongly.
    #[error("[[records]] entry {index} (`{file}`): `channels`: {reason}")]
    BadChannels {
        index: usize,
        file: String,
        reason: String,
    },
    /// Both a constant normal force and a normal-force column.
    #[error("[[records]] entry {index} (`{file}`): give either `normal_force` (a constant) or `normal_force_column`, not both")]
    NormalForceTwice { index: usize, file: String },
}

/// How the records of a run are used: what decides whether an entry needs `x0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecordUse {
    /// Simulated from rest at x0 (a velocity fit): x0 given or measured.
    Simulated,
    /// Replayed as measured (a force-domain fit): x0 only where the energy analysis or Eq. 7
    /// integrates a velocity ([`crate::record::Record::require_x0`]).
    Replayed,
    /// Simulated on an axis without a restoring law (a driven axis, a free mass): the
    /// position enters no equation, so x0 is not needed (0 stands in).
    Unpositioned,
}

/// Every key of [`RecordSource`], for the merge with `[record_defaults]`.
macro_rules! record_keys {
    ($m:ident) => {
        $m!(
            file,
            x0,
            v0,
            weight,
            format,
            delimiter,
            decimal,
            time_column,
            time_scale,
            velocity_column,
            velocity_scale,
            displacement_column,
            displacement_scale,
            acceleration_column,
            acceleration_scale,
            force_column,
            force_scale,
            normal_force_column,
            normal_force_scale,
            input_force_column,
            input_force_scale,
            normal_force,
            velocity_noise,
            displacement_noise,
            acceleration_noise,
            force_noise,
            input_force_noise,
            channels,
            release,
            min_samples,
            sampling_tolerance
        )
    };
}

/// A checked entry: the resolved file, the release state and how to read the file.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedSource {
    /// The file, resolved against the base directory.
    pub file: PathBuf,
    /// The file as written (the record's name in messages and reports).
    pub file_as_written: String,
    /// Release displacement \[m\] (`None`: the first displacement sample, else unknown).
    pub x0: Option<f64>,
    /// Release velocity [m/s].
    pub v0: f64,
    /// Weight in a joint fit.
    pub weight: f64,
    /// This record's constant normal force \[N\], if given.
    pub normal_force: Option<f64>,
    /// Noise levels given per channel, in the channel's SI unit.
    pub noise: Vec<(Channel, f64)>,
    /// Where the free vibration starts (`None`: at the first sample).
    pub release: Option<Release>,
    /// How to read the file.
    pub read: ReadOptions,
    /// The entry's 1-based position (for messages).
    pub entry: usize,
    /// How the record is used (a simulated one needs an x0).
    pub used: RecordUse,
}

impl ResolvedSource {
    /// Reads the file into a record named after the file as written, with this entry's x0
    /// ([`Record::set_release_displacement`]), v0, weight and normal force, starting at its
    /// release. A simulated record whose x0 is neither given nor measured is an error naming
    /// the entry.
    pub fn load(&self) -> Result<Record, DataError> {
        let mut record = read_record(&self.file, &self.read)?;
        record.name = self.file_as_written.clone();
        record.v0 = self.v0;
        record.weight = self.weight;
        if let Some(n) = self.normal_force {
            record.set_normal_force(Some(NormalForce::Constant(n)));
        }
        for &(channel, sigma) in &self.noise {
            record = record.with_noise(channel, sigma);
        }
        let mut record = self.start_at_release(record)?;
        record.set_release_displacement(self.x0);
        if record.x0_source == X0Source::Unknown && self.used == RecordUse::Unpositioned {
            record.x0_source = X0Source::Unused;
        }
        if record.x0_source == X0Source::Unknown && self.used == RecordUse::Simulated {
            return Err(RecordSourceError::MissingX0 {
                index: self.entry,
                file: self.file_as_written.clone(),
            }
            .into());
        }
        Ok(record)
    }

    /// [`ResolvedSource::load`], then the units checked against `osc`
    /// ([`crate::record::check_scales`]).
    pub fn load_checked(&self, osc: &Oscillator) -> Result<Record, DataError> {
        let record = self.load()?;
        check_scales(&record, osc)?;
        Ok(record)
    }

    /// The record from its release on (the last sample at or before the release instant).
    fn start_at_release(&self, record: Record) -> Result<Record, DataError> {
        let options = |reason: String| DataError::Options {
            file: self.file.clone(),
            reason,
        };
        let (release, found) = match self.release {
            None => return Ok(record),
            Some(Release::At(t)) => (t, false),
            Some(Release::Auto) => {
                if record.channel(Channel::Velocity).is_none() {
                    return Err(options(
                        "release = \"auto\" needs a velocity channel".into(),
                    ));
                }
                match detect_release(record.time(), record.velocity()) {
                    Some(t) => (t, true),
                    None => (record.time().first().copied().unwrap_or(0.0), false),
                }
            }
        };
        let last = record.time().last().copied().unwrap_or(f64::NAN);
        if release.is_nan() || release > last || last.is_nan() {
            return Err(options(format!(
                "release = {release} s is not before the last sample ({last} s)"
            )));
        }
        let first = record
            .time()
            .partition_point(|&t| t <= release)
            .saturating_sub(1);
        let mut started = record.starting_at(first);
        started.release_time = Some(release);
        started.release_found = found;
        let needed = self.read.min_samples.max(2);
        if started.len() < needed {
            return Err(DataError::TooFewSamples {
                file: self.file.clone(),
                found: started.len(),
                needed,
            });
        }
        Ok(started)
    }
}

impl RecordSource {
    /// This entry with every key it does not give taken from `defaults`.
    pub fn with_defaults(&self, defaults: &RecordSource) -> RecordSource {
        macro_rules! merge {
            ($($key:ident),*) => {
                RecordSource {
                    $($key: self.$key.clone().or_else(|| defaults.$key.clone()),)*
                }
            };
        }
        record_keys!(merge)
    }

    /// Checks the entry (the `index`-th, 1-based, for messages) for a simulated record and
    /// resolves its file against `base_dir` ([`RecordSource::resolve_for`]).
    pub fn resolve(
        &self,
        index: usize,
        base_dir: &Path,
    ) -> Result<ResolvedSource, RecordSourceError> {
        self.resolve_for(index, base_dir, RecordUse::Simulated)
    }

    /// Checks the entry (the `index`-th, 1-based, for messages) for `used` and resolves its
    /// file against `base_dir`. A simulated record without `x0` takes the first sample of its
    /// displacement channel; one without that channel either is refused once read
    /// ([`ResolvedSource::load`]).
    pub fn resolve_for(
        &self,
        index: usize,
        base_dir: &Path,
        used: RecordUse,
    ) -> Result<ResolvedSource, RecordSourceError> {
        let Some(file) = self.file.clone() else {
            return Err(RecordSourceError::MissingFile { index });
        };
        let finite = |key: &'static str, value: f64| {
            if value.is_finite() {
                Ok(value)
            } else {
                Err(RecordSourceError::NotFinite {
                    index,
                    file: file.clone(),
                    key,
                    value,
                })
            }
        };
        let weight = self.weight.unwrap_or(1.0);
        if !(weight.is_finite() && weight > 0.0) {
            return Err(RecordSourceError::BadWeight {
                index,
                file,
                value: weight,
            });
        }
        let x0 = self.x0.map(|x0| finite("x0", x0)).transpose()?;
        let v0 = finite("v0", self.v0.unwrap_or(0.0))?;
        if let Some(Release::At(t)) = self.release {
            finite("release", t)?;
        }
        let normal_force = self.normal_force(index, &file)?;
        let noise = self.noise(index, &file)?;
        self.named_channels()
            .map_err(|reason| RecordSourceError::BadChannels {
                index,
                file: file.clone(),
                reason,
            })?;
        let path = Path::new(&file);
        Ok(ResolvedSource {
            file: if path.is_absolute() {
                path.to_path_buf()
            } else {
                base_dir.join(path)
            },
            x0,
            v0,
            weight,
            normal_force,
            noise,
            release: self.release,
            read: self.read_options(),
            file_as_written: file,
            entry: index,
            used,
        })
    }

    /// The checked constant normal force, if given.
    fn normal_force(&self, index: usize, file: &str) -> Result<Option<f64>, RecordSourceError> {
        let Some(n) = self.normal_force else {
            return Ok(None);
        };
        if self.normal_force_column.is_some() {
            return Err(RecordSourceError::NormalForceTwice {
                index,
                file: file.into(),
            });
        }
        if !n.is_finite() {
            return Err(RecordSourceError::NotFinite {
                index,
                file: file.into(),
                key: "normal_force",
                value: n,
            });
        }
        if n < 0.0 {
            return Err(RecordSourceError::BadNormalForce {
                index,
                file: file.into(),
                value: n,
            });
        }
        Ok(Some(n))
    }

    /// The given noise levels (`<channel>_noise`), each checked to be > 0.
    fn noise(&self, index: usize, file: &str) -> Result<Vec<(Channel, f64)>, RecordSourceError> {
        let given = [
            (Channel::Velocity, self.velocity_noise),
            (Channel::Displacement, self.displacement_noise),
            (Channel::Acceleration, self.acceleration_noise),
            (Channel::Force, self.force_noise),
            (Channel::InputForce, self.input_force_noise),
        ];
        given
            .into_iter()
            .filter_map(|(c, sigma)| sigma.map(|s| (c, s)))
            .map(|(channel, value)| {
                if value.is_finite() && value > 0.0 {
                    Ok((channel, value))
                } else {
                    Err(RecordSourceError::BadNoise {
                        index,
                        file: file.into(),
                        key: format!("{channel}_noise"),
                        value,
                    })
                }
            })
            .collect()
    }

    /// The named channels: name, column and the scale given, checked: each name a valid
    /// formula name that is none of the record's own channels nor `v`, `N`, `x`, `a`, `u`,
    /// each `<name>_scale` a number for a channel named here; the message is the reason.
    pub fn named_channels(&self) -> Result<Vec<(String, String, Option<f64>)>, String> {
        let Some(table) = &self.channels else {
            return Ok(Vec::new());
        };
        let mut named = Vec::new();
        for (name, entry) in table {
            let NamedEntry::Column(column) = entry else {
                continue;
            };
            check_channel_name(name)?;
            let scale = match table.get(&format!("{name}_scale")) {
                Some(NamedEntry::Scale(s)) => Some(*s),
                Some(NamedEntry::Column(text)) => {
                    return Err(format!("`{name}_scale` must be a number, got \"{text}\""))
                }
                None => None,
            };
            named.push((name.clone(), column.clone(), scale));
        }
        for (key, entry) in table {
            let NamedEntry::Scale(_) = entry else {
                continue;
            };
            let base = key.strip_suffix("_scale").unwrap_or(key);
            if !named.iter().any(|(n, _, _)| n == base) {
                return Err(format!(
                    "`{key}` = a number names no channel (give `{base} = \"<column>\"`, or a \
                     column name as a channel's value)"
                ));
            }
        }
        Ok(named)
    }

    /// The column and scale keys of each channel.
    fn channel_keys(&self) -> [(Channel, Option<&String>, Option<f64>); 6] {
        [
            (
                Channel::Velocity,
                self.velocity_column.as_ref(),
                self.velocity_scale,
            ),
            (
                Channel::Displacement,
                self.displacement_column.as_ref(),
                self.displacement_scale,
            ),
            (
                Channel::Acceleration,
                self.acceleration_column.as_ref(),
                self.acceleration_scale,
            ),
            (Channel::Force, self.force_column.as_ref(), self.force_scale),
            (
                Channel::NormalForce,
                self.normal_force_column.as_ref(),
                self.normal_force_scale,
            ),
            (
                Channel::InputForce,
                self.input_force_column.as_ref(),
                self.input_force_scale,
            ),
        ]
    }

    /// How to read the file: the entry's keys over [`ReadOptions::default`]. A channel whose
    /// column is named must be in the file; a record with a constant `normal_force` does not
    /// look for a normal-force column.
    pub fn read_options(&self) -> ReadOptions {
        let mut read = ReadOptions::default();
        if let Some(format) = self.format {
            read.format = format;
        }
        if let Some(delimiter) = self.delimiter {
            read.delimiter = delimiter;
        }
        if let Some(decimal) = self.decimal {
            read.decimal = decimal;
        }
        if let Some(column) = &self.time_column {
            read.time.column = column.clone();
        }
        if let Some(scale) = self.time_scale {
            read = read.with_time_scale(scale);
        }
        for (channel, column, scale) in self.channel_keys() {
            if let Some(column) = column {
                read = read.with_column(channel, column.clone());
            }
            if let Some(scale) = scale {
                read = read.with_scale(channel, scale);
            }
        }
        if self.normal_force.is_some() {
            read.channels.remove(&Channel::NormalForce);
        }
        for (name, column, scale) in self.named_channels().unwrap_or_default() {
            read = read.with_named(name, column, scale);
        }
        if let Some(n) = self.min_samples {
            read.min_samples = n;
        }
        if let Some(tolerance) = self.sampling_tolerance {
            read.sampling_tolerance = tolerance;
        }
        read
    }

    /// Checks the entry and reads its file (relative paths against `base_dir`). An entry
    /// error is a [`DataError::Source`].
    pub fn load(&self, base_dir: &Path) -> Result<Record, DataError> {
        self.resolve(1, base_dir)?.load()
    }

    /// [`RecordSource::load`], then the units checked against `osc`.
    pub fn load_checked(&self, base_dir: &Path, osc: &Oscillator) -> Result<Record, DataError> {
        self.resolve(1, base_dir)?.load_checked(osc)
    }
}

/// A named channel's name is one a formula can read and no other key's.
fn check_channel_name(name: &str) -> Result<(), String> {
    if !frictionid_models::formula::is_identifier(name) {
        return Err(format!(
            "`{name}` is not a valid name (a letter or `_`, then letters, digits or `_`)"
        ));
    }
    if Channel::from_name(name).is_some() || name == "time" {
        return Err(format!(
            "`{name}` is a channel of its own: name its column with `{name}_column`"
        ));
    }
    if ["v", "N", "x", "a", "u"].contains(&name) || frictionid_models::formula::is_reserved(name) {
        return Err(format!(
            "`{name}` is reserved (v, N, x, a, u and function names cannot name a channel)"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The entry from TOML-like `key = value` lines (parsed as JSON: the engine has no TOML).
    fn source(text: &str) -> Result<RecordSource, serde_json::Error> {
        let fields: Vec<String> = text
            .lines()
            .filter_map(|l| l.split_once(" = "))
            .map(|(k, v)| format!("\"{k}\": {v}"))
            .collect();
        serde_json::from_str(&format!("{{{}}}", fields.join(",")))
    }

    #[test]
    fn defaults_and_keys() {
        let s = source("file = \"a.csv\"\nx0 = 0.014\nvelocity_scale = 1e-3\n").unwrap();
        let r = s.resolve(1, Path::new("dir")).unwrap();
        assert_eq!(r.file, Path::new("dir/a.csv"));
        assert_eq!(r.file_as_written, "a.csv");
        assert_eq!((r.x0, r.v0, r.weight), (Some(0.014), 0.0, 1.0));
        assert_eq!(r.read.scale(Channel::Velocity), 1e-3);
        assert_eq!(r.read.time.column, "time");
        assert_eq!(r.read.column(Channel::Velocity), "velocity");
        let abs = source("file = \"/data/a.csv\"\nx0 = 0.0\n").unwrap();
        assert_eq!(
            abs.resolve(1, Path::new("dir")).unwrap().file,
            Path::new("/data/a.csv")
        );
    }

    #[test]
    fn errors_name_the_entry_and_key() {
        for (index, toml, says) in [
            (
                2,
                "x0 = 1.0",
                "[[records]] entry 2: missing `file` (the record's data file)",
            ),
            (
                1,
                "file = \"a.csv\"\nx0 = 0.01\nweight = 0.0",
                "[[records]] entry 1 (`a.csv`): `weight` must be > 0, got 0",
            ),
        ] {
            let e = source(toml)
                .unwrap()
                .resolve(index, Path::new("."))
                .unwrap_err();
            assert_eq!(e.to_string(), says);
        }
        let nan = RecordSource {
            x0: Some(f64::NAN),
            ..source("file = \"a.csv\"").unwrap()
        };
        let e = nan.resolve(1, Path::new(".")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "[[records]] entry 1 (`a.csv`): `x0` must be finite, got NaN"
        );
        let e = source("file = \"a.csv\"\nx0 = 0.01\nvelocity_colum = \"v\"").unwrap_err();
        assert!(
            e.to_string().starts_with("unknown field `velocity_colum`"),
            "{e}"
        );
    }

    /// The rows `row(0)` to `row(count - 1)`, one a line.
    fn table(count: usize, row: impl Fn(usize) -> String) -> String {
        (0..count).map(|i| row(i) + "\n").collect()
    }

    /// A fresh directory `frictionid-<name>-<pid>` under the system's temporary directory
    /// holding `files` (name, contents).
    fn scratch(name: &str, files: &[(&str, String)]) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("frictionid-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (file, contents) in files {
            std::fs::write(dir.join(file), contents).unwrap();
        }
        dir
    }

    /// x0 is the entry's, else the first sample of the displacement channel (its column named,
    /// or found under its default name), else unknown: an error for a simulated record once
    /// read, a stand-in 0 for a force-domain fit on a measured force.
    #[test]
    fn x0_comes_from_the_entry_the_displacement_or_nowhere() {
        let rows = table(12, |i| {
            format!("{},{},{}", i as f64 * 1e-3, 0.5 - i as f64 * 1e-3, i)
        });
        let dir = scratch(
            "x0",
            &[
                ("r.csv", format!("time,x,velocity\n{rows}")),
                ("d.csv", format!("time,displacement,velocity\n{rows}")),
            ],
        );
        let with_x = source("file = \"r.csv\"\ndisplacement_column = \"x\"").unwrap();
        let r = with_x.resolve(1, &dir).unwrap().load().unwrap();
        assert_eq!((r.x0, r.x0_source), (0.5, X0Source::FirstDisplacement));
        let by_default_name = source("file = \"d.csv\"").unwrap();
        let r = by_default_name.resolve(1, &dir).unwrap().load().unwrap();
        assert_eq!((r.x0, r.x0_source), (0.5, X0Source::FirstDisplacement));
        let given = source("file = \"d.csv\"\nx0 = 0.25").unwrap();
        let r = given.resolve(1, &dir).unwrap().load().unwrap();
        assert_eq!((r.x0, r.x0_source), (0.25, X0Source::Given));
        let bare = source("file = \"r.csv\"").unwrap();
        let e = bare
            .resolve(2, &dir)
            .unwrap()
            .load()
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "[[records]] entry 2 (`r.csv`): missing `x0` (the release displacement, m)"
        );
        let replayed = bare.resolve_for(1, &dir, RecordUse::Replayed).unwrap();
        let r = replayed.load().unwrap();
        assert_eq!((r.x0, r.x0_source), (0.0, X0Source::Unknown));
        let e = r.require_x0("a test").unwrap_err().to_string();
        assert_eq!(
            e,
            "record `r.csv`: missing `x0` (the release displacement, m): a test needs it for a \
             record without a displacement channel"
        );
        std::fs::remove_dir_all(&dir).ok();
    }

    /// Named channels are read from their columns with their scales (a unit in a column
    /// found by its bare name scales it, one in a column named in full does not), cut at the
    /// release with the motion; a wrong table is one line naming the entry and the name.
    #[test]
    fn named_channels_are_read_scaled_and_cut_at_the_release() {
        let rows = table(14, |i| {
            format!("{},{},{},{}", i as f64 * 1e-3, i, 20 + i, 2 * i)
        });
        let header = "time,velocity,T [degC],Load torque [mN m]";
        let dir = scratch("named", &[("r.csv", format!("{header}\n{rows}"))]);
        let s = source(
            "file = \"r.csv\"\nx0 = 0.0\nrelease = 0.0035\nchannels = { \"temperature\": \"T [degC]\", \"load\": \"Load torque\", \"temperature_scale\": 2.0 }",
        )
        .unwrap();
        let r = s.load(&dir).unwrap();
        assert_eq!(r.named_channels(), vec!["load", "temperature"]);
        assert_eq!(r.len(), 11);
        assert_eq!(r.named_channel("temperature").unwrap()[0], 2.0 * 23.0);
        let load = r.named_channel("load").unwrap();
        assert!((load[1] - 8e-3).abs() < 1e-15, "{load:?}");
        for (channels, says) in [
            (
                "{ \"velocity\": \"v\" }",
                "`velocity` is a channel of its own",
            ),
            ("{ \"x\": \"X\" }", "`x` is reserved"),
            (
                "{ \"load\": \"L\", \"lod_scale\": 2.0 }",
                "`lod_scale` = a number names no channel",
            ),
            (
                "{ \"load\": \"L\", \"load_scale\": \"2\" }",
                "`load_scale` must be a number",
            ),
        ] {
            let e = source(&format!("file = \"r.csv\"\nchannels = {channels}"))
                .unwrap()
                .resolve(3, &dir)
                .unwrap_err()
                .to_string();
            assert!(
                e.starts_with("[[records]] entry 3 (`r.csv`): `channels`: ") && e.contains(says),
                "{e}"
            );
        }
        let missing = source("file = \"r.csv\"\nx0 = 0.0\nchannels = { \"load\": \"Torque\" }")
            .unwrap()
            .load(&dir)
            .unwrap_err()
            .to_string();
        assert!(missing.contains("no column `Torque`"), "{missing}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn load_reads_the_file_and_sets_the_release_state() {
        let rows = table(12, |i| format!("{},{}", i as f64 * 1e-3, i));
        let dir = scratch("source", &[("r.csv", format!("time,v\n{rows}"))]);
        let s = source(
            "file = \"r.csv\"\nx0 = 0.02\nv0 = 0.1\nvelocity_column = \"v\"\nvelocity_scale = 1e-3",
        )
        .unwrap();
        let r = s.load(&dir).unwrap();
        assert_eq!(r.name, "r.csv");
        assert_eq!((r.x0, r.v0, r.len()), (0.02, 0.1, 12));
        assert_eq!(r.velocity()[11], 11e-3);
        let e = source("file = \"r.csv\"\nvelocity_column = \"v\"")
            .unwrap()
            .load(&dir)
            .unwrap_err();
        assert!(
            matches!(e, DataError::Source(RecordSourceError::MissingX0 { .. })),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
