//! Delimited text records: CSV (comma, semicolon or tab) or whitespace-separated columns with a
//! header row. Blank lines and lines starting with `#` are skipped anywhere in the file.

use super::{finish, quoted, too_many_samples, DataError, DataFormat, ReadOptions, MAX_SAMPLES};
use crate::record::Record;
use std::path::Path;

/// How the fields of a line are separated.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Separator {
    Char(char),
    Whitespace,
}

impl Separator {
    /// Chooses the separator from the header row.
    fn detect(header: &str, format: DataFormat) -> Self {
        let by_char = [',', ';', '\t']
            .into_iter()
            .find(|c| header.contains(*c))
            .map(Separator::Char);
        match format {
            DataFormat::Whitespace => Separator::Whitespace,
            DataFormat::Csv => by_char.unwrap_or(Separator::Char(',')),
            _ => match by_char {
                Some(Separator::Char('\t')) | None => Separator::Whitespace,
                Some(sep) => sep,
            },
        }
    }

    fn split<'a>(&self, line: &'a str) -> Vec<&'a str> {
        match self {
            Separator::Char(c) => line.split(*c).map(clean_field).collect(),
            Separator::Whitespace => line.split_whitespace().map(clean_field).collect(),
        }
    }
}

fn clean_field(field: &str) -> &str {
    let f = field.trim();
    f.strip_prefix('"')
        .and_then(|g| g.strip_suffix('"'))
        .unwrap_or(f)
        .trim()
}

/// Position of `name` in the header: exact match first, then ignoring case.
fn find_column(header: &[&str], name: &str) -> Option<usize> {
    header
        .iter()
        .position(|h| *h == name)
        .or_else(|| header.iter().position(|h| h.eq_ignore_ascii_case(name)))
}

