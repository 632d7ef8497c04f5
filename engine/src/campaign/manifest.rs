//! The manifest of a campaign: a CSV file with one row per record.
//!
//! A `file` column names each row's data file; a column named like a `[[records]]` key
//! (`x0`, `normal_force`, `release`, `weight`, `velocity_scale`, `force_column`, ...) sets that
//! key for its row, typed as the key is (an empty cell leaves it to `[record_defaults]`);
//! every other column is a condition. Blank lines and lines starting with `#` are skipped;
//! cells may be quoted (`"a, b"`, `""` for a quote).

use super::CampaignError;
use crate::data::RecordSource;
use serde_json::{Map, Value};
use std::io::Read;
use std::path::Path;

/// Largest manifest read \[bytes\] (64 MiB).
pub(crate) const MAX_MANIFEST_BYTES: u64 = 64 * 1024 * 1024;

/// The column that names each row's data file.
pub(crate) const FILE_COLUMN: &str = "file";

/// A read and typed manifest.
#[derive(Debug, Clone, PartialEq)]
pub struct Manifest {
    /// The file as written in `[campaign] manifest` (the name in messages).
    pub file: String,
    /// The header's column names, in file order.
    pub columns: Vec<String>,
    /// Whether each column is a `[[records]]` key (else a condition).
    pub record_key: Vec<bool>,
    /// The rows, in file order.
    pub rows: Vec<ManifestRow>,
}

/// One row: its cells and the record entry they set.
#[derive(Debug, Clone, PartialEq)]
pub struct ManifestRow {
    /// The row's line in the file (1-based).
    pub line: usize,
    /// The cells, one per column (trimmed).
    pub cells: Vec<String>,
    /// The `[[records]]` keys the row sets (not yet merged with `[record_defaults]`).
    pub source: RecordSource,
}

/// The names of every `[[records]]` key, from the entry's own declaration.
pub(crate) fn record_key_names() -> Vec<String> {
    match serde_json::to_value(RecordSource::default()) {
        Ok(Value::Object(map)) => map.keys().cloned().collect(),
        _ => vec![FILE_COLUMN.to_string()],
    }
}

impl Manifest {
    /// Reads the manifest `file` (as written; relative to `base_dir` unless absolute).
    pub fn load(file: &str, base_dir: &Path) -> Result<Self, CampaignError> {
        let path = base_dir.join(file);
        let read_error = |reason: String| CampaignError::Read {
            file: file.to_string(),
            reason,
        };
        let mut bytes = Vec::new();
        std::fs::File::open(&path)
            .and_then(|f| f.take(MAX_MANIFEST_BYTES + 1).read_to_end(&mut bytes))
            .map_err(|e| read_error(e.to_string()))?;
        if bytes.len() as u64 > MAX_MANIFEST_BYTES {
            return Err(read_error(format!(
                "over {} MiB; is it the right file?",
                MAX_MANIFEST_BYTES >> 20
            )));
        }
        let text = String::from_utf8(bytes).map_err(|_| read_error("not UTF-8 text".into()))?;
        Self::parse(file, &text)
    }

    /// Parses manifest `text` read from `file` (the name in messages).
    pub fn parse(file: &str, text: &str) -> Result<Self, CampaignError> {
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
        let Some((header_line, header)) = lines.next() else {
            return Err(CampaignError::Empty {
                file: file.into(),
                what: "no header line",
            });
        };
        let columns = header_columns(file, header_line, header)?;
        let keys = record_key_names();
        let record_key: Vec<bool> = columns.iter().map(|c| keys.contains(c)).collect();
        let mut manifest = Self {
            file: file.into(),
            columns,
            record_key,
            rows: Vec::new(),
        };
        for (line, text) in lines {
            let row = manifest.parse_row(line, text)?;
            manifest.rows.push(row);
        }
        if manifest.rows.is_empty() {
            return Err(CampaignError::Empty {
                file: file.into(),
                what: "no rows",
            });
        }
        Ok(manifest)
    }

    /// The index of column `name`.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }

    /// One row: its cells, and the record keys they set.
    fn parse_row(&self, line: usize, text: &str) -> Result<ManifestRow, CampaignError> {
        let cells = split_cells(text);
        if cells.len() != self.columns.len() {
            return Err(CampaignError::RowLength {
                file: self.file.clone(),
                line,
                found: cells.len(),
                expected: self.columns.len(),
            });
        }
        let mut source = RecordSource::default();
        for (column, cell) in self.columns.iter().zip(&cells) {
            let is_key = self.column(column).is_some_and(|i| self.record_key[i]);
            if !is_key || cell.is_empty() {
                continue;
            }
            let one = typed_key(column, cell).map_err(|reason| CampaignError::Cell {
                file: self.file.clone(),
                line,
                column: column.clone(),
                reason,
            })?;
            source = one.with_defaults(&source);
        }
        if source.file.is_none() {
            return Err(CampaignError::Cell {
                file: self.file.clone(),
                line,
                column: FILE_COLUMN.into(),
                reason: "empty (the record's data file)".into(),
            });
        }
        Ok(ManifestRow {
            line,
            cells,
            source,
        })
    }
}

