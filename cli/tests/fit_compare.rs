//! `fit` and `compare` end to end on the bundled FMM fixture (truth: Coulomb, mu = 0.24,
//! N = 14.5 N; see fixtures/README.md), and their failure modes.

use assert_cmd::Command;
use frictionid_cli::testing::Says::Contains;
use frictionid_cli::testing::{
    assert_bad_inputs, fixture_config, fixtures_dir, read_report, runs_ok, scratch_dir, BadInput,
    FMM_OSCILLATOR,
};
use std::path::Path;

fn frictionid() -> Command {
    Command::new(env!("CARGO_BIN_EXE_frictionid"))
}

/// Runs `frictionid <args> --out <out> --json` and checks that it succeeds; its output and
/// report.json.
fn run_json(args: &[&str], out: &Path) -> (std::process::Output, serde_json::Value) {
    let o = frictionid()
        .args(args)
        .arg("--out")
        .arg(out)
        .arg("--json")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    (o, read_report(out))
}

/// `compare` of `models` on the FMM fixture into a scratch directory named `tag`: it must
/// succeed; the directory and the JSON report.
fn compare_fixture(tag: &str, models: &str) -> (std::path::PathBuf, serde_json::Value) {
    let out = scratch_dir("fc", tag);
    let cfg = fixtures_dir().join("fmm-compare.toml");
    let (_, r) = run_json(
        &["compare", cfg.to_str().unwrap(), "--models", models],
        &out,
    );
    (out, r)
}

const TRUTH_MU: f64 = 0.24;
const MU_N: f64 = TRUTH_MU * 14.5;

#[test]
fn fit_recovers_the_fixture_truth_and_writes_every_output() {
    let out = scratch_dir("fc", "fit");
    let cfg = fixtures_dir().join("fmm-fit.toml");
    let (o, r) = run_json(&["fit", cfg.to_str().unwrap()], &out);
    let stdout: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(stdout, r, "--json prints report.json");
    assert_eq!(r["command"], "fit");
    assert_eq!(r["model"], "coulomb");
    assert_eq!(r["converged"], true);
    let p = &r["parameters"][0];
    assert_eq!(p["name"], "mu");
    assert_eq!(p["free"], true);
    assert_eq!(p["unit"], "1");
    let mu = p["value"].as_f64().unwrap();
    assert!((mu - TRUTH_MU).abs() / TRUTH_MU < 1e-3, "mu {mu}");
    // The interval is the estimate ± t * SE; this one noise realisation puts the truth 2.4 SE
    // away (a 1.6 % event; over 300 realisations the 95 % interval covers the truth 97 % of
    // the time, see engine/examples/calibration.rs), so check the truth within 3.5 SE.
    let se = p["std_error"].as_f64().unwrap();
    assert!(se > 0.0);
    assert!((mu - TRUTH_MU).abs() < 3.5 * se, "mu {mu} se {se}");
    let ci = p["ci95"].as_array().unwrap();
    let (lo, hi) = (ci[0].as_f64().unwrap(), ci[1].as_f64().unwrap());
    assert!((lo - (mu - 1.96 * se)).abs() < 1e-3 * se && (hi - (mu + 1.96 * se)).abs() < 1e-3 * se);
    // The records: noise 2e-4 m/s, so the residual RMS is the noise level.
    let recs = r["records"].as_array().unwrap();
    assert_eq!(recs.len(), 3);
    for rec in recs {
        let rms = rec["rms_residual"].as_f64().unwrap();
        assert!((rms / 2e-4 - 1.0).abs() < 0.05, "rms {rms}");
        let ef = &rec["energy_force"];
        let reference = ef["reference"].as_f64().unwrap();
        assert!((reference - mu * 14.5).abs() < 1e-9, "reference = mu N");
        let mean = ef["mean_abs"].as_f64().unwrap();
        assert!((mean - MU_N).abs() / MU_N < 0.03, "mean |F| {mean}");
        let pd = ef["percent_difference"].as_f64().unwrap();
        assert!((pd - 100.0 * (mean - reference) / reference).abs() < 1e-9);
    }
    for key in [
        "rms_residual",
        "aic",
        "bic",
        "iterations",
        "simulations",
        "wall_time_s",
        "termination",
    ] {
        assert!(!r[key].is_null(), "{key}");
    }
    for f in r["files"].as_array().unwrap() {
        let f = f.as_str().unwrap();
        assert!(out.join(f).is_file(), "{f} missing");
        if f.ends_with(".svg") {
            let text = std::fs::read_to_string(out.join(f)).unwrap();
            assert!(text.starts_with("<svg") && text.contains("</svg>"), "{f}");
        }
    }
    assert!(out.join("x14mm_velocity_fit.svg").is_file());
    assert!(out.join("x14mm_friction_force.svg").is_file());
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("| mu "), "{md}");
}

