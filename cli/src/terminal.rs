//! The terminal writer: the summary blocks of a report as aligned plain text on stdout.

use crate::report::text_table;
use frictionid_engine::report::{Render, Role, Sink, Status, Table};

/// Collects the summary of a report (blocks with [`Role::Summary`] or [`Role::Brief`]) as
/// plain text.
#[derive(Debug, Clone, Default)]
pub struct TerminalWriter {
    out: String,
}

impl TerminalWriter {
    /// The terminal summary of `report`.
    pub fn render(report: &dyn Render) -> String {
        let mut w = Self::default();
        report.render(&mut w);
        w.out
    }
}

fn shown(role: Role) -> bool {
    role != Role::Detail
}

impl Sink for TerminalWriter {
    fn title(&mut self, _text: &str) {}

    fn heading(&mut self, _level: usize, text: &str, role: Role) {
        if shown(role) {
            if !self.out.is_empty() && !self.out.ends_with("\n\n") {
                self.out.push('\n');
            }
            self.out.push_str(text);
            self.out.push('\n');
        }
    }

    fn paragraph(&mut self, text: &str, role: Role) {
        if shown(role) {
            self.out.push_str(text);
            self.out.push('\n');
        }
    }

    fn recommendation(&mut self, _status: Status, text: &str, reasons: &[String]) {
        self.out
            .push_str(&format!("recommended: {}\n", text.replace('`', "")));
        self.list(reasons, Role::Summary);
        self.out.push('\n');
    }

    fn table(&mut self, table: &Table, role: Role) {
        if shown(role) {
            let headers: Vec<&str> = table.headers.iter().map(String::as_str).collect();
            self.out.push_str(&text_table(&headers, &table.rows));
            self.out.push('\n');
        }
    }

    fn list(&mut self, items: &[String], role: Role) {
        if shown(role) {
            for item in items {
                self.out.push_str(&format!("- {item}\n"));
            }
        }
    }

    fn files(&mut self, _files: &[String]) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use frictionid_engine::report::SampleReport;

    #[test]
    fn terminal_shows_summary_blocks_only() {
        assert_eq!(
            TerminalWriter::render(&SampleReport),
            "best: coulomb\ncheck           a|b\n--------------  ----\nenergy_balance  warn\n\n"
        );
    }
}
