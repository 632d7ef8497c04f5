//! A rotary axis from the command line: every unit a report, a summary or a plot shows is the
//! rotary one (rad, rad/s, N m, kg m^2, N m s/rad), never a linear one (m/s, N/m), and a
//! record with a measured input gets a plot of it.

use assert_cmd::Command;
use frictionid_cli::testing::Says::Contains;
use frictionid_cli::testing::{assert_bad_inputs, scratch_dir, BadInput};
use std::fmt::Write;
use std::path::Path;

fn frictionid() -> Command {
    Command::new(env!("CARGO_BIN_EXE_frictionid"))
}

/// A pendulum's inertia J [kg m^2], gravity moment M_g [N m], damping c [N m s/rad] and
/// Coulomb torque T_c [N m] (no normal force: the level is the torque itself).
const PENDULUM: &str = "axis = \"rotary\"\ninertia = 0.02\ndamping = 0.002\n\
                        restoring = { type = \"pendulum\", gravity_moment = 0.5 }";

/// Runs `frictionid <command> <config> --out <out>` and returns its standard output.
fn run(command: &str, config: &Path, out: &Path) -> String {
    let o = frictionid()
        .args([command, config.to_str().unwrap_or_default(), "--out"])
        .arg(out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(out.join("report.json").exists(), "{stderr}");
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The JSON `unit` fields and the Markdown tables of a report hold every unit in `shown` and
/// none of the linear ones.
fn assert_rotary_units(out: &Path, shown: &[&str]) {
    let json = read(&out.join("report.json"));
    let md = read(&out.join("report.md"));
    for unit in shown {
        assert!(
            json.contains(&format!("\"{unit}\"")),
            "report.json lacks {unit}"
        );
        assert!(md.contains(unit), "report.md lacks {unit}");
    }
    for linear in ["m/s", "N/m", "N s/m", "[m]", "\"m\"", "\"kg\"", "\"N\""] {
        assert!(!json.contains(linear), "report.json shows {linear}");
        assert!(!md.contains(linear), "report.md shows {linear}");
    }
}

/// A pendulum released at 60 degrees, simulated by `simulate` (a Coulomb torque of 0.012 N m
/// times a unit normal force) into a noisy velocity record,
/// then fitted with its damping and gravity moment free and no normal force: the velocity
/// residuals are in rad/s, the release angle in rad, the gravity moment and the Coulomb
/// torque (0.012 N m recovered) in N m and the damping in N m s/rad.
#[test]
fn a_pendulum_fit_reports_rotary_units() {
    let out = scratch_dir("rotary", "pendulum");
    let sim = format!(
        "[oscillator]\n{PENDULUM}\nnormal_force = 1.0\n[model]\ntype = \"coulomb\"\nmu = 0.012\n\
         [simulation]\nx0 = 1.0471976\nduration = 3.0\nsample_rate = 200.0\nnoise = 1e-4\nseed = 7\n"
    );
    let sim_cfg = out.join("simulate.toml");
    std::fs::write(&sim_cfg, sim).unwrap();
    let sim_out = out.join("sim");
    let summary = run("simulate", &sim_cfg, &sim_out);
    assert!(summary.contains("rad"), "{summary}");
    let sim_md = read(&sim_out.join("report.md"));
    assert!(sim_md.contains("displacement [rad]"), "{sim_md}");
    assert!(!sim_md.contains("| m |"), "{sim_md}");
    let svg = read(&sim_out.join("displacement_velocity.svg"));
    assert!(svg.contains("velocity [rad/s]"), "the velocity axis");

    let fit = format!(
        "[oscillator]\n{PENDULUM}\n[model]\ntype = \"coulomb\"\nmu = 0.02\n\
         [fit.options]\noscillator = [\"damping\", \"gravity_moment\"]\n\
         [[records]]\nfile = \"sim/record.csv\"\nx0 = 1.0471976\n"
    );
    let fit_cfg = out.join("fit.toml");
    std::fs::write(&fit_cfg, fit).unwrap();
    let fit_out = out.join("fit");
    let summary = run("fit", &fit_cfg, &fit_out);
    assert!(summary.contains("rad/s"), "{summary}");
    assert!(!summary.contains("m/s"), "{summary}");
    assert_rotary_units(&fit_out, &["rad/s", "N m", "N m s/rad"]);
    assert!(read(&fit_out.join("report.md")).contains("x0 [rad]"));
    // No normal force: the Coulomb level is the torque the record was simulated with.
    let json: serde_json::Value = serde_json::from_str(&read(&fit_out.join("report.json")))
        .unwrap_or(serde_json::Value::Null);
    let mu = &json["parameters"][0];
    assert_eq!(
        (mu["name"].as_str(), mu["unit"].as_str()),
        (Some("mu"), Some("N m"))
    );
    let torque = mu["value"].as_f64().unwrap_or(f64::NAN);
    assert!((torque / 0.012 - 1.0).abs() < 0.02, "{torque} N m");
    let _ = std::fs::remove_dir_all(&out);
}

/// A driven pendulum: the angle q = 0.6 sin(2.1 t) + 0.3 sin(5.3 t) and its derivatives in
/// closed form, the input torque from the balance u = J a + c v + M_g sin q + T_c sgn v
/// (the oracle: the equation itself, J = 0.02, c = 0.002, M_g = 0.5, T_c = 0.012).
fn driven_csv() -> String {
    driven_pendulum_csv(|| 0.0)
}

/// The driven pendulum of [`driven_csv`] over 3 s at 500 Hz, `noise()` added to each sample
/// of the input torque.
pub(crate) fn driven_pendulum_csv(mut noise: impl FnMut() -> f64) -> String {
    let mut csv = String::from("time,angle,velocity,acceleration,torque\n");
    for i in 0..1500 {
        let t = i as f64 * 2e-3;
        let (w1, w2) = (2.1, 5.3);
        let q = 0.6 * (w1 * t).sin() + 0.3 * (w2 * t).sin();
        let v = 0.6 * w1 * (w1 * t).cos() + 0.3 * w2 * (w2 * t).cos();
        let a = -0.6 * w1 * w1 * (w1 * t).sin() - 0.3 * w2 * w2 * (w2 * t).sin();
        let u = 0.02 * a + 0.002 * v + 0.5 * q.sin() + 0.012 * v.signum() + noise();
        let _ = writeln!(csv, "{t:.4},{q:.9},{v:.9},{a:.9},{u:.9}");
    }
    csv
}

/// Inverse dynamics of the driven pendulum with its inertia, damping and gravity moment
/// fitted: the inertia named so and in kg m^2 in every writer, the torques in N m, the
/// damping in N m s/rad; the measured input torque is plotted against time
/// (`<record>_input.svg`, listed with the files).
#[test]
fn a_driven_pendulum_reports_rotary_units_and_plots_its_input() {
    let out = scratch_dir("rotary", "driven");
    std::fs::write(out.join("driven.csv"), driven_csv()).unwrap();
    let cfg = format!(
        "[oscillator]\n{PENDULUM}\ninertia_std = 1e-4\n[model]\ntype = \"coulomb\"\nmu = 0.02\n\
         [fit.options]\ndomain = \"force\"\n\
         force_target = \"inverse_dynamics\"\n\
         oscillator = [\"mass\", \"damping\", \"gravity_moment\"]\n\
         [[records]]\nfile = \"driven.csv\"\nx0 = 0.0\ndisplacement_column = \"angle\"\n\
         velocity_column = \"velocity\"\nacceleration_column = \"acceleration\"\n\
         input_force_column = \"torque\"\n"
    );
    let cfg_path = out.join("driven.toml");
    std::fs::write(&cfg_path, cfg).unwrap();
    let fit_out = out.join("fit");
    run("fit", &cfg_path, &fit_out);
    assert_rotary_units(&fit_out, &["kg m^2", "N m", "N m s/rad"]);
    let svg = read(&fit_out.join("driven_input.svg"));
    assert!(svg.contains("input u [N m]"), "the input's axis");
    assert!(svg.contains("measured input"));
    let json: serde_json::Value = serde_json::from_str(&read(&fit_out.join("report.json")))
        .unwrap_or(serde_json::Value::Null);
    let files: Vec<&str> = json["files"]
        .as_array()
        .map(|f| f.iter().filter_map(|x| x.as_str()).collect())
        .unwrap_or_default();
    assert!(files.contains(&"driven_input.svg"), "{files:?}");
    let parameters = json["parameters"].as_array().cloned().unwrap_or_default();
    let value_in = |unit: &str| {
        parameters
            .iter()
            .find(|p| p["unit"] == unit)
            .and_then(|p| p["value"].as_f64())
            .unwrap_or(f64::NAN)
    };
    let inertia = value_in("kg m^2");
    assert!((inertia - 0.02).abs() < 2e-4, "J = {inertia} kg m^2");
    let md = read(&fit_out.join("report.md"));
    assert!(md.contains("driven_input.svg"));
    // The inertia is named so in every table: its row, the budget's column (inertia_std
    // given) and the oscillator's quantities; none says mass or m.
    assert!(md.contains("| inertia | "), "{md}");
    assert!(
        md.contains("| parameter | data | inertia | damping |"),
        "{md}"
    );
    assert!(md.contains("| c/J |"), "{md}");
    assert!(!md.contains("mass") && !md.contains("c/m"), "{md}");
    let html = read(&fit_out.join("report.html"));
    assert!(html.contains(">inertia<") && !html.contains(">mass<"));
    let terminal = run("fit", &cfg_path, &out.join("again"));
    assert!(
        terminal.lines().any(|l| l.starts_with("inertia ")),
        "{terminal}"
    );
    let _ = std::fs::remove_dir_all(&out);
}

/// `models --axis rotary` lists the viscous coefficients in N m s/rad, none in N s/m; the
/// default listing keeps N s/m.
#[test]
fn models_list_rotary_units_on_request() {
    let listing = |args: &[&str]| {
        let o = frictionid().args(args).output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let rotary = listing(&["models", "--json", "--axis", "rotary"]);
    assert!(rotary.contains("\"N m s/rad\""), "{rotary}");
    assert!(!rotary.contains("\"N s/m\""), "{rotary}");
    let linear = listing(&["models", "--json"]);
    assert!(linear.contains("\"N s/m\""));
    assert!(!linear.contains("rad"));
}

/// A rotary config without `inertia` is refused where the inertia is needed (a velocity fit,
/// inverse dynamics without it fitted), naming the key by its rotary name, never fitted on
/// the placeholder J = 1.
#[test]
fn a_rotary_axis_without_inertia_is_named_where_it_is_needed() {
    let oscillator = "[oscillator]\naxis = \"rotary\"\ndamping = 0.002\nstiffness = 20.0\n\
                      normal_force = 1.0\n[model]\ntype = \"coulomb\"\n";
    let record = "[[records]]\nfile = \"driven.csv\"\nx0 = 0.0\ndisplacement_column = \"angle\"\n\
                  velocity_column = \"velocity\"\ninput_force_column = \"torque\"\n";
    let binary = std::path::Path::new(env!("CARGO_BIN_EXE_frictionid"));
    assert_bad_inputs(
        binary,
        "rotary",
        &[
            BadInput::new(
                "no-inertia-velocity",
                "fit",
                format!("{oscillator}{record}"),
            )
            .with_file("driven.csv", driven_csv())
            .says(Contains(
                "a velocity-domain fit needs inertia, damping and stiffness; `inertia` not \
                     given",
            )),
            BadInput::new(
                "no-inertia-inverse",
                "fit",
                format!(
                    "{oscillator}[fit.options]\ndomain = \"force\"\n\
                     force_target = \"inverse_dynamics\"\n{record}"
                ),
            )
            .with_file("driven.csv", driven_csv())
            .says(Contains("needs the mass (the inertia)")),
        ],
    );
}
