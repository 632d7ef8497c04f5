//! Readers for measured records: delimited text (CSV, whitespace-separated), the universal
//! file format's dataset 58 (ASCII), as exported by laser vibrometers and modal-test software,
//! and MATLAB MAT-files of level 5, as drive, robot and benchmark data come.
//!
//! Every reader returns an engine [`Record`] released from rest at x0 = 0 with unit weight; the
//! caller sets `x0`, `v0` and `weight` from its configuration: [`RecordSource`] (one
//! `[[records]]` entry, in `source.rs`) reads its file here and cuts it at the release. Every error is a [`DataError`] whose
//! message is one line naming the file and, where there is one, the line and the reason.

mod delimited;
pub mod layout;
mod mat5;
pub mod sniff;
pub mod source;
mod uff58;
pub mod units;

pub use delimited::read_delimited;
pub use layout::{DecimalMark, Delimiter};
pub use mat5::read_mat;
pub use source::{RecordSource, RecordSourceError, RecordUse, ResolvedSource};
pub use uff58::read_uff58;

pub use crate::record::Channel;
use crate::record::{Record, ScaleError, TimeBase, TimeError};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Largest record file read \[bytes\] (256 MiB, about six million `time,velocity` lines); a
/// larger file is refused with [`DataError::TooLarge`] before it is read.
pub const MAX_FILE_BYTES: u64 = 256 * 1024 * 1024;

/// Most samples accepted in one record (ten million: over two hours at 1 kHz).
pub const MAX_SAMPLES: usize = 10_000_000;

/// Longest text of a field or header quoted in an error message \[characters\].
const MAX_QUOTED_CHARS: usize = 60;

/// `text` for an error message: at most [`MAX_QUOTED_CHARS`] characters, with an ellipsis
/// and the full length when it is cut.
pub(crate) fn quoted(text: &str) -> String {
    let n = text.chars().count();
    if n <= MAX_QUOTED_CHARS {
        text.to_string()
    } else {
        let head: String = text.chars().take(MAX_QUOTED_CHARS).collect();
        format!("{head}... ({n} characters)")
    }
}

/// The format of a record file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DataFormat {
    /// Chosen from the file extension (`.uff`, `.unv`, `.58` are UFF; `.mat` is a MAT-file;
    /// anything else is delimited text with the delimiter taken from the header row).
    #[default]
    Auto,
    /// Comma-, semicolon- or tab-separated text with a header row.
    Csv,
    /// Text whose columns are separated by runs of spaces or tabs, with a header row.
    Whitespace,
    /// Universal file format, dataset 58, ASCII.
    Uff58,
    /// MATLAB MAT-file, level 5 (`save -v7` or -v6, SciPy's `savemat`), compressed or not:
    /// each column names a numeric vector variable.
    Mat,
}

/// Where one quantity is in a file and the factor that turns the file's unit into SI.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnSpec {
    /// Header name of the column (delimited text), or the variable's name (MAT-file).
    pub column: String,
    /// Factor from the file's unit to SI (1e-3 for mm/s; negative to flip a sign convention).
    pub scale: f64,
    /// Whether a file without the column is an error (a column named in the configuration);
    /// otherwise the channel is read when its column is found.
    #[serde(default)]
    pub required: bool,
    /// Whether `scale` was given: a scale given replaces the unit in the column's name
    /// (`Velocity [mm/s]`), which otherwise scales a column found by its name without it.
    #[serde(default)]
    pub scale_given: bool,
}

impl ColumnSpec {
    /// The required column `column` with unit scale.
    pub fn named(column: impl Into<String>) -> Self {
        Self {
            column: column.into(),
            scale: 1.0,
            required: true,
            scale_given: false,
        }
    }

    /// The channel's own name as an optional column, with unit scale.
    pub fn default_for(channel: Channel) -> Self {
        Self {
            required: false,
            ..Self::named(channel.name())
        }
    }
}

