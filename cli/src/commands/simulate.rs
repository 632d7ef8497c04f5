//! `frictionid simulate CONFIG`: one free vibration from `[oscillator]`, `[model]` and
//! `[simulation]`; writes trajectory.csv, optional record.csv (noisy velocity), plots,
//! report.md and report.json.

use super::{print_json, say, warn, Outcome};
use crate::args::OutputArgs;
use crate::config::{Config, IntegratorConfig, IntegratorMethod, SimulationConfig};
use crate::plots;
use crate::report::{csv_columns, fmt_num, markdown_table, text_table, OutputDir};
use anyhow::Context;
use frictionid_engine::synthetic::{add_gaussian_noise, uniform_times};
use frictionid_engine::{simulate, Initial, Integrator, SimOptions, Trajectory};
use serde_json::json;
use std::path::Path;
use std::time::Instant;

/// The engine options for `[simulation.integrator]` (engine defaults where not given).
pub fn sim_options(cfg: &IntegratorConfig) -> SimOptions {
    let mut opts = SimOptions::default();
    match cfg.method {
        IntegratorMethod::Auto => opts.integrator = Integrator::Auto,
        IntegratorMethod::Exact => opts.integrator = Integrator::Exact,
        IntegratorMethod::Dopri5 => opts.integrator = Integrator::Dopri5,
        IntegratorMethod::Euler => {
            let steps_per_period = match (cfg.steps_per_period, &opts.integrator) {
                (Some(n), _) => n,
                (None, Integrator::Euler { steps_per_period }) => *steps_per_period,
                (None, _) => 10_000.0,
            };
            opts.integrator = Integrator::Euler { steps_per_period };
        }
    }
    if let Some(r) = cfg.rtol {
        opts.rtol = r;
    }
    if let Some(a) = cfg.atol {
        opts.atol = a;
    }
    if let Some(m) = cfg.max_steps {
        opts.max_steps = m;
    }
    if let Some(m) = cfg.max_events {
        opts.max_events = m;
    }
    opts
}

/// Rate of change of the mechanical energy along the exact states:
/// dE/dt = v (m a + k x) = -(c v + F) v.
pub fn energy_rate(mass: f64, stiffness: f64, x: &[f64], v: &[f64], a: &[f64]) -> Vec<f64> {
    x.iter()
        .zip(v)
        .zip(a)
        .map(|((&x, &v), &a)| v * (mass * a + stiffness * x))
        .collect()
}

/// Final displacement and rest time: at rest if the mass stuck for good, else at the end.
fn final_state(traj: &Trajectory) -> (f64, Option<f64>) {
    match &traj.rest {
        Some(r) => (r.displacement, Some(r.time)),
        None => (traj.x.last().copied().unwrap_or(f64::NAN), None),
    }
}

/// trajectory.csv: time, x, v, a, internal states z1..zn, friction, energies.
fn trajectory_csv(traj: &Trajectory) -> String {
    let state_names: Vec<String> = (1..=traj.states.len()).map(|j| format!("z{j}")).collect();
    let mut cols: Vec<(&str, &[f64])> = vec![
        ("time", &traj.time),
        ("x", &traj.x),
        ("v", &traj.v),
        ("a", &traj.a),
    ];
    for (name, z) in state_names.iter().zip(&traj.states) {
        cols.push((name, z));
    }
    cols.extend([
        ("friction", traj.friction.as_slice()),
        ("kinetic", traj.kinetic.as_slice()),
        ("potential", traj.potential.as_slice()),
        ("stored", traj.stored.as_slice()),
        ("energy", traj.energy.as_slice()),
    ]);
    csv_columns(&cols)
}

