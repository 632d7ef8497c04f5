//! compare's report recommends: stdout, report.md and report.html open with the law
//! report.json names as `recommended` and why; the HTML verdict box takes that law's own
//! status; a Diagnostics section lists every law's findings as report.json holds them; the
//! plots start with the recommended law's; a `--models` selection writes its own folder; and
//! a driven rotary axis without a normal force shows rad/s and N m, no N = 1 N and no empty
//! energy columns.

use crate::html::{tokens, Html};
use crate::rotary::driven_pendulum_csv;
use frictionid_cli::testing::{read_report, run_ok, scratch_dir};
use std::path::Path;
use std::process::Command;

/// A driven pendulum (J = 0.02 kg m^2, c = 0.002 N m s/rad, M_g = 0.5 N m, Coulomb torque
/// 0.012 N m, no normal force): the angle and its derivatives in closed form, the input
/// torque from the balance u = J a + c v + M_g sin q + T_c sgn v with 1e-3 N m of
/// deterministic pseudo-random noise.
fn driven_csv() -> String {
    let mut state: u64 = 12345;
    let mut uniform = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    // Twelve uniforms of variance 1/12 each: unit variance.
    driven_pendulum_csv(move || 1e-3 * (0..12).map(|_| uniform()).sum::<f64>())
}

const DRIVEN_CONFIG: &str = "[oscillator]\naxis = \"rotary\"\ninertia = 0.02\ndamping = 0.002\n\
    restoring = { type = \"pendulum\", gravity_moment = 0.5 }\n\
    [model]\ntype = \"coulomb\"\nmu = 0.02\n\
    [fit.options]\ndomain = \"force\"\nforce_target = \"inverse_dynamics\"\n\
    oscillator = [\"mass\", \"damping\", \"gravity_moment\"]\n\
    [[records]]\nfile = \"driven.csv\"\nx0 = 0.0\ndisplacement_column = \"angle\"\n\
    velocity_column = \"velocity\"\nacceleration_column = \"acceleration\"\n\
    input_force_column = \"torque\"\n";

/// A scratch directory holding the driven pendulum's record and config (`driven.toml`).
fn driven_case(name: &str) -> std::path::PathBuf {
    let dir = scratch_dir("compare-report", name);
    std::fs::write(dir.join("driven.csv"), driven_csv()).unwrap();
    std::fs::write(dir.join("driven.toml"), DRIVEN_CONFIG).unwrap();
    dir
}

