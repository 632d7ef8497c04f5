//! From manifest rows to groups: rows with equal `group_by` values are fitted jointly, each
//! group as one configuration listing its records.

use super::cell::{condition_value, CellValue};
use super::manifest::{Manifest, FILE_COLUMN};
use super::{CampaignError, CampaignSpec};
use crate::data::{RecordSource, RecordUse};
use crate::record::Record;
use frictionid_models::suggest::did_you_mean;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The `[[records]]` keys that state a run's physical condition: carried into the results
/// as conditions (when constant within a group) besides setting the record's key.
pub(crate) const CONDITION_KEYS: [&str; 3] = ["x0", "v0", "normal_force"];

/// One group: everything a worker needs to fit it, as plain data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GroupTask {
    /// The group's id: its number and a name made of its `group_by` values (or its file).
    pub id: String,
    /// The group's conditions in manifest column order (`None`: empty, or not the same in
    /// every row of the group).
    pub conditions: Vec<(String, Option<CellValue>)>,
    /// Its records' entries, `[record_defaults]` merged, in manifest order.
    pub sources: Vec<RecordSource>,
    /// The manifest lines of its rows.
    pub lines: Vec<usize>,
    /// The directory relative files are taken from (the configuration's).
    pub base_dir: PathBuf,
}

impl GroupTask {
    /// The data file of a single-record group.
    pub fn single_file(&self) -> Option<&str> {
        match self.sources.as_slice() {
            [one] => one.file.as_deref(),
            _ => None,
        }
    }

    /// The task with each named channel that all of `records` carry added as a condition
    /// `<name>_mean`, the channel's mean over the group's samples (a run's temperature or
    /// load), so that a campaign trends the fitted parameters against what was measured. A
    /// condition of that name from the manifest keeps its own value.
    pub fn with_channel_means(&self, records: &[Record]) -> Self {
        let mut task = self.clone();
        for name in shared_channel_names(records) {
            let key = format!("{name}_mean");
            if task.conditions.iter().any(|(n, _)| *n == key) {
                continue;
            }
            let mean = channel_mean(records, &name).map(CellValue::Number);
            task.conditions.push((key, mean));
        }
        task
    }

    /// The value of condition `name`, when the group has one.
    pub fn condition(&self, name: &str) -> Option<&CellValue> {
        condition_value(&self.conditions, name)
    }
}

/// The named channels every one of `records` carries, in the first record's order.
fn shared_channel_names(records: &[Record]) -> Vec<String> {
    let Some(first) = records.first() else {
        return Vec::new();
    };
    first
        .named_channels()
        .into_iter()
        .filter(|name| records.iter().all(|r| r.named_channel(name).is_some()))
        .map(str::to_string)
        .collect()
}

/// The mean of the finite samples of channel `name` over all of `records`.
fn channel_mean(records: &[Record], name: &str) -> Option<f64> {
    let (sum, count) = records
        .iter()
        .filter_map(|r| r.named_channel(name))
        .flatten()
        .filter(|x| x.is_finite())
        .fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    (count > 0).then(|| sum / count as f64)
}

/// The condition columns of `manifest`: every column that is not a `[[records]]` key, and
/// the keys of [`CONDITION_KEYS`], in manifest order.
pub(crate) fn condition_columns(manifest: &Manifest) -> Vec<usize> {
    (0..manifest.columns.len())
        .filter(|&i| {
            !manifest.record_key[i] || CONDITION_KEYS.contains(&manifest.columns[i].as_str())
        })
        .collect()
}

/// The groups of a campaign, in the order of their first rows. Every row's entry is checked
/// for how the fits `used` its record (with `defaults` merged, files against `base_dir`: a
/// replayed record needs no `x0`) and no group may hold more than `max_records` records.
pub fn plan_groups(
    manifest: &Manifest,
    spec: &CampaignSpec,
    defaults: &RecordSource,
    used: RecordUse,
    base_dir: &Path,
    max_records: usize,
) -> Result<Vec<GroupTask>, CampaignError> {
    let keys = group_key_columns(manifest, &spec.group_by)?;
    let mut members: Vec<(Vec<&str>, Vec<usize>)> = Vec::new();
    for (r, row) in manifest.rows.iter().enumerate() {
        let key: Vec<&str> = match &keys {
            Some(cols) => cols.iter().map(|&c| row.cells[c].as_str()).collect(),
            None => vec![],
        };
        match members
            .iter_mut()
            .find(|(k, _)| keys.is_some() && *k == key)
        {
            Some((_, rows)) => rows.push(r),
            None => members.push((key, vec![r])),
        }
    }
    let width = members.len().to_string().len().max(3);
    members
        .iter()
        .enumerate()
        .map(|(n, (key, rows))| {
            let id = group_id(n + 1, width, key, manifest, rows);
            let entries = GroupEntries {
                rows,
                defaults,
                used,
                base_dir,
            };
            group_task(manifest, id, entries, max_records)
        })
        .collect()
}

