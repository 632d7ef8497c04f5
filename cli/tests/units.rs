//! Units on every rig from the command line: a driven axis whose position in millimetres is
//! read as metres, and a pendulum whose angle in degrees is read as radians (its gravity
//! moment fitted or not), are refused with one line naming the record and the scale to set
//! (exit 1), while their correct twins fit; a formula that is not finite on the data and
//! `max_iterations = 0` are config errors. The records are made by `simulate`.

use frictionid_cli::testing::{
    assert_bad_inputs, fitted_value, run_ok, scratch_dir, BadInput, Says,
};
use std::fmt::Write;
use std::path::Path;
use std::process::{Command, Output};

pub(crate) fn frictionid() -> Command {
    Command::new(env!("CARGO_BIN_EXE_frictionid"))
}

/// Runs `frictionid <command> --quiet --out <out> <config>` and checks that it succeeds.
pub(crate) fn run_quiet(command: &str, config: &Path, out: &Path) -> Output {
    run_ok(
        frictionid()
            .args([command, "--quiet", "--out"])
            .arg(out)
            .arg(config),
    )
}

/// Runs `simulate` on `config` in `dir` and returns the rows of its trajectory.csv as
/// (time, x, v).
fn simulate(dir: &Path, config: &str) -> Vec<(f64, f64, f64)> {
    std::fs::write(dir.join("sim.toml"), config).unwrap();
    let out = dir.join("sim");
    run_quiet("simulate", &dir.join("sim.toml"), &out);
    let text = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (t, x, v) = (col("time"), col("x"), col("v"));
    lines
        .map(|l| {
            let f: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (f[t], f[x], f[v])
        })
        .collect()
}

/// The drive's multisine input [N] at 1 kHz over 2 s.
fn multisine(t: f64) -> f64 {
    [
        (40.0, 0.7, 0.0),
        (25.0, 1.9, 1.0),
        (15.0, 3.3, 2.0),
        (10.0, 5.1, 0.5),
    ]
    .iter()
    .map(|&(a, f, p)| a * (2.0 * std::f64::consts::PI * f * t + p).sin())
    .sum()
}

/// A driven slide (M 12 kg, viscous 30 N s/m, Coulomb 8 N, offset 0.5 N) simulated under
/// the multisine, its position quantised to 1 um and written in metres (`unit` 1) or
/// millimetres (`unit` 1000) beside the input.
pub(crate) fn drive_csv(dir: &Path, unit: f64) -> String {
    let mut input = String::from("time,u\n");
    for i in 0..=2000 {
        let t = i as f64 * 1e-3;
        let _ = writeln!(input, "{t},{:.9}", multisine(t));
    }
    std::fs::write(dir.join("input.csv"), &input).unwrap();
    let rows = simulate(
        dir,
        "[oscillator]\nmass = 12.0\ndamping = 30.0\nnormal_force = 1.0\ninput_offset = 0.5\n\
         restoring = { type = \"none\" }\n[model]\ntype = \"coulomb\"\nmu = 8.0\n\
         [simulation]\nx0 = 0.0\nduration = 2.0\nsample_rate = 1000.0\n\
         input = { file = \"input.csv\", input_force_column = \"u\" }\n",
    );
    let mut csv = String::from("time,position,u\n");
    for (t, x, _) in rows {
        let x = (x * 1e6).round() * 1e-6 * unit;
        let _ = writeln!(csv, "{t},{x:.9},{:.9}", multisine(t));
    }
    csv
}

/// The force-balance plot a fit wrote into `out`, as SVG text.
pub(crate) fn force_balance_svg(out: &Path) -> String {
    let plot = std::fs::read_dir(out)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.to_string_lossy().ends_with("_force_balance.svg"))
        .expect("a force-balance plot");
    std::fs::read_to_string(&plot).unwrap()
}

/// The `element`s (`"circle"`, `"polygon"`) in `svg` filled with the colour `fill`.
pub(crate) fn filled(svg: &str, element: &str, fill: &str) -> usize {
    svg.split(&format!("<{element}"))
        .skip(1)
        .filter(|c| {
            let element = c.split('>').next().unwrap_or_default();
            element.to_ascii_uppercase().contains(fill)
        })
        .count()
}

/// The drive fitted with its mass (start 10 kg), damping and offset free, by inverse
/// dynamics or by its velocity.
pub(crate) fn drive_config(domain: &str, mass_line: &str) -> String {
    let target = if domain == "force" {
        "force_target = \"inverse_dynamics\"\n"
    } else {
        ""
    };
    format!(
        "[oscillator]\n{mass_line}damping = 20.0\nnormal_force = 1.0\n\
         restoring = {{ type = \"none\" }}\n[model]\ntype = \"coulomb\"\nmu = 5.0\n\
         [fit.options]\ndomain = \"{domain}\"\n{target}oscillator = [\"mass\", \"damping\", \"input_offset\"]\n\
         [[records]]\nfile = \"drive.csv\"\nx0 = 0.0\ndisplacement_column = \"position\"\n\
         input_force_column = \"u\"\n"
    )
}

