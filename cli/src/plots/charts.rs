//! The named charts: one function per kind of figure the reports show.

use super::{draw, Figure, Panel, Series, XTicks};
use crate::error::CliError;
use frictionid_engine::identify::ForceBalance;
use frictionid_engine::Axis;
use frictionid_models::FrictionModel;
use plotters::style::RGBColor;
use std::path::Path;

/// How a chart over time is shown: the axis whose units its labels show, and the time window
/// it is cut to (`None`: the whole record).
#[derive(Debug, Clone, Copy, Default)]
pub struct View {
    /// The axis of the units shown.
    pub axis: Axis,
    /// The time window shown.
    pub window: Option<(f64, f64)>,
}

impl From<Axis> for View {
    fn from(axis: Axis) -> Self {
        Self { axis, window: None }
    }
}

/// The measured line (thin, dark and see-through, drawn first) and the fitted line of
/// `model` over it (wider, in the model's colour), so that the fit is never hidden under a
/// noisy measurement and the measurement shows wherever the fit leaves it.
fn fit_and_measured<'a>(
    panel: Panel<'a>,
    x: &'a [f64],
    measured: (&str, &'a [f64]),
    fitted: &'a [f64],
    model: &str,
) -> Panel<'a> {
    panel
        .with(
            Series::solid(measured.0, x, measured.1)
                .width(1)
                .alpha(0.65)
                .color(super::MEASURED),
        )
        .with(
            Series::solid(format!("fitted ({model})"), x, fitted)
                .width(3)
                .alpha(0.9)
                .color(super::model_color(model)),
        )
}

/// The measured and fitted response of one record over time, and their difference:
/// `quantity` is the compared channel and its unit as shown (velocity in m/s, or
/// displacement in m for interferometer records; a fit's units are on its axis already);
/// `window` the time shown; the samples a robust loss down-weighted (`down_weighted`, their
/// times) are marked at zero residual.
pub fn response_fit(
    path: &Path,
    record: &str,
    quantity: (&str, &str),
    time: &[f64],
    series: (&[f64], &[f64]),
    (model, window): (&str, Option<(f64, f64)>),
    down_weighted: &[f64],
) -> Result<(), CliError> {
    let ((name, unit), (measured, fitted)) = (quantity, series);
    let residual: Vec<f64> = measured.iter().zip(fitted).map(|(m, f)| m - f).collect();
    let fit_panel = fit_and_measured(
        Panel::new(name, unit),
        time,
        ("measured", measured),
        fitted,
        model,
    );
    let residual_panel = Panel::new("residual measured - fitted", unit)
        .with(
            Series::solid("", time, &residual)
                .width(1)
                .color(super::REFERENCE_GREY),
        )
        .with_reference("", 0.0);
    let residual_panel = with_sample_marks(
        residual_panel,
        SampleMarks {
            excluded: &[],
            down_weighted,
        },
        0.0,
    );
    let title = format!("{record}: measured and fitted {name}");
    draw(
        path,
        &Figure::over_time(title, vec![fit_panel, residual_panel]).window(window),
    )
}

