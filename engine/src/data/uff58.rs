//! The universal file format (UFF), dataset 58 "function at nodal DOF", ASCII variant.
//!
//! A dataset sits between two lines holding `-1` (format I6); the line after the opening `-1`
//! holds the dataset number, `58`. Then come eleven header records and the data:
//!
//! | record | format | content used here |
//! |---|---|---|
//! | 1-5 | 80A1 | ID lines (free text) |
//! | 6 | I5,I10,I5,I10,1X,10A1,I10,I4,1X,10A1,I10,I4 | field 1: function type (0 general, 1 time response) |
//! | 7 | 3I10,3E13.5 | ordinate data type (2 real single, 4 real double, 5/6 complex), number of points, abscissa spacing (1 even, 0 uneven), abscissa minimum, abscissa increment, z value |
//! | 8 | I10,3I5,2(1X,20A1) | abscissa: specific data type (17 time, 0 unknown), unit exponents, label, unit label |
//! | 9 | I10,3I5,2(1X,20A1) | ordinate (numerator): specific data type (11 velocity, 0 unknown) |
//! | 10, 11 | I10,3I5,2(1X,20A1) | ordinate denominator, z axis (not used) |
//! | 12 | 6E13.5 (single) / 4E20.12 (double), or (x, y) pairs for uneven abscissa | data |
//!
//! The first dataset 58 of the file is read; other datasets (units 164, header 151, ...) are
//! skipped. Values are read as whitespace-separated numbers, or by their fixed field widths
//! when adjacent numbers touch. Binary files (`58b`) are rejected with a message.

use super::{finish, quoted, Channel, DataError, RawSamples, ReadOptions, MAX_SAMPLES};
use crate::record::Record;
use std::path::Path;

/// Names of the common UFF specific data types, for messages.
fn spec_type_name(code: i64) -> &'static str {
    match code {
        0 => "unknown",
        1 => "general",
        2 => "stress",
        3 => "strain",
        5 => "temperature",
        6 => "heat flux",
        8 => "displacement",
        9 => "reaction force",
        11 => "velocity",
        12 => "acceleration",
        13 => "excitation force",
        15 => "pressure",
        16 => "mass",
        17 => "time",
        18 => "frequency",
        19 => "rpm",
        _ => "other",
    }
}

/// Splits `line` into fields of the given widths (the last field takes what remains of its
/// width); `None` if the line is not ASCII.
fn fixed_fields<'a>(line: &'a str, widths: &[usize]) -> Option<Vec<&'a str>> {
    if !line.is_ascii() {
        return None;
    }
    let mut out = Vec::with_capacity(widths.len());
    let mut start = 0;
    for &w in widths {
        if start >= line.len() {
            break;
        }
        let end = (start + w).min(line.len());
        out.push(line.get(start..end)?.trim());
        start = end;
    }
    Some(out)
}

/// Parses the numeric header fields of a record: fixed widths first, then whitespace tokens.
fn header_numbers(line: &str, widths: &[usize]) -> Option<Vec<f64>> {
    let parse = |fields: Vec<&str>| -> Option<Vec<f64>> {
        let v: Option<Vec<f64>> = fields
            .iter()
            .filter(|f| !f.is_empty())
            .map(|f| parse_fortran(f))
            .collect();
        v.filter(|v| v.len() >= widths.len())
    };
    fixed_fields(line, widths)
        .and_then(parse)
        .or_else(|| parse(line.split_whitespace().collect()))
}

/// Parses a Fortran-style real (also accepting a `D` exponent).
fn parse_fortran(text: &str) -> Option<f64> {
    text.parse::<f64>()
        .ok()
        .or_else(|| text.replace(['D', 'd'], "E").parse::<f64>().ok())
}

fn is_delimiter(line: &str) -> bool {
    line.trim() == "-1"
}

/// One header record's leading integer field (width `width`), fixed width or first token.
fn leading_int(line: &str, width: usize) -> Option<i64> {
    fixed_fields(line, &[width])
        .and_then(|f| f.first().and_then(|s| s.parse::<i64>().ok()))
        .or_else(|| line.split_whitespace().next()?.parse::<i64>().ok())
}

