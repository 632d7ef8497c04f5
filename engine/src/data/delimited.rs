//! Delimited text records: columns separated by a comma, semicolon, tab or whitespace, with
//! a header row, after any preamble (comment lines starting with `#`, or lines of text before
//! the header); numbers with a decimal point or comma. The layout is sniffed from the file
//! ([`super::layout`]) where the `delimiter` and `decimal` keys do not give it. Blank lines
//! and lines starting with `#` are skipped anywhere in the file. A unit in a column's name
//! (`Velocity [mm/s]`) scales a column found by its name without the unit, unless a scale is
//! given ([`super::units`]).

use super::layout::{parse_number, sniff_layout, DecimalMark, Separator, SNIFF_LINES};
use super::units::{split_unit, unit_of, Quantity};
use super::{
    finish, quoted, too_many_samples, Channel, ColumnSpec, DataError, DataFormat, RawSamples,
    ReadOptions, MAX_SAMPLES,
};
use crate::record::Record;
use std::path::Path;

/// Position of `name` in the header: exact match first, then ignoring case, then the
/// header's names without their units (`velocity` finds `Velocity [mm/s]`). The flag says
/// whether the name was found without its unit (so the unit is the reader's to apply).
fn find_column(header: &[&str], name: &str) -> Option<(usize, bool)> {
    header
        .iter()
        .position(|h| *h == name)
        .or_else(|| header.iter().position(|h| h.eq_ignore_ascii_case(name)))
        .map(|i| (i, false))
        .or_else(|| {
            header
                .iter()
                .position(|h| split_unit(h).0.eq_ignore_ascii_case(name.trim()))
                .map(|i| (i, true))
        })
}

/// The header row: its line, the separator and decimal mark of the file and its column
/// names.
struct Header<'a> {
    line: usize,
    sep: Separator,
    decimal: DecimalMark,
    names: Vec<&'a str>,
}

/// Where the time and each channel found are in a line's fields.
struct Columns {
    time: usize,
    time_scale: f64,
    channels: Vec<(Channel, usize, f64)>,
    named: Vec<(String, usize, f64)>,
}

/// Parses delimited text (already read from `path`) into a record.
pub fn read_delimited(
    path: &Path,
    text: &str,
    format: DataFormat,
    opts: &ReadOptions,
) -> Result<Record, DataError> {
    let mut lines = content_lines(text);
    let head: Vec<(usize, &str)> = lines.by_ref().take(SNIFF_LINES).collect();
    let layout = sniff_layout(&head, format, opts.delimiter, opts.decimal);
    let header = read_header(path, head.get(layout.header).copied(), layout, opts)?;
    let columns = locate_columns(path, &header, opts)?;
    let rows = head.iter().skip(layout.header + 1).copied().chain(lines);
    let raw = read_rows(path, &header, &columns, rows)?;
    finish(path, raw, opts)
}

/// The lines of `text` that are not blank or comments, with their 1-based line numbers.
fn content_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
        .filter(|(_, l)| {
            let t = l.trim_start();
            !t.is_empty() && !t.starts_with('#')
        })
}

/// The header row (the line before the data block, or the first line that is not blank or
/// a comment when no data block is found).
fn read_header<'a>(
    path: &Path,
    first: Option<(usize, &'a str)>,
    layout: super::layout::Layout,
    opts: &ReadOptions,
) -> Result<Header<'a>, DataError> {
    let Some((line, text)) = first else {
        return Err(DataError::Empty {
            file: path.to_path_buf(),
            reason: "the file has no header row and no data".into(),
        });
    };
    let sep = layout.separator;
    let names = sep.split(text);
    if names
        .iter()
        .all(|h| parse_number(h, layout.decimal).is_some())
    {
        let first_channel = opts
            .channels
            .values()
            .next()
            .map_or("velocity", |c| &c.column);
        return Err(DataError::Empty {
            file: path.to_path_buf(),
            reason: format!(
                "line {line}: expected a header row with column names (`{}`, `{first_channel}`), found numbers",
                opts.time.column
            ),
        });
    }
    Ok(Header {
        line,
        sep,
        decimal: layout.decimal,
        names,
    })
}

