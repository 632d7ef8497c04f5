//! Only the keys the equation uses: a driven slide without a spring (velocity route, the
//! axis simulated under its measured input) fits with `mass` and `restoring = none` alone, or
//! with `stiffness = 0` (a free mass): no damping (0 assumed, and said), no x0, no normal
//! force (the levels are forces). Truth: m 2 kg, F_c 2 N, viscous 4 N s/m, against the closed
//! form of m v' = u - F_c - b v between the input's steps.

use frictionid_cli::testing::{fitted_value, runs_ok, scratch_dir};
use frictionid_engine::synthetic::add_gaussian_noise;
use std::fmt::Write as _;
use std::process::Command;

const MASS: f64 = 2.0;
const COULOMB: f64 = 2.0;
const VISCOUS: f64 = 4.0;

/// The input's steps [N] and their starts [s].
const STEPS: [(f64, f64); 3] = [(0.0, 10.0), (0.5, 6.0), (1.0, 12.0)];

/// time, velocity and the input at 1 kHz over 1.5 s, velocity noise 1 mm/s.
fn drive_csv() -> String {
    let n = 1500;
    let mut v = Vec::with_capacity(n + 1);
    let mut u = Vec::with_capacity(n + 1);
    let (mut v_start, mut t_start, mut step) = (0.0, 0.0, 0);
    for i in 0..=n {
        let t = i as f64 * 1e-3;
        while step + 1 < STEPS.len() && t >= STEPS[step + 1].0 {
            let (t0, push) = (STEPS[step + 1].0, STEPS[step].1);
            let v_inf = (push - COULOMB) / VISCOUS;
            v_start = v_inf + (v_start - v_inf) * (-VISCOUS * (t0 - t_start) / MASS).exp();
            t_start = t0;
            step += 1;
        }
        let push = STEPS[step].1;
        let v_inf = (push - COULOMB) / VISCOUS;
        v.push(v_inf + (v_start - v_inf) * (-VISCOUS * (t - t_start) / MASS).exp());
        u.push(push);
    }
    add_gaussian_noise(&mut v, 1e-3, 3);
    let mut csv = String::from("time,velocity,u\n");
    for (i, (v, u)) in v.iter().zip(&u).enumerate() {
        let _ = writeln!(csv, "{},{v},{u}", i as f64 * 1e-3);
    }
    csv
}

fn fit(tag: &str, oscillator: &str) -> (serde_json::Value, String) {
    let dir = scratch_dir("driven-keys", tag);
    std::fs::write(dir.join("drive.csv"), drive_csv()).unwrap();
    let cfg = dir.join("c.toml");
    std::fs::write(
        &cfg,
        format!(
            "[oscillator]\n{oscillator}\n[model]\ntype = \"viscous_coulomb\"\n\
             [[records]]\nfile = \"drive.csv\"\ninput_force_column = \"u\"\n"
        ),
    )
    .unwrap();
    let out = dir.join("out");
    runs_ok(
        Command::new(env!("CARGO_BIN_EXE_frictionid"))
            .arg("fit")
            .arg(&cfg)
            .arg("--quiet")
            .arg("--out")
            .arg(&out)
            .output(),
        &out,
    )
}

fn value(r: &serde_json::Value, name: &str) -> f64 {
    fitted_value(r, name)
}

#[test]
fn a_driven_axis_fits_with_its_mass_and_no_spring_alone() {
    for (tag, oscillator) in [
        ("none", "mass = 2.0\nrestoring = { type = \"none\" }"),
        ("k0", "mass = 2.0\nstiffness = 0.0"),
    ] {
        let (r, stderr) = fit(tag, oscillator);
        let (mu, viscous) = (value(&r, "mu"), value(&r, "viscous"));
        assert!((mu / COULOMB - 1.0).abs() < 0.01, "{tag}: F_c {mu}");
        assert!(
            (viscous / VISCOUS - 1.0).abs() < 0.01,
            "{tag}: viscous {viscous}"
        );
        assert!(
            stderr.contains("`damping` not given: assumed 0"),
            "{tag}: {stderr}"
        );
        assert!(
            states_assumed_damping(&r),
            "{tag}: no assumption finding in report.json"
        );
    }
}

/// Whether the report's findings state the assumed damping, as every writer prints them.
fn states_assumed_damping(r: &serde_json::Value) -> bool {
    r["diagnostics"].as_array().is_some_and(|d| {
        d.iter().any(|f| {
            f["check"] == "assumption"
                && f["message"]
                    .as_str()
                    .is_some_and(|m| m.contains("`damping` not given: assumed 0"))
        })
    })
}