/// How to read a record file: the time column and, keyed by [`Channel`], the channels to read.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ReadOptions {
    /// File format.
    pub format: DataFormat,
    /// How the fields of a delimited text file are separated (default: sniffed).
    pub delimiter: Delimiter,
    /// The decimal mark of a delimited text file's numbers (default: sniffed).
    pub decimal: DecimalMark,
    /// The time column \[s after scaling\].
    pub time: ColumnSpec,
    /// The channels looked for, each in its column: a required column must be present, an
    /// optional one is read when present; at least one channel must be found.
    pub channels: BTreeMap<Channel, ColumnSpec>,
    /// Named channels besides those (a load torque, a temperature), each in its column,
    /// which must be present: conditions a law may read.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub named: BTreeMap<String, ColumnSpec>,
    /// Fewest samples accepted.
    pub min_samples: usize,
    /// Largest accepted deviation of one time step from the median step, relative to the
    /// median step (the analyses assume even sampling).
    pub sampling_tolerance: f64,
}

impl Default for ReadOptions {
    /// Time from column `time`, and every channel whose own name is a column (`velocity`,
    /// `displacement`, `acceleration`, `force`, `normal_force`), all unscaled.
    fn default() -> Self {
        Self {
            format: DataFormat::Auto,
            delimiter: Delimiter::Auto,
            decimal: DecimalMark::Auto,
            time: ColumnSpec::named("time"),
            // The input is read where its column or scale is named: a column of that name
            // alone is not a record of the motion.
            channels: Channel::ALL
                .into_iter()
                .filter(|&c| c != Channel::InputForce)
                .map(|c| (c, ColumnSpec::default_for(c)))
                .collect(),
            named: BTreeMap::new(),
            min_samples: 10,
            sampling_tolerance: 0.01,
        }
    }
}

impl ReadOptions {
    /// The column spec of `channel`, added as [`ColumnSpec::default_for`] if it is not looked
    /// for yet.
    pub fn channel_mut(&mut self, channel: Channel) -> &mut ColumnSpec {
        self.channels
            .entry(channel)
            .or_insert_with(|| ColumnSpec::default_for(channel))
    }

    /// These options with `channel` read from `column`, which must be present.
    pub fn with_column(mut self, channel: Channel, column: impl Into<String>) -> Self {
        let spec = self.channel_mut(channel);
        spec.column = column.into();
        spec.required = true;
        self
    }

    /// These options with the named channel `name` read from `column` (which must be
    /// present), scaled by `scale` when one is given.
    pub fn with_named(
        mut self,
        name: impl Into<String>,
        column: impl Into<String>,
        scale: Option<f64>,
    ) -> Self {
        let mut spec = ColumnSpec::named(column);
        if let Some(scale) = scale {
            spec.scale = scale;
            spec.scale_given = true;
        }
        self.named.insert(name.into(), spec);
        self
    }

    /// These options with the time stamps multiplied by `scale` (1e-3 for milliseconds).
    pub fn with_time_scale(mut self, scale: f64) -> Self {
        self.time.scale = scale;
        self.time.scale_given = true;
        self
    }

    /// These options with `channel` scaled by `scale`.
    pub fn with_scale(mut self, channel: Channel, scale: f64) -> Self {
        let spec = self.channel_mut(channel);
        spec.scale = scale;
        spec.scale_given = true;
        self
    }

    /// The column `channel` is read from (its own name when it is not configured).
    pub fn column(&self, channel: Channel) -> &str {
        self.channels
            .get(&channel)
            .map_or(channel.name(), |c| c.column.as_str())
    }

    /// The scale of `channel` (1 when it is not configured).
    pub fn scale(&self, channel: Channel) -> f64 {
        self.channels.get(&channel).map_or(1.0, |c| c.scale)
    }

