//! The Markdown writer (report.md).

use super::format::serialized_name;
use super::{Render, Role, Sink, Status, Table};

/// Collects a report as Markdown text.
#[derive(Debug, Clone, Default)]
pub struct MarkdownWriter {
    out: String,
}

impl MarkdownWriter {
    /// The Markdown of `report`.
    pub fn render(report: &dyn Render) -> String {
        let mut w = Self::default();
        report.render(&mut w);
        w.finish()
    }

    /// The text written so far, ending in exactly one newline.
    pub fn finish(self) -> String {
        let mut text = self.out.trim_end().to_string();
        text.push('\n');
        text
    }
}

/// A Markdown table (cells with `|` escaped).
pub fn markdown_table(table: &Table) -> String {
    let esc = |s: &str| s.replace('|', "\\|");
    let row = |cells: &[String]| {
        let cells: Vec<String> = cells.iter().map(|c| esc(c)).collect();
        format!("| {} |\n", cells.join(" | "))
    };
    let rule: Vec<&str> = table.headers.iter().map(|_| "---").collect();
    let mut out = row(&table.headers);
    out.push_str(&format!("|{}|\n", rule.join("|")));
    for r in &table.rows {
        out.push_str(&row(r));
    }
    out
}

impl Sink for MarkdownWriter {
    fn title(&mut self, text: &str) {
        self.out.push_str(&format!("# {text}\n\n"));
    }

    fn heading(&mut self, level: usize, text: &str, role: Role) {
        if role == Role::Brief {
            return;
        }
        self.out
            .push_str(&format!("{} {text}\n\n", "#".repeat(level.clamp(1, 6))));
    }

    fn paragraph(&mut self, text: &str, role: Role) {
        if role == Role::Brief {
            return;
        }
        self.out.push_str(&format!("{text}\n\n"));
    }

    fn recommendation(&mut self, status: Status, text: &str, reasons: &[String]) {
        self.out.push_str(&format!(
            "**Recommended: {text}** ({})\n\n",
            serialized_name(&status)
        ));
        self.list(reasons, Role::Summary);
    }

    fn table(&mut self, table: &Table, role: Role) {
        if role == Role::Brief {
            return;
        }
        self.out.push_str(&markdown_table(table));
        self.out.push('\n');
    }

    fn list(&mut self, items: &[String], role: Role) {
        if role == Role::Brief {
            return;
        }
        for item in items {
            self.out.push_str(&format!("- {item}\n"));
        }
        self.out.push('\n');
    }

    fn files(&mut self, files: &[String]) {
        self.heading(2, "Files", Role::Detail);
        let items: Vec<String> = files.iter().map(|f| format!("`{f}`")).collect();
        self.list(&items, Role::Detail);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::SampleReport;

    #[test]
    fn markdown_has_title_verdict_tables_and_files() {
        assert_eq!(
            MarkdownWriter::render(&SampleReport),
            "# frictionid sample\n\nConfig: `a<b>.toml` & more.\n\n\
             Verdict: the fit did not converge\n\n\
             | check | a\\|b |\n|---|---|\n| energy_balance | warn |\n\n\
             ## Files\n\n- `p.svg`\n- `missing.svg`\n- `report.json`\n"
        );
    }
}