#[test]
fn a_drive_in_millimetres_read_as_metres_is_refused_and_its_twin_fits() {
    let dir = scratch_dir("units", "drive");
    let mm = drive_csv(&dir, 1000.0);
    let says = Says::Contains(
        "drive.csv: the displacement looks like millimetres read as metres: the input balances J a with J = 1.2",
    );
    let end = Says::EndsWith("set displacement_scale = 0.001");
    let cases: Vec<BadInput> = [
        ("drive-force", drive_config("force", "mass = 10.0\n")),
        ("drive-velocity", drive_config("velocity", "mass = 10.0\n")),
        // A fixed mass tells as well.
        (
            "drive-fixed",
            drive_config("force", "mass = 12.0\n").replace("\"mass\", ", ""),
        ),
    ]
    .into_iter()
    .map(|(name, config)| {
        BadInput::new(name, "fit", config)
            .with_file("drive.csv", mm.clone())
            .says(says)
            .says(end)
    })
    .collect();
    assert_bad_inputs(Path::new(env!("CARGO_BIN_EXE_frictionid")), "units", &cases);

    // The same motion in metres fits: M, Fv and Fc within 1 %.
    std::fs::write(dir.join("drive.csv"), drive_csv(&dir, 1.0)).unwrap();
    std::fs::write(dir.join("fit.toml"), drive_config("force", "mass = 10.0\n")).unwrap();
    let out = dir.join("fit");
    let o = run_quiet("fit", &dir.join("fit.toml"), &out);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("_scale"), "{stderr}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let value = |name: &str| fitted_value(&report, name);
    for (name, truth) in [("mass", 12.0), ("damping", 30.0), ("mu", 8.0)] {
        assert!(
            (value(name) / truth - 1.0).abs() < 0.01,
            "{name} = {}",
            value(name)
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A pendulum (J 0.02 kg m^2, M_g 0.5 N m, c 0.002 N m s/rad, Coulomb 0.012 N m) released
/// at 60 degrees, its angle written in degrees (`degrees`) or radians.
fn pendulum_csv(dir: &Path, degrees: bool) -> String {
    let rows = simulate(
        dir,
        "[oscillator]\naxis = \"rotary\"\ninertia = 0.02\ndamping = 0.002\n\
         restoring = { type = \"pendulum\", gravity_moment = 0.5 }\nnormal_force = 1.0\n\
         [model]\ntype = \"coulomb\"\nmu = 0.012\n\
         [simulation]\nx0 = 1.0471976\nduration = 3.0\nsample_rate = 200.0\n",
    );
    let mut csv = String::from("time,angle\n");
    for (t, q, _) in rows {
        let q = if degrees { q.to_degrees() } else { q };
        let _ = writeln!(csv, "{t},{q:.6}");
    }
    csv
}

/// The pendulum fitted with `fitted` free and no normal force given.
fn pendulum_config(fitted: &str) -> String {
    format!(
        "[oscillator]\naxis = \"rotary\"\ninertia = 0.02\ndamping = 0.002\n\
         restoring = {{ type = \"pendulum\", gravity_moment = 0.5 }}\n\
         [model]\ntype = \"coulomb\"\nmu = 0.02\n[fit.options]\noscillator = [{fitted}]\n\
         [[records]]\nfile = \"swing.csv\"\ndisplacement_column = \"angle\"\n"
    )
}

#[test]
fn a_pendulum_in_degrees_is_refused_whether_or_not_its_gravity_moment_is_fitted() {
    let dir = scratch_dir("units", "pendulum");
    let degrees = pendulum_csv(&dir, true);
    let cases: Vec<BadInput> = [
        ("swing-fitted", "\"damping\", \"gravity_moment\""),
        ("swing-fixed", "\"damping\""),
    ]
    .into_iter()
    .map(|(name, fitted)| {
        BadInput::new(name, "fit", pendulum_config(fitted))
            .with_file("swing.csv", degrees.clone())
            .says(Says::Contains("swing.csv: the angle swings"))
            .says(Says::EndsWith(
                "is the angle in degrees? set displacement_scale = 0.0174533 (pi/180)",
            ))
    })
    .collect();
    assert_bad_inputs(Path::new(env!("CARGO_BIN_EXE_frictionid")), "units", &cases);

    std::fs::write(dir.join("swing.csv"), pendulum_csv(&dir, false)).unwrap();
    std::fs::write(
        dir.join("fit.toml"),
        pendulum_config("\"damping\", \"gravity_moment\""),
    )
    .unwrap();
    let o = run_quiet("fit", &dir.join("fit.toml"), &dir.join("fit"));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("_scale"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_formula_not_finite_on_the_data_and_no_iterations_are_config_errors() {
    let fmm = frictionid_cli::testing::FMM_OSCILLATOR;
    let records = "[[records]]\nfile = \"r.csv\"\nx0 = 0.0\n[fit.options]\ndomain = \"force\"\n\
                   force_target = \"measured\"\n";
    let with_force: String = (0..=200).fold(String::from("time,velocity,force\n"), |mut s, i| {
        let t = i as f64 * 0.01;
        let v = 0.1 * (2.0 * t).cos();
        let _ = writeln!(s, "{t},{v},{}", 3.0 * v.signum());
        s
    });
    let cases = [
        BadInput::new(
            "pole",
            "fit",
            format!(
                "{fmm}[model]\ntype = \"expression\"\nforce = \"mu * N / (v - 0.1)\"\n\
                 params = {{ mu = 0.2 }}\n{records}"
            ),
        )
        .with_file("r.csv", with_force.clone())
        .says(Says::Contains(
            "[model] force = `mu * N / (v - 0.1)`: the force is inf on record `r.csv` at v = 1e-1 (t = 0 s)",
        )),
        BadInput::new(
            "no-iterations",
            "fit",
            format!("{fmm}[model]\ntype = \"coulomb\"\n[fit]\nmax_iterations = 0\n"),
        )
        .says(Says::Contains("[fit] max_iterations = 0 allows no iteration")),
    ];
    assert_bad_inputs(Path::new(env!("CARGO_BIN_EXE_frictionid")), "units", &cases);
}
