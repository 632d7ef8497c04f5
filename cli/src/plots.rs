//! SVG plots (plotters): line charts of named series against time in one or more stacked
//! panels, with axis labels and units, dashed reference lines, and the steady-state friction
//! curves F_ss(v) of several models.
//!
//! Non-finite values (e.g. the masked samples of the energy-based friction force) break a line
//! into segments instead of being drawn.

use crate::error::CliError;
use crate::report::write_atomic;
use frictionid_models::FrictionModel;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Line colours (Tableau 10), cycled.
const COLORS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

/// One named line.
#[derive(Debug, Clone)]
pub struct Series<'a> {
    /// Legend label.
    pub label: String,
    /// Abscissa values.
    pub x: &'a [f64],
    /// Ordinate values (same length as `x`; non-finite values leave gaps).
    pub y: &'a [f64],
    /// Draw dashed instead of solid.
    pub dashed: bool,
    /// Line width in pixels.
    pub width: u32,
}

impl<'a> Series<'a> {
    /// A solid line.
    pub fn solid(label: impl Into<String>, x: &'a [f64], y: &'a [f64]) -> Self {
        Self {
            label: label.into(),
            x,
            y,
            dashed: false,
            width: 2,
        }
    }

    /// The same line drawn `width` pixels wide.
    pub fn width(self, width: u32) -> Self {
        Self { width, ..self }
    }

    /// A dashed line.
    pub fn dashed(label: impl Into<String>, x: &'a [f64], y: &'a [f64]) -> Self {
        Self {
            dashed: true,
            ..Self::solid(label, x, y)
        }
    }
}

/// A horizontal dashed reference line (e.g. the Coulomb level mu N).
#[derive(Debug, Clone)]
pub struct RefLine {
    /// Legend label.
    pub label: String,
    /// Level on the panel's y axis.
    pub y: f64,
}

/// One chart panel: its y axis and its lines.
#[derive(Debug, Clone)]
pub struct Panel<'a> {
    /// Quantity on the y axis, e.g. "velocity".
    pub y_label: String,
    /// Unit of the y axis, e.g. "m/s".
    pub y_unit: String,
    /// The lines.
    pub series: Vec<Series<'a>>,
    /// Dashed horizontal reference lines.
    pub reference: Vec<RefLine>,
}

impl<'a> Panel<'a> {
    /// A panel with a y label and unit and no lines yet.
    pub fn new(y_label: impl Into<String>, y_unit: impl Into<String>) -> Self {
        Self {
            y_label: y_label.into(),
            y_unit: y_unit.into(),
            series: Vec::new(),
            reference: Vec::new(),
        }
    }

    /// Adds a line.
    pub fn with(mut self, s: Series<'a>) -> Self {
        self.series.push(s);
        self
    }

    /// Adds a dashed reference level.
    pub fn with_reference(mut self, label: impl Into<String>, y: f64) -> Self {
        self.reference.push(RefLine {
            label: label.into(),
            y,
        });
        self
    }
}

/// A figure: a title, a shared x axis and one or more panels stacked vertically.
#[derive(Debug, Clone)]
pub struct Figure<'a> {
    /// Title above the panels.
    pub title: String,
    /// Quantity on the x axis.
    pub x_label: String,
    /// Unit of the x axis.
    pub x_unit: String,
    /// The panels, top to bottom.
    pub panels: Vec<Panel<'a>>,
}

fn axis_text(label: &str, unit: &str) -> String {
    if unit.is_empty() {
        label.to_string()
    } else {
        format!("{label} [{unit}]")
    }
}

