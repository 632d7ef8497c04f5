//! `frictionid init DATAFILE [--out CONFIG] [--mass ..]`: reads a data file (the engine's
//! [`survey`]), prints what it found and writes a commented configuration that runs once the
//! rig's values are given (here, or on the lines marked `<- SET`).

pub use crate::args::RigValues;
use crate::error::CliError;
use frictionid_engine::data::sniff::{survey, Survey};
use frictionid_engine::record::Channel;
use frictionid_engine::Axis;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The marker of a line that needs the rig's value.
const SET: &str = "<- SET";

/// Runs `frictionid init`.
pub fn run(
    datafile: &Path,
    out: Option<&Path>,
    rig: &RigValues,
    force: bool,
    quiet: bool,
) -> anyhow::Result<()> {
    let found = survey(datafile)?;
    let config = out
        .map(Path::to_path_buf)
        .unwrap_or_else(|| datafile.with_extension("toml"));
    if config.exists() && !force {
        return Err(CliError::Config(format!(
            "{}: exists; give another --out or --force to replace it",
            config.display()
        ))
        .into());
    }
    let plan = Plan::new(&found, rig);
    let text = config_text(&found, rig, &plan, &record_path(datafile, &config));
    std::fs::write(&config, text).map_err(|e| CliError::Write {
        path: config.clone(),
        reason: e.to_string(),
    })?;
    if !quiet {
        print!("{}", summary(&found, &plan, &config));
    }
    Ok(())
}

/// The data file as the config names it: relative to the config's directory when it lies in
/// it or below it (its name when both sit in one directory), else its absolute path.
fn record_path(datafile: &Path, config: &Path) -> String {
    let dir = |p: &Path| {
        p.parent()
            .map(|d| {
                if d.as_os_str().is_empty() {
                    Path::new(".")
                } else {
                    d
                }
            })
            .and_then(|d| d.canonicalize().ok())
    };
    let below = match (dir(datafile), dir(config), datafile.file_name()) {
        (Some(a), Some(b), Some(name)) => a.strip_prefix(&b).ok().map(|rel| rel.join(name)),
        _ => None,
    };
    match below {
        Some(relative) => relative.display().to_string(),
        None => datafile
            .canonicalize()
            .unwrap_or_else(|_| PathBuf::from(datafile))
            .display()
            .to_string(),
    }
}

/// What the configuration will say: the axis, whether the axis has a spring, the domain, and
/// where x0 comes from.
struct Plan {
    axis: Axis,
    spring: bool,
    driven: bool,
    force_domain: bool,
    x0: X0,
}

/// Where a record's release displacement comes from.
enum X0 {
    /// Not needed (a displacement channel, no spring, or a force-domain fit).
    NotNeeded,
    /// Given on the command line.
    Given(f64),
    /// Estimated from the velocity and fitted from there.
    Estimated(f64),
    /// Unknown: to set.
    Unknown,
}

impl Plan {
    fn new(found: &Survey, rig: &RigValues) -> Self {
        let channels = found.channels();
        let driven = channels.contains(&Channel::InputForce);
        let spring = rig.stiffness.map_or(!driven, |k| k > 0.0);
        let force_domain = channels.contains(&Channel::Force) && !driven;
        let needs_x0 = spring
            && !force_domain
            && !channels.contains(&Channel::Displacement)
            && channels.contains(&Channel::Velocity);
        let x0 = match (needs_x0, rig.x0, found.x0_estimate) {
            (false, _, _) => X0::NotNeeded,
            (true, Some(x), _) => X0::Given(x),
            (true, None, Some(x)) => X0::Estimated(x),
            (true, None, None) => X0::Unknown,
        };
        Self {
            axis: rig.axis.or(found.axis).unwrap_or(Axis::Linear),
            spring,
            driven,
            force_domain,
            x0,
        }
    }
}

/// The unit of an oscillator property on the plan's axis.
fn unit(plan: &Plan, linear: &'static str, rotary: &'static str) -> &'static str {
    if plan.axis.is_linear() {
        linear
    } else {
        rotary
    }
}

/// `key = value  # comment`, or the key commented out and marked when the value is not known.
fn line(out: &mut String, key: &str, value: Option<f64>, comment: &str, required: bool) {
    let _ = match value {
        Some(v) => writeln!(out, "{:<30} # {comment}", format!("{key} = {v:?}")),
        None if required => writeln!(out, "{:<30} # {SET}: {comment}", format!("# {key} = ")),
        None => writeln!(out, "{:<30} # {comment}", format!("# {key} = ")),
    };
}