/// The positions of the time column and of every channel found, with their scales: a
/// required column that is missing is an error, and so is a header without any channel
/// column.
fn locate_columns(path: &Path, header: &Header, opts: &ReadOptions) -> Result<Columns, DataError> {
    let missing = |name: &str| DataError::MissingColumn {
        file: path.to_path_buf(),
        line: header.line,
        column: quoted(name),
        hint: suggestion(header, name),
        available: quoted(&header.names.join(", ")),
    };
    let (time, bare) =
        find_column(&header.names, &opts.time.column).ok_or_else(|| missing(&opts.time.column))?;
    let time_scale = column_scale(
        path,
        header,
        time,
        bare,
        &opts.time,
        "time",
        &[Quantity::Time],
    )?;
    let mut channels = Vec::new();
    for (&channel, spec) in &opts.channels {
        match find_column(&header.names, &spec.column) {
            Some((idx, bare)) => {
                let quantities = channel_quantities(channel);
                let scale =
                    column_scale(path, header, idx, bare, spec, channel.name(), quantities)?;
                channels.push((channel, idx, scale));
            }
            None if spec.required => return Err(missing(&spec.column)),
            None => {}
        }
    }
    if channels.is_empty() {
        return Err(no_channel(path, header, opts, missing));
    }
    let mut named = Vec::with_capacity(opts.named.len());
    for (name, spec) in &opts.named {
        let (idx, bare) =
            find_column(&header.names, &spec.column).ok_or_else(|| missing(&spec.column))?;
        let scale = column_scale(path, header, idx, bare, spec, name, ANY_QUANTITY)?;
        named.push((name.clone(), idx, scale));
    }
    Ok(Columns {
        time,
        time_scale,
        channels,
        named,
    })
}

/// Every quantity: a named channel's unit may measure any (a load torque, a length), and a
/// unit not recognised (`degC`) leaves its values as they are.
const ANY_QUANTITY: &[Quantity] = &[
    Quantity::Time,
    Quantity::Length,
    Quantity::Velocity,
    Quantity::Acceleration,
    Quantity::Force,
    Quantity::Angle,
    Quantity::AngularVelocity,
    Quantity::AngularAcceleration,
    Quantity::Torque,
];

/// The quantities a channel's unit may measure (on a linear or a rotary axis).
fn channel_quantities(channel: Channel) -> &'static [Quantity] {
    match channel {
        Channel::Velocity => &[Quantity::Velocity, Quantity::AngularVelocity],
        Channel::Displacement => &[Quantity::Length, Quantity::Angle],
        Channel::Acceleration => &[Quantity::Acceleration, Quantity::AngularAcceleration],
        Channel::Force | Channel::NormalForce => &[Quantity::Force],
        Channel::InputForce => &[Quantity::Force, Quantity::Torque],
    }
}

/// The scale of the column at `idx`: the one given, else the factor of the unit in its name
/// when the column was found by its name without the unit (`bare`), else 1. A unit that does
/// not measure the column's quantity is an error naming the key that overrides it.
fn column_scale(
    path: &Path,
    header: &Header,
    idx: usize,
    bare: bool,
    spec: &ColumnSpec,
    key: &str,
    quantities: &[Quantity],
) -> Result<f64, DataError> {
    if spec.scale_given || !bare {
        return Ok(spec.scale);
    }
    let name = header.names.get(idx).copied().unwrap_or_default();
    match unit_of(name) {
        Some(unit) if quantities.contains(&unit.quantity) => Ok(spec.scale * unit.factor),
        Some(_) => Err(DataError::UnitMismatch {
            file: path.to_path_buf(),
            line: header.line,
            column: quoted(name),
            key: key.to_string(),
        }),
        None => Ok(spec.scale),
    }
}

/// The error for a header without any channel column: a near miss of one column name is
/// named as missing (with its suggestion), otherwise every column looked for is listed.
fn no_channel(
    path: &Path,
    header: &Header,
    opts: &ReadOptions,
    missing: impl Fn(&str) -> DataError,
) -> DataError {
    let columns: Vec<&str> = opts.channels.values().map(|s| s.column.as_str()).collect();
    if let Some(near) = columns.iter().find(|c| !suggestion(header, c).is_empty()) {
        return missing(near);
    }
    let looked_for: Vec<String> = columns.iter().map(|c| format!("`{}`", quoted(c))).collect();
    DataError::NoChannel {
        file: path.to_path_buf(),
        line: header.line,
        looked_for: looked_for.join(", "),
        available: quoted(&header.names.join(", ")),
    }
}

