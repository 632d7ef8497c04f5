//! MATLAB MAT-files, level 5 (`save -v5`, `-v6`, `-v7`; SciPy's `savemat`), with or without
//! compression.
//!
//! A file is a 128-byte header (116 bytes of text, an 8-byte subsystem offset, the version
//! `0x0100` and the endian indicator `IM` or `MI`) followed by data elements. Each element is
//! an 8-byte tag (data type, byte count) and its data, padded to 8 bytes; a tag whose upper
//! 16 bits are non-zero is a small element (count and type in one word, up to 4 bytes of data
//! in the next). A variable is a `miMATRIX` element, or a `miCOMPRESSED` element holding one
//! zlib-compressed `miMATRIX`. Inside the matrix come the array flags (its class), the
//! dimensions, the name and the real part, whose data type may be narrower than the class
//! (MATLAB stores whole numbers in the smallest integer type that holds them).
//!
//! Each `*_column` of the [`ReadOptions`] names a variable: a numeric vector (1xN or Nx1, any
//! numeric class) with one value per sample. Text, cell, struct, sparse and complex variables
//! are refused with a message; so are version 7.3 files (HDF5) and version 4 files. Every
//! compressed variable is first inflated only as far as its name; a variable read is inflated
//! to at most [`MAX_SAMPLES`] values, so a small file cannot expand without bound.

use super::{finish, quoted, DataError, RawSamples, ReadOptions, MAX_SAMPLES};
use crate::record::Record;
use std::io::Read;
use std::path::Path;

/// Length of the file header \[bytes\].
const HEADER_BYTES: usize = 128;

const MI_INT8: u32 = 1;
const MI_UINT8: u32 = 2;
const MI_INT16: u32 = 3;
const MI_UINT16: u32 = 4;
const MI_INT32: u32 = 5;
const MI_UINT32: u32 = 6;
const MI_SINGLE: u32 = 7;
const MI_DOUBLE: u32 = 9;
const MI_INT64: u32 = 12;
const MI_UINT64: u32 = 13;
const MI_MATRIX: u32 = 14;
const MI_COMPRESSED: u32 = 15;

/// Bytes of a compressed variable inflated to read its flags, dimensions and name.
const NAME_PREFIX_BYTES: u64 = 4096;

/// Largest inflated variable read: [`MAX_SAMPLES`] doubles and the matrix's own headers.
const MAX_VARIABLE_BYTES: u64 = MAX_SAMPLES as u64 * 8 + NAME_PREFIX_BYTES;

/// Most variables in one file.
const MAX_VARIABLES: usize = 100_000;

/// Byte order of the file, from its endian indicator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Endian {
    Little,
    Big,
}

impl Endian {
    /// The `N` bytes at the start of `bytes` in little-endian order (missing bytes are 0).
    fn le<const N: usize>(self, bytes: &[u8]) -> [u8; N] {
        let mut word = [0u8; N];
        word.iter_mut().zip(bytes).for_each(|(w, b)| *w = *b);
        if self == Endian::Big {
            word.reverse();
        }
        word
    }

    fn u32(self, bytes: &[u8]) -> u32 {
        u32::from_le_bytes(self.le(bytes))
    }
}

/// One data element: its type and its data.
#[derive(Debug, Clone, Copy)]
struct Element<'a> {
    kind: u32,
    data: &'a [u8],
}

/// Reads data elements one after the other; a reason on failure.
struct Elements<'a> {
    bytes: &'a [u8],
    pos: usize,
    endian: Endian,
}

impl<'a> Elements<'a> {
    fn new(bytes: &'a [u8], endian: Endian) -> Self {
        Self {
            bytes,
            pos: 0,
            endian,
        }
    }