/// Parses UFF text (already read from `path`) and returns the first dataset 58 as a record.
pub fn read_uff58(path: &Path, text: &str, opts: &ReadOptions) -> Result<Record, DataError> {
    let lines: Vec<(usize, &str)> = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
        .collect();
    let err = |line: usize, reason: String| DataError::Uff {
        file: path.to_path_buf(),
        line,
        reason,
    };
    if let Some(name) = opts.named.keys().next() {
        return Err(DataError::Options {
            file: path.to_path_buf(),
            reason: format!(
                "channel `{name}`: a UFF dataset 58 holds one function, so named channels \
                 cannot be read from it; export them with the motion as CSV or a MAT-file"
            ),
        });
    }
    let mut i = 0;
    while let Some(&(_, line)) = lines.get(i) {
        if !is_delimiter(line) {
            i += 1;
            continue;
        }
        let Some(&(id_line, id_text)) = lines.get(i + 1) else {
            break;
        };
        let id = id_text.split_whitespace().next().unwrap_or_default();
        if id.eq_ignore_ascii_case("58b") {
            return Err(err(
                id_line,
                "binary UFF dataset 58b is not supported; export the record as ASCII".into(),
            ));
        }
        if id == "58" {
            return parse_dataset(path, &lines, i + 2, opts);
        }
        // Skip another dataset: find its closing delimiter.
        i += 2;
        while lines.get(i).is_some_and(|&(_, l)| !is_delimiter(l)) {
            i += 1;
        }
        i += 1;
    }
    Err(DataError::Empty {
        file: path.to_path_buf(),
        reason: "no UFF dataset 58 in the file".into(),
    })
}

/// What records 6-11 of a dataset 58 declare about its data.
struct DatasetHeader {
    /// Number of points.
    n: usize,
    /// Ordinates in double precision.
    double: bool,
    /// An evenly spaced abscissa (`x_min + i dx`), else (x, y) pairs.
    even: bool,
    x_min: f64,
    dx: f64,
    /// The channel the ordinate holds.
    channel: Channel,
}

impl DatasetHeader {
    /// Number of values in the data record.
    fn values(&self) -> usize {
        if self.even {
            self.n
        } else {
            2 * self.n
        }
    }

    /// The fixed field widths of a data line.
    fn widths(&self) -> &'static [usize] {
        match (self.double, self.even) {
            (false, _) => &[13; 6],
            (true, true) => &[20; 4],
            (true, false) => &[13, 20, 13, 20],
        }
    }
}

/// The lines of one dataset and how to report its errors.
struct Dataset<'a, 'l> {
    path: &'a Path,
    lines: &'a [(usize, &'l str)],
    /// Index in `lines` of header record 1.
    start: usize,
}

impl<'l> Dataset<'_, 'l> {
    fn err(&self, line: usize, reason: String) -> DataError {
        DataError::Uff {
            file: self.path.to_path_buf(),
            line,
            reason,
        }
    }

    fn last_line(&self) -> usize {
        self.lines.last().map(|l| l.0).unwrap_or(0)
    }

    /// Header record `k` (1-based) and its line number.
    fn record(&self, k: usize) -> Result<(usize, &'l str), DataError> {
        self.lines
            .get(self.start + k - 1)
            .copied()
            .filter(|(_, l)| !is_delimiter(l))
            .ok_or_else(|| {
                self.err(
                    self.last_line(),
                    format!("dataset 58 ends before its header record {k}"),
                )
            })
    }
}

/// Parses the dataset 58 whose first header record (ID line 1) is `lines[start]`.
fn parse_dataset(
    path: &Path,
    lines: &[(usize, &str)],
    start: usize,
    opts: &ReadOptions,
) -> Result<Record, DataError> {
    let ds = Dataset { path, lines, start };
    check_function_type(&ds)?;
    let mut header = parse_layout(&ds)?;
    check_abscissa(&ds)?;
    header.channel = ordinate_channel(&ds)?;
    ds.record(10)?;
    ds.record(11)?;
    let (values, value_lines) = read_values(&ds, &header)?;
    finish(path, samples(&header, values, value_lines, opts), opts)
}