/// ` (did you mean `...`?)` for a near header name, or empty.
fn suggestion(header: &Header, name: &str) -> String {
    // Only short names are compared (the edit distance costs the product of lengths).
    frictionid_models::suggest::did_you_mean(
        name,
        header.names.iter().copied().filter(|h| h.len() <= 64),
    )
}

/// Parses the data rows: time and each channel's column, scaled.
fn read_rows<'a>(
    path: &Path,
    header: &Header,
    columns: &Columns,
    lines: impl Iterator<Item = (usize, &'a str)>,
) -> Result<RawSamples, DataError> {
    let mut raw = RawSamples {
        time: Vec::new(),
        channels: columns
            .channels
            .iter()
            .map(|&(c, _, _)| (c, Vec::new()))
            .collect(),
        named: columns
            .named
            .iter()
            .map(|(n, _, _)| (n.clone(), Vec::new()))
            .collect(),
        lines: Vec::new(),
    };
    for (line, text) in lines {
        if raw.time.len() >= MAX_SAMPLES {
            return Err(too_many_samples(path, line));
        }
        let fields = header.sep.split(text);
        if fields.len() != header.names.len() {
            return Err(DataError::ColumnCount {
                file: path.to_path_buf(),
                line,
                found: fields.len(),
                expected: header.names.len(),
            });
        }
        let number = |idx: usize| field_number(path, line, header, &fields, idx);
        raw.time.push(number(columns.time)? * columns.time_scale);
        for ((_, idx, scale), (_, values)) in columns.channels.iter().zip(&mut raw.channels) {
            values.push(number(*idx)? * scale);
        }
        for ((_, idx, scale), (_, values)) in columns.named.iter().zip(&mut raw.named) {
            values.push(number(*idx)? * scale);
        }
        raw.lines.push(line);
    }
    if raw.time.is_empty() {
        return Err(DataError::Empty {
            file: path.to_path_buf(),
            reason: format!("no data rows after the header on line {}", header.line),
        });
    }
    Ok(raw)
}