/// Tick label for `v` on an axis spanning `span`: round-off next to zero shows as 0, and the
/// number of decimals follows the span.
fn tick(v: f64, span: f64) -> String {
    let span = if span.is_finite() && span > 0.0 {
        span
    } else {
        1.0
    };
    if v.abs() < 1e-9 * span {
        return "0".into();
    }
    if !(1e-3..1e5).contains(&span) {
        let s = format!("{v:.2e}");
        return match s.split_once('e') {
            Some((m, e)) => format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.')),
            None => s,
        };
    }
    let decimals = (2.0 - (span / 10.0).log10().floor()).clamp(0.0, 8.0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// The finite range of `values`, padded by 5 %; [0, 1] if there is none.
fn range(values: impl Iterator<Item = f64>, pad: bool) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !(lo.is_finite() && hi.is_finite()) {
        return (0.0, 1.0);
    }
    if hi - lo <= f64::EPSILON * (lo.abs() + hi.abs()).max(1e-300) {
        let d = if lo == 0.0 { 1.0 } else { lo.abs() * 0.1 };
        return (lo - d, hi + d);
    }
    let p = if pad { 0.05 * (hi - lo) } else { 0.0 };
    (lo - p, hi + p)
}

/// Runs of consecutive finite points.
fn segments(x: &[f64], y: &[f64]) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut cur = Vec::new();
    for (&a, &b) in x.iter().zip(y) {
        if a.is_finite() && b.is_finite() {
            cur.push((a, b));
        } else if !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

type PlotResult<T> = Result<T, String>;

fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    fig: &Figure<'_>,
    panel: &Panel<'_>,
    x_range: (f64, f64),
    is_last: bool,
) -> PlotResult<()> {
    let mut y_range = range(
        panel
            .series
            .iter()
            .flat_map(|s| s.y.iter().copied())
            .chain(panel.reference.iter().map(|r| r.y)),
        true,
    );
    // A legend for more than one line (or any reference line), in the upper right corner:
    // extend the y range upwards so that it covers no data.
    let entries = panel.series.iter().filter(|s| !s.label.is_empty()).count()
        + panel
            .reference
            .iter()
            .filter(|r| !r.label.is_empty())
            .count();
    let show_legend = entries > 1 || !panel.reference.is_empty();
    if show_legend {
        y_range.1 += (0.04 + 0.075 * entries as f64) * (y_range.1 - y_range.0);
    }
    let (x_span, y_span) = (x_range.1 - x_range.0, y_range.1 - y_range.0);
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(if is_last { 45 } else { 30 })
        .y_label_area_size(80)
        .build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1)
        .map_err(|e| e.to_string())?;
    let x_desc = axis_text(&fig.x_label, &fig.x_unit);
    let y_desc = axis_text(&panel.y_label, &panel.y_unit);
    let x_fmt = |v: &f64| tick(*v, x_span);
    let y_fmt = |v: &f64| tick(*v, y_span);
    let mut mesh = chart.configure_mesh();
    mesh.y_desc(y_desc)
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .light_line_style(RGBColor(235, 235, 235));
    if is_last {
        mesh.x_desc(x_desc);
    }
    mesh.draw().map_err(|e| e.to_string())?;

    for (i, s) in panel.series.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        let style = color.stroke_width(s.width);
        let width = s.width;
        for (k, seg) in segments(s.x, s.y).into_iter().enumerate() {
            let anno = if s.dashed {
                chart
                    .draw_series(DashedLineSeries::new(seg, 8, 5, style))
                    .map_err(|e| e.to_string())?
            } else {
                chart
                    .draw_series(LineSeries::new(seg, style))
                    .map_err(|e| e.to_string())?
            };
            if k == 0 && !s.label.is_empty() {
                anno.label(s.label.clone()).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 22, y)], color.stroke_width(width))
                });
            }
        }
    }
    for (j, r) in panel.reference.iter().enumerate() {
        let color = if j == 0 {
            BLACK
        } else {
            RGBColor(110, 110, 110)
        };
        let style = color.stroke_width(1);
        let line = vec![(x_range.0, r.y), (x_range.1, r.y)];
        let anno = chart
            .draw_series(DashedLineSeries::new(line, 6, 4, style))
            .map_err(|e| e.to_string())?;
        if !r.label.is_empty() {
            anno.label(r.label.clone()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 8, y), (x + 14, y), (x + 22, y)], style)
            });
        }
    }
    if show_legend {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font(("sans-serif", 14))
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(160, 160, 160))
            .draw()
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// Renders `fig` as SVG text.
pub fn render(fig: &Figure<'_>) -> Result<String, String> {
    let n = fig.panels.len().max(1);
    let size = (960u32, 70 + 330 * n as u32);
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let root = root
            .titled(&fig.title, ("sans-serif", 22))
            .map_err(|e| e.to_string())?;
        let x_range = range(
            fig.panels
                .iter()
                .flat_map(|p| p.series.iter())
                .flat_map(|s| s.x.iter().copied()),
            false,
        );
        let areas = root.split_evenly((n, 1));
        for (i, (area, panel)) in areas.iter().zip(&fig.panels).enumerate() {
            draw_panel(area, fig, panel, x_range, i + 1 == fig.panels.len())?;
        }
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(buf)
}

/// Renders `fig` and writes it atomically to `path`.
pub fn draw(path: &Path, fig: &Figure<'_>) -> Result<(), CliError> {
    let svg = render(fig).map_err(|reason| CliError::Plot {
        path: path.to_path_buf(),
        reason,
    })?;
    write_atomic(path, svg.as_bytes())
}

