//! `frictionid export`: every built-in law, fitted in the force domain to a window of the real
//! tribometer record (../shared/data/tribometer, FrictionModels.jl, MIT) and a dynamic law in
//! the velocity domain to an FMM record, exported as C, Rust and Python; each export, compiled
//! and run on the record's motion, must give the engine's own replay of the same law
//! (`energy::model_force_with_normal`, an independent implementation) to within 1e-9 of the
//! force level. A missing C compiler, rustc or python3 skips its test with a message.

use frictionid_cli::testing::{fixtures_dir, read_report, scratch_dir};
use frictionid_cli::Config;
use frictionid_engine::energy::{model_force_with_normal, record_motion};
use frictionid_engine::record::NormalForce;
use frictionid_models::FrictionModel;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

fn frictionid() -> Command {
    Command::new(env!("CARGO_BIN_EXE_frictionid"))
}

/// A fitted law and the motion it is replayed along.
struct Case {
    name: String,
    dir: PathBuf,
    /// The record's time, velocity and normal force at every sample.
    t: Vec<f64>,
    v: Vec<f64>,
    n: Vec<f64>,
    /// The engine's replay of the fitted law along that motion.
    engine: Vec<f64>,
}

/// The real tribometer record beside the repository, if present.
fn real_tribometer() -> Option<PathBuf> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/tribometer/test_data_2.txt");
    path.exists().then_some(path)
}

/// Samples 1400 to 3399 of the real record (evenly sampled at 200 Hz, 10 s), header kept.
fn tribometer_window(real: &Path, dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(real).unwrap();
    let mut lines = text.lines();
    let mut window = vec![lines.next().unwrap()];
    window.extend(lines.skip(1400).take(2000));
    let path = dir.join("tribometer-window.txt");
    std::fs::write(&path, window.join("\n") + "\n").unwrap();
    path
}

/// The `[model]` tables fitted in the force domain: every built-in law with parameters.
const FORCE_LAWS: [(&str, &str); 8] = [
    ("coulomb", "type = \"coulomb\""),
    ("viscous_coulomb", "type = \"viscous_coulomb\""),
    ("stribeck", "type = \"stribeck\""),
    ("makkar", "type = \"makkar\""),
    (
        "expression",
        "type = \"expression\"\nforce = \"mu * N * tanh(v / eps) + b * v - c * sign(v) * exp(-(v / vs)^2)\"\nparams = { mu = 0.4, eps = 1.0e-4, b = 1.0, c = 0.1, vs = 1.0e-3 }",
    ),
    ("dahl", "type = \"dahl\""),
    ("lugre", "type = \"lugre\""),
    (
        "gms",
        "type = \"gms\"\nelements = 2\nsharpness = 2.0\n\n[fit]\nfree = [\"k_1\", \"k_2\", \"w_1\", \"w_2\", \"mu_c\", \"mu_s\", \"v_s\", \"viscous\"]",
    ),
];

/// The force-domain fit of `model` along `record`, replayed along its velocity: the
/// convention the exports' `update` follows sample by sample.
fn force_config(record: &Path, model: &str) -> String {
    format!(
        "[oscillator]\n\n[model]\n{model}\n\n[fit.options]\ndomain = \"force\"\nforce_offset = true\nreplay_path = \"velocity\"\n\n\
         [[records]]\nfile = \"{}\"\ntime_column = \"Time [s]\"\ndisplacement_column = \"Position [mm]\"\n\
         displacement_scale = 1e-3\nforce_column = \"Friction [uN]\"\nforce_scale = -1e-6\n\
         normal_force_column = \"Normal [uN]\"\nnormal_force_scale = 1e-6\n",
        record.display()
    )
}

/// Fits `config` (written in `dir`) and returns its report (a fit that did not converge or
/// failed a diagnostic still writes one).
fn fit(dir: &Path, config: &str) -> Value {
    std::fs::create_dir_all(dir).unwrap();
    let cfg = dir.join("c.toml");
    std::fs::write(&cfg, config).unwrap();
    let o = frictionid()
        .arg("fit")
        .arg(&cfg)
        .arg("--out")
        .arg(dir.join("fit"))
        .arg("-q")
        .output()
        .unwrap();
    let report = read_report(&dir.join("fit"));
    assert!(
        report.is_object(),
        "{}: {}",
        dir.display(),
        String::from_utf8_lossy(&o.stderr)
    );
    report
}

