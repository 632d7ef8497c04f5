//! Campaigns: many records across conditions, fitted group by group, with the fitted
//! parameters tabulated against the conditions and their trends.
//!
//! ```toml
//! [campaign]
//! manifest = "runs.csv"            # relative to the configuration file
//! group_by = ["normal_force"]      # rows with equal values are fitted jointly (default: each row alone)
//! models = ["coulomb", "dahl"]     # compared in every group (default: the [model])
//! ```
//!
//! The manifest ([`manifest`]) holds one row per record: a `file` column, columns named like a
//! `[[records]]` key that set that key for their row, and conditions (every other column).
//! [`groups`] turns its rows into one [`GroupTask`] per group: plain data, the records of one
//! configuration, fitted by [`crate::jobs::campaign_group_job`] exactly as `fit` or `compare`
//! fits a configuration listing them. [`table`] turns each group's fits into rows of the
//! results table, [`trends`] fits each parameter against each numeric condition.

pub(crate) mod cell;
pub(crate) mod groups;
pub(crate) mod manifest;
pub(crate) mod table;
pub(crate) mod trends;

pub use cell::CellValue;
pub use groups::{plan_groups, GroupTask};
pub use manifest::{Manifest, ManifestRow};
pub use table::{CampaignRow, GroupResult, ParamCell, RowVerdict};
pub use trends::{campaign_trends, LineFit, Trend, TrendForm};

use crate::data::source::RecordSourceError;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// The `[campaign]` table.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignSpec {
    /// The manifest CSV file, relative to the configuration file (or absolute).
    pub manifest: String,
    /// Manifest columns whose equal values make one group (empty: each row alone).
    #[serde(default)]
    pub group_by: Vec<String>,
    /// Models compared in every group (`None`: the `[model]` alone, fitted as by `fit`).
    pub models: Option<Vec<String>>,
}

/// Why a campaign cannot start. Each message is one line naming the manifest and, where it
/// applies, its line and column.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CampaignError {
    /// The manifest cannot be read.
    #[error("{file}: cannot read the manifest: {reason}")]
    Read {
        /// The manifest as written.
        file: String,
        /// Why.
        reason: String,
    },
    /// The manifest has no header or no row.
    #[error("{file}: the manifest has {what}")]
    Empty {
        /// The manifest.
        file: String,
        /// `no header line` or `no rows`.
        what: &'static str,
    },
    /// A header without a `file` column, or with a column twice.
    #[error("{file}:{line}: {reason}")]
    Header {
        /// The manifest.
        file: String,
        /// The header's line.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// A row whose cells cannot be used.
    #[error("{file}:{line}: column `{column}`: {reason}")]
    Cell {
        /// The manifest.
        file: String,
        /// The row's line.
        line: usize,
        /// The column.
        column: String,
        /// What is wrong.
        reason: String,
    },
    /// A row with more or fewer cells than the header has columns.
    #[error("{file}:{line}: {found} cells, the header has {expected} columns")]
    RowLength {
        /// The manifest.
        file: String,
        /// The row's line.
        line: usize,
        /// Cells in the row.
        found: usize,
        /// Columns in the header.
        expected: usize,
    },
    /// A row's record entry is incomplete or invalid.
    #[error("{file}:{line}: {source}")]
    Record {
        /// The manifest.
        file: String,
        /// The row's line.
        line: usize,
        /// Why.
        source: RecordSourceError,
    },
    /// A `group_by` name that is not a manifest column.
    #[error("[campaign] group_by: no column `{column}` in {file}{hint}; columns: {columns}")]
    UnknownGroupColumn {
        /// The manifest.
        file: String,
        /// The name given.
        column: String,
        /// A "did you mean" suggestion, or empty.
        hint: String,
        /// The manifest's columns.
        columns: String,
    },
    /// A group with more records than one configuration may list.
    #[error("{file}: group `{group}` has {found} records; at most {max} are accepted per group")]
    TooManyRecords {
        /// The manifest.
        file: String,
        /// The group's id.
        group: String,
        /// Its records.
        found: usize,
        /// The limit.
        max: usize,
    },
}