/// Record 6: the function type must be a time response (1) or general (0).
fn check_function_type(ds: &Dataset) -> Result<(), DataError> {
    let (l6, r6) = ds.record(6)?;
    let func_type = leading_int(r6, 5)
        .ok_or_else(|| ds.err(l6, "record 6: the function type is not an integer".into()))?;
    if !(func_type == 0 || func_type == 1) {
        return Err(ds.err(
            l6,
            format!("function type {func_type} is not a time response (1)"),
        ));
    }
    Ok(())
}

/// Record 7: data type, number of points and abscissa spacing.
fn parse_layout(ds: &Dataset) -> Result<DatasetHeader, DataError> {
    let (l7, r7) = ds.record(7)?;
    let r7v = header_numbers(r7, &[10, 10, 10, 13, 13, 13]).unwrap_or_default();
    let [data_type, n_points, even, x_min, dx, ..] = r7v[..] else {
        return Err(ds.err(
            l7,
            "record 7: expected 3 integers and 3 reals (data type, points, spacing, start, increment, z)".into(),
        ));
    };
    let double = match data_type as i64 {
        2 => false,
        4 => true,
        5 | 6 => {
            return Err(ds.err(
                l7,
                "complex ordinate data is not a velocity time history".into(),
            ))
        }
        other => return Err(ds.err(l7, format!("unknown ordinate data type {other}"))),
    };
    if !(n_points >= 0.0 && n_points.fract() == 0.0) {
        return Err(ds.err(l7, format!("bad number of points {n_points}")));
    }
    if n_points > MAX_SAMPLES as f64 {
        return Err(DataError::TooLarge {
            file: ds.path.to_path_buf(),
            reason: format!(
                "line {l7}: record 7 declares {n_points} points; more than {MAX_SAMPLES} samples are refused"
            ),
        });
    }
    let even = match even as i64 {
        1 => true,
        0 => false,
        other => return Err(ds.err(l7, format!("bad abscissa spacing flag {other}"))),
    };
    if even && !(dx.is_finite() && dx > 0.0 && x_min.is_finite()) {
        return Err(ds.err(
            l7,
            format!("even abscissa needs a positive increment, got start {x_min}, increment {dx}"),
        ));
    }
    Ok(DatasetHeader {
        // In range: a non-negative integer of at most MAX_SAMPLES.
        n: n_points as usize,
        double,
        even,
        x_min,
        dx,
        channel: Channel::Velocity,
    })
}

/// Record 8: the abscissa must be time (17) or unknown (0).
fn check_abscissa(ds: &Dataset) -> Result<(), DataError> {
    check_data_type(ds, 8, "abscissa", (17, "time"))
}

/// Record 9: the channel of the ordinate; velocity (11) or unknown (0, read as velocity).
fn ordinate_channel(ds: &Dataset) -> Result<Channel, DataError> {
    check_data_type(ds, 9, "ordinate", (11, "velocity"))?;
    Ok(Channel::Velocity)
}

/// The specific data type in the first field of `record` (8 or 9) must be `expected`'s code
/// or 0 (unknown); otherwise an error naming the `axis` and both types.
fn check_data_type(
    ds: &Dataset,
    record: usize,
    axis: &str,
    (code, name): (i64, &str),
) -> Result<(), DataError> {
    let (line, text) = ds.record(record)?;
    let found = leading_int(text, 10).ok_or_else(|| {
        ds.err(
            line,
            format!("record {record}: the {axis} data type is not an integer"),
        )
    })?;
    if found == 0 || found == code {
        return Ok(());
    }
    Err(ds.err(
        line,
        format!(
            "the {axis} is {} (specific data type {found}), not {name} ({code})",
            spec_type_name(found)
        ),
    ))
}