/// The engine's replay of the report's law along the first record of `config`.
fn engine_case(name: &str, dir: &Path, report: &Value) -> Case {
    let cfg = Config::load(&dir.join("c.toml")).unwrap();
    let records = cfg.load_records("fit").unwrap();
    let rec = &records[0];
    let v = record_motion(rec).unwrap().v;
    let osc = frictionid_engine::Oscillator {
        normal_force: report["oscillator"]["normal_force"].as_f64().unwrap_or(1.0),
        ..frictionid_engine::Oscillator::fmm()
    };
    let normal = rec.normal_force_with(&osc);
    let model: Box<dyn FrictionModel> =
        serde_json::from_value(report["model_parameters"].clone()).unwrap();
    let t = rec.time().to_vec();
    let engine = model_force_with_normal(&*model, &t, &v, &normal).unwrap();
    let n = (0..t.len()).map(|i| normal.at(i)).collect();
    Case {
        name: name.into(),
        dir: dir.to_path_buf(),
        t,
        v,
        n,
        engine,
    }
}

/// In the force domain the report's fitted series is the same replay plus the force offset:
/// the report and the replay the exports are held to agree.
fn check_report_series(case: &Case, report: &Value) {
    let series = &report["records"][0]["series"];
    let fitted = series["fitted"].as_array().unwrap();
    let offset = report["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"].as_str().unwrap().starts_with("force_offset"))
        .map_or(0.0, |p| p["value"].as_f64().unwrap());
    assert_eq!(fitted.len(), case.engine.len(), "{}", case.name);
    let level = level(&case.engine);
    for (f, e) in fitted.iter().zip(&case.engine) {
        let f = f.as_f64().unwrap() - offset;
        assert!((f - e).abs() <= 1e-9 * level, "{}: {f} vs {e}", case.name);
    }
    assert_eq!(series["time"].as_array().unwrap().len(), case.t.len());
    assert!(report["records"][0]["max_speed"].as_f64().unwrap() > 0.0);
}

/// The largest |force| of a replay (1 for a law without force).
fn level(forces: &[f64]) -> f64 {
    let top = forces.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    if top > 0.0 {
        top
    } else {
        1.0
    }
}

/// The no-friction law, from a hand-written report: it has nothing to fit.
fn none_case(like: &Case) -> Case {
    let dir = like.dir.parent().unwrap().join("none");
    std::fs::create_dir_all(dir.join("fit")).unwrap();
    let report = serde_json::json!({
        "command": "fit",
        "model": "none",
        "model_parameters": { "type": "none" },
        "parameters": [],
        "records": [{ "file": "tribometer-window.txt" }],
        "compared": "force",
    });
    std::fs::write(dir.join("fit/report.json"), report.to_string()).unwrap();
    Case {
        name: "none".into(),
        dir,
        t: like.t.clone(),
        v: like.v.clone(),
        n: like.n.clone(),
        engine: vec![0.0; like.t.len()],
    }
}

/// Every case: the force-domain laws on the real record (when present) and Dahl fitted to
/// an FMM record in the velocity domain. Fitted once per test binary.
fn cases() -> &'static Vec<Case> {
    static CASES: OnceLock<Vec<Case>> = OnceLock::new();
    CASES.get_or_init(|| {
        let root = scratch_dir("export", "cases");
        let mut cases = Vec::new();
        match real_tribometer() {
            Some(real) => {
                let record = tribometer_window(&real, &root);
                for (name, model) in FORCE_LAWS {
                    let dir = root.join(name);
                    let report = fit(&dir, &force_config(&record, model));
                    let case = engine_case(name, &dir, &report);
                    check_report_series(&case, &report);
                    cases.push(case);
                }
                let none = none_case(&cases[0]);
                cases.push(none);
            }
            None => eprintln!(
                "skipped the force-domain laws: the real tribometer record \
                 (../shared/data/tribometer/test_data_2.txt) is absent"
            ),
        }
        let dir = root.join("dahl-velocity");
        let config = format!(
            "{}\n[model]\ntype = \"dahl\"\nsigma0 = 5.0e4\nmu_c = 0.2\n\n[fit]\nfree = [\"sigma0\", \"mu_c\"]\n\n\
             [[records]]\nfile = \"{}\"\nx0 = 0.014\n",
            frictionid_cli::testing::FMM_OSCILLATOR,
            fixtures_dir().join("x14mm.csv").display()
        );
        let report = fit(&dir, &config);
        assert_eq!(report["compared"], "velocity");
        cases.push(engine_case("dahl (velocity domain)", &dir, &report));
        cases
    })
}