/// The header's column names: unique, with a `file` column.
fn header_columns(file: &str, line: usize, header: &str) -> Result<Vec<String>, CampaignError> {
    let columns = split_cells(header);
    let error = |reason: String| CampaignError::Header {
        file: file.into(),
        line,
        reason,
    };
    for (i, c) in columns.iter().enumerate() {
        if c.is_empty() {
            return Err(error(format!("column {} has no name", i + 1)));
        }
        if columns[..i].contains(c) {
            return Err(error(format!("column `{c}` appears twice")));
        }
    }
    if !columns.iter().any(|c| c == FILE_COLUMN) {
        return Err(error(format!(
            "no `{FILE_COLUMN}` column (each row's data file); columns: {}",
            columns.join(", ")
        )));
    }
    Ok(columns)
}

/// The entry that sets `key` to `cell`: a number where the cell reads as one and the key
/// takes one, else the text; the key's own type decides, and its complaint is the error.
fn typed_key(key: &str, cell: &str) -> Result<RecordSource, String> {
    let entry = |value: Value| {
        let mut map = Map::new();
        map.insert(key.to_string(), value);
        serde_json::from_value::<RecordSource>(Value::Object(map))
    };
    let as_text = entry(Value::String(cell.to_string()));
    match serde_json::from_str::<Value>(cell) {
        Ok(number @ Value::Number(_)) => entry(number).or(as_text),
        _ => as_text,
    }
    .map_err(|e| format!("cannot use `{cell}` ({e})"))
}

/// The cells of one CSV line, trimmed; a quoted cell keeps its commas, `""` is a quote.
pub(crate) fn split_cells(line: &str) -> Vec<String> {
    let mut cells = Vec::new();
    let mut cell = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cell.push('"');
                chars.next();
            }
            ('"', true) => quoted = false,
            ('"', false) if cell.trim().is_empty() => {
                cell.clear();
                quoted = true;
            }
            (',', false) => cells.push(std::mem::take(&mut cell).trim().to_string()),
            _ => cell.push(c),
        }
    }
    cells.push(cell.trim().to_string());
    cells
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::Release;

    #[test]
    fn record_keys_are_typed_and_other_columns_are_conditions() {
        let m = Manifest::parse(
            "runs.csv",
            "# a sweep\nfile, x0, normal_force, release, force_column, lubricant\n\
             a.csv, 0.01, 5, auto, \"F, N\", oil\n\nb.csv,0.02,,0.5,F,\"dry\"\n",
        )
        .unwrap();
        assert_eq!(m.record_key, [true, true, true, true, true, false]);
        let a = &m.rows[0];
        assert_eq!(a.line, 3);
        assert_eq!(a.source.file.as_deref(), Some("a.csv"));
        assert_eq!(
            (a.source.x0, a.source.normal_force),
            (Some(0.01), Some(5.0))
        );
        assert_eq!(a.source.release, Some(Release::Auto));
        assert_eq!(a.source.force_column.as_deref(), Some("F, N"));
        let b = &m.rows[1];
        assert_eq!((b.line, b.source.normal_force), (5, None));
        assert_eq!(b.source.release, Some(Release::At(0.5)));
        assert_eq!(b.cells[5], "dry");
    }

    #[test]
    fn errors_name_the_line_and_column() {
        for (text, says) in [
            (
                "file,x0\na.csv,abc\n",
                "runs.csv:2: column `x0`: cannot use `abc`",
            ),
            (
                "file,min_samples\na.csv,1.5\n",
                "runs.csv:2: column `min_samples`: cannot use `1.5`",
            ),
            ("x0\n0.1\n", "runs.csv:1: no `file` column"),
            ("file,x0,x0\n", "runs.csv:1: column `x0` appears twice"),
            (
                "file,x0\na.csv\n",
                "runs.csv:2: 1 cells, the header has 2 columns",
            ),
            ("file,x0\n,0.1\n", "runs.csv:2: column `file`: empty"),
            ("file,x0\n", "runs.csv: the manifest has no rows"),
            ("", "runs.csv: the manifest has no header line"),
        ] {
            let e = Manifest::parse("runs.csv", text).unwrap_err().to_string();
            assert!(e.starts_with(says), "{e}");
            assert!(!e.contains('\n'), "{e}");
        }
    }

    #[test]
    fn every_record_key_is_known() {
        let keys = record_key_names();
        for key in [
            "file",
            "x0",
            "weight",
            "normal_force",
            "velocity_scale",
            "force_column",
        ] {
            assert!(keys.iter().any(|k| k == key), "{key}");
        }
    }
}
