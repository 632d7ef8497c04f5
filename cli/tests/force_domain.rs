//! Force-domain fits from the command line: the real tribometer record (FrictionModels.jl,
//! MIT, where the developers keep it) and the simulated one bundled in fixtures/tribometer
//! compared across static and dynamic models, and the one-line errors of force-domain
//! configurations.

use assert_cmd::Command;
use frictionid_cli::testing::Says::{Contains, EndsWith};
use frictionid_cli::testing::{assert_bad_inputs, fixtures_dir, runs_ok, scratch_dir, BadInput};
use frictionid_engine::testing::real_tribometer_slice;
use std::path::Path;

fn frictionid() -> Command {
    Command::new(env!("CARGO_BIN_EXE_frictionid"))
}

const STATIC: [&str; 3] = ["coulomb", "viscous_coulomb", "stribeck"];
const DYNAMIC: [&str; 3] = ["dahl", "lugre", "gms"];

/// Hysteresis dominates a tribometer's force at every reversal and dwell: each bristle
/// model must explain the measured force better (lower AIC, lower RMS in N) than each
/// static law. The independent check is the record itself: a static law gives zero force
/// at rest, while the measured force holds about 2.3 N through every dwell.
#[test]
fn tribometer_compare_ranks_dynamic_models_ahead_of_static_ones() {
    let out = scratch_dir("force", "tribometer");
    let slice = match real_tribometer_slice(&out) {
        Ok(slice) => slice,
        Err(skipped) => return eprintln!("{skipped}"),
    };
    let cfg = out.join("tribometer.toml");
    let text = std::fs::read_to_string(fixtures_dir().join("tribometer.toml")).unwrap();
    let text = text.replace(
        "tribometer/tribometer-sim.txt",
        &slice.display().to_string(),
    );
    std::fs::write(&cfg, text).unwrap();
    let o = frictionid()
        .args(["compare", cfg.to_str().unwrap(), "--json", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let ranking = r["ranking"].as_array().unwrap();
    assert_eq!(ranking.len(), 6, "{stderr}");
    let place = |m: &str| ranking.iter().position(|f| f["model"] == m).unwrap();
    let rms = |m: &str| ranking[place(m)]["rms_residual"].as_f64().unwrap();
    for d in DYNAMIC {
        assert_eq!(ranking[place(d)]["residual_unit"], "N");
        for s in STATIC {
            assert!(place(d) < place(s), "{d} ranks behind {s}");
            assert!(rms(d) < rms(s), "{d}: {} N, {s}: {} N", rms(d), rms(s));
        }
    }
    // The config gives no x0: the record starts at its first position sample, -110.0353 mm.
    let x0 = ranking[0]["records"][0]["x0"].as_f64().unwrap();
    assert!((x0 + 0.1100353).abs() < 1e-12, "x0 = {x0}");
    // Static laws cannot hold the ~2.3 N of the dwells: their RMS is far above 0.5 N.
    for s in STATIC {
        assert!(rms(s) > 0.5, "{s}: {} N", rms(s));
    }
    for f in [
        "best_real-tribometer_force_displacement.svg",
        "best_real-tribometer_force_velocity.svg",
    ] {
        let svg = std::fs::read_to_string(out.join(f)).unwrap();
        assert!(svg.contains("displacement [mm]") || svg.contains("velocity [mm/s]"));
        assert!(svg.contains("measured"), "{f}");
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// The bundled tribometer record is simulated (fixtures/README.md): Dahl's law, sigma0
/// 6e4 N/m, mu_c 0.45, alpha 1, along the stroke under the measured N(t), with a 0.15 N
/// load-cell offset and 0.02 N of noise on the force. `compare` ranks Dahl first, recovers
/// its truth and the offset, and leaves a residual at the noise level; the static laws,
/// which give no force at the reversals, are far behind.
#[test]
fn the_simulated_tribometer_record_gives_back_its_dahl_truth() {
    let out = scratch_dir("force", "tribometer-sim");
    let cfg = fixtures_dir().join("tribometer.toml");
    let run = frictionid()
        .args(["compare", cfg.to_str().unwrap(), "--json", "--out"])
        .arg(&out)
        .output();
    let (r, stderr) = runs_ok(run, &out);
    let ranking = r["ranking"].as_array().unwrap();
    assert_eq!(ranking[0]["model"], "dahl", "{stderr}");
    let dahl = &ranking[0];
    let value = |name: &str| {
        dahl["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"].as_str().unwrap().starts_with(name))
            .and_then(|p| p["value"].as_f64())
            .unwrap()
    };
    assert!(
        (value("sigma0") / 6e4 - 1.0).abs() < 0.02,
        "{}",
        value("sigma0")
    );
    assert!(
        (value("mu_c") / 0.45 - 1.0).abs() < 0.01,
        "{}",
        value("mu_c")
    );
    assert!((value("alpha") - 1.0).abs() < 0.03, "{}", value("alpha"));
    assert!(
        (value("force_offset") - 0.15).abs() < 0.01,
        "{}",
        value("force_offset")
    );
    let rms = dahl["rms_residual"].as_f64().unwrap();
    assert!((0.018..0.023).contains(&rms), "rms = {rms} N");
    for f in &ranking[1..] {
        let model = f["model"].as_str().unwrap();
        if STATIC.contains(&model) {
            let rms = f["rms_residual"].as_f64().unwrap();
            assert!(rms > 0.5, "{model}: {rms} N");
        }
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// A velocity record (no force column).
fn velocity_csv() -> String {
    let mut s = String::from("time,velocity\n");
    for i in 0..200 {
        let t = i as f64 * 1e-3;
        s.push_str(&format!("{t},{}\n", 0.1 * (13.8 * t).cos()));
    }
    s
}

fn config(oscillator: &str, options: &str, record: &str) -> String {
    format!(
        "[oscillator]\n{oscillator}\n[model]\ntype = \"coulomb\"\n[fit.options]\n{options}\n\
         [[records]]\nfile = \"r.csv\"\nx0 = 0.0138\n{record}"
    )
}

const FULL: &str = "mass = 10.391\ndamping = 0.275\nstiffness = 1982.0\nnormal_force = 14.5";

/// Force-domain configurations that cannot run are named in one line: the missing channel,
/// column or oscillator keys, a misspelt domain and an offset without a measured force.
#[test]
fn bad_force_domain_configurations_are_named() {
    let case = |name, command, config| {
        BadInput::new(name, command, config).with_file("r.csv", velocity_csv())
    };
    let cases = [
        case(
            "no-force",
            "fit",
            config(FULL, "domain = \"force\"\nforce_target = \"measured\"", ""),
        )
        .says(Contains("c.toml: record `r.csv`: [fit.options] force_target = \"measured\" but the record has no force channel (it has: velocity")),
        case("no-mck-velocity", "fit", config("normal_force = 14.5", "", ""))
            .says(Contains("c.toml: invalid input: [oscillator]: a velocity-domain fit needs mass, damping and stiffness; `mass`, `stiffness` not given")),
        // Force domain without a force channel falls back to Eq. 7, which needs them too.
        case(
            "no-mck-energy",
            "compare",
            config("normal_force = 14.5\nmass = 10.0", "domain = \"force\"", ""),
        )
        .says(Contains("the energy-based force (Eq. 7) needs mass, damping and stiffness; `stiffness` not given")),
        case(
            "no-column",
            "fit",
            config(
                "normal_force = 5.0",
                "domain = \"force\"",
                "force_column = \"F [N]\"\n",
            ),
        )
        .says(EndsWith(
            "r.csv: line 1: no column `F [N]`; the header has: time, velocity",
        )),
        case("bad-domain", "fit", config(FULL, "domain = \"forces\"", "")).says(Contains(
            "unknown value `forces` in [fit.options] (did you mean `force`?)",
        )),
        case(
            "offset-energy",
            "fit",
            config(FULL, "domain = \"force\"\nforce_offset = true", ""),
        )
        .says(Contains("force_offset = true needs a measured force channel")),
        // Eq. 7 integrates a velocity-only record from x0: without it, the record is named.
        case(
            "no-x0-energy",
            "fit",
            config(FULL, "domain = \"force\"", "").replace("x0 = 0.0138\n", ""),
        )
        .says(Contains("c.toml: record `r.csv`: missing `x0` (the release displacement, m): the energy analysis (it integrates the velocity from x0) needs it for a record without a displacement channel")),
    ];
    assert_bad_inputs(Path::new(env!("CARGO_BIN_EXE_frictionid")), "force", &cases);
}

/// A drive's friction record: 20 N Coulomb friction (plus 0.2 N of deterministic ripple as
/// noise) along a 2 Hz sinusoid, with no normal-force channel.
fn coulomb_20n_csv() -> String {
    let mut s = String::from("time,velocity,force\n");
    for i in 0..1000 {
        let t = i as f64 * 1e-3;
        let v = 0.05 * (4.0 * std::f64::consts::PI * t).sin();
        let ripple = 0.2 * (1.7e3 * t).sin() * (0.37e3 * t).cos();
        s.push_str(&format!("{t},{v},{}\n", 20.0 * v.signum() + ripple));
    }
    s
}

/// With N = 1 a 20 N level needs mu = 20, above mu's bound 10: the fit stops on the bound,
/// and compare says so on stderr and in its verdict (the bound named, and what to do)
/// instead of ranking a pinned law as if it were fitted.
#[test]
fn compare_names_a_level_pinned_at_its_bound_on_stderr_and_in_the_verdict() {
    let dir = scratch_dir("force", "pinned-level");
    std::fs::write(dir.join("r.csv"), coulomb_20n_csv()).unwrap();
    let cfg = dir.join("c.toml");
    std::fs::write(
        &cfg,
        "[oscillator]\nnormal_force = 1.0\n[fit.options]\ndomain = \"force\"\n\
         models = [\"coulomb\", \"stribeck\"]\n[[records]]\nfile = \"r.csv\"\nx0 = 0.0\n",
    )
    .unwrap();
    let out = dir.join("out");
    let o = frictionid()
        .args(["compare", cfg.to_str().unwrap(), "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        stderr.contains("model `coulomb`: `mu` = 1.0000e1 is at its upper bound 1.0000e1")
            && stderr.contains("normal force"),
        "{stderr}"
    );
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let verdict = r["verdict"]["message"].as_str().unwrap();
    let best = r["verdict"]["best"].as_str().unwrap();
    assert!(
        verdict.contains(&format!("`{best}` has `"))
            && verdict.contains("= 10 at a bound")
            && verdict.contains("widen its [fit] bounds or set the normal force"),
        "{verdict}"
    );
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        md.contains("at a bound, so its rank is not reliable"),
        "{md}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