/// The record's motion as `t,v,n` lines (shortest round-trip decimals).
fn write_motion(case: &Case) -> PathBuf {
    let path = case.dir.join("motion.csv");
    let text: String = (0..case.t.len())
        .map(|i| format!("{:?},{:?},{:?}\n", case.t[i], case.v[i], case.n[i]))
        .collect();
    std::fs::write(&path, text).unwrap();
    path
}

/// Exports the case's law in `lang` into `file`.
fn export(case: &Case, lang: &str, file: &Path, extra: &[&str]) {
    let o = frictionid()
        .arg("export")
        .arg(case.dir.join("fit"))
        .args(["--lang", lang, "--out"])
        .arg(file)
        .args(extra)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{} {lang}: {}",
        case.name,
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Runs `command`, panicking with its stderr when it fails; its stdout.
fn run(command: &mut Command) -> String {
    let o = command.output().unwrap();
    assert!(
        o.status.success(),
        "{command:?}: {}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).unwrap()
}

/// The largest |a - b| over the pairs of `a` and `b`.
fn worst_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f64, f64::max)
}

/// The exported replay's forces (one per line) against the engine's.
fn assert_matches_engine(case: &Case, lang: &str, output: &str) {
    let forces: Vec<f64> = output.lines().map(|l| l.trim().parse().unwrap()).collect();
    assert_eq!(forces.len(), case.engine.len(), "{} {lang}", case.name);
    let level = level(&case.engine);
    let worst = worst_difference(&forces, &case.engine);
    assert!(
        worst <= 1e-9 * level,
        "{} in {lang}: off by {worst:e} N at a force level of {level} N",
        case.name
    );
}

/// The tool named by the environment variable `var` (else `default`), where it runs; prints
/// that `test` is skipped where it does not.
fn tool(var: &str, default: &str, test: &str) -> Option<String> {
    let tool = std::env::var(var).unwrap_or_else(|_| default.into());
    available(&tool, test).then_some(tool)
}

/// Exports each case's law in `lang` into `<case>/<lang>/law.<ext>`, replays its record with
/// the program `replay` builds in that folder (its output: one force a line) and checks the
/// forces against the engine's.
fn replay_each_case(lang: &str, ext: &str, label: &str, replay: impl Fn(&Case, &Path) -> String) {
    for case in cases() {
        let dir = case.dir.join(lang);
        std::fs::create_dir_all(&dir).unwrap();
        export(case, lang, &dir.join(format!("law.{ext}")), &[]);
        let out = replay(case, &dir);
        assert_matches_engine(case, label, &out);
    }
}

/// Whether `tool` runs; prints that the test is skipped when not.
fn available(tool: &str, test: &str) -> bool {
    let ok = Command::new(tool)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        eprintln!("skipped {test}: `{tool}` not found");
    }
    ok
}

const C_MAIN: &str = r#"#include <stdio.h>
#include "law.c"

int main(void) {
    double t, v, n, tp = 0.0, vp = 0.0, np = 0.0;
    int i = 0;
    fid_state s;
    fid_init(&s);
    while (scanf("%lf,%lf,%lf", &t, &v, &n) == 3) {
        if (i > 0) {
            fid_update(&s, 0.5 * (vp + v), 0.5 * (np + n), t - tp);
        }
        printf("%.17g\n", fid_force(&s, v, n));
        tp = t;
        vp = v;
        np = n;
        ++i;
    }
    return 0;
}
"#;

