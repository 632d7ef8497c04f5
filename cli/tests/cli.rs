//! End-to-end tests of the `frictionid` binary: the model listing against the registry, and
//! every input error the CLI must report as one line on stderr with a non-zero exit code,
//! no panic and no report.json.

use assert_cmd::Command;
use frictionid_cli::testing::{fails_with_one_line, fixtures_dir, scratch_dir, FMM_OSCILLATOR};

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

/// Runs `frictionid <cmd> CONFIG --out DIR` on a config written into a scratch directory
/// (with the given data files) and checks the failure contract; returns the stderr line.
fn fails(name: &str, cmd: &str, config: &str, files: &[(&str, &str)]) -> String {
    let binary = std::path::Path::new(env!("CARGO_BIN_EXE_frictionid"));
    fails_with_one_line(binary, ("cli", name), cmd, config, files)
}

fn with_record(extra: &str) -> String {
    format!("{FMM_OSCILLATOR}[model]\ntype = \"coulomb\"\n[[records]]\nfile = \"r.csv\"\nx0 = 0.014\n{extra}")
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

#[test]
fn missing_record_file() {
    let e = fails("missing-file", "fit", &with_record(""), &[]);
    assert!(
        e.ends_with("r.csv: cannot read the file: no such file"),
        "{e}"
    );
}

#[test]
fn bad_csv_line_names_its_line() {
    let mut data = csv(20);
    data = data.replacen("0.005,", "0.005,x", 1);
    let e = fails("bad-line", "fit", &with_record(""), &[("r.csv", &data)]);
    // Line 1 is a comment, line 2 the header, t = 0.005 s is the sixth sample: line 8.
    assert!(e.contains("r.csv: line 8: column `velocity`: `x"), "{e}");
    assert!(e.ends_with("is not a number"), "{e}");
}

#[test]
fn wrong_column_count_names_its_line() {
    let data = csv(20) + "0.02,1,2\n";
    let e = fails("columns", "energy", &with_record(""), &[("r.csv", &data)]);
    assert!(
        e.contains("r.csv: line 23: 3 fields, but the header has 2"),
        "{e}"
    );
}

#[test]
fn nan_is_rejected() {
    let data = csv(20).replacen("0.003,", "0.003,NaN\n0.0035,", 1);
    let data = data.replacen("NaN\n0.0035,", "NaN\n#", 1);
    let e = fails("nan", "fit", &with_record(""), &[("r.csv", &data)]);
    assert!(e.contains("r.csv: line 6: column `velocity` is NaN"), "{e}");
}

#[test]
fn non_increasing_time_is_rejected() {
    let data = csv(20).replacen("0.004,", "0.002,", 1);
    let e = fails("time", "compare", &with_record(""), &[("r.csv", &data)]);
    assert!(
        e.contains("r.csv: line 7: time 0.002 s does not increase (previous 0.003 s)"),
        "{e}"
    );
}

#[test]
fn uneven_sampling_and_too_few_samples() {
    let data = csv(20).replacen("0.004,", "0.0045,", 1);
    let e = fails("uneven", "fit", &with_record(""), &[("r.csv", &data)]);
    assert!(e.contains("line 7: uneven sampling"), "{e}");
    let e = fails("few", "fit", &with_record(""), &[("r.csv", &csv(4))]);
    assert!(e.contains("r.csv: 4 samples, at least 10 needed"), "{e}");
}

#[test]
fn bad_toml_names_line_and_column() {
    let cfg = format!("{FMM_OSCILLATOR}[model]\ntype = \"coulomb\nmu = 0.2\n");
    let e = fails("toml", "fit", &cfg, &[]);
    assert!(e.contains("c.toml:7:"), "{e}");
}

#[test]
fn unknown_key_suggests_the_nearest() {
    let e = fails(
        "key",
        "fit",
        &with_record("velocity_colum = \"v\"\n"),
        &[("r.csv", &csv(20))],
    );
    assert!(
        e.contains("c.toml:11:1: unknown key `velocity_colum` in [[records]] (did you mean `velocity_column`?)"),
        "{e}"
    );
    let e = fails(
        "key2",
        "simulate",
        &format!("{FMM_OSCILLATOR}[simulaton]\nx0 = 0.1\n"),
        &[],
    );
    assert!(
        e.contains("unknown key `simulaton` at the top level (did you mean `simulation`?)"),
        "{e}"
    );
}

#[test]
fn unknown_model_and_parameter_suggest_the_nearest() {
    let e = fails(
        "model",
        "fit",
        &format!("{FMM_OSCILLATOR}[model]\ntype = \"stribek\"\n"),
        &[],
    );
    assert!(
        e.contains("[model]: unknown friction model `stribek` (did you mean `stribeck`?)"),
        "{e}"
    );
    let e = fails(
        "param",
        "fit",
        &format!("{FMM_OSCILLATOR}[model]\ntype = \"stribeck\"\nmu_d = 0.3\n"),
        &[],
    );
    assert!(e.contains("unknown parameter `mu_d`"), "{e}");
}

#[test]
fn missing_x0_is_named() {
    let cfg = format!("{FMM_OSCILLATOR}[[records]]\nfile = \"r.csv\"\n");
    let e = fails("x0", "fit", &cfg, &[("r.csv", &csv(20))]);
    assert!(
        e.ends_with(
            "c.toml: [[records]] entry 1 (`r.csv`): missing `x0` (the release displacement, m)"
        ),
        "{e}"
    );
    let cfg =
        format!("{FMM_OSCILLATOR}[model]\ntype = \"coulomb\"\n[simulation]\nduration = 1.0\n");
    let e = fails("x0-sim", "simulate", &cfg, &[]);
    assert!(e.contains("[simulation]: missing `x0`"), "{e}");
}

#[test]
fn out_of_bounds_parameter_is_an_error() {
    let e = fails(
        "bounds",
        "fit",
        &format!("{FMM_OSCILLATOR}[model]\ntype = \"coulomb\"\nmu = -0.1\n"),
        &[],
    );
    assert!(
        e.contains("parameter `mu` of model `coulomb` is -0.1"),
        "{e}"
    );
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

#[test]
fn simulate_and_energy_name_what_they_need() {
    let cases = [
        (
            "no-sim",
            "simulate",
            "[model]\ntype = \"coulomb\"\n",
            "simulate needs a [simulation] table",
        ),
        (
            "no-model",
            "simulate",
            "[simulation]\nx0 = 0.01\nduration = 1.0\n",
            "simulate needs a [model] table",
        ),
        (
            "no-records",
            "energy",
            "[model]\ntype = \"coulomb\"\n",
            "energy needs at least one [[records]] entry",
        ),
    ];
    for (name, command, tables, says) in cases {
        let e = fails(name, command, &format!("{FMM_OSCILLATOR}{tables}"), &[]);
        assert!(e.contains(says), "{name}: {e}");
    }
}

/// `simulate` needs every oscillator property: a missing normal force is an error naming it,
/// never a silent frictionless run on a placeholder N = 0.
#[test]
fn simulate_without_a_normal_force_names_the_missing_key() {
    let config = "[oscillator]\nmass = 10.391\ndamping = 0.275\nstiffness = 1982.0\n\
                  [model]\ntype = \"coulomb\"\nmu = 0.24\n\
                  [simulation]\nx0 = 0.01\nduration = 1.0\nsample_rate = 1000.0\n";
    let e = fails("no_normal_force", "simulate", config, &[]);
    assert!(
        e.contains(
            "simulate needs mass, damping, stiffness and normal_force; `normal_force` not given"
        ),
        "{e}"
    );
}