    /// The next element, or `None` when fewer than 8 bytes (a tag) are left.
    fn next_element(&mut self) -> Result<Option<Element<'a>>, String> {
        let start = self.pos;
        let Some(tag) = self.bytes.get(start..start + 8) else {
            return Ok(None);
        };
        let first = self.endian.u32(tag);
        if first >> 16 != 0 {
            // A small element: count in the upper half-word, type in the lower, data inline.
            let len = (first >> 16) as usize;
            let data = tag
                .get(4..4 + len)
                .ok_or_else(|| format!("byte {start}: a small element declares {len} bytes"))?;
            self.pos = start + 8;
            return Ok(Some(Element {
                kind: first & 0xffff,
                data,
            }));
        }
        let len = self.endian.u32(&tag[4..]) as usize;
        let data = self
            .bytes
            .get(start + 8..)
            .and_then(|rest| rest.get(..len))
            .ok_or_else(|| {
                format!(
                    "byte {start}: the element declares {len} bytes, {} are left",
                    self.bytes.len().saturating_sub(start + 8)
                )
            })?;
        // Compressed elements are not padded; every other element to a multiple of 8 bytes.
        let padded = if first == MI_COMPRESSED {
            len
        } else {
            len.div_ceil(8) * 8
        };
        self.pos = start + 8 + padded;
        Ok(Some(Element { kind: first, data }))
    }

    /// The next element, which must be there.
    fn expect(&mut self, what: &str) -> Result<Element<'a>, String> {
        self.next_element()?
            .ok_or_else(|| format!("the array ends before its {what}"))
    }
}

/// The class of an array (`mxDOUBLE_CLASS`, ...), as far as this reader tells them apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ArrayClass {
    Numeric,
    Text,
    Cell,
    Struct,
    Object,
    Sparse,
    Unknown(u8),
}

impl ArrayClass {
    fn from_code(code: u8) -> Self {
        match code {
            1 => Self::Cell,
            2 => Self::Struct,
            3 => Self::Object,
            4 => Self::Text,
            5 => Self::Sparse,
            6..=15 => Self::Numeric,
            other => Self::Unknown(other),
        }
    }

    fn name(self) -> String {
        match self {
            Self::Numeric => "a numeric array".into(),
            Self::Text => "text (a char array)".into(),
            Self::Cell => "a cell array".into(),
            Self::Struct => "a struct".into(),
            Self::Object => "an object".into(),
            Self::Sparse => "a sparse matrix".into(),
            Self::Unknown(code) => format!("an array of unknown class {code}"),
        }
    }
}

/// The head of a `miMATRIX` element: class, complexity, dimensions and name, and the
/// elements that follow (the real part first).
struct ArrayHead<'a> {
    class: ArrayClass,
    complex: bool,
    dims: Vec<i64>,
    name: String,
    rest: Elements<'a>,
}

/// Parses the head of the matrix `data` (the contents of a `miMATRIX` element).
fn array_head(data: &[u8], endian: Endian) -> Result<ArrayHead<'_>, String> {
    let mut rest = Elements::new(data, endian);
    let flags = rest.expect("array flags")?;
    if flags.kind != MI_UINT32 || flags.data.len() < 4 {
        return Err("the array flags are not two uint32 words".into());
    }
    let word = endian.u32(flags.data);
    let dims = rest.expect("dimensions")?;
    if dims.kind != MI_INT32 || dims.data.len() % 4 != 0 {
        return Err("the array dimensions are not int32 values".into());
    }
    let dims = dims
        .data
        .chunks_exact(4)
        .map(|c| i64::from(i32::from_le_bytes(endian.le(c))))
        .collect();
    let name = rest.expect("name")?;
    if name.kind != MI_INT8 {
        return Err("the array name is not int8 text".into());
    }
    Ok(ArrayHead {
        class: ArrayClass::from_code((word & 0xff) as u8),
        complex: word & 0x0800 != 0,
        dims,
        name: String::from_utf8_lossy(name.data).into_owned(),
        rest,
    })
}

/// The number of values of a vector with dimensions `dims`: at most one dimension other than
/// 1; the reason otherwise.
fn vector_length(dims: &[i64]) -> Result<usize, String> {
    let shape = || {
        dims.iter()
            .map(i64::to_string)
            .collect::<Vec<_>>()
            .join("x")
    };
    if dims.iter().any(|&d| d < 0) {
        return Err(format!("has negative dimensions {}", shape()));
    }
    if dims.iter().filter(|&&d| d != 1).count() > 1 {
        return Err(format!(
            "is a {} matrix; store each channel as a 1xN or Nx1 vector",
            shape()
        ));
    }
    let n = dims.iter().copied().find(|&d| d != 1).unwrap_or(1);
    usize::try_from(n)
        .ok()
        .filter(|&n| n <= MAX_SAMPLES)
        .ok_or_else(|| format!("has {n} values; at most {MAX_SAMPLES} are read"))
}