/// mu is proportional to 1/N (the records fix mu N), so a normal force known to 1 % gives
/// mu's standard error a `normal_force` component of 1 % of mu; the total adds it in
/// quadrature to the data's part and gives the interval; report.md names the dominant source.
#[test]
fn a_normal_force_uncertainty_in_the_config_reaches_every_fitted_parameter() {
    let out = scratch_dir("fc", "budget");
    let config = fixture_config("fmm-fit.toml").replace(
        "normal_force = 14.5",
        "normal_force = 14.5\nnormal_force_std = 0.145",
    );
    let cfg = out.join("budget.toml");
    std::fs::write(&cfg, config).unwrap();
    let (_, r) = run_json(&["fit", cfg.to_str().unwrap()], &out.join("out"));
    let p = &r["parameters"][0];
    assert_eq!(p["name"], "mu");
    let c = &p["std_error_components"];
    let part = |k: &str| c[k].as_f64().unwrap_or_else(|| panic!("{k}: {c}"));
    let (data, normal_force) = (part("data"), part("normal_force"));
    let ratio = normal_force / (0.01 * TRUTH_MU);
    eprintln!("normal_force component / (0.01 mu) = {ratio}");
    assert!((ratio - 1.0).abs() < 0.05, "{c}");
    for k in ["mass", "damping", "stiffness"] {
        assert_eq!(part(k), 0.0, "{k}");
    }
    let total = p["std_error"].as_f64().unwrap();
    assert!((total - data.hypot(normal_force)).abs() < 1e-9 * total);
    let mu = p["value"].as_f64().unwrap();
    let ci = p["ci95"].as_array().unwrap();
    let half = (ci[1].as_f64().unwrap() - ci[0].as_f64().unwrap()) / 2.0;
    assert!(
        (half / total - 1.96).abs() < 1e-2,
        "{ci:?} for {mu} +- {total}"
    );
    let md = std::fs::read_to_string(out.join("out/report.md")).unwrap();
    assert!(md.contains("dominant source"), "{md}");
    assert!(md.contains("Uncertainty budget"), "{md}");
    let row = md.lines().find(|l| l.starts_with("| mu ")).unwrap();
    assert!(row.trim_end().ends_with("| normal_force |"), "{row}");
}

/// Without a normal force anywhere the Coulomb level is the friction force itself: the
/// fixture's mu N = 3.48 N within 0.5 %, in N in report.json, report.md and on the terminal,
/// with no diagnostic failed (exit 0).
#[test]
fn a_fit_without_a_normal_force_gives_the_level_in_newtons() {
    let out = scratch_dir("fc", "no-normal");
    let config = fixture_config("fmm-fit.toml")
        .replace("normal_force = 14.5    # N\n", "")
        .replace("bounds = { mu = [0.0, 1.0] }\n", "");
    assert!(!config.contains("normal_force") && !config.contains("bounds"));
    let cfg = out.join("no-normal.toml");
    std::fs::write(&cfg, config).unwrap();
    let o = frictionid()
        .args(["fit", cfg.to_str().unwrap(), "--out"])
        .arg(out.join("out"))
        .output()
        .unwrap();
    let (r, _) = runs_ok(Ok(o.clone()), &out.join("out"));
    let p = &r["parameters"][0];
    assert_eq!(
        (p["name"].as_str(), p["unit"].as_str()),
        (Some("mu"), Some("N"))
    );
    let mu = p["value"].as_f64().unwrap();
    assert!((mu / MU_N - 1.0).abs() < 5e-3, "mu {mu} N");
    let md = std::fs::read_to_string(out.join("out/report.md")).unwrap();
    let row = md.lines().find(|l| l.starts_with("| mu ")).unwrap();
    assert!(row.contains("| N |"), "{row}");
    let stdout = String::from_utf8_lossy(&o.stdout);
    let line = stdout.lines().find(|l| l.starts_with("mu ")).unwrap();
    assert!(line.split_whitespace().any(|w| w == "N"), "{line}");
}

