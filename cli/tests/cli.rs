//! End-to-end tests of the `frictionid` binary: the model listing against the registry, and
//! every input error the CLI must report as one line on stderr with a non-zero exit code,
//! no panic and no report.json.

use assert_cmd::Command;
use frictionid_cli::testing::Says::{Contains, EndsWith};
use frictionid_cli::testing::{
    assert_bad_inputs, fixtures_dir, scratch_dir, BadInput, FMM_OSCILLATOR,
};
use std::path::Path;

fn frictionid() -> Command {
    Command::new(env!("CARGO_BIN_EXE_frictionid"))
}

fn csv(n: usize) -> String {
    let mut s = String::from("# a test record\ntime,velocity\n");
    for i in 0..n {
        let t = i as f64 * 1e-3;
        s.push_str(&format!("{t},{}\n", 0.1 * (13.8 * t).sin()));
    }
    s
}

/// The binary under test, for the bad-input cases.
fn binary() -> &'static Path {
    Path::new(env!("CARGO_BIN_EXE_frictionid"))
}

/// A one-second `[simulation]` from 10 mm.
const SIMULATION: &str = "[simulation]\nx0 = 0.01\nduration = 1.0\n";

/// The FMM rig's `[oscillator]` table followed by `tables`.
fn fmm(tables: &str) -> String {
    format!("{FMM_OSCILLATOR}{tables}")
}

/// The FMM rig with Coulomb friction (`[model]`), followed by `tables`.
fn coulomb(tables: &str) -> String {
    fmm(&format!("[model]\ntype = \"coulomb\"\n{tables}"))
}

fn with_record(extra: &str) -> String {
    coulomb(&format!(
        "[[records]]\nfile = \"r.csv\"\nx0 = 0.014\n{extra}"
    ))
}

#[test]
fn models_lists_every_registered_model_with_its_equation() {
    let o = frictionid().arg("models").output().unwrap();
    assert!(o.status.success());
    let text = String::from_utf8(o.stdout).unwrap();
    for m in frictionid_models::listings() {
        assert!(
            text.lines()
                .any(|l| l.split_whitespace().next() == Some(m.name.as_str())),
            "{}",
            m.name
        );
        assert!(text.contains(&m.equation), "{}", m.equation);
        for p in &m.parameters {
            assert!(text.contains(&p.description), "{}", p.description);
        }
    }
}