/// The values of a numeric element as doubles.
fn numeric_values(element: Element<'_>, endian: Endian) -> Result<Vec<f64>, String> {
    /// The width of one value and the values, each read from `N` bytes by `to`.
    fn read<const N: usize>(
        data: &[u8],
        endian: Endian,
        to: fn([u8; N]) -> f64,
    ) -> (usize, Vec<f64>) {
        (N, data.chunks_exact(N).map(|c| to(endian.le(c))).collect())
    }
    let data = element.data;
    let (size, values) = match element.kind {
        MI_INT8 => read(data, endian, |b| f64::from(i8::from_le_bytes(b))),
        MI_UINT8 => read(data, endian, |b| f64::from(u8::from_le_bytes(b))),
        MI_INT16 => read(data, endian, |b| f64::from(i16::from_le_bytes(b))),
        MI_UINT16 => read(data, endian, |b| f64::from(u16::from_le_bytes(b))),
        MI_INT32 => read(data, endian, |b| f64::from(i32::from_le_bytes(b))),
        MI_UINT32 => read(data, endian, |b| f64::from(u32::from_le_bytes(b))),
        MI_SINGLE => read(data, endian, |b| f64::from(f32::from_le_bytes(b))),
        MI_DOUBLE => read(data, endian, f64::from_le_bytes),
        MI_INT64 => read(data, endian, |b| i64::from_le_bytes(b) as f64),
        MI_UINT64 => read(data, endian, |b| u64::from_le_bytes(b) as f64),
        other => return Err(format!("its real part has data type {other}, not a number")),
    };
    if element.data.len() % size != 0 {
        return Err(format!(
            "its real part holds {} bytes, not a whole number of {size}-byte values",
            element.data.len()
        ));
    }
    Ok(values)
}

/// The samples of the numeric vector `head`; the reason it is not one otherwise.
fn vector_values(mut head: ArrayHead<'_>, endian: Endian) -> Result<Vec<f64>, String> {
    match head.class {
        ArrayClass::Numeric => {}
        ArrayClass::Struct => {
            return Err("is a struct; save each channel as its own numeric variable".into())
        }
        other => return Err(format!("is {}, not a numeric vector", other.name())),
    }
    if head.complex {
        return Err("is complex; store the real signal".into());
    }
    let n = vector_length(&head.dims)?;
    let real = head.rest.expect("real part")?;
    let values = numeric_values(real, endian)?;
    if values.len() != n {
        return Err(format!(
            "declares {n} values but its real part holds {}",
            values.len()
        ));
    }
    Ok(values)
}

/// Inflates the zlib stream `data` up to `limit` bytes.
fn inflate(data: &[u8], limit: u64) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    flate2::read::ZlibDecoder::new(data)
        .take(limit)
        .read_to_end(&mut out)
        .map_err(|e| format!("a compressed variable cannot be inflated: {e}"))?;
    Ok(out)
}

/// The single `miMATRIX` element inside inflated bytes.
fn inner_matrix(inflated: &[u8], endian: Endian) -> Result<&[u8], String> {
    let element = Elements::new(inflated, endian).next_element()?;
    match element {
        Some(e) if e.kind == MI_MATRIX => Ok(e.data),
        Some(e) => Err(format!(
            "a compressed element holds data type {}, not an array",
            e.kind
        )),
        None => Err("a compressed element is empty".into()),
    }
}

/// One variable of the file: its name and, if it was asked for, its samples or the reason it
/// has none.
struct Variable {
    name: String,
    values: Option<Result<Vec<f64>, String>>,
}

