//! One report value per command, and the writers that turn it into files or text.
//!
//! A command's job ([`crate::jobs`]) returns a report value ([`SimulateReport`],
//! [`FitReport`], [`CompareReport`], [`EnergyReport`], [`ModelsReport`]). Each value is
//! serializable (its JSON form is report.json, see [`json::to_json`]) and implements
//! [`Render`]: it pushes its document, block by block, into a [`Sink`]. Every writer is a
//! sink (the idea of ripgrep's `Sink` and printers): [`markdown::MarkdownWriter`] here, a
//! terminal summary in the CLI, [`html::HtmlWriter`] (report.html). A new writer implements [`Sink`] and needs no
//! change to the reports.
//!
//! Inline code in text is written between backticks (`` `x14mm.csv` ``); writers render it
//! in their own syntax.

pub(crate) mod campaign;
pub(crate) mod compare;
pub(crate) mod energy;
pub mod fit;
pub(crate) mod format;
pub mod html;
pub mod json;
pub mod markdown;
pub(crate) mod models;
pub mod plan;
pub(crate) mod recommendation;
pub(crate) mod simulate;

pub use campaign::{CampaignReport, GroupReport};
pub use compare::CompareReport;
pub use energy::{EnergyRecord, EnergyReport};
pub use fit::FitReport;
pub use format::{fmt_num, serialized_name};
pub use models::ModelsReport;
pub use plan::PlanReport;
pub use simulate::{InputSeries, SimulateReport};

/// Where a block belongs: in the short summary a terminal shows, or only in the full report.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// Shown everywhere, including the terminal summary.
    Summary,
    /// Shown in full reports (files) only.
    Detail,
    /// Shown in the terminal summary only (a one-line result that the full report states at
    /// length elsewhere).
    Brief,
}

/// A table of formatted cells.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Table {
    /// Column headers.
    pub headers: Vec<String>,
    /// Rows of cells, as many as headers.
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// A table with `headers` and `rows`.
    pub fn new(headers: &[&str], rows: Vec<Vec<String>>) -> Self {
        Self {
            headers: headers.iter().map(|h| h.to_string()).collect(),
            rows,
        }
    }

    /// The table with one more column, `header`, holding `cells` (one per row; a missing
    /// cell is `-`).
    pub fn with_column(mut self, header: &str, cells: Vec<String>) -> Self {
        self.headers.push(header.to_string());
        let mut cells = cells.into_iter();
        for row in &mut self.rows {
            row.push(cells.next().unwrap_or_else(|| "-".into()));
        }
        self
    }
}

/// A writer: receives a report's document block by block.
pub trait Sink {
    /// The document's title (once, first).
    fn title(&mut self, text: &str);
    /// A section heading; `level` 2 is a section, 3 a subsection.
    fn heading(&mut self, level: usize, text: &str, role: Role);
    /// A paragraph of text.
    fn paragraph(&mut self, text: &str, role: Role);
    /// A result's verdict (`status` the worst of its checks), with what it rests on (shown near the top of a full report).
    /// Writers without their own way of showing it write a paragraph.
    fn verdict(&mut self, status: Status, text: &str) {
        let _ = status;
        self.paragraph(&format!("Verdict: {text}"), Role::Detail);
    }
    /// A recommendation (compare's verdict), shown first everywhere: `text` names what to use
    /// (written after "Recommended:"), `status` is its own result's, and `reasons` are the
    /// grounds it rests on, one per item. Writers without their own way of showing it write
    /// a paragraph, then the reasons as a list.
    fn recommendation(&mut self, status: Status, text: &str, reasons: &[String]) {
        let _ = status;
        self.paragraph(&format!("Recommended: {text}"), Role::Summary);
        self.list(reasons, Role::Summary);
    }
    /// A table.
    fn table(&mut self, table: &Table, role: Role);
    /// A bulleted list.
    fn list(&mut self, items: &[String], role: Role);
    /// The files written with the report (plots, data), by name in the output directory.
    fn files(&mut self, files: &[String]);
    /// Plots to show here, ahead of the files (a writer that shows plots shows these here
    /// and the rest with the files; others list them with the files only).
    fn figures(&mut self, plots: &[String]) {
        let _ = plots;
    }
}

/// A report that can write itself into any [`Sink`].
pub trait Render {
    /// Pushes the report's document into `sink`.
    fn render(&self, sink: &mut dyn Sink);
}

pub use crate::identify::Status;
/// Whether a command's result can be trusted as it stands (the fit's verdict; a command
/// without a fit is `Ok`); decides the exit code of a front end.
pub use crate::identify::Verdict;

/// A report with one block of each kind, for the tests of writers (this crate's, the CLI's
/// terminal writer, a plugin's own): a title, a detail paragraph with inline code and
/// characters markup languages escape, a failed verdict, a terminal-only line, a summary
/// table whose second cell is a check status, and three files (two plots, one data file).
#[derive(Debug, Clone, Copy, Default)]
pub struct SampleReport;

impl Render for SampleReport {
    fn render(&self, sink: &mut dyn Sink) {
        sink.title("frictionid sample");
        sink.paragraph("Config: `a<b>.toml` & more.", Role::Detail);
        sink.verdict(Status::Fail, "the fit did not converge");
        sink.paragraph("best: coulomb", Role::Brief);
        sink.table(
            &Table::new(
                &["check", "a|b"],
                vec![vec!["energy_balance".into(), "warn".into()]],
            ),
            Role::Summary,
        );
        sink.files(&["p.svg".into(), "missing.svg".into(), "report.json".into()]);
    }
}

/// Renders the opening of a command's report (shared by the report values): the title
/// `frictionid <command>` and a detail paragraph naming the config, then `summary`.
fn render_opening(sink: &mut dyn Sink, command: &str, config: &str, summary: &str) {
    sink.title(&format!("frictionid {command}"));
    sink.paragraph(&format!("Config: `{config}`. {summary}"), Role::Detail);
}

/// Renders a "## Files" section (shared by the report values).
fn render_files(sink: &mut dyn Sink, files: &[String]) {
    if !files.is_empty() {
        sink.files(files);
    }
}