#[test]
fn c_exports_replay_records_as_the_engine_does() {
    let Some(cc) = tool("CC", "cc", "the C exports") else {
        return;
    };
    replay_each_case("c", "c", "C", |case, dir| {
        std::fs::write(dir.join("main.c"), C_MAIN).unwrap();
        run(Command::new(&cc)
            .args(["-std=c99", "-Wall", "-Werror", "-O2", "-o"])
            .arg(dir.join("replay"))
            .arg(dir.join("main.c"))
            .arg("-lm"));
        let motion = std::fs::File::open(write_motion(case)).unwrap();
        run(Command::new(dir.join("replay")).stdin(motion))
    });
}

/// Two laws in one C program, kept apart by their prefixes.
#[test]
fn c_prefixes_keep_several_laws_apart() {
    let Some(cc) = tool("CC", "cc", "the C prefixes") else {
        return;
    };
    let cases = cases();
    let (Some(a), Some(b)) = (cases.first(), cases.last()) else {
        return;
    };
    let dir = b.dir.join("prefixes");
    std::fs::create_dir_all(&dir).unwrap();
    export(a, "c", &dir.join("a.c"), &["--prefix", "a_"]);
    export(b, "c", &dir.join("b.c"), &["--prefix", "b_"]);
    let main = "#include <stdio.h>\n#include \"a.c\"\n#include \"b.c\"\nint main(void) {\n    a_state x;\n    b_state y;\n    a_init(&x);\n    b_init(&y);\n    a_update(&x, 0.01, 1.0, 0.01);\n    b_update(&y, 0.01, 14.5, 0.01);\n    printf(\"%.17g %.17g\\n\", a_force(&x, 0.01, 1.0), b_force(&y, 0.01, 14.5));\n    return 0;\n}\n";
    std::fs::write(dir.join("main.c"), main).unwrap();
    run(Command::new(&cc)
        .args(["-std=c99", "-Wall", "-Werror", "-o"])
        .arg(dir.join("two"))
        .arg(dir.join("main.c"))
        .arg("-lm"));
    let out = run(&mut Command::new(dir.join("two")));
    assert_eq!(out.split_whitespace().count(), 2, "{out}");
}

/// libm's functions from std, for compiling the no_std export without the crate.
const LIBM_SHIM: &str = "pub fn fabs(x: f64) -> f64 { x.abs() }\npub fn exp(x: f64) -> f64 { x.exp() }\n\
pub fn expm1(x: f64) -> f64 { x.exp_m1() }\npub fn log(x: f64) -> f64 { x.ln() }\n\
pub fn log1p(x: f64) -> f64 { x.ln_1p() }\npub fn log10(x: f64) -> f64 { x.log10() }\n\
pub fn sqrt(x: f64) -> f64 { x.sqrt() }\npub fn sin(x: f64) -> f64 { x.sin() }\n\
pub fn cos(x: f64) -> f64 { x.cos() }\npub fn tan(x: f64) -> f64 { x.tan() }\n\
pub fn asin(x: f64) -> f64 { x.asin() }\npub fn acos(x: f64) -> f64 { x.acos() }\n\
pub fn atan(x: f64) -> f64 { x.atan() }\npub fn sinh(x: f64) -> f64 { x.sinh() }\n\
pub fn cosh(x: f64) -> f64 { x.cosh() }\npub fn tanh(x: f64) -> f64 { x.tanh() }\n\
pub fn pow(x: f64, y: f64) -> f64 { x.powf(y) }\npub fn fmin(x: f64, y: f64) -> f64 { x.min(y) }\n\
pub fn fmax(x: f64, y: f64) -> f64 { x.max(y) }\npub fn ceil(x: f64) -> f64 { x.ceil() }\npub fn atan2(y: f64, x: f64) -> f64 { y.atan2(x) }\n";