/// The file's endianness from its header; the reason it is not a level-5 MAT-file otherwise.
fn file_endian(bytes: &[u8]) -> Result<Endian, String> {
    let Some(header) = bytes.get(..HEADER_BYTES) else {
        return Err(format!(
            "{} bytes: too short for a MAT-file (a 128-byte header)",
            bytes.len()
        ));
    };
    let endian = match &header[126..128] {
        b"IM" => Endian::Little,
        b"MI" => Endian::Big,
        _ => {
            return Err(
                "not a MAT-file of level 5 (no endian indicator at byte 126); \
                        save it with `save -v7` (or -v6)"
                    .into(),
            )
        }
    };
    let version = u16::from_le_bytes(endian.le(&header[124..126]));
    if version == 0x0200 {
        return Err(
            "a MAT-file of version 7.3 (HDF5) is not supported; save it with \
                    `save -v7` (or -v6)"
                .into(),
        );
    }
    Ok(endian)
}

/// Every variable of the file, the samples read for those whose name `wanted` accepts.
fn scan(
    bytes: &[u8],
    endian: Endian,
    wanted: &dyn Fn(&str) -> bool,
) -> Result<Vec<Variable>, String> {
    let mut elements = Elements::new(bytes.get(HEADER_BYTES..).unwrap_or_default(), endian);
    let mut variables = Vec::new();
    while let Some(element) = elements.next_element()? {
        let variable = match element.kind {
            MI_MATRIX => plain_variable(element.data, endian, wanted)?,
            MI_COMPRESSED => compressed_variable(element.data, endian, wanted)?,
            // Other top-level elements (none in files MATLAB or SciPy write) are skipped.
            _ => continue,
        };
        if variables.len() >= MAX_VARIABLES {
            return Err(format!(
                "more than {MAX_VARIABLES} variables; save the channels in a smaller file"
            ));
        }
        variables.push(variable);
    }
    Ok(variables)
}

fn plain_variable(
    data: &[u8],
    endian: Endian,
    wanted: &dyn Fn(&str) -> bool,
) -> Result<Variable, String> {
    let head = array_head(data, endian)?;
    let name = head.name.clone();
    let values = wanted(&name).then(|| vector_values(head, endian));
    Ok(Variable { name, values })
}

fn compressed_variable(
    data: &[u8],
    endian: Endian,
    wanted: &dyn Fn(&str) -> bool,
) -> Result<Variable, String> {
    let prefix = inflate(data, NAME_PREFIX_BYTES)?;
    let name = array_head(inner_matrix_prefix(&prefix, endian)?, endian)?.name;
    if !wanted(&name) {
        return Ok(Variable { name, values: None });
    }
    let full = inflate(data, MAX_VARIABLE_BYTES + 1)?;
    let values = if full.len() as u64 > MAX_VARIABLE_BYTES {
        Err(format!("inflates to over {MAX_VARIABLE_BYTES} bytes"))
    } else {
        inner_matrix(&full, endian).and_then(|m| vector_values(array_head(m, endian)?, endian))
    };
    Ok(Variable {
        name,
        values: Some(values),
    })
}

/// The start of the `miMATRIX` data in an inflated prefix (its tag read, its length not
/// checked: the prefix may end inside it).
fn inner_matrix_prefix(prefix: &[u8], endian: Endian) -> Result<&[u8], String> {
    let kind = prefix
        .get(..4)
        .map(|t| endian.u32(t))
        .ok_or("a compressed element is empty")?;
    if kind != MI_MATRIX {
        return Err(format!(
            "a compressed element holds data type {kind}, not an array"
        ));
    }
    Ok(prefix.get(8..).unwrap_or_default())
}

/// Position of the variable named `name`: exact match first, then ignoring case.
fn find_variable(variables: &[Variable], name: &str) -> Option<usize> {
    variables.iter().position(|v| v.name == name).or_else(|| {
        variables
            .iter()
            .position(|v| v.name.eq_ignore_ascii_case(name))
    })
}

/// The variables of a file and how to report a problem with one of them.
struct MatVariables<'a> {
    path: &'a Path,
    variables: Vec<Variable>,
}