/// The configuration's text.
fn config_text(found: &Survey, rig: &RigValues, plan: &Plan, file: &str) -> String {
    let mut t = String::new();
    let name = found.file.display();
    let _ = writeln!(
        t,
        "# Written by `frictionid init {name}`. Give the rig's values where a line says SET\n\
         # (or on init's command line), then:\n\
         #   frictionid compare THIS.toml   (which friction law fits; the report recommends one)\n\
         #   frictionid fit THIS.toml       (the law of [model])\n\
         # Every key: `frictionid help config`.\n"
    );
    oscillator_table(&mut t, rig, plan);
    let _ = writeln!(
        t,
        "\n[model]\ntype = \"coulomb\"                # the law `fit` fits (`frictionid models` lists them)\n"
    );
    let _ = writeln!(t, "[fit.options]");
    let _ = writeln!(
        t,
        "models = [\"coulomb\", \"viscous_coulomb\", \"stribeck\"]  # compare's laws; add \"dahl\", \"lugre\" (slower)"
    );
    if plan.force_domain {
        let _ = writeln!(
            t,
            "domain = \"force\"               # fit the measured friction force along the motion"
        );
    }
    if let X0::Estimated(_) = plan.x0 {
        let _ = writeln!(t, "x0 = true                       # fit the release displacement from the estimate below");
    }
    record_entry(&mut t, found, plan, file);
    t
}

/// The `[oscillator]` table.
fn oscillator_table(t: &mut String, rig: &RigValues, plan: &Plan) {
    let _ = writeln!(
        t,
        "[oscillator]                    # m x'' + c x' + R(x) + F = u"
    );
    if !plan.axis.is_linear() {
        let _ = writeln!(t, "axis = \"rotary\"");
    }
    let mass = if plan.axis.is_linear() {
        "mass"
    } else {
        "inertia"
    };
    line(
        t,
        mass,
        rig.mass,
        unit(plan, "kg, the moving mass", "kg m^2, the moment of inertia"),
        true,
    );
    line(
        t,
        "damping",
        rig.damping,
        unit(
            plan,
            "N s/m (0 when not given)",
            "N m s/rad (0 when not given)",
        ),
        false,
    );
    if plan.spring {
        line(
            t,
            "stiffness",
            rig.stiffness,
            unit(plan, "N/m, the spring", "N m/rad, the spring"),
            true,
        );
    } else {
        let _ = writeln!(t, "restoring = {{ type = \"none\" }}  # no spring: the axis is driven (give `stiffness` if it has one)");
    }
    line(
        t,
        "normal_force",
        rig.normal_force,
        "N (without it the friction levels are forces, not coefficients)",
        false,
    );
}

/// The `[[records]]` entry.
fn record_entry(t: &mut String, found: &Survey, plan: &Plan, file: &str) {
    let _ = writeln!(t, "\n[[records]]\nfile = {file:?}");
    let delimiter = serde_json::to_value(found.delimiter).ok();
    let decimal = found.decimal.name();
    if let Some(serde_json::Value::String(d)) = delimiter {
        let _ = writeln!(t, "delimiter = {d:?}");
    }
    let _ = writeln!(t, "decimal = {decimal:?}");
    for c in &found.columns {
        let Some(role) = c.role else { continue };
        let key = role.key();
        let _ = writeln!(t, "{key}_column = {:?}", c.name);
        match c.scale {
            Some(s) => {
                let from = c.unit.as_deref().unwrap_or("no unit given: SI assumed");
                let _ = writeln!(
                    t,
                    "{:<30} # {from} -> {}",
                    format!("{key}_scale = {s:?}"),
                    role.si_unit(plan.axis)
                );
            }
            None => {
                let _ = writeln!(
                    t,
                    "{key}_scale = nan                # {SET}: the factor from {} to {}",
                    c.unit.as_deref().unwrap_or("?"),
                    role.si_unit(plan.axis)
                );
            }
        }
    }
    for u in &found.undecided {
        let _ = writeln!(t, "# {} = ...   # {SET}: {}", u.key, u.reason);
    }
    if let Some(r) = found.release {
        let _ = writeln!(
            t,
            "release = \"auto\"               # the rest before the release ({r:.6} s) is dropped"
        );
    }
    let len = unit(plan, "m", "rad");
    match plan.x0 {
        X0::NotNeeded => {}
        X0::Given(x) => {
            let _ = writeln!(
                t,
                "{:<30} # {len}, the release displacement",
                format!("x0 = {x:?}")
            );
        }
        X0::Estimated(x) => {
            let _ = writeln!(
                t,
                "{:<30} # {len}, estimated from the velocity; give the measured one and drop \
                 `x0 = true` in [fit.options]",
                format!("x0 = {:?}", round_sig(x, 4))
            );
        }
        X0::Unknown => {
            let _ = writeln!(
                t,
                "# x0 =                          # {SET}: {len}, the release displacement"
            );
        }
    }
}