/// Parses delimited text (already read from `path`) into a record.
pub fn read_delimited(
    path: &Path,
    text: &str,
    format: DataFormat,
    opts: &ReadOptions,
) -> Result<Record, DataError> {
    let file = || path.to_path_buf();
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
        .filter(|(_, l)| {
            let t = l.trim_start();
            !t.is_empty() && !t.starts_with('#')
        });
    let Some((header_line, header_text)) = lines.next() else {
        return Err(DataError::Empty {
            file: file(),
            reason: "the file has no header row and no data".into(),
        });
    };
    let sep = Separator::detect(header_text, format);
    let header = sep.split(header_text);
    if header.iter().all(|h| h.parse::<f64>().is_ok()) {
        return Err(DataError::Empty {
            file: file(),
            reason: format!(
                "line {header_line}: expected a header row with column names (`{}`, `{}`), found numbers",
                opts.time_column, opts.velocity_column
            ),
        });
    }
    let column = |name: &str| {
        find_column(&header, name).ok_or_else(|| DataError::MissingColumn {
            file: file(),
            line: header_line,
            column: quoted(name),
            // Only short names are compared (the edit distance costs the product of lengths).
            hint: frictionid_models::suggest::did_you_mean(
                name,
                header.iter().copied().filter(|h| h.len() <= 64),
            ),
            available: quoted(&header.join(", ")),
        })
    };
    let ti = column(&opts.time_column)?;
    let vi = column(&opts.velocity_column)?;

    let (mut time, mut velocity, mut line_numbers) = (Vec::new(), Vec::new(), Vec::new());
    for (line, text) in lines {
        if time.len() >= MAX_SAMPLES {
            return Err(too_many_samples(path, line));
        }
        let fields = sep.split(text);
        if fields.len() != header.len() {
            return Err(DataError::ColumnCount {
                file: file(),
                line,
                found: fields.len(),
                expected: header.len(),
            });
        }
        let number = |idx: usize| -> Result<f64, DataError> {
            let name = header.get(idx).copied().unwrap_or_default();
            let raw = fields.get(idx).copied().unwrap_or_default();
            let value = raw.parse::<f64>().map_err(|_| DataError::BadNumber {
                file: file(),
                line,
                column: quoted(name),
                text: quoted(raw),
            })?;
            if value.is_finite() {
                Ok(value)
            } else {
                Err(DataError::NonFinite {
                    file: file(),
                    line,
                    column: quoted(name),
                    value,
                })
            }
        };
        time.push(number(ti)?);
        velocity.push(number(vi)? * opts.velocity_scale);
        line_numbers.push(line);
    }
    if time.is_empty() {
        return Err(DataError::Empty {
            file: file(),
            reason: format!("no data rows after the header on line {header_line}"),
        });
    }
    finish(path, time, velocity, &line_numbers, opts)
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
        assert_eq!(r.time, vec![0.0, 0.001, 0.002, 0.003, 0.004]);
        assert_eq!(r.velocity, vec![0.0, 0.5, 1.0, 1.5, 2.0]);
        assert_eq!(r.name, "r.csv");
    }

    #[test]
    fn reads_whitespace_columns_in_any_order_with_scale() {
        let text = "velocity   extra time\n 1.0 a 0.0\n2.0 b 0.1\n\t3.0 c 0.2\n";
        let opts = ReadOptions {
            velocity_scale: 1e-3,
            min_samples: 3,
            ..ReadOptions::default()
        };
        let r = read_delimited(Path::new("w.txt"), text, DataFormat::Whitespace, &opts).unwrap();
        assert_eq!(r.time, vec![0.0, 0.1, 0.2]);
        assert_eq!(r.velocity, vec![1e-3, 2e-3, 3e-3]);
    }

    #[test]
    fn semicolon_and_quoted_headers_with_custom_columns() {
        let text = "\"t [s]\";\"v [mm/s]\"\n0;1\n1;2\n2;3\n";
        let opts = ReadOptions {
            time_column: "t [s]".into(),
            velocity_column: "v [mm/s]".into(),
            min_samples: 3,
            ..ReadOptions::default()
        };
        let r = read_delimited(Path::new("s.csv"), text, DataFormat::Csv, &opts).unwrap();
        assert_eq!(r.velocity, vec![1.0, 2.0, 3.0]);
    }

    #[test]
    fn bad_number_names_the_line_and_column() {
        let text = "time,velocity\n0,1\n0.001,abc\n0.002,3\n";
        assert_eq!(
            read(text).unwrap_err().to_string(),
            "r.csv: line 3: column `velocity`: `abc` is not a number"
        );
    }

    #[test]
    fn wrong_field_count_names_the_line() {
        let text = "time,velocity\n0,1\n0.001,2,7\n";
        assert_eq!(
            read(text).unwrap_err().to_string(),
            "r.csv: line 3: 3 fields, but the header has 2"
        );
    }

    #[test]
    fn nan_and_infinity_are_rejected() {
        let e = read("time,velocity\n0,1\n0.001,NaN\n0.002,1\n").unwrap_err();
        assert!(matches!(e, DataError::NonFinite { line: 3, .. }), "{e}");
        let e = read("time,velocity\n0,1\ninf,1\n").unwrap_err();
        assert!(matches!(e, DataError::NonFinite { line: 3, .. }), "{e}");
    }

    #[test]
    fn time_must_increase() {
        let e = read("time,velocity\n0,1\n0.001,1\n0.001,1\n0.003,1\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "r.csv: line 4: time 0.001 s does not increase (previous 0.001 s)"
        );
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
    fn too_few_samples() {
        let e = read("time,velocity\n0,1\n0.001,1\n").unwrap_err();
        assert_eq!(e.to_string(), "r.csv: 2 samples, at least 3 needed");
    }

    #[test]
    fn missing_column_suggests_the_nearest() {
        let e = read("time,velocty\n0,1\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "r.csv: line 1: no column `velocity` (did you mean `velocty`?); the header has: time, velocty"
        );
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
}