/// Runs `frictionid simulate`.
pub fn run(config: &Path, output: &OutputArgs) -> anyhow::Result<Outcome> {
    let cfg = Config::load(config)?;
    let model_cfg = cfg.require_model("simulate")?;
    for w in &model_cfg.warnings {
        warn(&format!("{}: [model]: {w}", config.display()));
    }
    let sim: &SimulationConfig = cfg.require_simulation("simulate")?;
    let model = model_cfg.model.as_ref();
    let times = uniform_times(sim.duration, sim.sample_rate);
    let opts = sim_options(&sim.integrator);
    let init = Initial {
        x0: sim.x0,
        v0: sim.v0,
        z0: sim.z0.clone(),
    };

    let started = Instant::now();
    let traj = simulate(&cfg.oscillator, model, &init, sim.duration, &times, &opts)
        .with_context(|| format!("{}: simulation failed", config.display()))?;
    let wall_time_s = started.elapsed().as_secs_f64();

    let (final_displacement, rest_time) = final_state(&traj);
    let half_cycles = traj.half_cycles();
    let osc = &cfg.oscillator;
    let de_dt = energy_rate(osc.mass, osc.stiffness, &traj.x, &traj.v, &traj.a);

    // Everything is computed; now write, report.json last.
    let out = OutputDir::create(&output.out)?;
    let mut files = vec!["trajectory.csv".to_string()];
    out.write_text("trajectory.csv", &trajectory_csv(&traj))?;
    if let Some(sigma) = sim.noise {
        let mut noisy = traj.v.clone();
        add_gaussian_noise(&mut noisy, sigma, sim.seed);
        let header = format!(
            "# synthetic velocity record: frictionid simulate {}; model {}; x0 = {} m; noise sigma = {} m/s; seed = {}\n",
            config.display(),
            serde_json::to_string(&model_cfg.model)?,
            sim.x0,
            sigma,
            sim.seed
        );
        let body = csv_columns(&[("time", &traj.time), ("velocity", &noisy)]);
        out.write_text("record.csv", &(header + &body))?;
        files.push("record.csv".into());
    }
    let title = format!("{} from x0 = {} m", model.name(), fmt_num(sim.x0));
    plots::displacement_velocity(
        &out.path("displacement_velocity.svg"),
        &format!("Free vibration: {title}"),
        &traj.time,
        &traj.x,
        &traj.v,
    )?;
    files.push("displacement_velocity.svg".into());
    plots::draw(
        &out.path("energy.svg"),
        &plots::Figure {
            title: format!("Energy: {title}"),
            x_label: "time".into(),
            x_unit: "s".into(),
            panels: vec![
                plots::Panel::new("energy", "J")
                    .with(plots::Series::solid("kinetic", &traj.time, &traj.kinetic))
                    .with(plots::Series::solid(
                        "potential",
                        &traj.time,
                        &traj.potential,
                    ))
                    .with(plots::Series::solid(
                        "E = KE + PE",
                        &traj.time,
                        &traj.energy,
                    )),
                plots::Panel::new("dE/dt", "W").with(plots::Series::solid(
                    "dE/dt = -(c v + F) v",
                    &traj.time,
                    &de_dt,
                )),
            ],
        },
    )?;
    files.push("energy.svg".into());
    files.push("report.md".into());
    files.push("report.json".into());

    let report = json!({
        "command": "simulate",
        "config": config.display().to_string(),
        "oscillator": osc,
        "model": &model_cfg.model,
        "x0": sim.x0,
        "v0": sim.v0,
        "duration": sim.duration,
        "sample_rate": sim.sample_rate,
        "samples": traj.time.len(),
        "final_displacement": final_displacement,
        "rest_time": rest_time,
        "half_cycles": half_cycles,
        "events": &traj.events,
        "stats": &traj.stats,
        "wall_time_s": wall_time_s,
        "noise": sim.noise,
        "seed": sim.noise.map(|_| sim.seed),
        "files": files,
    });

    let summary_rows = vec![
        vec!["model".to_string(), model.name().to_string(), String::new()],
        vec!["x0".into(), fmt_num(sim.x0), "m".into()],
        vec![
            "final displacement".into(),
            fmt_num(final_displacement),
            "m".into(),
        ],
        vec![
            "rest time".into(),
            rest_time.map(fmt_num).unwrap_or_else(|| "no rest".into()),
            "s".into(),
        ],
        vec!["half-cycles".into(), half_cycles.to_string(), String::new()],
        vec![
            "events".into(),
            traj.events.len().to_string(),
            String::new(),
        ],
        vec![
            "steps (rejected)".into(),
            format!("{} ({})", traj.stats.steps, traj.stats.rejected_steps),
            String::new(),
        ],
        vec![
            "rhs evaluations".into(),
            traj.stats.rhs_evaluations.to_string(),
            String::new(),
        ],
        vec!["wall time".into(), format!("{wall_time_s:.4}"), "s".into()],
    ];
    let event_rows: Vec<Vec<String>> = traj
        .events
        .iter()
        .map(|e| {
            vec![
                fmt_num(e.time),
                serde_json::to_value(e.kind)
                    .ok()
                    .and_then(|k| k.as_str().map(str::to_string))
                    .unwrap_or_default(),
                fmt_num(e.displacement),
            ]
        })
        .collect();
    let md = format!(
        "# frictionid simulate\n\nConfig: `{}`. Model: `{}`.\n\n{}\n## Events\n\n{}\n## Files\n\n{}\n",
        config.display(),
        serde_json::to_string(&model_cfg.model)?,
        markdown_table(&["quantity", "value", "unit"], &summary_rows),
        markdown_table(&["time [s]", "kind", "displacement [m]"], &event_rows),
        report["files"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|f| f.as_str())
            .map(|f| format!("- `{f}`\n"))
            .collect::<String>()
    );
    out.write_text("report.md", &md)?;
    out.write_json("report.json", &report)?;

    say(
        output,
        &format!(
            "{}\nwrote {}\n",
            text_table(&["quantity", "value", "unit"], &summary_rows),
            out.dir().display()
        ),
    );
    print_json(output, &report)?;
    Ok(Outcome::Done)
}

