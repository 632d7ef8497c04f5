//! The layout of a delimited text file: which line is the header row, how fields are
//! separated and which decimal mark the numbers use, sniffed from the file's first lines
//! where the `delimiter` and `decimal` keys do not say.
//!
//! Instrument exports open with a preamble (comment lines, or plain lines of text that may
//! hold commas), then a header row, then the data. The data block is what is looked for: for
//! each delimiter and decimal mark, the first line whose fields are mostly numbers, preceded
//! by a line with as many fields and no number among them (the header). Of the layouts that
//! find one, the one under which most of the following lines read as rows of that width
//! wins (ties: semicolon, comma, tab, whitespace; point before comma).

use super::DataFormat;
use serde::{Deserialize, Serialize};

/// The `delimiter` key: how the fields of a line are separated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Delimiter {
    /// Sniffed from the file (the default).
    #[default]
    Auto,
    /// `,`
    #[serde(alias = ",")]
    Comma,
    /// `;`
    #[serde(alias = ";")]
    Semicolon,
    /// A tab character.
    #[serde(alias = "\t")]
    Tab,
    /// Runs of spaces or tabs.
    #[serde(alias = " ")]
    Whitespace,
}

/// The `decimal` key: the decimal mark of the numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DecimalMark {
    /// Sniffed from the file (the default).
    #[default]
    Auto,
    /// `1.5`
    #[serde(alias = ".")]
    Point,
    /// `1,5` (a comma cannot then also separate the fields).
    #[serde(alias = ",")]
    Comma,
}

impl DecimalMark {
    /// The mark's name in messages and configs.
    pub fn name(self) -> &'static str {
        match self {
            DecimalMark::Auto => "auto",
            DecimalMark::Point => "point",
            DecimalMark::Comma => "comma",
        }
    }
}

/// How the fields of a line are separated, once decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Separator {
    /// One character.
    Char(char),
    /// Runs of whitespace.
    Whitespace,
}

impl Separator {
    /// The fields of `line`, trimmed and unquoted.
    pub fn split<'a>(&self, line: &'a str) -> Vec<&'a str> {
        match self {
            Separator::Char(c) => line.split(*c).map(clean_field).collect(),
            Separator::Whitespace => line.split_whitespace().map(clean_field).collect(),
        }
    }

    /// The `delimiter` key that names it.
    pub fn delimiter(self) -> Delimiter {
        match self {
            Separator::Char(',') => Delimiter::Comma,
            Separator::Char(';') => Delimiter::Semicolon,
            Separator::Char('\t') => Delimiter::Tab,
            _ => Delimiter::Whitespace,
        }
    }

    /// Chooses the separator from the header row alone (the layout of a file whose data
    /// block is not found, so that its errors name the first line).
    fn from_header(header: &str, format: DataFormat) -> Self {
        let by_char = [',', ';', '\t']
            .into_iter()
            .find(|c| header.contains(*c))
            .map(Separator::Char);
        match format {
            DataFormat::Whitespace => Separator::Whitespace,
            DataFormat::Csv => by_char.unwrap_or(Separator::Char(',')),
            _ => match by_char {
                // Tabs separate names that hold spaces (`Time [s]`); otherwise any whitespace.
                Some(Separator::Char('\t')) if tab_fields_hold_spaces(header) => {
                    Separator::Char('\t')
                }
                Some(Separator::Char('\t')) | None => Separator::Whitespace,
                Some(sep) => sep,
            },
        }
    }
}

/// Whether a tab-separated header has a column name with a space inside.
fn tab_fields_hold_spaces(header: &str) -> bool {
    header
        .split('\t')
        .any(|f| f.trim().contains(char::is_whitespace))
}

fn clean_field(field: &str) -> &str {
    let f = field.trim();
    f.strip_prefix('"')
        .and_then(|g| g.strip_suffix('"'))
        .unwrap_or(f)
        .trim()
}