#[test]
fn compare_ranks_the_classical_models() {
    let (out, r) = compare_fixture("compare", "coulomb,viscous_coulomb,none");
    assert_eq!(r["command"], "compare");
    let ranking = r["ranking"].as_array().unwrap();
    let names: Vec<&str> = ranking
        .iter()
        .map(|f| f["model"].as_str().unwrap())
        .collect();
    assert_eq!(ranking.len(), 3, "{names:?}");
    // No friction at all cannot explain a friction-damped record: it ranks last.
    assert_eq!(names[2], "none", "{names:?}");
    let aics: Vec<f64> = ranking.iter().map(|f| f["aic"].as_f64().unwrap()).collect();
    assert!(aics.windows(2).all(|w| w[0] <= w[1]), "{aics:?}");
    let coulomb = ranking.iter().find(|f| f["model"] == "coulomb").unwrap();
    let mu = coulomb["parameters"][0]["value"].as_f64().unwrap();
    assert!((mu - TRUTH_MU).abs() / TRUTH_MU < 1e-3);
    // Akaike weights exp(-delta/2), normalised: they sum to 1.
    let best = aics[0];
    let mut sum = 0.0;
    for (f, aic) in ranking.iter().zip(&aics) {
        let delta = f["delta_aic"].as_f64().unwrap();
        assert!((delta - (aic - best)).abs() < 1e-9, "{f}");
        sum += f["akaike_weight"].as_f64().unwrap();
    }
    assert!((sum - 1.0).abs() < 1e-9, "weights sum to {sum}");
    // The truth is Coulomb: the verdict names it, or says that the top models cannot be told
    // apart on this data (the nested viscous_coulomb law fits the same records as well).
    let verdict = &r["verdict"];
    let simplest = verdict["simplest"].as_str().unwrap();
    let tied = verdict["indistinguishable"].as_array().unwrap();
    assert!(
        simplest == "coulomb" || (tied.len() > 1 && tied.iter().any(|m| m == "coulomb")),
        "{verdict}"
    );
    assert!(out.join("steady_state_curves.svg").is_file());
    assert!(out.join("best_x10mm_velocity_fit.svg").is_file());
}