impl MatVariables<'_> {
    fn error(&self, reason: String) -> DataError {
        DataError::Mat {
            file: self.path.to_path_buf(),
            reason,
        }
    }

    fn names(&self) -> String {
        let names: Vec<&str> = self.variables.iter().map(|v| v.name.as_str()).collect();
        quoted(&names.join(", "))
    }

    /// The error for a variable `name` (the `key` names it) that is not in the file.
    fn missing(&self, key: &str, name: &str) -> DataError {
        let hint = frictionid_models::suggest::did_you_mean(
            name,
            self.variables
                .iter()
                .map(|v| v.name.as_str())
                .filter(|n| n.len() <= 64),
        );
        self.error(format!(
            "{key}: no variable `{}`{hint}; the file has: {}",
            quoted(name),
            self.names()
        ))
    }

    /// The samples of the variable at `index`, scaled.
    fn samples(&self, index: usize, key: &str, scale: f64) -> Result<Vec<f64>, DataError> {
        let variable = self.variables.get(index);
        let name = variable.map_or("", |v| v.name.as_str());
        match variable.and_then(|v| v.values.as_ref()) {
            Some(Ok(values)) => Ok(values.iter().map(|v| v * scale).collect()),
            Some(Err(reason)) => {
                Err(self.error(format!("{key}: variable `{}` {reason}", quoted(name))))
            }
            None => Err(self.error(format!("{key}: variable `{}` was not read", quoted(name)))),
        }
    }
}

/// Parses the bytes of a level-5 MAT-file (already read from `path`) into a record.
pub fn read_mat(path: &Path, bytes: &[u8], opts: &ReadOptions) -> Result<Record, DataError> {
    let error = |reason: String| DataError::Mat {
        file: path.to_path_buf(),
        reason,
    };
    let endian = file_endian(bytes).map_err(error)?;
    let names: Vec<&str> = std::iter::once(opts.time.column.as_str())
        .chain(opts.channels.values().map(|c| c.column.as_str()))
        .chain(opts.named.values().map(|c| c.column.as_str()))
        .collect();
    let wanted = |name: &str| names.iter().any(|n| n.eq_ignore_ascii_case(name));
    let variables = scan(bytes, endian, &wanted).map_err(error)?;
    let file = MatVariables { path, variables };
    let raw = collect(&file, opts)?;
    finish(path, raw, opts).map_err(|e| in_samples(path, e))
}

/// The time and every channel found, as raw samples; the lines are the sample numbers.
fn collect(file: &MatVariables<'_>, opts: &ReadOptions) -> Result<RawSamples, DataError> {
    let time_index = find_variable(&file.variables, &opts.time.column)
        .ok_or_else(|| file.missing("time_column", &opts.time.column))?;
    let time = file.samples(time_index, "time_column", opts.time.scale)?;
    let mut channels = Vec::new();
    for (&channel, spec) in &opts.channels {
        let key = format!("{channel}_column");
        match find_variable(&file.variables, &spec.column) {
            Some(index) => {
                let values = file.samples(index, &key, spec.scale)?;
                if values.len() != time.len() {
                    return Err(file.error(format!(
                        "{key}: variable `{}` has {} samples, the time `{}` has {}",
                        quoted(&spec.column),
                        values.len(),
                        quoted(&opts.time.column),
                        time.len()
                    )));
                }
                channels.push((channel, values));
            }
            None if spec.required => return Err(file.missing(&key, &spec.column)),
            None => {}
        }
    }
    if channels.is_empty() {
        return Err(no_channel(file, opts));
    }
    let named = named_channels(file, opts, time.len())?;
    Ok(RawSamples {
        lines: (1..=time.len()).collect(),
        time,
        channels,
        named,
    })
}

/// Every named channel's variable, scaled; each must be present and as long as the time.
fn named_channels(
    file: &MatVariables<'_>,
    opts: &ReadOptions,
    len: usize,
) -> Result<Vec<(String, Vec<f64>)>, DataError> {
    let mut named = Vec::with_capacity(opts.named.len());
    for (name, spec) in &opts.named {
        let key = format!("channels.{name}");
        let index = find_variable(&file.variables, &spec.column)
            .ok_or_else(|| file.missing(&key, &spec.column))?;
        let values = file.samples(index, &key, spec.scale)?;
        if values.len() != len {
            return Err(file.error(format!(
                "{key}: variable `{}` has {} samples, the time `{}` has {len}",
                quoted(&spec.column),
                values.len(),
                quoted(&opts.time.column),
            )));
        }
        named.push((name.clone(), values));
    }
    Ok(named)
}