/// The finite number in field `idx` of a data line.
fn field_number(
    path: &Path,
    line: usize,
    header: &Header,
    fields: &[&str],
    idx: usize,
) -> Result<f64, DataError> {
    let name = header.names.get(idx).copied().unwrap_or_default();
    let raw = fields.get(idx).copied().unwrap_or_default();
    let value = parse_number(raw, header.decimal).ok_or_else(|| DataError::BadNumber {
        file: path.to_path_buf(),
        line,
        column: quoted(name),
        text: quoted(raw),
    })?;
    if value.is_finite() {
        Ok(value)
    } else {
        Err(DataError::NonFinite {
            file: path.to_path_buf(),
            line,
            column: quoted(name),
            value,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<Record, DataError> {
        read_delimited(
            Path::new("r.csv"),
            text,
            DataFormat::Auto,
            &ReadOptions {
                min_samples: 3,
                ..ReadOptions::default()
            },
        )
    }

    fn rows(n: usize) -> String {
        (0..n)
            .map(|i| format!("{},{}\n", i as f64 * 1e-3, 0.5 * i as f64))
            .collect()
    }

    #[test]
    fn reads_csv_with_comments_and_blank_lines() {
        let text = format!("# exported by a test\n\ntime,velocity\n{}# end\n", rows(5));
        let r = read(&text).unwrap();
        assert_eq!(r.time(), vec![0.0, 0.001, 0.002, 0.003, 0.004]);
        assert_eq!(r.velocity(), vec![0.0, 0.5, 1.0, 1.5, 2.0]);
        assert_eq!(r.name, "r.csv");
    }

    #[test]
    fn reads_whitespace_columns_in_any_order_with_scale() {
        let text = "velocity   extra time\n 1.0 a 0.0\n2.0 b 0.1\n\t3.0 c 0.2\n";
        let opts = ReadOptions {
            min_samples: 3,
            ..ReadOptions::default()
        }
        .with_scale(Channel::Velocity, 1e-3);
        let r = read_delimited(Path::new("w.txt"), text, DataFormat::Whitespace, &opts).unwrap();
        assert_eq!(r.time(), vec![0.0, 0.1, 0.2]);
        assert_eq!(r.velocity(), vec![1e-3, 2e-3, 3e-3]);
    }

    #[test]
    fn semicolon_and_quoted_headers_with_custom_columns() {
        let text = "\"t [s]\";\"v [mm/s]\"\n0;1\n1;2\n2;3\n";
        let opts = ReadOptions {
            time: crate::data::ColumnSpec::named("t [s]"),
            min_samples: 3,
            ..ReadOptions::default()
        }
        .with_column(Channel::Velocity, "v [mm/s]");
        let r = read_delimited(Path::new("s.csv"), text, DataFormat::Csv, &opts).unwrap();
        assert_eq!(r.velocity(), vec![1.0, 2.0, 3.0]);
    }

    /// Each reading error is one line naming the file and, where there is one, the line and
    /// the column.
    #[test]
    fn errors_name_the_file_line_and_column() {
        for (text, message) in [
            (
                "time,velocity\n0,1\n0.001,abc\n0.002,3\n",
                "r.csv: line 3: column `velocity`: `abc` is not a number",
            ),
            (
                "time,velocity\n0,1\n0.001,2,7\n",
                "r.csv: line 3: 3 fields, but the header has 2",
            ),
            (
                "time,velocity\n0,1\n0.001,1\n0.001,1\n0.003,1\n",
                "r.csv: line 4: time 0.001 s does not increase (previous 0.001 s)",
            ),
            (
                "time,velocity\n0,1\n0.001,1\n",
                "r.csv: 2 samples, at least 3 needed",
            ),
            (
                "time,velocty\n0,1\n",
                "r.csv: line 1: no column `velocity` (did you mean `velocty`?); the header has: time, velocty",
            ),
        ] {
            assert_eq!(read(text).unwrap_err().to_string(), message);
        }
    }

    #[test]
    fn nan_and_infinity_are_rejected() {
        let e = read("time,velocity\n0,1\n0.001,NaN\n0.002,1\n").unwrap_err();
        assert!(matches!(e, DataError::NonFinite { line: 3, .. }), "{e}");
        let e = read("time,velocity\n0,1\ninf,1\n").unwrap_err();
        assert!(matches!(e, DataError::NonFinite { line: 3, .. }), "{e}");
    }

    #[test]
    fn uneven_sampling_is_rejected_beyond_the_tolerance() {
        let e = read("time,velocity\n0,1\n0.001,1\n0.002,1\n0.0035,1\n0.0045,1\n").unwrap_err();
        assert!(
            matches!(e, DataError::UnevenSampling { line: 5, .. }),
            "{e}"
        );
        // A jitter of 0.1 % of the step is accepted.
        read("time,velocity\n0,1\n0.001001,1\n0.002,1\n0.003,1\n").unwrap();
    }

    #[test]
    fn header_is_required() {
        let e = read("0,1\n0.001,2\n").unwrap_err();
        assert!(
            e.to_string().contains("line 1: expected a header row"),
            "{e}"
        );
        let e = read("# only a comment\n").unwrap_err();
        assert!(matches!(e, DataError::Empty { .. }), "{e}");
        let e = read("time,velocity\n").unwrap_err();
        assert!(e.to_string().contains("no data rows"), "{e}");
    }

    #[test]
    fn every_channel_found_is_read_with_its_scale() {
        let text = "time_ms;displacement;force;velocity;normal_force;other\n\
                    0;1;-2;3;4;x\n1;2;-4;6;8;y\n2;3;-6;9;12;z\n";
        let opts = ReadOptions {
            time: crate::data::ColumnSpec::named("time_ms"),
            min_samples: 3,
            ..ReadOptions::default()
        }
        .with_time_scale(1e-3)
        .with_column(Channel::Displacement, "DISPLACEMENT")
        .with_scale(Channel::Displacement, 1e-3)
        .with_scale(Channel::Force, -1.0);
        let r = read_delimited(Path::new("c.csv"), text, DataFormat::Auto, &opts).unwrap();
        assert_eq!(r.time(), vec![0.0, 1e-3, 2e-3]);
        assert_eq!(
            r.channel(Channel::Displacement),
            Some(&[1e-3, 2e-3, 3e-3][..])
        );
        assert_eq!(r.channel(Channel::Force), Some(&[2.0, 4.0, 6.0][..]));
        assert_eq!(r.velocity(), vec![3.0, 6.0, 9.0]);
        assert_eq!(r.channel(Channel::NormalForce), Some(&[4.0, 8.0, 12.0][..]));
        assert_eq!(r.channel(Channel::Acceleration), None);
    }

    /// A vibrometer's ASCII export: `#` lines holding commas, a line of plain text, a
    /// header with units, semicolons and decimal commas; the units scale the columns found
    /// by their names without them.
    #[test]
    fn an_instrument_export_after_its_preamble_with_decimal_commas_and_units() {
        let rows: String = (0..5)
            .map(|i| format!("{:.6};{:.3}\n", i as f64 * 2e-4, 1.5 * i as f64).replace('.', ","))
            .collect();
        let text = format!(
            "# Vibrometer export, channel 1, velocity\n# Sample rate: 5000,0 Hz\n\
             # Range: 100 mm/s, filter off\nMeasured on the rig, run 3\n\
             Time [s];Velocity [mm/s]\n{rows}"
        );
        let r = read(&text).unwrap();
        assert_eq!(r.time(), vec![0.0, 2e-4, 4e-4, 6e-4, 8e-4]);
        let expected = [0.0, 1.5e-3, 3e-3, 4.5e-3, 6e-3];
        for (v, e) in r.velocity().iter().zip(expected) {
            assert!((v - e).abs() < 1e-15, "{v} {e}");
        }
        // A scale given replaces the unit; a column named with its unit is read as written.
        let opts = ReadOptions {
            min_samples: 3,
            ..ReadOptions::default()
        };
        let given = opts.clone().with_scale(Channel::Velocity, 1.0);
        let r = read_delimited(Path::new("v.txt"), &text, DataFormat::Auto, &given).unwrap();
        assert_eq!(r.velocity()[1], 1.5);
        let named = opts
            .clone()
            .with_column(Channel::Velocity, "Velocity [mm/s]");
        let r = read_delimited(Path::new("v.txt"), &text, DataFormat::Auto, &named).unwrap();
        assert_eq!(r.velocity()[1], 1.5);
        // The keys decide what sniffing cannot: here a point read as the decimal mark.
        let point = ReadOptions {
            decimal: crate::data::DecimalMark::Point,
            ..opts
        };
        let e = read_delimited(Path::new("v.txt"), &text, DataFormat::Auto, &point).unwrap_err();
        assert_eq!(
            e.to_string(),
            "v.txt: line 6: column `Time [s]`: `0,000000` is not a number"
        );
    }

    #[test]
    fn a_unit_of_another_quantity_names_the_key_that_overrides_it() {
        let e = read("time,velocity [mm]\n0,1\n1,2\n2,3\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "r.csv: line 1: column `velocity [mm]`: its unit is not one of a velocity column; \
             give `velocity_scale` (the factor to SI) or fix the name"
        );
        let r = read("time (ms)\tvelocity\n0\t1\n1\t2\n2\t3\n").unwrap();
        assert_eq!(r.time(), vec![0.0, 1e-3, 2e-3]);
    }

    #[test]
    fn a_displacement_only_file_is_a_record_without_velocity() {
        let r = read("time,displacement\n0,1\n1,2\n2,3\n").unwrap();
        assert_eq!(r.channels(), vec![Channel::Displacement]);
        assert!(r.velocity().is_empty());
    }

    #[test]
    fn a_named_column_must_exist_and_some_channel_must_be_found() {
        let opts = ReadOptions {
            min_samples: 3,
            ..ReadOptions::default()
        }
        .with_column(Channel::Force, "F [N]");
        let e = read_delimited(
            Path::new("r.csv"),
            "time,velocity\n0,1\n",
            DataFormat::Auto,
            &opts,
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "r.csv: line 1: no column `F [N]`; the header has: time, velocity"
        );
        let e = read("time,pressure\n0,1\n1,2\n2,3\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "r.csv: line 1: no channel column found (looked for `velocity`, `displacement`, \
             `acceleration`, `force`, `normal_force`); the header has: time, pressure"
        );
    }
}