/// A quantity against time, drawn in a panel of its own by [`over_time`].
#[derive(Debug, Clone, Copy)]
pub enum Quantity<'a> {
    /// Displacement \[m\], shown in mm when it stays within +-0.1 m (records of a few mm).
    Displacement(&'a [f64]),
    /// Velocity [m/s].
    Velocity(&'a [f64]),
    /// Acceleration [m/s²].
    Acceleration(&'a [f64]),
    /// Mechanical energy E = KE + PE \[J\].
    Energy(&'a [f64]),
    /// The rate of change of the mechanical energy \[W\].
    EnergyRate(&'a [f64]),
}

impl<'a> Quantity<'a> {
    /// Its panel: one solid line against `time`; `scaled` holds the values when they are
    /// shown in another unit.
    fn panel(self, time: &'a [f64], scaled: &'a mut Vec<f64>) -> Panel<'a> {
        let (axis, name, y) = match self {
            Quantity::Displacement(x) => return displacement_panel(time, x, scaled),
            Quantity::Velocity(v) => (("velocity", "m/s"), "v", v),
            Quantity::Acceleration(a) => (("acceleration", "m/s²"), "a", a),
            Quantity::Energy(e) => (("energy E = KE + PE", "J"), "E", e),
            Quantity::EnergyRate(r) => (("dE/dt", "W"), "dE/dt", r),
        };
        Panel::new(axis.0, axis.1).with(Series::solid(name, time, y))
    }
}

/// Displacement in mm when it stays within +-0.1 m (records of a few mm), else in m.
fn displacement_panel<'a>(time: &'a [f64], x: &'a [f64], scaled: &'a mut Vec<f64>) -> Panel<'a> {
    let peak = x
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let (unit, y) = if peak < 0.1 {
        *scaled = x.iter().map(|v| v * 1e3).collect();
        ("mm", &scaled[..])
    } else {
        ("m", x)
    };
    Panel::new("displacement", unit).with(Series::solid("x", time, y))
}

/// Quantities against time in stacked panels, in the order given: displacement and velocity
/// (simulations), displacement and the acceleration derived from a measured velocity (the
/// paper's Figs. 9-10), mechanical energy and its rate of change (Figs. 4-5, 11).
/// Units are shown on `view`'s axis, over its window.
pub fn over_time(
    path: &Path,
    title: &str,
    time: &[f64],
    quantities: &[Quantity<'_>],
    view: impl Into<View>,
) -> Result<(), CliError> {
    let view = view.into();
    let mut scaled = vec![Vec::new(); quantities.len()];
    let panels = quantities
        .iter()
        .zip(scaled.iter_mut())
        .map(|(q, s)| q.panel(time, s))
        .collect();
    let fig = Figure::over_time(title, panels)
        .on(view.axis)
        .window(view.window);
    draw(path, &fig)
}

/// Energy-based friction force against the model's force, with dashed levels at +-reference
/// (the paper's Figs. 6, 12), in the units of `view`'s axis: the noisy Eq. 7 trace thin and
/// see-through, the model's force (label, values, colour) wide and drawn over it.
pub fn friction_force(
    path: &Path,
    title: &str,
    time: &[f64],
    energy_force: &[f64],
    model_force: Option<(&str, &[f64], RGBColor)>,
    reference: Option<(&str, f64)>,
    view: View,
) -> Result<(), CliError> {
    let mut panel = Panel::new("friction force", "N").with(
        Series::solid("energy-based (Eq. 7)", time, energy_force)
            .width(1)
            .alpha(0.55)
            .color(super::MEASURED),
    );
    if let Some((name, f, color)) = model_force {
        panel = panel.with(Series::solid(name, time, f).width(3).color(color));
    }
    if let Some((label, r)) = reference {
        panel = panel.with_reference(label, r).with_reference("", -r);
    }
    let fig = Figure::over_time(title, vec![panel])
        .on(view.axis)
        .window(view.window);
    draw(path, &fig)
}

/// The samples a fit's plots mark, by their times: those left out for an unreliable target
/// and those a robust loss down-weighted.
#[derive(Debug, Clone, Copy, Default)]
pub struct SampleMarks<'a> {
    /// Left out of the comparison (an unreliable target).
    pub excluded: &'a [f64],
    /// Given a weight below one half by a robust loss.
    pub down_weighted: &'a [f64],
}

/// Labels of the marked samples in the legends.
const EXCLUDED_LABEL: &str = "left out: unreliable target";
const DOWN_WEIGHTED_LABEL: &str = "down-weighted by the robust loss";

/// `panel` with `marks` at the level `y`: circles for the samples left out, triangles for
/// those down-weighted.
fn with_sample_marks<'a>(panel: Panel<'a>, marks: SampleMarks<'a>, y: f64) -> Panel<'a> {
    panel
        .with_marks(EXCLUDED_LABEL, marks.excluded, y)
        .with_shaped_marks(
            DOWN_WEIGHTED_LABEL,
            super::MarkShape::Triangle,
            marks.down_weighted,
            y,
        )
}

/// The force balance of an inverse-dynamics fit over time: in the upper panel the input u
/// with the inertial force J a and the restoring force R(q); in the lower panel the friction
/// force the balance leaves (u - J a - c v - R(q) - offset) and the fitted law's. Lines break
/// across the samples left out (at rest); the samples left out for an unreliable target and
/// those a robust loss down-weighted (`marks`) are marked at zero friction force. Units are
/// shown on `axis`.
pub fn force_balance(
    path: &Path,
    title: &str,
    time: &[f64],
    balance: &ForceBalance,
    marks: SampleMarks<'_>,
    model: &str,
    axis: Axis,
) -> Result<(), CliError> {
    let gap = |y: &[f64]| super::sets::break_at_gaps(time, y);
    let (input, inertia, restoring) = (
        gap(&balance.input),
        gap(&balance.inertia),
        gap(&balance.restoring),
    );
    let (from_balance, fitted) = (
        gap(&balance.friction_balance),
        gap(&balance.friction_fitted),
    );
    let forces = Panel::new("force", "N")
        .with(Series::solid("input u", time, &input).color(super::MEASURED))
        .with(Series::solid("inertia J a", time, &inertia).width(1))
        .with(Series::dashed("restoring R(q)", time, &restoring).width(1));
    let friction = with_sample_marks(
        fit_and_measured(
            Panel::new("friction force", "N"),
            time,
            ("from the balance", &from_balance),
            &fitted,
            model,
        ),
        marks,
        0.0,
    );
    draw(
        path,
        &Figure::over_time(title, vec![forces, friction]).on(axis),
    )
}

/// The measured input u of a driven record over time (a force, a torque on a rotary axis),
/// its units shown on `axis`.
pub fn input_force(
    path: &Path,
    record: &str,
    time: &[f64],
    input: &[f64],
    axis: Axis,
) -> Result<(), CliError> {
    let panel = Panel::new("input u", "N")
        .with(Series::solid("measured input", time, input).color(super::MEASURED));
    let title = format!("{record}: measured input");
    draw(path, &Figure::over_time(title, vec![panel]).on(axis))
}

/// The named channels of one record (a load, a temperature) against time, one panel each,
/// in the SI unit their scales gave them.
pub fn named_channels(
    path: &Path,
    record: &str,
    time: &[f64],
    channels: &[(&str, &[f64])],
) -> Result<(), CliError> {
    let panels = channels
        .iter()
        .map(|&(name, values)| {
            Panel::new(name, "").with(Series::solid(name, time, values).color(super::MEASURED))
        })
        .collect();
    let title = format!("{record}: named channels");
    draw(path, &Figure::over_time(title, panels))
}

/// The motion axis of a force-against-motion chart: quantity, unit and the factor from SI.
#[derive(Debug, Clone, Copy)]
pub struct MotionAxis {
    /// Quantity, e.g. "displacement".
    pub quantity: &'static str,
    /// Unit shown, e.g. "mm".
    pub unit: &'static str,
    /// Factor from the SI value to the unit shown.
    pub factor: f64,
}

/// Measured and fitted friction force against a motion quantity of one record (force-domain
/// fits): against the displacement these are the hysteresis loops, against the velocity the
/// friction curve. Lines break where samples are missing (masked samples of Eq. 7). `motion`
/// is the motion axis and its values; units are shown on `rig`.
pub fn force_against_motion(
    path: &Path,
    title: &str,
    (axis, motion): (MotionAxis, &[f64]),
    measured: (&str, &[f64]),
    fitted: &[f64],
    model: &str,
    rig: Axis,
) -> Result<(), CliError> {
    let x: Vec<f64> = motion.iter().map(|m| m * axis.factor).collect();
    let panel = fit_and_measured(
        Panel::new("friction force", "N"),
        &x,
        measured,
        fitted,
        model,
    );
    let fig = Figure {
        title: title.into(),
        x_label: axis.quantity.into(),
        x_unit: axis.unit.into(),
        x_ticks: XTicks::Linear,
        panels: vec![panel],
        axis: rig,
        x_window: None,
    };
    draw(path, &fig)
}

/// Half-width of the linear region of the steady-state chart's velocity axis \[m/s\]: below
/// the smallest Stribeck velocities (1e-3 m/s) and above a vibrometer's noise.
pub const STEADY_STATE_LINEAR_WIDTH: f64 = 1e-4;

/// The steady-state friction curves F_ss(v) of several models on one chart, for
/// v in [-v_max, v_max] on a symmetric-log axis (linear within +-1e-4 m/s, then one decade
/// per unit), so that Stribeck regions (1e-3 to 1e-2 m/s) are as wide as the sliding range.
/// Each model keeps its colour ([`super::model_color`]); units are shown on `axis`.
/// `normal_force` is the N the curves are drawn at, `None` when the fit had none (its levels
/// are forces, drawn at N = 1 and the title says so).
pub fn steady_state_curves(
    path: &Path,
    models: &[(&str, &dyn FrictionModel)],
    normal_force: Option<f64>,
    v_max: f64,
    axis: Axis,
) -> Result<(), CliError> {
    let title = match normal_force {
        Some(n) => format!(
            "Steady-state friction curves (N = {} N)",
            crate::report::fmt_num(n)
        ),
        None => "Steady-state friction curves (no normal force: the levels are forces)".into(),
    };
    let normal_force = normal_force.unwrap_or(1.0);
    let n = 1601;
    let w = STEADY_STATE_LINEAR_WIDTH;
    let v_max = if v_max.is_finite() && v_max > w {
        v_max
    } else {
        0.1
    };
    let u_max = super::symlog(v_max, w);
    let u: Vec<f64> = (0..n)
        .map(|i| -u_max + 2.0 * u_max * i as f64 / (n - 1) as f64)
        .collect();
    let v: Vec<f64> = u.iter().map(|&ui| super::symlog_inverse(ui, w)).collect();
    let curves: Vec<Vec<f64>> = models
        .iter()
        .map(|(_, m)| {
            v.iter()
                .map(|&vi| m.steady_state(vi, normal_force))
                .collect()
        })
        .collect();
    // Earlier curves are drawn wider and later ones dashed, so that coinciding curves
    // stay visible.
    let mut panel = Panel::new("steady-state friction force F_ss", "N");
    for (i, ((name, _), f)) in models.iter().zip(&curves).enumerate() {
        let width = 8u32.saturating_sub(3 * i as u32).max(2);
        let s = if i >= 3 {
            Series::dashed(*name, &u, f)
        } else {
            Series::solid(*name, &u, f)
        };
        panel = panel.with(s.width(width).color(super::model_color(name)));
    }
    let fig = Figure {
        title,
        x_label: "sliding velocity (symmetric log scale)".into(),
        x_unit: "m/s".into(),
        x_ticks: XTicks::SymLog { linear_width: w },
        panels: vec![panel],
        axis,
        x_window: None,
    };
    draw(path, &fig)
}