/// The indices of the `group_by` columns (`None`: each row alone).
fn group_key_columns(
    manifest: &Manifest,
    group_by: &[String],
) -> Result<Option<Vec<usize>>, CampaignError> {
    if group_by.is_empty() {
        return Ok(None);
    }
    group_by
        .iter()
        .map(|name| {
            manifest
                .column(name)
                .ok_or_else(|| CampaignError::UnknownGroupColumn {
                    file: manifest.file.clone(),
                    column: name.clone(),
                    hint: did_you_mean(name, manifest.columns.iter().map(String::as_str)),
                    columns: manifest.columns.join(", "),
                })
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}

/// `007-10_oil`: the group's number, then its key values (or its single file's stem), in
/// characters safe in a directory name.
fn group_id(n: usize, width: usize, key: &[&str], manifest: &Manifest, rows: &[usize]) -> String {
    let name = if key.is_empty() {
        let file = manifest
            .column(FILE_COLUMN)
            .and_then(|c| rows.first().map(|&r| manifest.rows[r].cells[c].as_str()))
            .unwrap_or_default();
        Path::new(file)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    } else {
        key.join("_")
    };
    let safe: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .take(48)
        .collect();
    format!("{n:0width$}-{safe}")
}

/// The manifest rows of one group and how their entries are completed and checked.
struct GroupEntries<'a> {
    rows: &'a [usize],
    defaults: &'a RecordSource,
    used: RecordUse,
    base_dir: &'a Path,
}

/// The task of one group: its checked entries and its conditions.
fn group_task(
    manifest: &Manifest,
    id: String,
    entries: GroupEntries<'_>,
    max_records: usize,
) -> Result<GroupTask, CampaignError> {
    let GroupEntries {
        rows,
        defaults,
        used,
        base_dir,
    } = entries;
    if rows.len() > max_records {
        return Err(CampaignError::TooManyRecords {
            file: manifest.file.clone(),
            group: id,
            found: rows.len(),
            max: max_records,
        });
    }
    let mut sources = Vec::with_capacity(rows.len());
    for &r in rows {
        let row = &manifest.rows[r];
        let source = row.source.with_defaults(defaults);
        source
            .resolve_for(row.line, base_dir, used)
            .map_err(|source| CampaignError::Record {
                file: manifest.file.clone(),
                line: row.line,
                source,
            })?;
        sources.push(source);
    }
    let numeric = numeric_columns(manifest);
    let conditions = condition_columns(manifest)
        .into_iter()
        .map(|c| {
            let first = &manifest.rows[rows[0]].cells[c];
            let same = rows.iter().all(|&r| &manifest.rows[r].cells[c] == first);
            let value = (same && !first.is_empty()).then(|| CellValue::parse(first, numeric[c]));
            (manifest.columns[c].clone(), value)
        })
        .collect();
    Ok(GroupTask {
        id,
        conditions,
        sources,
        lines: rows.iter().map(|&r| manifest.rows[r].line).collect(),
        base_dir: base_dir.to_path_buf(),
    })
}

/// Whether each column is numeric: every non-empty cell reads as a finite number.
pub(crate) fn numeric_columns(manifest: &Manifest) -> Vec<bool> {
    (0..manifest.columns.len())
        .map(|c| {
            manifest
                .rows
                .iter()
                .map(|r| r.cells[c].as_str())
                .filter(|cell| !cell.is_empty())
                .all(|cell| cell.parse::<f64>().is_ok_and(f64::is_finite))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const RUNS: &str = "file,normal_force,lubricant,x0,repeat\n\
                        a.csv,5,oil,0.01,1\nb.csv,5,oil,0.02,2\nc.csv,10,oil,0.01,1\nd.csv,10,dry,0.01,1\n";

    fn plan(group_by: &[&str]) -> Result<Vec<GroupTask>, CampaignError> {
        let m = Manifest::parse("runs.csv", RUNS).unwrap();
        let spec = CampaignSpec {
            manifest: "runs.csv".into(),
            group_by: group_by.iter().map(|s| s.to_string()).collect(),
            models: None,
        };
        let defaults = RecordSource::default();
        plan_groups(
            &m,
            &spec,
            &defaults,
            RecordUse::Simulated,
            Path::new("d"),
            1000,
        )
    }

    #[test]
    fn rows_with_equal_keys_form_one_group_in_first_row_order() {
        let g = plan(&["normal_force", "lubricant"]).unwrap();
        let ids: Vec<&str> = g.iter().map(|t| t.id.as_str()).collect();
        assert_eq!(ids, ["001-5_oil", "002-10_oil", "003-10_dry"]);
        assert_eq!(g[0].lines, [2, 3]);
        assert_eq!(g[0].single_file(), None);
        assert_eq!(g[1].single_file(), Some("c.csv"));
        let c = &g[0].conditions;
        let names: Vec<&str> = c.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["normal_force", "lubricant", "x0", "repeat"]);
        assert_eq!(c[0].1, Some(CellValue::Number(5.0)));
        assert_eq!(c[1].1, Some(CellValue::Text("oil".into())));
        assert_eq!(c[2].1, None, "x0 differs within the group");
    }

    #[test]
    fn each_row_alone_by_default_and_unknown_columns_are_named() {
        let g = plan(&[]).unwrap();
        assert_eq!(g.len(), 4);
        assert_eq!(g[3].id, "004-d");
        let e = plan(&["lubricnt"]).unwrap_err().to_string();
        assert!(
            e.contains("no column `lubricnt` in runs.csv (did you mean `lubricant`?)"),
            "{e}"
        );
        let m = Manifest::parse("runs.csv", "file,weight\na.csv,0\n").unwrap();
        let spec = CampaignSpec::default();
        let defaults = RecordSource::default();
        let e = plan_groups(
            &m,
            &spec,
            &defaults,
            RecordUse::Simulated,
            Path::new("."),
            10,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("runs.csv:2: [[records]] entry 2 (`a.csv`): `weight` must be > 0"),
            "{e}"
        );
        // Replayed along its measured motion (a force-domain fit), a record needs no x0.
        let bare = Manifest::parse("runs.csv", "file\na.csv\n").unwrap();
        let replayed = plan_groups(
            &bare,
            &spec,
            &defaults,
            RecordUse::Replayed,
            Path::new("."),
            10,
        );
        assert_eq!(replayed.unwrap()[0].single_file(), Some("a.csv"));
    }
}
