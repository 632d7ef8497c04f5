//! report.html of every report command: a well-formed, self-contained HTML document (checked
//! with html5gum, a WHATWG-conformant tokenizer) that shows the report's content and its
//! plots inline and loads nothing from outside the file.

use crate::html::{tokens, Html};
use frictionid_cli::testing::{fixtures_dir, run_ok, scratch_dir};
use std::process::Command;

/// Runs `frictionid <command> <config> --out <fresh dir> --quiet` and returns report.html.
fn report_html(command: &str, config: &str, extra: &[&str]) -> String {
    let out = scratch_dir("html", command);
    run_ok(
        Command::new(env!("CARGO_BIN_EXE_frictionid"))
            .arg(command)
            .arg(fixtures_dir().join(config))
            .args(extra)
            .arg("--out")
            .arg(&out)
            .arg("--quiet"),
    );
    std::fs::read_to_string(out.join("report.html")).unwrap()
}

/// Elements HTML closes without an end tag.
const VOID: [&str; 6] = ["meta", "br", "hr", "img", "input", "link"];
/// Elements that load or run something from elsewhere.
const FORBIDDEN: [&str; 7] = [
    "script", "link", "img", "iframe", "object", "embed", "image",
];

/// The document's structure as the tokenizer sees it: start tags in order, with every parse
/// error, unbalanced end tag and outside reference reported.
fn check_document(html: &str) -> Vec<String> {
    let mut open: Vec<String> = Vec::new();
    let mut seen = Vec::new();
    for token in tokens(html) {
        match token {
            Html::Start(tag) => {
                let name = tag.name;
                assert!(!FORBIDDEN.contains(&name.as_str()), "<{name}> in the page");
                for (key, value) in &tag.attributes {
                    let key = key.to_lowercase();
                    let value = value.to_lowercase();
                    assert!(
                        !matches!(key.as_str(), "src" | "href" | "xlink:href" | "srcset"),
                        "<{name} {key}=\"{value}\"> refers to another resource"
                    );
                    assert!(!value.contains("url("), "<{name} {key}> loads {value}");
                }
                if !tag.self_closing && !VOID.contains(&name.as_str()) {
                    open.push(name.clone());
                }
                seen.push(name);
            }
            Html::End(name) => {
                assert_eq!(
                    open.pop().as_deref(),
                    Some(name.as_str()),
                    "unbalanced </{name}>"
                );
            }
            Html::Text(text) => {
                let text = text.to_lowercase();
                assert!(
                    !text.contains("@import") && !text.contains("url("),
                    "styles load something from elsewhere"
                );
            }
        }
    }
    assert!(open.is_empty(), "elements left open: {open:?}");
    seen
}

fn count(tags: &[String], name: &str) -> usize {
    tags.iter().filter(|t| *t == name).count()
}

#[test]
fn fit_report_html_has_verdict_parameters_plots_and_config() {
    let html = report_html("fit", "fmm-fit.toml", &[]);
    let tags = check_document(&html);
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert_eq!(count(&tags, "html"), 1);
    // Verdict and diagnostics come before the parameter table.
    let verdict = html.find("class=\"verdict").expect("verdict");
    let diagnostics = html.find("<h2>Diagnostics</h2>").expect("diagnostics");
    let parameters = html.find("<h2>Parameters</h2>").expect("parameters");
    assert!(verdict < diagnostics && diagnostics < parameters);
    assert!(html.contains("<td>mu</td>"), "the fitted parameter");
    // Seven plots (velocity fit and friction force per record, steady state), all inline.
    assert_eq!(count(&tags, "svg"), 7);
    assert!(html.contains("<h2>Configuration</h2>"));
    assert!(html.contains("[oscillator]"), "the config echoed");
    assert!(html.contains(&format!("frictionid {}", env!("CARGO_PKG_VERSION"))));
}

#[test]
fn compare_report_html_ranks_the_models_and_names_the_verdict() {
    let html = report_html(
        "compare",
        "fmm-compare.toml",
        &["--models", "coulomb,viscous_coulomb,none"],
    );
    let tags = check_document(&html);
    assert!(html.contains("Akaike weight"));
    assert!(html.contains("<td>coulomb</td>") && html.contains("<td>none</td>"));
    assert!(html.contains("class=\"verdict"));
    assert!(count(&tags, "svg") >= 1);
}

#[test]
fn energy_and_simulate_report_html_are_self_contained_pages_with_plots() {
    for (command, config) in [
        ("energy", "fmm-energy.toml"),
        ("simulate", "paper-140mm.toml"),
    ] {
        let html = report_html(command, config, &[]);
        let tags = check_document(&html);
        assert!(count(&tags, "svg") >= 1, "{command}: no inline plot");
        assert!(count(&tags, "table") >= 1, "{command}: no table");
    }
}

#[test]
#[should_panic(expected = "unbalanced")]
fn the_checker_catches_misnested_elements() {
    check_document("<!DOCTYPE html><html><body><p><b></p></b></body></html>");
}

#[test]
#[should_panic(expected = "refers to another resource")]
fn the_checker_catches_outside_references() {
    check_document(
        "<!DOCTYPE html><html><body><a href=\"https://example.org\">x</a></body></html>",
    );
}