/// `x` to `digits` significant digits.
fn round_sig(x: f64, digits: i32) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let scale = 10f64.powi(digits - 1 - x.abs().log10().floor() as i32);
    (x * scale).round() / scale
}

/// What init found and what is left to set, for the terminal.
fn summary(found: &Survey, plan: &Plan, config: &Path) -> String {
    let mut s = String::new();
    let delimiter = serde_json::to_value(found.delimiter)
        .ok()
        .and_then(|v| v.as_str().map(String::from))
        .unwrap_or_default();
    let _ = writeln!(
        s,
        "{}: {delimiter}-separated, decimal {}, header on line {} after {} preamble line(s)",
        found.file.display(),
        found.decimal.name(),
        found.header_line,
        found.preamble_lines
    );
    for c in &found.columns {
        let role = c
            .role
            .map_or("not read".to_string(), |r| r.key().to_string());
        let scale = c.scale.map_or("scale unknown".into(), |x| format!("x {x}"));
        let _ = writeln!(s, "  `{}` -> {role} ({scale})", c.name);
    }
    let _ = writeln!(
        s,
        "  {} samples at {:.6} Hz over {:.6} s",
        found.samples, found.sample_rate, found.duration
    );
    if let Some(r) = found.release {
        let _ = writeln!(
            s,
            "  a pre-trigger rest until {r:.6} s: release = \"auto\" drops it"
        );
    }
    match plan.x0 {
        X0::Estimated(x) => {
            let _ = writeln!(
                s,
                "  x0 estimated from the velocity: {x:.6} (fitted from there)"
            );
        }
        X0::Unknown => {
            let _ = writeln!(s, "  x0: cannot be estimated: give --x0 or set `x0`");
        }
        _ => {}
    }
    if plan.driven {
        let _ = writeln!(
            s,
            "  an input column: a driven axis (no spring unless --stiffness)"
        );
    }
    let text = std::fs::read_to_string(config).unwrap_or_default();
    let to_set: Vec<&str> = text.lines().filter(|l| l.contains(SET)).collect();
    if to_set.is_empty() {
        let _ = writeln!(s, "wrote {} (runs as written)", config.display());
    } else {
        let _ = writeln!(s, "wrote {}; set these lines first:", config.display());
        for l in to_set {
            let _ = writeln!(s, "  {}", l.trim());
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A config beside or above its data file names it relatively, so the two travel
    /// together; elsewhere it names it absolutely.
    #[test]
    fn the_record_path_is_relative_to_the_config_where_it_can_be() {
        let root =
            std::env::temp_dir().join(format!("frictionid-init-path-{}", std::process::id()));
        let data_dir = root.join("data").join("run1");
        std::fs::create_dir_all(&data_dir).unwrap();
        let data = data_dir.join("v.csv");
        std::fs::write(&data, "time,velocity\n0,0\n").unwrap();
        assert_eq!(record_path(&data, &data_dir.join("c.toml")), "v.csv");
        assert_eq!(record_path(&data, &root.join("c.toml")), "data/run1/v.csv");
        let elsewhere = record_path(&data, &data_dir.join("..").join("other").join("c.toml"));
        assert!(Path::new(&elsewhere).is_absolute(), "{elsewhere}");
        let _ = std::fs::remove_dir_all(&root);
    }

    #[test]
    fn significant_digits() {
        assert_eq!(round_sig(0.0140123, 4), 0.01401);
        assert_eq!(round_sig(-2.5e-5, 2), -2.5e-5);
    }
}