#[cfg(test)]
mod tests {
    use super::*;
    use frictionid_engine::exact::coulomb_free_vibration;
    use frictionid_engine::Oscillator;

    #[test]
    fn integrator_config_maps_onto_engine_options() {
        let d = SimOptions::default();
        assert_eq!(sim_options(&IntegratorConfig::default()), d);
        let o = sim_options(&IntegratorConfig {
            method: IntegratorMethod::Euler,
            steps_per_period: Some(1e5),
            rtol: Some(1e-6),
            max_events: Some(7),
            ..IntegratorConfig::default()
        });
        assert_eq!(
            o.integrator,
            Integrator::Euler {
                steps_per_period: 1e5
            }
        );
        assert_eq!((o.rtol, o.atol, o.max_events), (1e-6, d.atol, 7));
    }

    /// The energy rate from the states equals the power of the dissipative forces,
    /// -(c v + mu N sgn v) v, on the exact Coulomb solution.
    #[test]
    fn energy_rate_is_the_dissipated_power() {
        let osc = Oscillator::fmm();
        let f = 0.24 * osc.normal_force;
        let t: Vec<f64> = (0..500).map(|i| i as f64 * 1e-3 + 1e-4).collect();
        let s = coulomb_free_vibration(&osc, f, 0.014, &t).unwrap();
        let rate = energy_rate(osc.mass, osc.stiffness, &s.x, &s.v, &s.a);
        for i in 0..t.len() {
            let v = s.v[i];
            let expect = -(osc.damping * v + f * v.signum()) * v;
            let expect = if v == 0.0 { 0.0 } else { expect };
            assert!(
                (rate[i] - expect).abs() < 1e-9,
                "t = {}: {} vs {expect}",
                t[i],
                rate[i]
            );
        }
    }
}