#[test]
fn models_json_matches_the_registry() {
    let o = frictionid().args(["models", "--json"]).output().unwrap();
    assert!(o.status.success());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let list = v.as_array().unwrap();
    let names: Vec<String> = list
        .iter()
        .map(|m| m["name"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(names, frictionid_models::names());
    for m in list {
        let model = frictionid_models::default_model(m["name"].as_str().unwrap()).unwrap();
        assert_eq!(m["equation"].as_str().unwrap(), model.equation());
        let params = m["parameters"].as_array().unwrap();
        let info = model.param_info();
        assert_eq!(params.len(), info.len());
        for (p, i) in params.iter().zip(&info) {
            assert_eq!(p["name"].as_str().unwrap(), i.name);
            assert_eq!(p["unit"].as_str().unwrap(), i.unit);
            assert_eq!(p["default"].as_f64().unwrap(), i.default);
            assert_eq!(p["lower"].as_f64(), Some(i.lower).filter(|x| x.is_finite()));
            if i.upper.is_finite() {
                assert_eq!(p["upper"].as_f64().unwrap(), i.upper);
            }
        }
        // The listed defaults are the model's default parameter values.
        let defaults: Vec<f64> = params
            .iter()
            .map(|p| p["default"].as_f64().unwrap())
            .collect();
        assert_eq!(defaults, model.params());
    }
}

#[test]
fn help_shows_an_example_for_every_subcommand() {
    for cmd in ["models", "simulate", "fit", "compare", "energy"] {
        let o = frictionid().args([cmd, "--help"]).output().unwrap();
        assert!(o.status.success(), "{cmd}");
        let text = String::from_utf8(o.stdout).unwrap();
        assert!(
            text.contains(&format!("frictionid {cmd} ")),
            "{cmd}: {text}"
        );
    }
}

#[test]
fn usage_error_is_not_the_non_convergence_code() {
    let o = frictionid().arg("fitt").output().unwrap();
    assert_eq!(o.status.code(), Some(1));
}

#[test]
fn missing_config_file() {
    let dir = scratch_dir("cli", "missing-config");
    let o = frictionid()
        .args(["fit", "nope.toml", "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        e,
        "error: nope.toml: cannot read the config file: no such file\n"
    );
    assert_eq!(o.status.code(), Some(1));
}

/// Errors in a record file name the file and, where there is one, the line (comment and
/// header lines count).
#[test]
fn record_file_errors_name_the_file_and_line() {
    let cases = [
        BadInput::new("missing-file", "fit", with_record(""))
            .says(EndsWith("r.csv: cannot read the file: no such file")),
        // Line 1 is a comment, line 2 the header, t = 0.005 s is the sixth sample: line 8.
        BadInput::new("bad-line", "fit", with_record(""))
            .with_file("r.csv", csv(20).replacen("0.005,", "0.005,x", 1))
            .says(Contains("r.csv: line 8: column `velocity`: `x"))
            .says(EndsWith("is not a number")),
        BadInput::new("columns", "energy", with_record(""))
            .with_file("r.csv", csv(20) + "0.02,1,2\n")
            .says(Contains("r.csv: line 23: 3 fields, but the header has 2")),
        BadInput::new("nan", "fit", with_record(""))
            .with_file(
                "r.csv",
                csv(20)
                    .replacen("0.003,", "0.003,NaN\n0.0035,", 1)
                    .replacen("NaN\n0.0035,", "NaN\n#", 1),
            )
            .says(Contains("r.csv: line 6: column `velocity` is NaN")),
        BadInput::new("time", "compare", with_record(""))
            .with_file("r.csv", csv(20).replacen("0.004,", "0.002,", 1))
            .says(Contains(
                "r.csv: line 7: time 0.002 s does not increase (previous 0.003 s)",
            )),
        BadInput::new("uneven", "fit", with_record(""))
            .with_file("r.csv", csv(20).replacen("0.004,", "0.0045,", 1))
            .says(Contains("line 7: uneven sampling")),
        BadInput::new("few", "fit", with_record(""))
            .with_file("r.csv", csv(4))
            .says(Contains("r.csv: 4 samples, at least 10 needed")),
    ];
    assert_bad_inputs(binary(), "cli", &cases);
}

/// Errors in the config name the file, line and column or the table and key, and suggest the
/// nearest known name.
#[test]
fn config_errors_name_the_key_and_suggest_the_nearest() {
    // A string left open on line 7.
    let unterminated = fmm("[model]\ntype = \"coulomb\nmu = 0.2\n");
    let cases = [
        BadInput::new("toml", "fit", unterminated).says(Contains("c.toml:7:")),
        BadInput::new("key", "fit", with_record("velocity_colum = \"v\"\n"))
            .with_file("r.csv", csv(20))
            .says(Contains("c.toml:11:1: unknown key `velocity_colum` in [[records]] (did you mean `velocity_column`?)")),
        BadInput::new("key2", "simulate", fmm("[simulaton]\nx0 = 0.1\n"))
            .says(Contains(
                "unknown key `simulaton` at the top level (did you mean `simulation`?)",
            )),
        BadInput::new("model", "fit", fmm("[model]\ntype = \"stribek\"\n"))
            .says(Contains(
                "[model]: unknown friction model `stribek` (did you mean `stribeck`?)",
            )),
        BadInput::new(
            "param",
            "fit",
            fmm("[model]\ntype = \"stribeck\"\nmu_d = 0.3\n"),
        )
        .says(Contains("unknown parameter `mu_d`")),
        BadInput::new(
            "bounds",
            "fit",
            coulomb("mu = -0.1\n"),
        )
        .says(Contains("parameter `mu` of model `coulomb` is -0.1")),
    ];
    assert_bad_inputs(binary(), "cli", &cases);
}

/// Each command names the tables and keys it needs and does not have. `simulate` needs every
/// oscillator property: a missing normal force is an error naming it, never a silent
/// frictionless run on a placeholder N = 0.
#[test]
fn commands_name_the_tables_and_keys_they_need() {
    let cases = [
        BadInput::new("x0", "fit", fmm("[[records]]\nfile = \"r.csv\"\n"))
            .with_file("r.csv", csv(20))
            .says(EndsWith(
                "c.toml: [[records]] entry 1 (`r.csv`): missing `x0` (the release displacement, m)",
            )),
        BadInput::new(
            "x0-sim",
            "simulate",
            coulomb("[simulation]\nduration = 1.0\n"),
        )
        .says(Contains("[simulation]: missing `x0`")),
        BadInput::new("no-sim", "simulate", coulomb(""))
            .says(Contains("simulate needs a [simulation] table")),
        BadInput::new("no-model", "simulate", fmm(SIMULATION))
            .says(Contains("simulate needs a [model] table")),
        BadInput::new("no-records", "energy", coulomb(""))
            .says(Contains("energy needs at least one [[records]] entry")),
        BadInput::new(
            "no_normal_force",
            "simulate",
            "[oscillator]\nmass = 10.391\ndamping = 0.275\nstiffness = 1982.0\n\
             [model]\ntype = \"coulomb\"\nmu = 0.24\n\
             [simulation]\nx0 = 0.01\nduration = 1.0\nsample_rate = 1000.0\n",
        )
        .says(Contains(
            "simulate needs mass, damping, stiffness and normal_force; `normal_force` not given",
        )),
    ];
    assert_bad_inputs(binary(), "cli", &cases);
}

#[test]
fn fixture_configs_parse() {
    for f in [
        "paper-140mm.toml",
        "paper-110mm.toml",
        "fmm-sim-10mm.toml",
        "fmm-sim-14mm.toml",
        "fmm-sim-22mm.toml",
        "fmm-fit.toml",
        "fmm-compare.toml",
        "fmm-energy.toml",
    ] {
        let c = frictionid_cli::Config::load(&fixtures_dir().join(f)).unwrap();
        assert!(c.spec.oscillator.mass > 0.0, "{f}");
    }
}