/// Runs `frictionid <args>` in `dir` and returns its standard output.
fn run_in(dir: &Path, args: &[&str]) -> String {
    let o = run_ok(
        Command::new(env!("CARGO_BIN_EXE_frictionid"))
            .current_dir(dir)
            .args(args),
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The status a fit's verdict box shows, worked out from its report.json entry: `fail` when
/// it did not converge or a finding failed, else `warn` when one warned, else `pass`.
fn expected_status(fit: &serde_json::Value) -> &'static str {
    let statuses: Vec<&str> = fit["diagnostics"]
        .as_array()
        .map(|d| d.iter().filter_map(|f| f["status"].as_str()).collect())
        .unwrap_or_default();
    if fit["converged"] != true || statuses.contains(&"fail") {
        "fail"
    } else if statuses.contains(&"warn") {
        "warn"
    } else {
        "pass"
    }
}

/// What report.html shows, read with html5gum: the first verdict box's classes and text, the
/// h2 headings in order, each law's Diagnostics rows (check, status) under its h3, and the
/// figure captions in order.
#[derive(Debug, Default)]
struct Page {
    verdict_class: String,
    verdict_text: String,
    h2: Vec<String>,
    diagnostics: Vec<(String, Vec<(String, String)>)>,
    captions: Vec<String>,
}

/// Reads `html` into a [`Page`].
fn read_page(html: &str) -> Page {
    let mut page = Page::default();
    let mut open: Vec<String> = Vec::new();
    let mut verdict_depth: Option<usize> = None;
    let mut section = String::new();
    let mut text = String::new();
    let mut row: Vec<String> = Vec::new();
    for token in tokens(html) {
        match token {
            Html::Start(tag) => {
                let name = tag.name;
                let class = tag
                    .attributes
                    .into_iter()
                    .find(|(k, _)| k == "class")
                    .map(|(_, v)| v)
                    .unwrap_or_default();
                if verdict_depth.is_none()
                    && page.verdict_class.is_empty()
                    && class.split(' ').any(|c| c == "verdict")
                {
                    page.verdict_class = class;
                    verdict_depth = Some(open.len());
                }
                if matches!(name.as_str(), "h2" | "h3" | "td" | "figcaption") {
                    text.clear();
                }
                if name == "tr" {
                    row.clear();
                }
                if !tag.self_closing && !matches!(name.as_str(), "meta" | "br") {
                    open.push(name);
                }
            }
            Html::End(name) => {
                open.pop();
                if verdict_depth == Some(open.len()) {
                    verdict_depth = None;
                }
                match name.as_str() {
                    "h2" => {
                        section = text.clone();
                        page.h2.push(text.clone());
                    }
                    "h3" if section == "Diagnostics" => {
                        page.diagnostics.push((text.clone(), Vec::new()));
                    }
                    "td" => row.push(text.clone()),
                    "tr" if section == "Diagnostics" && row.len() >= 2 => {
                        if let Some((_, rows)) = page.diagnostics.last_mut() {
                            rows.push((row[0].clone(), row[1].clone()));
                        }
                    }
                    "figcaption" => page.captions.push(text.clone()),
                    _ => {}
                }
            }
            Html::Text(s) => {
                if verdict_depth.is_some() {
                    page.verdict_text.push_str(&s);
                }
                text.push_str(&s);
            }
        }
    }
    page
}

/// compare on the driven pendulum: every writer opens with the law report.json recommends;
/// the verdict box has that law's own status; each law's findings are listed under
/// Diagnostics as report.json holds them; the first plot is the recommended law's; the units
/// are rotary and the steady-state chart does not claim a normal force the rig lacks.
#[test]
fn every_writer_opens_with_the_recommended_law_and_lists_each_laws_findings() {
    let dir = driven_case("recommends");
    let stdout = run_in(
        &dir,
        &[
            "compare",
            "driven.toml",
            "--models",
            "coulomb,viscous_coulomb",
            "--out",
            "out",
        ],
    );
    let out = dir.join("out");
    let r = read_report(&out);
    let law = r["recommended"].as_str().expect("a recommended law");
    let ranking = r["ranking"].as_array().unwrap();
    let fit = ranking.iter().find(|f| f["model"] == law).unwrap();

    // stdout: the law first, then why.
    let first = stdout.lines().next().unwrap_or_default();
    assert_eq!(first, format!("recommended: {law}"), "{stdout}");
    let why: Vec<&str> = stdout.lines().skip(1).take(3).collect();
    assert!(why[0].starts_with("- held-out validation"), "{stdout}");
    assert!(why[1].starts_with("- parsimony"), "{stdout}");
    assert!(why[2].starts_with("- identifiability"), "{stdout}");

    // report.md: the recommendation before any section.
    let md = read(&out.join("report.md"));
    let recommended = md
        .find(&format!("**Recommended: `{law}`**"))
        .expect("the recommendation in report.md");
    assert!(recommended < md.find("\n## ").unwrap(), "{md}");
    for model in ranking.iter().filter_map(|f| f["model"].as_str()) {
        let section = md.find("## Diagnostics").unwrap();
        assert!(
            md[section..].contains(&format!("### {model}\n")),
            "{model} in the Diagnostics section"
        );
    }

    // report.html: the verdict box first, coloured by the recommended law's own findings.
    let html = read(&out.join("report.html"));
    let page = read_page(&html);
    assert!(
        page.verdict_class
            .split(' ')
            .any(|c| c == expected_status(fit)),
        "{} for {law}",
        page.verdict_class
    );
    assert!(
        page.verdict_text
            .trim_start()
            .starts_with(&format!("Recommended: {law}")),
        "{}",
        page.verdict_text
    );
    assert!(html.find("class=\"verdict").unwrap() < html.find("<h2>").unwrap());
    assert!(
        page.h2.contains(&"Diagnostics".to_string()),
        "{:?}",
        page.h2
    );
    // Each law's findings, in report.json's order, the recommended law first.
    assert_eq!(page.diagnostics.len(), ranking.len());
    assert_eq!(page.diagnostics[0].0, law);
    for (model, rows) in &page.diagnostics {
        let entry = ranking
            .iter()
            .find(|f| f["model"] == model.as_str())
            .unwrap();
        let findings: Vec<(String, String)> = entry["diagnostics"]
            .as_array()
            .unwrap()
            .iter()
            .map(|d| {
                (
                    d["check"].as_str().unwrap().to_string(),
                    d["status"].as_str().unwrap().to_string(),
                )
            })
            .collect();
        assert_eq!(rows, &findings, "{model}");
    }
    // The first plot is the recommended law's fit.
    let first_plot = page.captions.first().expect("a plot");
    assert!(first_plot.starts_with("best_"), "{first_plot}");
    let svg = read(&out.join(first_plot));
    assert!(svg.contains(&format!("fitted ({law})")), "{first_plot}");

    // Rotary units, and no normal force claimed.
    assert!(md.contains("[N m]") && !md.contains("m/s"), "{md}");
    let velocity = read(&out.join("best_driven_force_velocity.svg"));
    assert!(velocity.contains("velocity [rad/s]"));
    let steady = read(&out.join("steady_state_curves.svg"));
    assert!(steady.contains("[N m]") && steady.contains("[rad/s]"));
    assert!(
        !steady.contains("N = "),
        "N = 1 N on a rig without a normal force"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The driven axis's fit report has no energy-check columns of dashes (the check does not
/// run on a driven record), its units are rotary, and with a normal force given the
/// steady-state chart names it (the other direction of the test above).
#[test]
fn a_driven_fit_report_has_no_empty_columns_and_names_a_given_normal_force() {
    let dir = driven_case("fit");
    run_in(&dir, &["fit", "driven.toml", "--out", "out", "--quiet"]);
    let md = read(&dir.join("out/report.md"));
    let records = &md[md.find("## Records").unwrap()..];
    let header = records.lines().nth(2).unwrap_or_default();
    assert!(header.starts_with("| record | x0 [rad] |"), "{header}");
    assert!(!header.contains("Eq. 7"), "{header}");
    let table_row = records.lines().nth(4).unwrap_or_default();
    assert!(!table_row.contains("| - | - |"), "{table_row}");

    let with_n = DRIVEN_CONFIG.replace("inertia = 0.02\n", "inertia = 0.02\nnormal_force = 2.0\n");
    std::fs::write(dir.join("with-n.toml"), with_n).unwrap();
    run_in(&dir, &["fit", "with-n.toml", "--out", "n", "--quiet"]);
    let steady = read(&dir.join("n/steady_state.svg"));
    assert!(steady.contains("N = 2 N"), "the given normal force");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Without `--out`, a `--models` selection writes into its own folder next to the plain
/// run's and leaves that folder as it was.
#[test]
fn a_models_selection_writes_its_own_folder() {
    let dir = driven_case("folder");
    let plain = dir.join("frictionid-out/driven/compare");
    std::fs::create_dir_all(&plain).unwrap();
    std::fs::write(plain.join("report.json"), "{\"plain\": true}\n").unwrap();
    run_in(
        &dir,
        &["compare", "driven.toml", "--models", "coulomb", "--quiet"],
    );
    let own = dir.join("frictionid-out/driven/compare-coulomb");
    let r = read_report(&own);
    assert_eq!(r["recommended"], "coulomb");
    assert_eq!(read(&plain.join("report.json")), "{\"plain\": true}\n");
    let names: Vec<String> = std::fs::read_dir(&plain)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["report.json"], "the plain run's folder untouched");
    let _ = std::fs::remove_dir_all(&dir);
}
