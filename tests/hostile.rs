//! Hostile inputs: every one must end in bounded time and memory with a result or one clear
//! error line, never a panic, a hang or an unbounded allocation.

use frictionid_cli::config::{Config, MAX_RECORDS};
use frictionid_engine::data::{read_record, DataError, ReadOptions, MAX_FILE_BYTES};
use frictionid_engine::identify::{
    fit, FitOptions, Hooks, ParamOptions, SearchOptions, TargetOptions,
};
use frictionid_engine::simulate::{simulate, Initial, SimOptions};
use frictionid_engine::synthetic::uniform_times;
use frictionid_engine::{analyze_record, EnergyOptions, EngineError, Oscillator, Record};
use frictionid_models::formula::MAX_FORMULA_CHARS;
use frictionid_models::{build_json, Coulomb, LuGre};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("frictionid-hostile-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

fn csv(time: &[f64], velocity: &[f64]) -> String {
    let mut s = String::from("time,velocity\n");
    for (t, v) in time.iter().zip(velocity) {
        let _ = writeln!(s, "{t},{v}");
    }
    s
}

/// Writes the samples as a CSV file at `path` and returns the error reading it back gives.
fn read_error(path: &Path, time: &[f64], velocity: &[f64]) -> DataError {
    std::fs::write(path, csv(time, velocity)).expect("write");
    read_record(path, &ReadOptions::default()).unwrap_err()
}

fn one_line(e: &impl std::fmt::Display) -> String {
    let msg = e.to_string();
    assert!(!msg.contains('\n'), "multi-line error: {msg}");
    assert!(
        msg.len() < 400,
        "overlong error ({} bytes): {msg}",
        msg.len()
    );
    msg
}

#[test]
fn a_file_over_the_size_limit_is_refused_before_reading() {
    let dir = scratch("huge");
    let path = dir.join("huge.csv");
    // A sparse file: the limit is checked before a byte is read.
    let f = std::fs::File::create(&path).expect("create");
    f.set_len(MAX_FILE_BYTES + 1).expect("sparse length");
    let e = read_record(&path, &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, DataError::TooLarge { .. }), "{e}");
    let msg = one_line(&e);
    assert!(msg.contains("huge.csv") && msg.contains("MiB"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_endless_device_is_refused_at_the_limit() {
    // /dev/zero reports length 0 and never ends: the reader stops at the limit.
    let path = std::path::Path::new("/dev/zero");
    if !path.exists() {
        return;
    }
    let e = read_record(path, &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, DataError::TooLarge { .. }), "{e}");
}

#[test]
fn a_million_line_record_is_read() {
    let dir = scratch("million");
    let path = dir.join("million.csv");
    let n = 1_000_000;
    let time: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
    let velocity: Vec<f64> = time.iter().map(|t| (50.0 * t).sin() * 0.1).collect();
    std::fs::write(&path, csv(&time, &velocity)).expect("write");
    let r = read_record(&path, &ReadOptions::default()).expect("a million lines are read");
    assert_eq!(r.len(), n);
    assert_eq!(r.time()[n - 1], time[n - 1]);
    assert_eq!(r.velocity()[12345], velocity[12345]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_huge_header_gives_a_short_error() {
    let dir = scratch("header");
    let path = dir.join("header.csv");
    let text = format!("{},velocity\n0,1\n", "t".repeat(5_000_000));
    std::fs::write(&path, text).expect("write");
    let e = read_record(&path, &ReadOptions::default()).unwrap_err();
    let msg = one_line(&e);
    assert!(msg.contains("no column `time`"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
}

fn fmm_record(model: &dyn frictionid_models::FrictionModel, x0: f64) -> Record {
    let times = uniform_times(1.0, 500.0);
    let (osc, opts) = (Oscillator::fmm(), SimOptions::default());
    let start = Initial::at_rest(x0);
    let traj = simulate(&osc, model, &start, 1.0, &times, &opts).expect("simulation");
    Record::new("fmm", times, traj.v, x0)
}

/// A coefficient beyond the law's bounds is refused by a simulation, by a fit that holds it
/// fixed and by a config; a fit that frees it starts at the bound and finds the record's.
#[test]
fn an_extreme_friction_coefficient_is_refused_by_simulation_and_fit() {
    let osc = Oscillator::fmm();
    let model = Coulomb { mu: 1e6 };
    let times = uniform_times(1.0, 100.0);
    let e = simulate(
        &osc,
        &model,
        &Initial::at_rest(0.02),
        1.0,
        &times,
        &SimOptions::default(),
    )
    .unwrap_err();
    assert!(one_line(&e).contains("`mu`"), "{e}");
    let rec = fmm_record(&Coulomb { mu: 0.2 }, 0.02);
    let fixed = FitOptions {
        params: ParamOptions {
            free: Some(Vec::new()),
            ..ParamOptions::default()
        },
        ..FitOptions::default()
    };
    let e = fit(&osc, &model, std::slice::from_ref(&rec), &fixed).unwrap_err();
    assert!(one_line(&e).contains("`mu`"), "{e}");
    let projected = FitOptions {
        params: ParamOptions {
            guess: false,
            ..ParamOptions::default()
        },
        ..FitOptions::default()
    };
    let fitted = fit(&osc, &model, &[rec], &projected).expect("a start projected to the bound");
    let mu = fitted.fitted_model.params()[0];
    assert!((mu - 0.2).abs() < 1e-6, "mu = {mu}");
    // Through a config file the message names the table.
    let text = OSC.replace("type = \"coulomb\"", "type = \"coulomb\"\nmu = 1e6");
    let e = Config::parse(std::path::Path::new("mu.toml"), &text).unwrap_err();
    assert!(one_line(&e).contains("[model]"), "{e}");
}

#[test]
fn a_very_stiff_bristle_model_ends_at_the_step_limit() {
    let model = LuGre {
        sigma0: 1e12,
        ..LuGre::default()
    };
    let times = uniform_times(1.0, 100.0);
    let opts = SimOptions {
        max_steps: 100_000,
        ..SimOptions::default()
    };
    let r = simulate(
        &Oscillator::fmm(),
        &model,
        &Initial::at_rest(0.02),
        1.0,
        &times,
        &opts,
    );
    match r {
        Err(EngineError::Integration(failure)) => {
            let reason = failure.to_string();
            assert!(reason.contains("max_steps"), "{reason}")
        }
        Err(e) => panic!("unexpected error: {e}"),
        Ok(t) => assert!(t.stats.steps + t.stats.rejected_steps <= 100_000),
    }
}

#[test]
fn a_tiny_mass_ends_at_the_step_limit() {
    // m = 1e-12 kg: T_n = 1.4e-7 s, so 1 s needs about 6e7 steps of at most T_n / 8.
    let osc = Oscillator::new(1e-12, 0.275, 1982.0, 14.5).expect("valid oscillator");
    let times = uniform_times(1.0, 100.0);
    let opts = SimOptions {
        max_steps: 200_000,
        ..SimOptions::default()
    };
    let e = simulate(
        &osc,
        &Coulomb { mu: 1e-3 },
        &Initial::at_rest(0.02),
        1.0,
        &times,
        &opts,
    )
    .unwrap_err();
    assert!(one_line(&e).contains("max_steps = 200000"), "{e}");
}

#[test]
fn a_record_of_zeros_is_read_and_analysed_without_panic() {
    let dir = scratch("zeros");
    let path = dir.join("zeros.csv");
    let time = uniform_times(1.0, 1000.0);
    let zeros = vec![0.0; time.len()];
    std::fs::write(&path, csv(&time, &zeros)).expect("write");
    let mut rec = read_record(&path, &ReadOptions::default()).expect("zeros are valid numbers");
    rec.x0 = 0.0;
    let osc = Oscillator::fmm();
    if let Err(e) = analyze_record(&rec, &osc, &EnergyOptions::default()) {
        one_line(&e);
    }
    // A mass released at rest from x0 = 0 with any friction stays there: the fit either
    // explains the zeros exactly or says why it cannot.
    let opts = FitOptions {
        hooks: Hooks {
            parallel: false,
            ..Hooks::default()
        },
        ..FitOptions::default()
    };
    match fit(&osc, &Coulomb::default(), &[rec], &opts) {
        Ok(r) => assert!(r.rms_residual == 0.0, "rms {}", r.rms_residual),
        Err(e) => {
            one_line(&e);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_spike_of_1e30_is_read_and_the_fit_does_not_panic() {
    let mut rec = fmm_record(&Coulomb { mu: 0.2 }, 0.014);
    rec.velocity_mut()[100] = 1e30;
    let dir = scratch("spike");
    let path = dir.join("spike.csv");
    std::fs::write(&path, csv(rec.time(), rec.velocity())).expect("write");
    let mut read = read_record(&path, &ReadOptions::default()).expect("1e30 is finite");
    assert_eq!(read.velocity()[100], 1e30);
    read.x0 = 0.014;
    let osc = Oscillator::fmm();
    if let Ok(a) = analyze_record(&read, &osc, &EnergyOptions::default()) {
        assert_eq!(a.time.len(), read.len());
    }
    let opts = FitOptions {
        hooks: Hooks {
            parallel: false,
            ..Hooks::default()
        },
        search: SearchOptions {
            max_iterations: 50,
            ..SearchOptions::default()
        },
        ..FitOptions::default()
    };
    match fit(&osc, &Coulomb::default(), &[read], &opts) {
        Ok(r) => assert!(r.cost.is_finite(), "cost {}", r.cost),
        Err(e) => {
            one_line(&e);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn duplicate_and_gapped_time_stamps_name_their_line() {
    let dir = scratch("stamps");
    let mut time = uniform_times(0.1, 1000.0);
    let v = vec![0.1; time.len()];
    // Duplicate at sample 50 (file line 52: header on line 1, samples from line 2).
    let mut dup = time.clone();
    dup[51] = dup[50];
    let e = read_error(&dir.join("dup.csv"), &dup, &v);
    assert!(
        matches!(e, DataError::NotIncreasing { line: 53, .. }),
        "{e}"
    );
    one_line(&e);
    // A gap: samples 60.. shifted by 5 steps.
    for t in time.iter_mut().skip(60) {
        *t += 0.005;
    }
    let e = read_error(&dir.join("gap.csv"), &time, &v);
    assert!(
        matches!(e, DataError::UnevenSampling { line: 62, .. }),
        "{e}"
    );
    one_line(&e);
    let _ = std::fs::remove_dir_all(&dir);
}

const OSC: &str = "[oscillator]\nmass = 10.391\ndamping = 0.275\nstiffness = 1982.0\nnormal_force = 14.5\n[model]\ntype = \"coulomb\"\n";

#[test]
fn a_config_with_10000_records_is_refused_with_the_limit() {
    let mut text = OSC.to_string();
    for i in 0..10_000 {
        let _ = write!(text, "[[records]]\nfile = \"r{i}.csv\"\nx0 = 0.01\n");
    }
    let e = Config::parse(std::path::Path::new("many.toml"), &text).unwrap_err();
    let msg = one_line(&e);
    assert!(
        msg.contains("10000 [[records]]") && msg.contains(&MAX_RECORDS.to_string()),
        "{msg}"
    );
    // At the limit the file is accepted.
    let mut text = OSC.to_string();
    for i in 0..MAX_RECORDS {
        let _ = write!(text, "[[records]]\nfile = \"r{i}.csv\"\nx0 = 0.01\n");
    }
    let cfg = Config::parse(std::path::Path::new("many.toml"), &text).expect("at the limit");
    assert_eq!(cfg.records.len(), MAX_RECORDS);
}

#[test]
fn an_oversized_config_file_is_refused() {
    let dir = scratch("bigconfig");
    let path = dir.join("big.toml");
    let text = format!("{OSC}# {}\n", "x".repeat(2 * 1024 * 1024));
    std::fs::write(&path, text).expect("write");
    let e = Config::load(&path).unwrap_err();
    assert!(one_line(&e).contains("KiB"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn long_formulas_are_refused_and_the_longest_accepted_one_builds() {
    // A flat chain is as deep as it is long; without the length limit 1e5 terms overflowed
    // the stack.
    let head = "mu * N * tanh(v / eps)";
    let terms = (MAX_FORMULA_CHARS - head.len()) / 4;
    let ok = format!("{head}{}", " + v".repeat(terms));
    assert!(ok.chars().count() <= MAX_FORMULA_CHARS);
    let params = serde_json::json!({ "mu": 0.2, "eps": 1e-4 });
    build_json(&serde_json::json!({ "type": "expression", "force": ok, "params": params }))
        .expect("a formula at the length limit");
    for n in [terms + 1, 100_000, 1_000_000] {
        let force = format!("{head}{}", " + v".repeat(n));
        let e = build_json(&serde_json::json!({ "type": "expression", "force": force }))
            .expect_err("over the limit");
        assert!(one_line(&e).contains("at most 2000"), "{e}");
    }
    // Deep nesting is refused by the parser's depth limit.
    let deep = format!("{}v{}", "(".repeat(300), ")".repeat(300));
    assert!(build_json(&serde_json::json!({ "type": "expression", "force": deep })).is_err());
    let deep = format!("{}v", "-".repeat(1500));
    assert!(build_json(&serde_json::json!({ "type": "expression", "force": deep })).is_err());
}

#[test]
fn deeply_nested_toml_is_an_error() {
    for depth in [100usize, 10_000, 1_000_000] {
        let arrays = format!("x = {}1{}\n", "[".repeat(depth), "]".repeat(depth));
        let tables = format!("x = {}1{}\n", "{a = ".repeat(depth), "}".repeat(depth));
        for text in [arrays, tables] {
            let text = format!("{OSC}{text}");
            let e = Config::parse(std::path::Path::new("deep.toml"), &text).unwrap_err();
            one_line(&e);
        }
    }
}

#[test]
fn a_simulation_of_1e18_samples_is_refused_before_allocating() {
    let text = format!("{OSC}[simulation]\nx0 = 0.01\nduration = 1e9\nsample_rate = 1e9\n");
    let e = Config::parse(std::path::Path::new("long.toml"), &text).unwrap_err();
    assert!(one_line(&e).contains("samples"), "{e}");
}

#[test]
fn an_absurd_number_of_starts_is_refused_before_allocating() {
    let rec = fmm_record(&Coulomb { mu: 0.2 }, 0.014);
    let opts = FitOptions {
        search: SearchOptions {
            multistart: Some(usize::MAX),
            ..SearchOptions::default()
        },
        ..FitOptions::default()
    };
    let e = fit(&Oscillator::fmm(), &Coulomb::default(), &[rec], &opts).unwrap_err();
    assert!(one_line(&e).contains("multistart"), "{e}");
}

/// A driven axis along 5 mm at 2 Hz (velocity, displacement and a friction force of 3 N
/// Coulomb plus 0.05 N noise), 2 s at 1 kHz.
fn driven_record() -> Record {
    use frictionid_engine::record::{Channel, TimeBase};
    let time = uniform_times(2.0, 1000.0);
    let w = 4.0 * std::f64::consts::PI;
    let x: Vec<f64> = time.iter().map(|t| 5e-3 * (w * t).sin()).collect();
    let v: Vec<f64> = time.iter().map(|t| 5e-3 * w * (w * t).cos()).collect();
    let mut f: Vec<f64> = v.iter().map(|v| 3.0 * v.signum()).collect();
    frictionid_engine::synthetic::add_gaussian_noise(&mut f, 0.05, 9);
    Record::from_time_base("driven", TimeBase::new(time).expect("time base"))
        .with_channel(Channel::Displacement, x)
        .with_channel(Channel::Velocity, v)
        .with_channel(Channel::Force, f)
}

/// A run at constant speed `v` (1 s at 100 Hz): 3 N Coulomb and 2 N s/m viscous friction
/// plus 0.05 N noise (seed `seed`).
fn constant_velocity_run(v: f64, seed: u64) -> Record {
    let force = 3.0 * v.signum() + 2.0 * v;
    frictionid_engine::testing::constant_velocity_run(
        uniform_times(1.0, 100.0),
        v,
        (0.05, seed),
        |_| force,
    )
}

fn force_domain() -> FitOptions {
    FitOptions {
        target: TargetOptions {
            domain: frictionid_engine::identify::FitDomain::Force,
            ..TargetOptions::default()
        },
        hooks: Hooks {
            parallel: false,
            ..Hooks::default()
        },
        ..FitOptions::default()
    }
}

fn expression(force: &str, params: serde_json::Value) -> Box<dyn frictionid_models::FrictionModel> {
    build_json(&serde_json::json!({ "type": "expression", "force": force, "params": params }))
        .expect("a valid formula")
        .model
}

/// The verdict a fit of degenerate input must not reach: converged with no failed finding.
fn failed_checks(r: &frictionid_engine::identify::FitResult) -> Vec<String> {
    r.diagnostics
        .iter()
        .filter(|d| d.status == frictionid_engine::identify::Status::Fail)
        .map(|d| d.message.clone())
        .collect()
}

#[test]
fn a_law_that_is_not_finite_over_part_of_the_data_is_an_error_or_a_failure() {
    // ln(v) is not a number wherever the axis moves backwards: half of every cycle.
    let model = expression("mu * N * ln(v)", serde_json::json!({ "mu": 0.2 }));
    let osc = Oscillator::fmm();
    for opts in [
        force_domain(),
        FitOptions {
            hooks: Hooks {
                parallel: false,
                ..Hooks::default()
            },
            ..FitOptions::default()
        },
    ] {
        match fit(&osc, model.as_ref(), &[driven_record()], &opts) {
            Ok(r) => assert!(
                !failed_checks(&r).is_empty() || !r.converged,
                "fitted a law that is NaN on half the record: cost {}",
                r.cost
            ),
            Err(e) => {
                one_line(&e);
            }
        }
    }
}

#[test]
fn a_record_without_motion_is_refused_with_one_line() {
    use frictionid_engine::record::Channel;
    let osc = Oscillator::fmm();
    let still = |v: Vec<f64>| {
        let time = uniform_times(1.0, 1000.0);
        Record::new("still", time, v, 0.0)
    };
    let n = uniform_times(1.0, 1000.0).len();
    let mut noise = vec![0.0; n];
    frictionid_engine::synthetic::add_gaussian_noise(&mut noise, 2e-4, 5);
    for (rec, says) in [
        (still(vec![0.0; n]), "every velocity sample is 0"),
        (still(noise), "no motion above the noise"),
    ] {
        let opts = FitOptions {
            hooks: Hooks {
                parallel: false,
                ..Hooks::default()
            },
            ..FitOptions::default()
        };
        let e = fit(&osc, &Coulomb::default(), std::slice::from_ref(&rec), &opts).unwrap_err();
        let msg = one_line(&e);
        assert!(msg.contains("still") && msg.contains(says), "{msg}");
        // In the force domain too (a force record of a stage that never moved).
        let forced = rec.with_channel(Channel::Force, vec![0.1; n]);
        let e = fit(&osc, &Coulomb::default(), &[forced], &force_domain()).unwrap_err();
        assert!(one_line(&e).contains(says), "{e}");
    }
}

#[test]
fn a_parameter_without_effect_on_the_residuals_fails_a_finding() {
    let osc = Oscillator::fmm();
    // `b` enters the formula but not the force.
    let model = expression(
        "mu * N * sign(v) + 0 * b * v",
        serde_json::json!({ "mu": 0.2, "b": 1.0 }),
    );
    let r = fit(&osc, model.as_ref(), &[driven_record()], &force_domain()).unwrap();
    let failed = failed_checks(&r);
    assert!(
        failed
            .iter()
            .any(|m| m.contains("`b`") && m.contains("changes no residual")),
        "{failed:?}"
    );
    // A Stribeck velocity of 0.1 mm/s held fixed under constant-velocity runs of 10 to
    // 100 mm/s: exp(-(v/v_s)^2) is 0 at every sample, so mu_s changes nothing.
    let stribeck = frictionid_models::Stribeck {
        v_s: 1e-4,
        ..frictionid_models::Stribeck::default()
    };
    let runs: Vec<Record> = [0.01, -0.01, 0.1, -0.1]
        .iter()
        .enumerate()
        .map(|(i, &v)| constant_velocity_run(v, i as u64))
        .collect();
    let opts = FitOptions {
        params: ParamOptions {
            free: Some(vec!["mu_c".into(), "mu_s".into(), "viscous".into()]),
            ..force_domain().params.clone()
        },
        ..force_domain()
    };
    let r = fit(&osc, &stribeck, &runs, &opts).unwrap();
    let failed = failed_checks(&r);
    assert!(failed.iter().any(|m| m.contains("`mu_s`")), "{failed:?}");
}
