//! `plan` end to end: a Coulomb coefficient on the paper's stage, whose information adds
//! over records (so the recommended pair is the two most informative candidates and its
//! standard error is (sum 1/sigma_i^2)^-1/2 of theirs, an identity independent of how each
//! is computed); the records already taken count; an unreachable level names the change that
//! reaches it; bad `[plan]` tables fail with one line.

use frictionid_cli::testing::{
    assert_bad_inputs, read_report, runs_ok, scratch_dir, BadInput, Says,
};
use std::path::Path;
use std::process::Command;

const STAGE: &str = "[oscillator]\nmass = 10.391\ndamping = 0.275\nstiffness = 1982.0\n\
                     normal_force = 14.5\n[model]\ntype = \"coulomb\"\nmu = 0.2\n";

fn plan_config(extra: &str) -> String {
    format!(
        "{STAGE}[plan]\nchoose = 2\nvelocity_noise = 2e-4\n{extra}candidates = [\n\
         {{ x0 = 0.004, duration = 1.0 }},\n{{ x0 = 0.010, duration = 1.0 }},\n\
         {{ x0 = 0.022, duration = 1.0, velocity_noise = 1e-3 }},\n]\n"
    )
}

fn run_plan(cfg: &Path, out: &Path) -> serde_json::Value {
    let run = Command::new(env!("CARGO_BIN_EXE_frictionid"))
        .args(["plan", cfg.to_str().unwrap_or_default(), "--quiet", "--out"])
        .arg(out)
        .output();
    runs_ok(run, out);
    read_report(out)
}

fn mu_std(v: &serde_json::Value) -> f64 {
    v["predicted_std"]["mu"].as_f64().unwrap()
}

#[test]
fn plan_recommends_the_most_informative_pair_and_adds_their_information() {
    let dir = scratch_dir("plan", "coulomb");
    let cfg = dir.join("c.toml");
    std::fs::write(&cfg, plan_config("")).unwrap();
    let out = dir.join("out");
    let report = run_plan(&cfg, &out);
    let stds: Vec<f64> = report["candidates"]
        .as_array()
        .unwrap()
        .iter()
        .map(mu_std)
        .collect();
    let mut order: Vec<usize> = (0..3).collect();
    order.sort_by(|&a, &b| stds[a].total_cmp(&stds[b]));
    let mut best: Vec<usize> = order[..2].to_vec();
    best.sort_unstable();
    let recommended: Vec<usize> = report["recommended"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i.as_u64().unwrap() as usize)
        .collect();
    assert_eq!(recommended, best, "{stds:?}");
    let combined = best
        .iter()
        .map(|&i| stds[i].powi(-2))
        .sum::<f64>()
        .powf(-0.5);
    assert!((mu_std(&report) / combined - 1.0).abs() < 1e-9);
    assert_eq!(report["out_of_reach"].as_array().unwrap().len(), 0);
    assert!(out.join("predicted_std.svg").exists());
    assert!(std::fs::read_to_string(out.join("report.md"))
        .unwrap()
        .contains("## The recommended records"));

    // A record already taken (the 22 mm fixture, its noise declared at 5e-4 m/s) adds its
    // information to every candidate's: 1/s^2 = 1/s_candidate^2 + 1/s_taken^2.
    let fixture = frictionid_cli::testing::fixtures_dir().join("x22mm.csv");
    std::fs::copy(fixture, dir.join("x22mm.csv")).unwrap();
    let taken = "[[records]]\nfile = \"x22mm.csv\"\nx0 = 0.022\nvelocity_noise = 5e-4\n";
    std::fs::write(&cfg, format!("{}{taken}", plan_config(""))).unwrap();
    let with_taken = run_plan(&cfg, &dir.join("out-taken"));
    let alone = with_taken["taken_std"]["mu"].as_f64().unwrap();
    for (i, c) in with_taken["candidates"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
    {
        let expected = (stds[i].powi(-2) + alone.powi(-2)).powf(-0.5);
        assert!(
            (mu_std(c) / expected - 1.0).abs() < 1e-9,
            "{i}: {} vs {expected}",
            mu_std(c)
        );
    }
}

#[test]
fn an_unreachable_level_names_the_change_that_reaches_it() {
    let dir = scratch_dir("plan", "reach");
    let cfg = dir.join("c.toml");
    std::fs::write(&cfg, plan_config("reach = 1e-4\n")).unwrap();
    let report = run_plan(&cfg, &dir.join("out"));
    let out = &report["out_of_reach"][0];
    assert_eq!(out["parameter"], "mu");
    let change = &out["change"];
    assert!(change.is_object(), "{out}");
    assert!(change["relative_std"].as_f64().unwrap() <= 1e-4);
    assert!(out["message"]
        .as_str()
        .unwrap()
        .contains("the smallest change that reaches it"));
}

#[test]
fn bad_plan_tables_fail_with_one_line() {
    let binary = Path::new(env!("CARGO_BIN_EXE_frictionid"));
    let cases = [
        BadInput::new("no-plan", "plan", STAGE).says(Says::Contains("needs a [plan] table")),
        BadInput::new("unknown-key", "plan", plan_config("chose = 1\n"))
            .says(Says::Contains("unknown key `chose` in [plan]")),
        BadInput::new(
            "too-many",
            "plan",
            plan_config("").replace("choose = 2", "choose = 4"),
        )
        .says(Says::Contains("choose = 4, but there are 3 candidates")),
        BadInput::new("parameter", "plan", plan_config("parameters = [\"muu\"]\n"))
            .says(Says::Contains("`muu` is not a free parameter")),
        BadInput::new(
            "no-noise",
            "plan",
            plan_config("").replace("velocity_noise = 2e-4\n", ""),
        )
        .says(Says::Contains("no velocity noise")),
    ];
    assert_bad_inputs(binary, "plan-bad", &cases);
}