/// `text` as a number written with `decimal` (point or comma), or `None`.
pub fn parse_number(text: &str, decimal: DecimalMark) -> Option<f64> {
    match decimal {
        DecimalMark::Comma if text.contains(',') => {
            if text.contains('.') {
                return None;
            }
            text.replace(',', ".").parse().ok()
        }
        _ => text.parse().ok(),
    }
}

/// A file's layout: the header row's position among the lines sniffed, the separator and
/// the decimal mark (point or comma).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    /// Index of the header row in the lines handed to [`sniff_layout`].
    pub header: usize,
    /// The separator.
    pub separator: Separator,
    /// The decimal mark (never `Auto`).
    pub decimal: DecimalMark,
    /// Whether the data block was found (else the header is the first line, a fallback
    /// whose errors name it).
    pub found: bool,
}

/// Lines read for sniffing.
pub const SNIFF_LINES: usize = 400;

/// Data lines after the header scored per layout.
const SCORED_ROWS: usize = 50;

/// The layout of `lines` (the file's first non-blank, non-comment lines: line number and
/// text) under the format and the `delimiter` and `decimal` keys.
pub fn sniff_layout(
    lines: &[(usize, &str)],
    format: DataFormat,
    delimiter: Delimiter,
    decimal: DecimalMark,
) -> Layout {
    let mut best: Option<(usize, Layout)> = None;
    for separator in separators(format, delimiter) {
        for mark in marks(decimal) {
            if separator == Separator::Char(',') && mark == DecimalMark::Comma {
                continue;
            }
            if let Some((score, header)) = data_block(lines, separator, mark) {
                if best.is_none_or(|(s, _)| score > s) {
                    let layout = Layout {
                        header,
                        separator,
                        decimal: mark,
                        found: true,
                    };
                    best = Some((score, layout));
                }
            }
        }
    }
    if let Some((_, layout)) = best {
        return layout;
    }
    if (delimiter, decimal) != (Delimiter::Auto, DecimalMark::Auto) {
        // The keys given do not read the data: the header found without them, read with
        // them, so that the error names the first row they do not read.
        let free = sniff_layout(lines, format, Delimiter::Auto, DecimalMark::Auto);
        if free.found {
            return Layout {
                separator: match delimiter {
                    Delimiter::Auto => free.separator,
                    given => separators(format, given)[0],
                },
                decimal: match decimal {
                    DecimalMark::Auto => free.decimal,
                    given => given,
                },
                found: false,
                ..free
            };
        }
    }
    Layout {
        header: 0,
        separator: match delimiter {
            Delimiter::Auto => Separator::from_header(lines.first().map_or("", |l| l.1), format),
            given => separators(format, given)[0],
        },
        decimal: match decimal {
            DecimalMark::Auto => DecimalMark::Point,
            given => given,
        },
        found: false,
    }
}

/// The separators tried, in the order that breaks ties.
fn separators(format: DataFormat, delimiter: Delimiter) -> Vec<Separator> {
    match (delimiter, format) {
        (Delimiter::Comma, _) => vec![Separator::Char(',')],
        (Delimiter::Semicolon, _) => vec![Separator::Char(';')],
        (Delimiter::Tab, _) => vec![Separator::Char('\t')],
        (Delimiter::Whitespace, _) | (Delimiter::Auto, DataFormat::Whitespace) => {
            vec![Separator::Whitespace]
        }
        (Delimiter::Auto, DataFormat::Csv) => [';', ',', '\t'].map(Separator::Char).to_vec(),
        (Delimiter::Auto, _) => vec![
            Separator::Char(';'),
            Separator::Char(','),
            Separator::Char('\t'),
            Separator::Whitespace,
        ],
    }
}

/// The decimal marks tried.
fn marks(decimal: DecimalMark) -> Vec<DecimalMark> {
    match decimal {
        DecimalMark::Auto => vec![DecimalMark::Point, DecimalMark::Comma],
        given => vec![given],
    }
}

