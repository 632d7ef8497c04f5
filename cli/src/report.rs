//! Output files: atomic writes into the output directory, terminal tables, CSV columns.
//!
//! Every file is written to a temporary name in its final directory and renamed into place,
//! so a reader never sees a half-written `report.json`, and an error leaves no partial file.
//! Commands write `report.json` last: its presence means the run completed.

use crate::error::CliError;
pub use frictionid_engine::report::fmt_num;
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

static COUNTER: AtomicUsize = AtomicUsize::new(0);

/// Writes `bytes` to `path` atomically: a temporary file in the same directory, flushed to
/// disk, then renamed over `path`. On error the temporary file is removed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    let fail = |e: std::io::Error| CliError::Write {
        path: path.to_path_buf(),
        reason: e.to_string(),
    };
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or_else(|| Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    let tmp = dir.join(format!(
        ".{name}.tmp-{}-{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(fail(e));
    }
    Ok(())
}

/// The output directory of a run.
#[derive(Debug, Clone)]
pub struct OutputDir {
    dir: PathBuf,
}

impl OutputDir {
    /// Creates the directory (and its parents) if needed.
    pub fn create(dir: &Path) -> Result<Self, CliError> {
        std::fs::create_dir_all(dir).map_err(|e| CliError::Write {
            path: dir.to_path_buf(),
            reason: e.to_string(),
        })?;
        Ok(Self {
            dir: dir.to_path_buf(),
        })
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The path of output file `name`.
    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// Writes `text` to `name` atomically; returns its path.
    pub fn write_text(&self, name: &str, text: &str) -> Result<PathBuf, CliError> {
        let p = self.path(name);
        write_atomic(&p, text.as_bytes())?;
        Ok(p)
    }

    /// Writes `value` as pretty JSON (with a final newline) to `name` atomically.
    pub fn write_json<T: Serialize>(&self, name: &str, value: &T) -> Result<PathBuf, CliError> {
        let mut text = serde_json::to_string_pretty(value).map_err(|e| CliError::Write {
            path: self.path(name),
            reason: e.to_string(),
        })?;
        text.push('\n');
        self.write_text(name, &text)
    }
}

/// A plain-text table with aligned columns, for the terminal.
pub fn text_table(headers: &[&str], rows: &[Vec<String>]) -> String {
    let n = headers.len();
    let mut width: Vec<usize> = headers.iter().map(|h| h.chars().count()).collect();
    for r in rows {
        for (w, c) in width.iter_mut().zip(r) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |cells: Vec<&str>| -> String {
        let mut s = String::new();
        for (i, c) in cells.iter().enumerate().take(n) {
            let w = width.get(i).copied().unwrap_or(0);
            s.push_str(c);
            if i + 1 < n {
                s.push_str(&" ".repeat(w.saturating_sub(c.chars().count()) + 2));
            }
        }
        s.trim_end().to_string() + "\n"
    };
    let mut out = line(headers.to_vec());
    out.push_str(&line(
        width
            .iter()
            .map(|&w| "-".repeat(w))
            .collect::<Vec<_>>()
            .iter()
            .map(String::as_str)
            .collect(),
    ));
    for r in rows {
        out.push_str(&line(r.iter().map(String::as_str).collect()));
    }
    out
}

/// CSV text of named columns of equal length (shorter columns leave empty cells), numbers in
/// shortest round-trip form.
pub fn csv_columns(columns: &[(&str, &[f64])]) -> String {
    let n = columns.iter().map(|(_, c)| c.len()).max().unwrap_or(0);
    let mut out = columns
        .iter()
        .map(|(h, _)| h.to_string())
        .collect::<Vec<_>>()
        .join(",");
    out.push('\n');
    for i in 0..n {
        let row: Vec<String> = columns
            .iter()
            .map(|(_, c)| c.get(i).map(|v| format!("{v}")).unwrap_or_default())
            .collect();
        out.push_str(&row.join(","));
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_replaces_and_leaves_no_temporary() {
        let dir =
            std::env::temp_dir().join(format!("frictionid-report-test-{}", std::process::id()));
        let out = OutputDir::create(&dir).unwrap();
        out.write_text("a.txt", "first").unwrap();
        out.write_json("a.txt", &serde_json::json!({"x": 1}))
            .unwrap();
        assert_eq!(
            std::fs::read_to_string(out.path("a.txt")).unwrap(),
            "{\n  \"x\": 1\n}\n"
        );
        let names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, vec!["a.txt".to_string()]);
        // A write into a missing directory fails and creates nothing.
        let e = write_atomic(&dir.join("missing/b.txt"), b"x").unwrap_err();
        assert!(e.to_string().contains("cannot write"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn tables_align() {
        let rows = vec![vec!["mu".to_string(), "0.2".to_string()]];
        assert_eq!(
            text_table(&["name", "value"], &rows),
            "name  value\n----  -----\nmu    0.2\n"
        );
    }

    #[test]
    fn csv_has_header_and_round_trip_numbers() {
        let t = [0.0, 0.001];
        let v = [0.1, -1e-7];
        assert_eq!(
            csv_columns(&[("time", &t), ("velocity", &v)]),
            "time,velocity\n0,0.1\n0.001,-0.0000001\n"
        );
    }
}
