//! The HTML writer (report.html): one self-contained page per report.
//!
//! The page carries everything it shows: styles in one `<style>` element, plots inline as
//! `<svg>` elements, no scripts, no fonts, no links to anything outside the file, so it opens
//! the same from a mail attachment, an archive or a printer. The report's own order is kept
//! (each report puts its verdict and diagnostics first); the configuration the run came from
//! and the frictionid version close the page.

use super::format::serialized_name;
use super::{Render, Role, Sink, Status, Table};
use std::fmt::Write as _;

/// What the page needs beyond the report value: the plots' SVG text and the configuration.
pub struct Page<'a> {
    /// The SVG text of a file the report lists, by name (`None`: listed, not inlined).
    pub plot: &'a dyn Fn(&str) -> Option<String>,
    /// The configuration file's name and text, echoed at the end of the page.
    pub config: Option<(&'a str, &'a str)>,
}

/// Collects a report as one HTML document.
pub struct HtmlWriter<'a> {
    page: &'a Page<'a>,
    title: String,
    body: String,
    /// The plots shown already (by [`Sink::figures`]), not shown again with the files.
    shown: Vec<String>,
}

impl<'a> HtmlWriter<'a> {
    /// The HTML document of `report` on `page`.
    pub fn render(report: &dyn Render, page: &'a Page<'a>) -> String {
        let mut w = Self {
            page,
            title: String::new(),
            body: String::new(),
            shown: Vec::new(),
        };
        report.render(&mut w);
        w.finish()
    }

    fn finish(mut self) -> String {
        self.push_config();
        let mut out = String::with_capacity(self.body.len() + STYLE.len() + 512);
        out.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
        out.push_str("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n");
        let _ = writeln!(out, "<title>{}</title>", escape(&self.title));
        let _ = writeln!(out, "<style>{STYLE}</style>\n</head>\n<body>\n<main>");
        out.push_str(&self.body);
        let _ = writeln!(
            out,
            "<footer>Written by frictionid {}.</footer>\n</main>\n</body>\n</html>",
            env!("CARGO_PKG_VERSION")
        );
        out
    }

    fn push_config(&mut self) {
        if let Some((name, text)) = self.page.config {
            let _ = write!(
                self.body,
                "<section class=\"config\">\n<h2>Configuration</h2>\n<p><code>{}</code></p>\n<pre>{}</pre>\n</section>\n",
                escape(name),
                escape(text)
            );
        }
    }

    fn push_figures(&mut self, names: &[&String]) {
        let heading = if self.shown.is_empty() {
            "Plots"
        } else {
            "Other plots"
        };
        let _ = writeln!(self.body, "<h2>{heading}</h2>");
        for name in names {
            self.shown.push(name.to_string());
            let Some(text) = (self.page.plot)(name) else {
                continue;
            };
            let Some(svg) = inline_svg(&text) else {
                continue;
            };
            let _ = write!(
                self.body,
                "<figure>\n{svg}\n<figcaption><code>{}</code></figcaption>\n</figure>\n",
                escape(name)
            );
        }
    }
}

impl Sink for HtmlWriter<'_> {
    fn title(&mut self, text: &str) {
        self.title = text.to_string();
        let _ = writeln!(self.body, "<h1>{}</h1>", escape(text));
    }

    fn heading(&mut self, level: usize, text: &str, role: Role) {
        if role == Role::Brief {
            return;
        }
        let level = level.clamp(2, 4);
        let _ = writeln!(self.body, "<h{level}>{}</h{level}>", inline(text));
    }

    fn paragraph(&mut self, text: &str, role: Role) {
        if role != Role::Brief {
            let _ = writeln!(self.body, "<p>{}</p>", inline(text));
        }
    }

    fn verdict(&mut self, status: Status, text: &str) {
        let class = serialized_name(&status);
        let _ = writeln!(
            self.body,
            "<p class=\"verdict {class}\"><strong>Verdict:</strong> {}</p>",
            inline(text)
        );
    }

    fn recommendation(&mut self, status: Status, text: &str, reasons: &[String]) {
        let class = serialized_name(&status);
        let _ = writeln!(
            self.body,
            "<div class=\"verdict recommendation {class}\">\n<p><strong>Recommended:</strong> {}</p>\n<ul>",
            inline(text)
        );
        for reason in reasons {
            let _ = writeln!(self.body, "<li>{}</li>", inline(reason));
        }
        self.body.push_str("</ul>\n</div>\n");
    }

    fn table(&mut self, table: &Table, role: Role) {
        if role != Role::Brief {
            self.body.push_str(&html_table(table));
        }
    }

    fn list(&mut self, items: &[String], role: Role) {
        if role == Role::Brief {
            return;
        }
        self.body.push_str("<ul>\n");
        for item in items {
            let _ = writeln!(self.body, "<li>{}</li>", inline(item));
        }
        self.body.push_str("</ul>\n");
    }

    fn figures(&mut self, plots: &[String]) {
        let plots: Vec<&String> = plots.iter().filter(|p| p.ends_with(".svg")).collect();
        if !plots.is_empty() {
            self.push_figures(&plots);
        }
    }

    fn files(&mut self, files: &[String]) {
        let (plots, others): (Vec<&String>, Vec<&String>) =
            files.iter().partition(|f| f.ends_with(".svg"));
        let rest: Vec<&String> = plots
            .iter()
            .copied()
            .filter(|p| !self.shown.contains(p))
            .collect();
        if !rest.is_empty() {
            self.push_figures(&rest);
        }
        self.body.push_str("<h2>Files</h2>\n<ul class=\"files\">\n");
        for f in plots.iter().chain(&others) {
            let _ = writeln!(self.body, "<li><code>{}</code></li>", escape(f));
        }
        self.body.push_str("</ul>\n");
    }
}