const RUST_MAIN: &str = r#"use std::io::Read;
fn main() {
    let mut text = String::new();
    std::io::stdin().read_to_string(&mut text).unwrap();
    let mut law = law::law::Law::new();
    let mut previous: Option<(f64, f64, f64)> = None;
    for line in text.lines() {
        let f: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let (t, v, n) = (f[0], f[1], f[2]);
        if let Some((tp, vp, np)) = previous {
            law.update(0.5 * (vp + v), 0.5 * (np + n), t - tp);
        }
        println!("{:?}", law.force(v, n));
        previous = Some((t, v, n));
    }
}
"#;

#[test]
fn rust_exports_build_without_std_and_replay_records_as_the_engine_does() {
    let Some(rustc) = tool("RUSTC", "rustc", "the Rust exports") else {
        return;
    };
    replay_each_case("rust", "rs", "Rust", |case, dir| {
        std::fs::write(dir.join("lib.rs"), "#![no_std]\npub mod law;\n").unwrap();
        std::fs::write(dir.join("libm.rs"), LIBM_SHIM).unwrap();
        std::fs::write(dir.join("main.rs"), RUST_MAIN).unwrap();
        let rustc = || {
            let mut c = Command::new(&rustc);
            c.args(["--edition", "2021", "-O", "--out-dir"]).arg(dir);
            c
        };
        run(rustc()
            .args(["--crate-type", "rlib", "--crate-name", "libm"])
            .arg(dir.join("libm.rs")));
        run(rustc()
            .args([
                "--crate-type",
                "rlib",
                "--crate-name",
                "law",
                "-D",
                "warnings",
            ])
            .arg("--extern")
            .arg(format!("libm={}", dir.join("liblibm.rlib").display()))
            .arg(dir.join("lib.rs")));
        run(rustc()
            .arg("--extern")
            .arg(format!("law={}", dir.join("liblaw.rlib").display()))
            .arg("-L")
            .arg(dir)
            .arg(dir.join("main.rs")));
        let motion = std::fs::File::open(write_motion(case)).unwrap();
        run(Command::new(dir.join("main")).stdin(motion))
    });
}

const PYTHON_MAIN: &str = r#"import sys
sys.path.insert(0, sys.argv[1])
import law
t, v, n = [], [], []
for line in open(sys.argv[2]):
    a, b, c = line.split(",")
    t.append(float(a)); v.append(float(b)); n.append(float(c))
for f in law.replay(t, v, n):
    print(repr(f))
"#;

#[test]
fn python_exports_replay_records_as_the_engine_does() {
    if !available("python3", "the Python exports") {
        return;
    }
    replay_each_case("python", "py", "Python", |case, dir| {
        std::fs::write(dir.join("main.py"), PYTHON_MAIN).unwrap();
        let motion = write_motion(case);
        run(Command::new("python3")
            .arg(dir.join("main.py"))
            .arg(dir)
            .arg(&motion))
    });
}

/// The compensation table is the law's steady-state curve on a grid symmetric about zero,
/// dense near it, spanning the record's speeds; Coulomb's is mu n sgn(v) exactly.
#[test]
fn the_table_is_the_steady_state_curve_over_the_records_speeds() {
    let Some(case) = cases().iter().find(|c| c.name == "coulomb") else {
        eprintln!("skipped the table: no Coulomb fit (the real tribometer record is absent)");
        return;
    };
    let file = case.dir.join("table.csv");
    export(case, "table", &file, &["--normal-force", "2.0"]);
    let text = std::fs::read_to_string(&file).unwrap();
    let mut rows = text.lines().filter(|l| !l.starts_with('#'));
    assert_eq!(rows.next(), Some("v [m/s],F [N]"));
    let rows: Vec<(f64, f64)> = rows
        .map(|l| {
            let (v, f) = l.split_once(',').unwrap();
            (v.parse().unwrap(), f.parse().unwrap())
        })
        .collect();
    let report = read_report(&case.dir.join("fit"));
    let mu = report["model_parameters"]["mu"].as_f64().unwrap();
    let top = report["records"][0]["max_speed"].as_f64().unwrap();
    assert!(rows.windows(2).all(|w| w[0].0 < w[1].0));
    assert_eq!(rows.first().unwrap().0, -top);
    assert_eq!(rows.last().unwrap().0, top);
    assert!(rows.iter().any(|r| r.0 == 0.0 && r.1 == 0.0));
    assert!(rows.iter().any(|r| r.0 > 0.0 && r.0 < 1e-3 * top));
    for (v, f) in rows {
        let expected = if v == 0.0 { 0.0 } else { mu * 2.0 * v.signum() };
        assert_eq!(f, expected, "{v}");
    }
}

