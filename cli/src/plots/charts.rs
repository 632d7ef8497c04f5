//! The named charts: one function per kind of figure the reports show.

use super::{draw, Figure, Panel, Series};
use crate::error::CliError;
use frictionid_models::FrictionModel;
use std::path::Path;

/// Measured and fitted velocity of one record (the paper's Fig. 8).
pub fn velocity_fit(
    path: &Path,
    record: &str,
    time: &[f64],
    measured: &[f64],
    fitted: &[f64],
    model: &str,
) -> Result<(), CliError> {
    let panel = Panel::new("velocity", "m/s")
        .with(Series::solid("measured", time, measured))
        .with(Series::dashed(format!("fitted ({model})"), time, fitted));
    let title = format!("{record}: measured and fitted velocity");
    draw(path, &Figure::over_time(title, vec![panel]))
}

/// A panel with one solid line `name` of `y` against `time`; `axis` is (quantity, unit).
fn line_panel<'a>(axis: (&str, &str), name: &str, time: &'a [f64], y: &'a [f64]) -> Panel<'a> {
    Panel::new(axis.0, axis.1).with(Series::solid(name, time, y))
}

/// Displacement and velocity against time (simulations).
pub fn displacement_velocity(
    path: &Path,
    title: &str,
    time: &[f64],
    x: &[f64],
    v: &[f64],
) -> Result<(), CliError> {
    let panels = vec![
        line_panel(("displacement", "m"), "x", time, x),
        line_panel(("velocity", "m/s"), "v", time, v),
    ];
    draw(path, &Figure::over_time(title, panels))
}

/// Displacement and acceleration derived from a measured velocity (the paper's Figs. 9-10).
pub fn displacement_acceleration(
    path: &Path,
    title: &str,
    time: &[f64],
    x: &[f64],
    a: &[f64],
) -> Result<(), CliError> {
    let panels = vec![
        line_panel(("displacement", "m"), "x", time, x),
        line_panel(("acceleration", "m/s²"), "a", time, a),
    ];
    draw(path, &Figure::over_time(title, panels))
}

/// Mechanical energy and its rate of change (the paper's Figs. 4-5, 11).
pub fn energy_rate(
    path: &Path,
    title: &str,
    time: &[f64],
    energy: &[f64],
    de_dt: &[f64],
) -> Result<(), CliError> {
    let panels = vec![
        line_panel(("energy E = KE + PE", "J"), "E", time, energy),
        line_panel(("dE/dt", "W"), "dE/dt", time, de_dt),
    ];
    draw(path, &Figure::over_time(title, panels))
}

/// Energy-based friction force against the model's force, with dashed levels at +-reference
/// (the paper's Figs. 6, 12).
pub fn friction_force(
    path: &Path,
    title: &str,
    time: &[f64],
    energy_force: &[f64],
    model_force: Option<(&str, &[f64])>,
    reference: Option<(&str, f64)>,
) -> Result<(), CliError> {
    let mut panel = Panel::new("friction force", "N").with(Series::solid(
        "energy-based (Eq. 7)",
        time,
        energy_force,
    ));
    if let Some((name, f)) = model_force {
        panel = panel.with(Series::dashed(name, time, f));
    }
    if let Some((label, r)) = reference {
        panel = panel.with_reference(label, r).with_reference("", -r);
    }
    draw(path, &Figure::over_time(title, vec![panel]))
}

/// The steady-state friction curves F_ss(v) of several models on one chart, for
/// v in [-v_max, v_max].
pub fn steady_state_curves(
    path: &Path,
    models: &[(&str, &dyn FrictionModel)],
    normal_force: f64,
    v_max: f64,
) -> Result<(), CliError> {
    let n = 801;
    let v_max = if v_max.is_finite() && v_max > 0.0 {
        v_max
    } else {
        0.1
    };
    let v: Vec<f64> = (0..n)
        .map(|i| -v_max + 2.0 * v_max * i as f64 / (n - 1) as f64)
        .collect();
    let curves: Vec<(String, Vec<f64>)> = models
        .iter()
        .map(|(name, m)| {
            (
                name.to_string(),
                v.iter()
                    .map(|&vi| m.steady_state(vi, normal_force))
                    .collect(),
            )
        })
        .collect();
    // Earlier curves are drawn wider and later ones dashed, so that coinciding curves
    // stay visible.
    let mut panel = Panel::new("steady-state friction force F_ss", "N");
    for (i, (name, f)) in curves.iter().enumerate() {
        let width = 5u32.saturating_sub(i as u32).max(2);
        let s = if i >= 3 {
            Series::dashed(name.clone(), &v, f)
        } else {
            Series::solid(name.clone(), &v, f)
        };
        panel = panel.with(s.width(width));
    }
    let fig = Figure {
        title: format!(
            "Steady-state friction curves (N = {} N)",
            crate::report::fmt_num(normal_force)
        ),
        x_label: "sliding velocity".into(),
        x_unit: "m/s".into(),
        panels: vec![panel],
    };
    draw(path, &fig)
}