/// An HTML table; cells that are a check status (`pass`, `skipped`, `warn`, `fail`) carry it
/// as class.
fn html_table(table: &Table) -> String {
    let mut out = String::from("<div class=\"scroll\"><table>\n<thead><tr>");
    for h in &table.headers {
        let _ = write!(out, "<th>{}</th>", inline(h));
    }
    out.push_str("</tr></thead>\n<tbody>\n");
    for row in &table.rows {
        out.push_str("<tr>");
        for cell in row {
            match cell.as_str() {
                "pass" | "skipped" | "warn" | "fail" => {
                    let _ = write!(out, "<td class=\"status {cell}\">{cell}</td>");
                }
                _ => {
                    let _ = write!(out, "<td>{}</td>", inline(cell));
                }
            }
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</tbody>\n</table></div>\n");
    out
}

/// `text` escaped, with inline code between backticks as `<code>`.
fn inline(text: &str) -> String {
    text.split('`')
        .enumerate()
        .map(|(i, part)| {
            if i % 2 == 1 {
                format!("<code>{}</code>", escape(part))
            } else {
                escape(part)
            }
        })
        .collect()
}

/// `text` with the characters that HTML gives a meaning escaped.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// The `<svg>` element of an SVG file's text (an XML prolog dropped), or `None` when the text
/// is not one SVG element.
fn inline_svg(text: &str) -> Option<&str> {
    let start = text.find("<svg")?;
    let end = text.rfind("</svg>")? + "</svg>".len();
    (start < end).then(|| &text[start..end])
}

/// The page's styles: readable on a laptop screen and in print, no external fonts.
const STYLE: &str = "
:root { color-scheme: light; --ink: #1a1a1a; --muted: #5a5a5a; --rule: #d0d0d0;
  --ok: #1b7837; --warn: #b35806; --fail: #b2182b; }
body { margin: 0; color: var(--ink); background: #fff;
  font: 15px/1.5 system-ui, -apple-system, 'Segoe UI', Roboto, 'Helvetica Neue', Arial, sans-serif; }
main { max-width: 1100px; margin: 0 auto; padding: 1.5rem 1.25rem 3rem; }
h1 { font-size: 1.6rem; margin: 0 0 .5rem; }
h2 { font-size: 1.25rem; margin: 2rem 0 .5rem; border-bottom: 1px solid var(--rule); }
h3 { font-size: 1.05rem; margin: 1.25rem 0 .4rem; }
code, pre { font-family: ui-monospace, 'SFMono-Regular', Menlo, Consolas, 'DejaVu Sans Mono', monospace;
  font-size: .9em; }
pre { background: #f6f6f6; border: 1px solid var(--rule); padding: .75rem; overflow-x: auto;
  white-space: pre-wrap; }
.verdict { padding: .6rem .9rem; border-left: 6px solid; background: #f7f7f7; font-size: 1.05rem; }
.verdict.pass { border-color: var(--ok); background: #eef6f0; }
.recommendation p { margin: 0 0 .3rem; font-size: 1.15rem; }
.recommendation ul { margin: 0; padding-left: 1.2rem; font-size: .95rem; }
.recommendation li { margin: .15rem 0; }
.verdict.warn { border-color: var(--warn); background: #fdf3e9; }
.verdict.fail { border-color: var(--fail); background: #fbeeee; }
.scroll { overflow-x: auto; }
table { border-collapse: collapse; margin: .5rem 0 1rem; font-variant-numeric: tabular-nums; }
th, td { padding: .25rem .55rem; border-bottom: 1px solid var(--rule); text-align: left;
  vertical-align: top; }
th { border-bottom: 2px solid var(--ink); }
td { white-space: nowrap; }
td:last-child { white-space: normal; }
td.status { font-weight: 600; text-transform: uppercase; font-size: .85em; }
td.status.pass { color: var(--ok); }
td.status.warn { color: var(--warn); }
td.status.fail { color: var(--fail); }
td.status.skipped { color: var(--muted); }
figure { margin: 1rem 0 1.5rem; }
figure svg { display: block; width: 100%; height: auto; }
figcaption { color: var(--muted); font-size: .9rem; }
ul.files { columns: 2; color: var(--muted); }
footer { margin-top: 3rem; color: var(--muted); font-size: .85rem; }
@media print {
  body { font-size: 10pt; }
  main { max-width: none; padding: 0; }
  h2 { break-after: avoid; }
  figure, table, .verdict { break-inside: avoid; }
  .scroll { overflow: visible; }
}
";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::SampleReport;

    fn page_of(config: Option<(&str, &str)>, f: impl Fn(&str) -> Option<String>) -> String {
        let page = Page { plot: &f, config };
        HtmlWriter::render(&SampleReport, &page)
    }

    #[test]
    fn escapes_text_and_keeps_inline_code() {
        let html = page_of(None, |_| None);
        assert!(html.contains("<p>Config: <code>a&lt;b&gt;.toml</code> &amp; more.</p>"));
        assert!(!html.contains("best: coulomb"));
        assert!(html.contains("<title>frictionid sample</title>"));
    }

    #[test]
    fn verdict_and_status_cells_carry_their_class() {
        let html = page_of(None, |_| None);
        assert!(html.contains("class=\"verdict fail\""));
        assert!(html.contains("<td class=\"status warn\">warn</td>"));
    }

    #[test]
    fn plots_are_inlined_without_their_prolog_and_config_is_echoed() {
        let svg = "<?xml version=\"1.0\"?>\n<svg viewBox=\"0 0 2 2\"><line/></svg>\n";
        let html = page_of(Some(("c.toml", "[model]\ntype = \"a<b\"")), |name| {
            (name == "p.svg").then(|| svg.to_string())
        });
        assert!(html.contains("<figure>\n<svg viewBox=\"0 0 2 2\"><line/></svg>"));
        assert!(!html.contains("<?xml"));
        assert_eq!(
            html.matches("<figure>").count(),
            1,
            "missing.svg is listed only"
        );
        assert!(html.contains("<li><code>missing.svg</code></li>"));
        assert!(html.contains("<pre>[model]\ntype = &quot;a&lt;b&quot;</pre>"));
        assert!(html.trim_end().ends_with("</html>"));
    }

    /// Plots shown early by `figures` are not shown again with the files, which still list
    /// them; the others follow under their own heading.
    #[test]
    fn figures_shown_early_are_shown_once() {
        struct Early;
        impl Render for Early {
            fn render(&self, sink: &mut dyn Sink) {
                sink.title("t");
                sink.figures(&["a.svg".into()]);
                sink.heading(2, "Parameters", Role::Detail);
                sink.files(&["a.svg".into(), "b.svg".into(), "report.json".into()]);
            }
        }
        let f = |_: &str| Some("<svg viewBox=\"0 0 1 1\"></svg>".to_string());
        let page = Page {
            plot: &f,
            config: None,
        };
        let html = HtmlWriter::render(&Early, &page);
        assert_eq!(html.matches("<figure>").count(), 2);
        let plots = html.find("<h2>Plots</h2>").unwrap();
        let parameters = html.find("<h2>Parameters</h2>").unwrap();
        let other = html.find("<h2>Other plots</h2>").unwrap();
        assert!(plots < parameters && parameters < other);
        assert!(html.contains("<li><code>a.svg</code></li>"));
    }

    #[test]
    fn a_file_that_is_not_svg_is_not_inlined() {
        let html = page_of(None, |_| Some("not an svg".into()));
        assert_eq!(html.matches("<figure>").count(), 0);
    }
}