/// Record 12: every value to the closing delimiter, with its line; checks the declared count.
fn read_values(ds: &Dataset, header: &DatasetHeader) -> Result<(Vec<f64>, Vec<usize>), DataError> {
    let expected = header.values();
    let first = ds.start + 11;
    // The declared count is not trusted for the allocation: at most six values fit a line.
    let room = expected.min(6 * ds.lines.len().saturating_sub(first));
    let mut values = Vec::with_capacity(room);
    let mut value_lines = Vec::with_capacity(room);
    let mut end_line = None;
    for &(ln, text) in ds.lines.iter().skip(first) {
        if is_delimiter(text) {
            end_line = Some(ln);
            break;
        }
        for v in parse_data_line(ds, ln, text, header.widths())? {
            values.push(v);
            value_lines.push(ln);
        }
    }
    let Some(end_line) = end_line else {
        return Err(ds.err(ds.last_line(), "dataset 58 has no closing `-1` line".into()));
    };
    if values.len() != expected {
        return Err(ds.err(
            end_line,
            format!(
                "record 7 declares {} points ({expected} values) but the dataset holds {}",
                header.n,
                values.len()
            ),
        ));
    }
    Ok((values, value_lines))
}

/// The finite numbers of one data line: whitespace tokens, or fixed-width fields when
/// adjacent numbers touch.
fn parse_data_line(
    ds: &Dataset,
    line: usize,
    text: &str,
    widths: &[usize],
) -> Result<Vec<f64>, DataError> {
    let tokens: Option<Vec<f64>> = text.split_whitespace().map(parse_fortran).collect();
    let parsed = tokens.or_else(|| {
        fixed_fields(text, widths)?
            .into_iter()
            .filter(|f| !f.is_empty())
            .map(parse_fortran)
            .collect()
    });
    let Some(parsed) = parsed else {
        return Err(ds.err(
            line,
            format!("`{}` is not a list of numbers", quoted(text.trim())),
        ));
    };
    if let Some(v) = parsed.iter().find(|v| !v.is_finite()) {
        return Err(ds.err(line, format!("value {v} is not finite")));
    }
    Ok(parsed)
}