/// The error for a file without any channel variable: a near miss of one name is named as
/// missing (with its suggestion), otherwise every name looked for is listed.
fn no_channel(file: &MatVariables<'_>, opts: &ReadOptions) -> DataError {
    let near = opts.channels.iter().find(|(_, spec)| {
        !frictionid_models::suggest::did_you_mean(
            &spec.column,
            file.variables.iter().map(|v| v.name.as_str()),
        )
        .is_empty()
    });
    if let Some((channel, spec)) = near {
        return file.missing(&format!("{channel}_column"), &spec.column);
    }
    let looked_for: Vec<String> = opts
        .channels
        .values()
        .map(|s| format!("`{}`", quoted(&s.column)))
        .collect();
    file.error(format!(
        "no channel variable found (looked for {}); the file has: {}",
        looked_for.join(", "),
        file.names()
    ))
}

/// The sample checks' errors, which name a line in text files, naming the sample instead.
fn in_samples(path: &Path, e: DataError) -> DataError {
    let reason = match e {
        DataError::NonFinite {
            line,
            column,
            value,
            ..
        } => format!("sample {line}: `{column}` is {value} (values must be finite)"),
        DataError::NotIncreasing {
            line,
            time,
            previous,
            ..
        } => format!("sample {line}: time {time} s does not increase (previous {previous} s)"),
        DataError::UnevenSampling {
            line,
            step,
            median,
            tolerance_percent,
            ..
        } => format!(
            "sample {line}: uneven sampling: step {step} s differs from the median step \
             {median} s by more than {tolerance_percent}%"
        ),
        other => return other,
    };
    DataError::Mat {
        file: path.to_path_buf(),
        reason,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::Channel;

    /// One data element in `endian` order, padded to 8 bytes (a small element when `small`).
    fn element(endian: Endian, kind: u32, data: &[u8], small: bool) -> Vec<u8> {
        let word = |v: u32| match endian {
            Endian::Little => v.to_le_bytes(),
            Endian::Big => v.to_be_bytes(),
        };
        let mut out = Vec::new();
        if small {
            out.extend(word(((data.len() as u32) << 16) | kind));
            out.extend(data);
            out.resize(8, 0);
            return out;
        }
        out.extend(word(kind));
        out.extend(word(data.len() as u32));
        out.extend(data);
        out.resize(8 + data.len().div_ceil(8) * 8, 0);
        out
    }

    /// A MAT-file with one 1xN double row per `(name, values)`; names of up to 4 bytes go in
    /// small elements.
    fn file(endian: Endian, variables: &[(&str, &[f64])]) -> Vec<u8> {
        let mut out = vec![b' '; HEADER_BYTES];
        let (version, indicator): ([u8; 2], &[u8; 2]) = match endian {
            Endian::Little => (0x0100u16.to_le_bytes(), b"IM"),
            Endian::Big => (0x0100u16.to_be_bytes(), b"MI"),
        };
        out[124..126].copy_from_slice(&version);
        out[126..128].copy_from_slice(indicator);
        for (name, values) in variables {
            let int32 = |v: i32| match endian {
                Endian::Little => v.to_le_bytes(),
                Endian::Big => v.to_be_bytes(),
            };
            let mut flags = int32(6).to_vec();
            flags.extend([0; 4]);
            let dims: Vec<u8> = [1, values.len() as i32]
                .into_iter()
                .flat_map(int32)
                .collect();
            let data: Vec<u8> = values
                .iter()
                .flat_map(|v| match endian {
                    Endian::Little => v.to_le_bytes(),
                    Endian::Big => v.to_be_bytes(),
                })
                .collect();
            let mut matrix = element(endian, MI_UINT32, &flags, false);
            matrix.extend(element(endian, MI_INT32, &dims, false));
            matrix.extend(element(endian, MI_INT8, name.as_bytes(), name.len() <= 4));
            matrix.extend(element(endian, MI_DOUBLE, &data, false));
            out.extend(element(endian, MI_MATRIX, &matrix, false));
        }
        out
    }

    fn opts() -> ReadOptions {
        ReadOptions {
            min_samples: 2,
            ..ReadOptions::default()
        }
    }

    fn read(bytes: &[u8]) -> Result<Record, DataError> {
        read_mat(Path::new("r.mat"), bytes, &opts())
    }

    #[test]
    fn both_byte_orders_and_small_name_elements_read_alike() {
        let t = [0.0, 0.5, 1.0];
        let v = [1.0, -2.0, 3.5];
        for endian in [Endian::Little, Endian::Big] {
            let r = read(&file(endian, &[("time", &t), ("velocity", &v)])).unwrap();
            assert_eq!(r.time(), t);
            assert_eq!(r.channel(Channel::Velocity), Some(&v[..]), "{endian:?}");
        }
    }

    /// A named channel is read from its variable with its scale; a missing one names the
    /// channel's key.
    #[test]
    fn named_channels_are_read_from_their_variables() {
        let t = [0.0, 0.5, 1.0];
        let v = [1.0, -2.0, 3.5];
        let load = [4.0, 5.0, 6.0];
        let bytes = file(
            Endian::Little,
            &[("time", &t), ("velocity", &v), ("tau_l", &load)],
        );
        let with = opts().with_named("load", "tau_l", Some(0.5));
        let r = read_mat(Path::new("r.mat"), &bytes, &with).unwrap();
        assert_eq!(r.named_channel("load"), Some(&[2.0, 2.5, 3.0][..]));
        let wrong = opts().with_named("load", "torque", None);
        let e = read_mat(Path::new("r.mat"), &bytes, &wrong)
            .unwrap_err()
            .to_string();
        assert!(e.contains("channels.load") && e.contains("torque"), "{e}");
    }

    /// Every prefix and every single-byte corruption of a valid file is read or refused with
    /// one line naming the file, never a panic.
    #[test]
    fn truncated_and_corrupted_files_are_refused_cleanly() {
        let good = file(
            Endian::Little,
            &[("time", &[0.0, 1.0]), ("velocity", &[1.0, 2.0])],
        );
        for end in 0..good.len() {
            if let Err(e) = read(&good[..end]) {
                let e = e.to_string();
                assert!(e.starts_with("r.mat: ") && !e.contains('\n'), "{e}");
            }
        }
        for at in HEADER_BYTES..good.len() {
            for byte in [0x00, 0x07, 0x7f, 0xff] {
                let mut bad = good.clone();
                bad[at] = byte;
                if let Err(e) = read(&bad) {
                    assert!(e.to_string().starts_with("r.mat: "), "{e}");
                }
            }
        }
    }

    #[test]
    fn other_files_are_refused_with_the_reason() {
        let e = read(b"time,velocity\n0,1\n").unwrap_err().to_string();
        assert!(e.contains("too short for a MAT-file"), "{e}");
        let mut v73 = file(Endian::Little, &[]);
        v73[124..126].copy_from_slice(&0x0200u16.to_le_bytes());
        let e = read(&v73).unwrap_err().to_string();
        assert!(e.contains("version 7.3 (HDF5) is not supported"), "{e}");
        let e = read(&file(Endian::Little, &[("time", &[0.0, 1.0])]))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("r.mat: no channel variable found"), "{e}");
    }

    #[test]
    fn sample_checks_name_the_sample() {
        let bytes = file(
            Endian::Little,
            &[("time", &[0.0, 1.0, 1.0]), ("velocity", &[1.0, 2.0, 3.0])],
        );
        assert_eq!(
            read(&bytes).unwrap_err().to_string(),
            "r.mat: sample 3: time 1 s does not increase (previous 1 s)"
        );
        let short = file(
            Endian::Little,
            &[("time", &[0.0, 1.0, 2.0]), ("velocity", &[1.0, 2.0])],
        );
        assert_eq!(
            read(&short).unwrap_err().to_string(),
            "r.mat: velocity_column: variable `velocity` has 2 samples, the time `time` has 3"
        );
    }
}