/// Bad input: one line naming the file or key, exit 1, no output file.
#[test]
fn bad_input_is_one_line_and_writes_nothing() {
    let dir = scratch_dir("export", "bad");
    let out = dir.join("law.c");
    let fails = |args: &[&str], says: &str| {
        let o = frictionid().arg("export").args(args).output().unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(
            stderr.starts_with("error: ") && stderr.contains(says),
            "{stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(!out.exists());
    };
    let o = out.to_str().unwrap();
    let missing = dir.join("nowhere");
    fails(
        &[missing.to_str().unwrap(), "--lang", "c", "--out", o],
        "nowhere",
    );
    let write = |name: &str, json: Value| {
        let d = dir.join(name);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join("report.json"), json.to_string()).unwrap();
        d.to_str().unwrap().to_string()
    };
    let energy = write(
        "energy",
        serde_json::json!({ "command": "energy", "records": [] }),
    );
    fails(&[&energy, "--lang", "c", "--out", o], "`model_parameters`");
    let empty = write(
        "compare",
        serde_json::json!({ "command": "compare", "ranking": [] }),
    );
    fails(&[&empty, "--lang", "rust", "--out", o], "`ranking`");
    let plugin = write(
        "plugin",
        serde_json::json!({ "command": "fit", "model_parameters": { "type": "my_plugin", "k": 1.0 } }),
    );
    fails(
        &[&plugin, "--lang", "python", "--out", o],
        "model `my_plugin` cannot be exported",
    );
    fails(&[&plugin, "--lang", "fortran", "--out", o], "fortran");
    let table = write(
        "table",
        serde_json::json!({ "command": "fit", "model_parameters": { "type": "coulomb", "mu": 0.2 } }),
    );
    fails(&[&table, "--lang", "table", "--out", o], "--normal-force");
}

/// GMS at a sharpness without closed form: the export's RK4 substeps against the engine's
/// error-controlled integration (rtol 1e-8), along the tribometer's motion.
#[test]
fn gms_at_another_sharpness_follows_the_engines_integration() {
    if !available("python3", "GMS at sharpness 3") {
        return;
    }
    let Some(like) = cases().iter().find(|c| c.name == "gms") else {
        eprintln!("skipped GMS at sharpness 3: the real tribometer record is absent");
        return;
    };
    let mut report = read_report(&like.dir.join("fit"));
    report["model_parameters"]["sharpness"] = 3.0.into();
    let dir = like.dir.parent().unwrap().join("gms-sharpness-3");
    std::fs::create_dir_all(dir.join("fit")).unwrap();
    std::fs::write(dir.join("fit/report.json"), report.to_string()).unwrap();
    let model: Box<dyn FrictionModel> =
        serde_json::from_value(report["model_parameters"].clone()).unwrap();
    let normal = NormalForce::Sampled(like.n.clone());
    let engine = model_force_with_normal(&*model, &like.t, &like.v, &normal).unwrap();
    let case = Case {
        name: "gms at sharpness 3".into(),
        dir: dir.clone(),
        t: like.t.clone(),
        v: like.v.clone(),
        n: like.n.clone(),
        engine,
    };
    export(&case, "python", &dir.join("law.py"), &[]);
    std::fs::write(dir.join("main.py"), PYTHON_MAIN).unwrap();
    let out = run(Command::new("python3")
        .arg(dir.join("main.py"))
        .arg(&dir)
        .arg(write_motion(&case)));
    let forces: Vec<f64> = out.lines().map(|l| l.parse().unwrap()).collect();
    let level = level(&case.engine);
    let worst = worst_difference(&forces, &case.engine);
    assert!(
        worst <= 1e-6 * level,
        "off by {worst:e} at a level of {level}"
    );
}