/// LuGre and Dahl on the bundled Coulomb fixture (truth: Coulomb, mu = 0.24): both converge, their
/// Coulomb level within 0.5 % of the Coulomb fit's mu, and sigma0 a lower bound (the records
/// do not resolve presliding) with the bound stated and no standard error; no parameter shows
/// a zero standard error.
#[test]
fn lugre_and_dahl_bound_presliding_from_below_on_the_coulomb_fixture() {
    let (_, r) = compare_fixture("presliding", "coulomb,dahl,lugre");
    let ranking = r["ranking"].as_array().unwrap();
    let model = |name: &str| ranking.iter().find(|f| f["model"] == name).unwrap();
    let param = |f: &serde_json::Value, name: &str| {
        f["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == name)
            .unwrap()
            .clone()
    };
    let mu = param(model("coulomb"), "mu")["value"].as_f64().unwrap();
    for name in ["dahl", "lugre"] {
        let f = model(name);
        assert_eq!(f["converged"], true, "{name}: {}", f["termination"]);
        let mu_c = param(f, "mu_c")["value"].as_f64().unwrap();
        assert!(
            (mu_c - mu).abs() / mu < 0.005,
            "{name}: mu_c {mu_c} vs {mu}"
        );
        let sigma0 = param(f, "sigma0");
        assert_eq!(sigma0["identifiability"], "lower_bound", "{name}: {sigma0}");
        let bound = sigma0["bound"].as_f64().unwrap();
        assert!(
            bound > 0.0 && bound <= sigma0["value"].as_f64().unwrap(),
            "{sigma0}"
        );
        assert!(sigma0["std_error"].is_null() && sigma0["ci95"].is_null());
        for p in f["parameters"].as_array().unwrap() {
            assert!(
                p["std_error"].is_null() || p["std_error"].as_f64().unwrap() > 0.0,
                "{name}: {p}"
            );
        }
    }
    // Dahl's shape exponent acts only through presliding, which the records do not resolve.
    assert_eq!(
        param(model("dahl"), "alpha")["identifiability"],
        "not_identifiable"
    );
}

#[test]
fn compare_rejects_an_unknown_model_with_a_suggestion() {
    let out = scratch_dir("fc", "compare-bad");
    let cfg = fixtures_dir().join("fmm-compare.toml");
    let o = frictionid()
        .args([
            "compare",
            cfg.to_str().unwrap(),
            "--models",
            "coulomb,stribek",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("`stribek`") && e.contains("did you mean `stribeck`"),
        "{e}"
    );
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(!out.join("report.json").exists());
}

#[test]
fn a_fit_that_does_not_converge_exits_2_with_its_report() {
    let dir = scratch_dir("fc", "noconv");
    let text = fixture_config("fmm-fit.toml").replace("[fit]\n", "[fit]\nmax_iterations = 1\n");
    let cfg = dir.join("fit.toml");
    std::fs::write(&cfg, text).unwrap();
    let out = dir.join("out");
    let o = frictionid()
        .args(["fit", cfg.to_str().unwrap(), "--quiet", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("did not converge"), "{e}");
    let r: serde_json::Value = read_report(&out);
    assert_eq!(r["converged"], false);
    assert!(r["termination"]
        .as_str()
        .unwrap()
        .contains("iteration limit"));
}

#[test]
fn unknown_fit_option_is_named() {
    let config = fixture_config("fmm-fit.toml") + "\n[fit.options]\nvelocity_ofset = true\n";
    let case = BadInput::new("fitopt", "fit", config)
        .says(Contains("`velocity_ofset`"))
        .says(Contains("did you mean `velocity_offset`"));
    assert_bad_inputs(Path::new(env!("CARGO_BIN_EXE_frictionid")), "fc", &[case]);
}

#[test]
fn energy_without_a_model_takes_its_reference_from_a_coulomb_fit() {
    let dir = scratch_dir("fc", "energy-fit");
    let text = fixture_config("fmm-compare.toml");
    let cfg = dir.join("energy.toml");
    std::fs::write(&cfg, text).unwrap();
    let out = dir.join("out");
    let (_, r) = run_json(&["energy", cfg.to_str().unwrap()], &out);
    for rec in r["records"].as_array().unwrap() {
        let reference = rec["reference"].as_f64().unwrap();
        // The fitted mu N: the truth 3.48 N within 0.1 %.
        assert!(
            (reference / MU_N - 1.0).abs() < 1e-3,
            "reference {reference}"
        );
        let half = rec["half_cycle_mean"].as_f64().unwrap();
        assert!((half / MU_N - 1.0).abs() < 0.01, "half-cycle mean {half}");
        assert_eq!(rec["sources"]["displacement"], "integrated");
        assert_eq!(rec["sources"]["acceleration"], "differentiated");
    }
}

/// A record with interferometer and accelerometer columns beside the velocity (the exact
/// Coulomb motion): `energy` uses the measured x and a, says so, and its Eq. 7 mean is mu N
/// to round-off.
#[test]
fn energy_uses_measured_displacement_and_acceleration_columns() {
    let dir = scratch_dir("fc", "energy-3ch");
    let ex = exact_release();
    let mut csv = String::from("time,velocity,displacement,acceleration\n");
    for i in 0..ex.time.len() {
        csv += &format!(
            "{:e},{:e},{:e},{:e}\n",
            ex.time[i], ex.v[i], ex.x[i], ex.a[i]
        );
    }
    std::fs::write(dir.join("r.csv"), csv).unwrap();
    let cfg = format!(
        "{FMM_OSCILLATOR}[model]\ntype = \"coulomb\"\nmu = {TRUTH_MU}\n[[records]]\nfile = \"r.csv\"\nx0 = 0.014\n"
    );
    std::fs::write(dir.join("energy.toml"), cfg).unwrap();
    let out = dir.join("out");
    let (_, r) = run_json(&["energy", dir.join("energy.toml").to_str().unwrap()], &out);
    let rec = &r["records"][0];
    assert_eq!(rec["sources"]["displacement"], "measured");
    assert_eq!(rec["sources"]["acceleration"], "measured");
    let mean = rec["mean_abs_force"].as_f64().unwrap();
    assert!((mean / MU_N - 1.0).abs() < 1e-6, "mean |F| {mean}");
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("measured / measured"), "{md}");
}

/// The exact Coulomb motion of the FMM oscillator released at 14 mm: 2 s at 1 kHz.
fn exact_release() -> frictionid_engine::exact::ExactCoulomb {
    let osc = frictionid_engine::Oscillator::fmm();
    let times = frictionid_engine::synthetic::uniform_times(2.0, 1000.0);
    frictionid_engine::exact::coulomb_free_vibration(&osc, MU_N, 0.014, &times).unwrap()
}

#[test]
fn expression_sign_law_fits_the_same_mu_as_coulomb() {
    let dir = scratch_dir("fc", "expr");
    let base = fixture_config("fmm-fit.toml");
    let expr = base.replace(
        "type = \"coulomb\"\nmu = 0.2               # initial value",
        "type = \"expression\"\nforce = \"mu * N * sign(v)\"\nparams = { mu = 0.2 }",
    );
    assert_ne!(expr, base, "the fixture's [model] table changed");
    let mut mus = Vec::new();
    for (name, text) in [("coulomb", &base), ("expression", &expr)] {
        let cfg = dir.join(format!("{name}.toml"));
        std::fs::write(&cfg, text).unwrap();
        let (_, r) = run_json(&["fit", cfg.to_str().unwrap()], &dir.join(name));
        assert_eq!(r["model"], name);
        mus.push(r["parameters"][0]["value"].as_f64().unwrap());
    }
    assert!((mus[0] - mus[1]).abs() < 1e-6, "{mus:?}");
}

/// An interferometer record (time and displacement only) is a valid fit input: the fit
/// compares displacement, in metres, and finds the exact motion's mu.
#[test]
fn a_displacement_only_record_is_fitted_in_displacement() {
    let dir = scratch_dir("fc", "fit-x");
    let ex = exact_release();
    let mut csv = String::from("time,displacement\n");
    for (t, x) in ex.time.iter().zip(&ex.x) {
        csv += &format!("{t:e},{x:e}\n");
    }
    std::fs::write(dir.join("x.csv"), csv).unwrap();
    let cfg = format!(
        "{FMM_OSCILLATOR}[model]\ntype = \"coulomb\"\n[[records]]\nfile = \"x.csv\"\nx0 = 0.014\n"
    );
    std::fs::write(dir.join("fit.toml"), cfg).unwrap();
    let out = dir.join("out");
    let (_, r) = run_json(&["fit", dir.join("fit.toml").to_str().unwrap()], &out);
    let mu = r["parameters"][0]["value"].as_f64().unwrap();
    assert!((mu / TRUTH_MU - 1.0).abs() < 1e-6, "mu {mu}");
    assert_eq!(r["residual_unit"], "m", "{}", r["residual_unit"]);
    assert!(out.join("x_displacement_fit.svg").exists());
}