/// Measured and fitted velocity of one record (the paper's Fig. 8).
pub fn velocity_fit(
    path: &Path,
    record: &str,
    time: &[f64],
    measured: &[f64],
    fitted: &[f64],
    model: &str,
) -> Result<(), CliError> {
    let fig = Figure {
        title: format!("{record}: measured and fitted velocity"),
        x_label: "time".into(),
        x_unit: "s".into(),
        panels: vec![Panel::new("velocity", "m/s")
            .with(Series::solid("measured", time, measured))
            .with(Series::dashed(format!("fitted ({model})"), time, fitted))],
    };
    draw(path, &fig)
}

/// Displacement and velocity against time (simulations).
pub fn displacement_velocity(
    path: &Path,
    title: &str,
    time: &[f64],
    x: &[f64],
    v: &[f64],
) -> Result<(), CliError> {
    let fig = Figure {
        title: title.into(),
        x_label: "time".into(),
        x_unit: "s".into(),
        panels: vec![
            Panel::new("displacement", "m").with(Series::solid("x", time, x)),
            Panel::new("velocity", "m/s").with(Series::solid("v", time, v)),
        ],
    };
    draw(path, &fig)
}

/// Displacement and acceleration derived from a measured velocity (the paper's Figs. 9-10).
pub fn displacement_acceleration(
    path: &Path,
    title: &str,
    time: &[f64],
    x: &[f64],
    a: &[f64],
) -> Result<(), CliError> {
    let fig = Figure {
        title: title.into(),
        x_label: "time".into(),
        x_unit: "s".into(),
        panels: vec![
            Panel::new("displacement", "m").with(Series::solid("x", time, x)),
            Panel::new("acceleration", "m/s²").with(Series::solid("a", time, a)),
        ],
    };
    draw(path, &fig)
}

/// Mechanical energy and its rate of change (the paper's Figs. 4-5, 11).
pub fn energy_rate(
    path: &Path,
    title: &str,
    time: &[f64],
    energy: &[f64],
    de_dt: &[f64],
) -> Result<(), CliError> {
    let fig = Figure {
        title: title.into(),
        x_label: "time".into(),
        x_unit: "s".into(),
        panels: vec![
            Panel::new("energy E = KE + PE", "J").with(Series::solid("E", time, energy)),
            Panel::new("dE/dt", "W").with(Series::solid("dE/dt", time, de_dt)),
        ],
    };
    draw(path, &fig)
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
    let fig = Figure {
        title: title.into(),
        x_label: "time".into(),
        x_unit: "s".into(),
        panels: vec![panel],
    };
    draw(path, &fig)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_split_at_non_finite_values() {
        let x = [0.0, 1.0, 2.0, 3.0, 4.0];
        let y = [1.0, f64::NAN, 2.0, 3.0, f64::INFINITY];
        assert_eq!(
            segments(&x, &y),
            vec![vec![(0.0, 1.0)], vec![(2.0, 2.0), (3.0, 3.0)]]
        );
    }

    #[test]
    fn ticks_hide_round_off_and_follow_the_span() {
        assert_eq!(tick(-5.6e-17, 0.5), "0");
        assert_eq!(tick(0.25, 0.5), "0.25");
        assert_eq!(tick(1.5, 20.0), "1.5");
        assert_eq!(tick(2e-5, 1e-4), "2e-5");
    }

    #[test]
    fn ranges_are_padded_and_never_empty() {
        assert_eq!(range([0.0, 10.0].into_iter(), true), (-0.5, 10.5));
        assert_eq!(range([f64::NAN].into_iter(), true), (0.0, 1.0));
        let (lo, hi) = range([2.0, 2.0].into_iter(), true);
        assert!(lo < 2.0 && hi > 2.0);
    }

    #[test]
    fn svg_has_title_labels_and_one_path_per_line() {
        let t = [0.0, 0.5, 1.0];
        let y1 = [0.0, 1.0, 0.0];
        let y2 = [0.0, 0.5, f64::NAN];
        let fig = Figure {
            title: "T1".into(),
            x_label: "time".into(),
            x_unit: "s".into(),
            panels: vec![Panel::new("velocity", "m/s")
                .with(Series::solid("measured", &t, &y1))
                .with(Series::dashed("fitted", &t, &y2))
                .with_reference("mu N", 0.8)],
        };
        let svg = render(&fig).unwrap();
        for text in [
            "T1",
            "time [s]",
            "velocity [m/s]",
            "measured",
            "fitted",
            "mu N",
        ] {
            assert!(svg.contains(text), "missing {text}");
        }
    }
}