    /// Checks scales and the sampling tolerance; the message is the reason.
    fn check(&self) -> Result<(), String> {
        if !(self.time.scale.is_finite() && self.time.scale > 0.0) {
            return Err(format!(
                "time_scale must be finite and > 0, got {}",
                self.time.scale
            ));
        }
        let scales = self
            .channels
            .iter()
            .map(|(c, spec)| (c.name(), spec))
            .chain(self.named.iter().map(|(n, spec)| (n.as_str(), spec)));
        for (channel, spec) in scales {
            if !(spec.scale.is_finite() && spec.scale != 0.0) {
                return Err(format!(
                    "{channel}_scale must be finite and non-zero, got {}",
                    spec.scale
                ));
            }
        }
        if !(self.sampling_tolerance.is_finite() && self.sampling_tolerance > 0.0) {
            return Err(format!(
                "sampling_tolerance must be > 0, got {}",
                self.sampling_tolerance
            ));
        }
        Ok(())
    }
}

/// Errors of the record readers. Each names the file; most name the line.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum DataError {
    /// The file cannot be opened or read.
    #[error("{file}: cannot read the file: {reason}")]
    Io { file: PathBuf, reason: String },
    /// The file has no header row or no data.
    #[error("{file}: {reason}")]
    Empty { file: PathBuf, reason: String },
    /// A named column is not in the header row.
    #[error("{file}: line {line}: no column `{column}`{hint}; the header has: {available}")]
    MissingColumn {
        file: PathBuf,
        line: usize,
        column: String,
        hint: String,
        available: String,
    },
    /// None of the channel columns looked for is in the header row.
    #[error("{file}: line {line}: no channel column found (looked for {looked_for}); the header has: {available}")]
    NoChannel {
        file: PathBuf,
        line: usize,
        looked_for: String,
        available: String,
    },
    /// A line does not have as many fields as the header.
    #[error("{file}: line {line}: {found} fields, but the header has {expected}")]
    ColumnCount {
        file: PathBuf,
        line: usize,
        found: usize,
        expected: usize,
    },
    /// A field is not a number.
    #[error("{file}: line {line}: column `{column}`: `{text}` is not a number")]
    BadNumber {
        file: PathBuf,
        line: usize,
        column: String,
        text: String,
    },
    /// The unit in a column's name does not measure the column's quantity.
    #[error("{file}: line {line}: column `{column}`: its unit is not one of a {key} column; give `{key}_scale` (the factor to SI) or fix the name")]
    UnitMismatch {
        file: PathBuf,
        line: usize,
        column: String,
        key: String,
    },
    /// A value is NaN or infinite.
    #[error("{file}: line {line}: column `{column}` is {value} (values must be finite)")]
    NonFinite {
        file: PathBuf,
        line: usize,
        column: String,
        value: f64,
    },
    /// The time stamps do not strictly increase.
    #[error("{file}: line {line}: time {time} s does not increase (previous {previous} s)")]
    NotIncreasing {
        file: PathBuf,
        line: usize,
        time: f64,
        previous: f64,
    },
    /// One time step deviates from the median step by more than the tolerance.
    #[error(
        "{file}: line {line}: uneven sampling: step {step} s differs from the median step {median} s by more than {tolerance_percent}%"
    )]
    UnevenSampling {
        file: PathBuf,
        line: usize,
        step: f64,
        median: f64,
        tolerance_percent: f64,
    },
    /// Fewer samples than required.
    #[error("{file}: {found} samples, at least {needed} needed")]
    TooFewSamples {
        file: PathBuf,
        found: usize,
        needed: usize,
    },
    /// A malformed or unsupported UFF dataset 58.
    #[error("{file}: line {line}: {reason}")]
    Uff {
        file: PathBuf,
        line: usize,
        reason: String,
    },
    /// A malformed or unsupported MAT-file, or a variable missing or unusable.
    #[error("{file}: {reason}")]
    Mat { file: PathBuf, reason: String },
    /// The file or record exceeds a size limit ([`MAX_FILE_BYTES`], [`MAX_SAMPLES`]).
    #[error("{file}: {reason}")]
    TooLarge { file: PathBuf, reason: String },
    /// Invalid read options.
    #[error("{file}: {reason}")]
    Options { file: PathBuf, reason: String },
    /// A `[[records]]` entry that cannot be used.
    #[error(transparent)]
    Source(#[from] RecordSourceError),
    /// The record's units disagree with its oscillator.
    #[error(transparent)]
    Scale(#[from] ScaleError),
}

/// Reads a record file in the format given by `opts.format` (see [`DataFormat::Auto`]).
pub fn read_record(path: &Path, opts: &ReadOptions) -> Result<Record, DataError> {
    opts.check().map_err(|reason| DataError::Options {
        file: path.to_path_buf(),
        reason,
    })?;
    let bytes = read_bytes(path)?;
    match resolve_format(path, opts.format) {
        DataFormat::Mat => read_mat(path, &bytes, opts),
        DataFormat::Uff58 => read_uff58(path, &into_text(bytes), opts),
        fmt => read_delimited(path, &into_text(bytes), fmt, opts),
    }
}

/// The concrete format for `path`: `Auto` resolved from the extension.
pub fn resolve_format(path: &Path, format: DataFormat) -> DataFormat {
    if format != DataFormat::Auto {
        return format;
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    match ext.as_str() {
        "uff" | "unv" | "58" => DataFormat::Uff58,
        "mat" => DataFormat::Mat,
        _ => DataFormat::Auto,
    }
}

/// The bytes of the file at `path`, refused beyond [`MAX_FILE_BYTES`].
fn read_bytes(path: &Path) -> Result<Vec<u8>, DataError> {
    use std::io::Read;
    let io = |e: std::io::Error| DataError::Io {
        file: path.to_path_buf(),
        reason: io_reason(&e),
    };
    let too_large = |size: String| DataError::TooLarge {
        file: path.to_path_buf(),
        reason: format!(
            "the file is {size}; records larger than {} MiB are refused",
            MAX_FILE_BYTES / (1024 * 1024)
        ),
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let declared = file.metadata().map_err(io)?.len();
    if declared > MAX_FILE_BYTES {
        return Err(too_large(format!("{declared} bytes")));
    }
    // The metadata length is 0 for pipes and devices: never read past the limit either way.
    let mut bytes = Vec::new();
    file.take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(too_large(format!("over {MAX_FILE_BYTES} bytes")));
    }
    Ok(bytes)
}

/// The file's text, its bytes taken over (a valid UTF-8 file is not copied: a long record's
/// text is tens of megabytes); invalid sequences replaced, a byte-order mark dropped.
fn into_text(bytes: Vec<u8>) -> String {
    let mut text = match String::from_utf8(bytes) {
        Ok(text) => text,
        Err(e) => String::from_utf8_lossy(e.as_bytes()).into_owned(),
    };
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    text
}

/// The error for a record with more than [`MAX_SAMPLES`] samples.
fn too_many_samples(path: &Path, line: usize) -> DataError {
    DataError::TooLarge {
        file: path.to_path_buf(),
        reason: format!("line {line}: more than {MAX_SAMPLES} samples; split the record"),
    }
}

fn io_reason(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".into(),
        std::io::ErrorKind::PermissionDenied => "permission denied".into(),
        _ => e.to_string(),
    }
}

/// A record name for reports: the file name as given.
fn record_name(path: &Path) -> String {
    path.display().to_string()
}

/// Samples read from a file, before the checks: time, the channels found and the file line of
/// each sample.
pub(crate) struct RawSamples {
    pub time: Vec<f64>,
    pub channels: Vec<(Channel, Vec<f64>)>,
    /// The named channels read, by name.
    pub named: Vec<(String, Vec<f64>)>,
    pub lines: Vec<usize>,
}

/// Checks the samples (count, finite values, increasing time, even sampling) and builds the
/// record.
fn finish(path: &Path, raw: RawSamples, opts: &ReadOptions) -> Result<Record, DataError> {
    let file = || path.to_path_buf();
    let line_of = |i: usize| raw.lines.get(i).copied().unwrap_or(0);
    let needed = opts.min_samples.max(2);
    if raw.time.len() < needed {
        return Err(DataError::TooFewSamples {
            file: file(),
            found: raw.time.len(),
            needed,
        });
    }
    // Values parse as finite, but scaling or an evenly spaced UFF abscissa can overflow.
    for i in 0..raw.time.len() {
        let columns = std::iter::once(("time", &raw.time))
            .chain(raw.channels.iter().map(|(c, v)| (c.name(), v)))
            .chain(raw.named.iter().map(|(n, v)| (n.as_str(), v)));
        for (column, values) in columns {
            let value = values.get(i).copied().unwrap_or(f64::NAN);
            if !value.is_finite() {
                return Err(DataError::NonFinite {
                    file: file(),
                    line: line_of(i),
                    column: column.into(),
                    value,
                });
            }
        }
    }
    let time = TimeBase::new(raw.time).map_err(|e| match e {
        TimeError::TooFew { found, needed } => DataError::TooFewSamples {
            file: file(),
            found,
            needed,
        },
        TimeError::NonFinite { index, value } => DataError::NonFinite {
            file: file(),
            line: line_of(index),
            column: "time".into(),
            value,
        },
        TimeError::NotIncreasing {
            index,
            time,
            previous,
        } => DataError::NotIncreasing {
            file: file(),
            line: line_of(index),
            time,
            previous,
        },
    })?;
    check_even_sampling(path, time.as_slice(), &raw.lines, opts.sampling_tolerance)?;
    let record = Record::from_time_base(record_name(path), time);
    let record = raw
        .channels
        .into_iter()
        .fold(record, |r, (channel, values)| {
            r.with_channel(channel, values)
        });
    Ok(raw.named.into_iter().fold(record, |r, (name, values)| {
        r.with_named_channel(name, values)
    }))
}

/// Checks that no time step deviates from the median step by more than `tolerance` of it.
fn check_even_sampling(
    path: &Path,
    time: &[f64],
    lines: &[usize],
    tolerance: f64,
) -> Result<(), DataError> {
    let mut steps: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
    steps.sort_by(f64::total_cmp);
    let median = steps.get(steps.len() / 2).copied().unwrap_or(0.0);
    for (i, w) in time.windows(2).enumerate() {
        let step = w[1] - w[0];
        if (step - median).abs() > tolerance * median {
            return Err(DataError::UnevenSampling {
                file: path.to_path_buf(),
                line: lines.get(i + 1).copied().unwrap_or(0),
                step,
                median,
                tolerance_percent: tolerance * 100.0,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn format_from_extension() {
        for (path, given, resolved) in [
            ("a/b.UFF", DataFormat::Auto, DataFormat::Uff58),
            ("a/b.MAT", DataFormat::Auto, DataFormat::Mat),
            ("a/b.csv", DataFormat::Auto, DataFormat::Auto),
            ("a/b.uff", DataFormat::Csv, DataFormat::Csv),
        ] {
            assert_eq!(
                resolve_format(Path::new(path), given),
                resolved,
                "{path} given {given:?}"
            );
        }
    }

    #[test]
    fn missing_file_is_an_io_error_naming_it() {
        let e = read_record(Path::new("/nonexistent/x.csv"), &ReadOptions::default()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "/nonexistent/x.csv: cannot read the file: no such file"
        );
    }

    #[test]
    fn bad_scale_is_rejected() {
        let opts = ReadOptions::default().with_scale(Channel::Velocity, 0.0);
        let e = read_record(Path::new("x.csv"), &opts).unwrap_err();
        assert!(matches!(e, DataError::Options { .. }), "{e}");
    }
}