/// Time, the ordinate's channel and the line of each sample, scaled.
fn samples(
    header: &DatasetHeader,
    values: Vec<f64>,
    value_lines: Vec<usize>,
    opts: &ReadOptions,
) -> RawSamples {
    let (time_scale, scale) = (opts.time.scale, opts.scale(header.channel));
    let (time, ordinate, lines): (Vec<f64>, Vec<f64>, Vec<usize>) = if header.even {
        (
            (0..header.n)
                .map(|i| (header.x_min + i as f64 * header.dx) * time_scale)
                .collect(),
            values.iter().map(|v| v * scale).collect(),
            value_lines,
        )
    } else {
        (
            values.iter().step_by(2).map(|t| t * time_scale).collect(),
            values
                .iter()
                .skip(1)
                .step_by(2)
                .map(|v| v * scale)
                .collect(),
            value_lines.iter().step_by(2).copied().collect(),
        )
    };
    RawSamples {
        time,
        channels: vec![(header.channel, ordinate)],
        named: Vec::new(),
        lines,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(data_type: i32, n: usize, even: i32, ordinate: i32) -> String {
        let mut s = String::from("    -1\n    58\n");
        for k in 1..=5 {
            s.push_str(&format!("ID line {k}\n"));
        }
        s.push_str(&format!(
            "{:5}{:10}{:5}{:10} {:>10}{:10}{:4} {:>10}{:10}{:4}\n",
            1, 0, 0, 0, "NONE", 1, 1, "NONE", 0, 0
        ));
        s.push_str(&format!(
            "{:10}{:10}{:10}{:13.5e}{:13.5e}{:13.5e}\n",
            data_type, n, even, 0.5, 0.01, 0.0
        ));
        s.push_str(&format!(
            "{:10}{:5}{:5}{:5} {:<20} {:<20}\n",
            17, 0, 0, 0, "Time", "s"
        ));
        s.push_str(&format!(
            "{:10}{:5}{:5}{:5} {:<20} {:<20}\n",
            ordinate, 1, 0, 0, "Velocity", "m/s"
        ));
        for _ in 0..2 {
            s.push_str(&format!(
                "{:10}{:5}{:5}{:5} {:<20} {:<20}\n",
                0, 0, 0, 0, "NONE", "NONE"
            ));
        }
        s
    }

    fn opts() -> ReadOptions {
        ReadOptions {
            min_samples: 3,
            ..ReadOptions::default()
        }
    }

    #[test]
    fn reads_single_precision_with_touching_fields() {
        let mut s = String::from("    -1\n   164\nunits\n    -1\n");
        s.push_str(&header(2, 7, 1, 11));
        // Six E13.5 fields, the negative ones touching their neighbours.
        // Six 13-character fields (six mantissa digits), the negative ones touching.
        s.push_str(
            " 0.100000E-02-0.200000E-02 0.300000E-02-0.400000E-02 0.500000E-02-0.600000E-02\n",
        );
        s.push_str(" 0.700000D-02\n    -1\n");
        let r = read_uff58(Path::new("a.uff"), &s, &opts()).unwrap();
        assert_eq!(r.len(), 7);
        for (i, (&t, &v)) in r.time().iter().zip(r.velocity()).enumerate() {
            assert!((t - (0.5 + 0.01 * i as f64)).abs() < 1e-12);
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            assert!((v - sign * 1e-3 * (i + 1) as f64).abs() < 1e-15);
        }
    }

    #[test]
    fn reads_uneven_double_pairs() {
        let mut s = header(4, 3, 0, 0);
        s.push_str(&format!(
            "{:13.5e}{:20.11e}{:13.5e}{:20.11e}\n",
            0.0, 1.5, 0.1, -2.5
        ));
        s.push_str(&format!("{:13.5e}{:20.11e}\n    -1\n", 0.2, 3.5));
        let r = read_uff58(Path::new("b.uff"), &s, &opts()).unwrap();
        assert_eq!(r.time(), vec![0.0, 0.1, 0.2]);
        assert_eq!(r.velocity(), vec![1.5, -2.5, 3.5]);
    }

    #[test]
    fn rejects_wrong_content_with_the_line() {
        let s = header(4, 3, 1, 12) + "1 2 3\n    -1\n";
        let e = read_uff58(Path::new("c.uff"), &s, &opts()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "c.uff: line 11: the ordinate is acceleration (specific data type 12), not velocity (11)"
        );
        let s = header(6, 3, 1, 11) + "1 2 3 4 5 6\n    -1\n";
        let e = read_uff58(Path::new("c.uff"), &s, &opts()).unwrap_err();
        assert!(e.to_string().contains("line 9: complex"), "{e}");
        let s = header(4, 4, 1, 11) + "1 2 3\n    -1\n";
        let e = read_uff58(Path::new("c.uff"), &s, &opts()).unwrap_err();
        assert!(
            e.to_string()
                .contains("line 15: record 7 declares 4 points (4 values) but the dataset holds 3"),
            "{e}"
        );
        let s = header(4, 3, 1, 11) + "1 x 3\n    -1\n";
        let e = read_uff58(Path::new("c.uff"), &s, &opts()).unwrap_err();
        assert!(
            e.to_string().contains("line 14: `1 x 3` is not a list"),
            "{e}"
        );
        let s = header(4, 3, 1, 11) + "1 2 3\n";
        let e = read_uff58(Path::new("c.uff"), &s, &opts()).unwrap_err();
        assert!(e.to_string().contains("no closing"), "{e}");
    }

    #[test]
    fn rejects_binary_and_files_without_dataset_58() {
        let e = read_uff58(Path::new("d.uff"), "    -1\n    58b     1\n", &opts()).unwrap_err();
        assert!(e.to_string().contains("line 2: binary"), "{e}");
        let e = read_uff58(Path::new("d.uff"), "    -1\n   151\nx\n    -1\n", &opts()).unwrap_err();
        assert!(matches!(e, DataError::Empty { .. }), "{e}");
    }
}