/// How many of the fields of `fields` are numbers.
fn numbers(fields: &[&str], decimal: DecimalMark) -> usize {
    fields
        .iter()
        .filter(|f| parse_number(f, decimal).is_some())
        .count()
}

/// Whether the fields look like a data row: two or more, mostly numbers.
fn is_row(fields: &[&str], decimal: DecimalMark) -> bool {
    let n = numbers(fields, decimal);
    n >= 2 && 2 * n > fields.len()
}

/// The header's index and the number of rows of its width among the next lines, under one
/// separator and decimal mark; `None` when no line of two or more names without a number
/// precedes a data row of as many fields.
fn data_block(
    lines: &[(usize, &str)],
    separator: Separator,
    decimal: DecimalMark,
) -> Option<(usize, usize)> {
    let header = (1..lines.len()).find_map(|j| {
        let row = separator.split(lines[j].1);
        let names = separator.split(lines[j - 1].1);
        (is_row(&row, decimal) && names.len() == row.len() && numbers(&names, decimal) == 0)
            .then_some(j - 1)
    })?;
    let width = separator.split(lines[header].1).len();
    let score = lines
        .iter()
        .skip(header + 1)
        .take(SCORED_ROWS)
        .filter(|(_, l)| {
            let fields = separator.split(l);
            fields.len() == width && is_row(&fields, decimal)
        })
        .count();
    Some((score, header))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sniff(text: &str) -> Layout {
        let lines: Vec<(usize, &str)> = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l))
            .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
            .collect();
        sniff_layout(&lines, DataFormat::Auto, Delimiter::Auto, DecimalMark::Auto)
    }

    #[test]
    fn a_vibrometer_export_after_a_preamble_of_text() {
        let text = "Polytec export, version 2, 5 kHz\nChannel 1, velocity\n\
                    Time [s];Velocity [mm/s]\n0,0000;0,000\n0,0002;1,250\n0,0004;2,5\n";
        let l = sniff(text);
        assert_eq!(
            (l.header, l.separator, l.decimal, l.found),
            (2, Separator::Char(';'), DecimalMark::Comma, true)
        );
    }

    #[test]
    fn plain_files_keep_their_layout() {
        let l = sniff("time,velocity\n0,1\n0.001,2\n");
        assert_eq!(
            (l.header, l.separator, l.decimal),
            (0, Separator::Char(','), DecimalMark::Point)
        );
        let l = sniff("time velocity\n0 1\n0.001 2\n");
        assert_eq!(
            (l.separator, l.decimal),
            (Separator::Whitespace, DecimalMark::Point)
        );
        let l = sniff("time\tv [m/s]\n0\t1,5\n0,001\t2\n");
        assert_eq!(
            (l.separator, l.decimal),
            (Separator::Char('\t'), DecimalMark::Comma)
        );
        let l = sniff("time;velocity\n0;1\n0,5;1,5\n1;2\n");
        assert_eq!(
            (l.separator, l.decimal),
            (Separator::Char(';'), DecimalMark::Comma)
        );
    }

    #[test]
    fn numbers_alone_have_no_header() {
        let l = sniff("0,1\n0.001,2\n");
        assert!(!l.found);
        assert_eq!(l.header, 0);
    }

    #[test]
    fn keys_read_names_and_characters() {
        for (text, d) in [
            ("\";\"", Delimiter::Semicolon),
            ("\"semicolon\"", Delimiter::Semicolon),
            ("\"\\t\"", Delimiter::Tab),
            ("\"whitespace\"", Delimiter::Whitespace),
        ] {
            assert_eq!(
                serde_json::from_str::<Delimiter>(text).unwrap(),
                d,
                "{text}"
            );
        }
        assert_eq!(
            serde_json::from_str::<DecimalMark>("\",\"").unwrap(),
            DecimalMark::Comma
        );
        let e = serde_json::from_str::<DecimalMark>("\"coma\"").unwrap_err();
        assert!(e.to_string().contains("unknown variant `coma`"), "{e}");
    }
}
