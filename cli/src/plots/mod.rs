//! SVG plots (plotters): line charts of named series against time in one or more stacked
//! panels, with axis labels and units, dashed reference lines, and the steady-state friction
//! curves F_ss(v) of several models.
//!
//! Non-finite values (e.g. the masked samples of the energy-based friction force) break a line
//! into segments instead of being drawn.

mod charts;
mod panel;
mod plan;
pub mod sets;
mod trends;

pub use charts::{
    force_against_motion, force_balance, friction_force, input_force, named_channels, over_time,
    response_fit, steady_state_curves, MotionAxis, Quantity, SampleMarks, View,
};
pub use plan::{plan_plots, PLAN_PLOT};
pub use trends::trend_plots;

use crate::error::CliError;
use crate::report::write_atomic;
use frictionid_engine::Axis;
use panel::{draw_panel, range};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// The palette of every plot: Okabe and Ito's colour-blind-safe colours, strongest first,
/// then a brown, a darkened yellow, four of Paul Tol's muted colours and a dark grey (one
/// colour for each registered law); cycled by series, or fixed per model by
/// [`model_color`]. Black is kept for measured data.
pub const PALETTE: [RGBColor; 14] = [
    RGBColor(0, 114, 178),   // blue
    RGBColor(213, 94, 0),    // vermillion
    RGBColor(0, 158, 115),   // bluish green
    RGBColor(204, 121, 167), // reddish purple
    RGBColor(230, 159, 0),   // orange
    RGBColor(86, 180, 233),  // sky blue
    RGBColor(140, 86, 75),   // brown
    RGBColor(160, 140, 0),   // dark yellow (Okabe-Ito yellow is faint on white)
    RGBColor(136, 34, 85),   // wine (Paul Tol's muted scheme: a colour per registered law)
    RGBColor(51, 34, 136),   // indigo (Tol's muted)
    RGBColor(68, 170, 153),  // teal (Tol's muted)
    RGBColor(204, 102, 119), // rose (Tol's muted)
    RGBColor(102, 102, 102), // dark grey
    RGBColor(0, 0, 0),       // black
];

/// The colour of measured data: drawn as a thin dark line under nothing, a fit over it in
/// its model's colour and wider.
pub const MEASURED: RGBColor = RGBColor(0, 0, 0);

/// Draws `chart`'s legend (a nearly opaque white box with a black border), then writes out
/// `root`, the area the chart is drawn on.
fn finish_with_legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    root: &DrawingArea<DB, Shift>,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}

/// The grey of reference levels (both signs of +-mu N alike).
pub const REFERENCE_GREY: RGBColor = RGBColor(90, 90, 90);

/// Colour of marked samples (those a fit left out).
pub const MARKED: RGBColor = RGBColor(230, 0, 120);

/// Radius of a marked sample's circle [px].
pub const MARK_RADIUS: i32 = 3;

/// The colour of samples a robust loss down-weighted (an orange apart from [`MARKED`]).
pub const DOWN_WEIGHTED: RGBColor = RGBColor(230, 120, 0);

/// The laws that get the strongest colours, in this order; other registered laws follow in
/// their registry order.
const COLOUR_ORDER: [&str; 9] = [
    "coulomb",
    "viscous_coulomb",
    "stribeck",
    "dahl",
    "lugre",
    "gms",
    "makkar",
    "expression",
    "none",
];

/// The fixed colour of a registered model, so a model has the same colour on every chart of
/// every report: the classical laws first ([`COLOUR_ORDER`]), then the other registered
/// names; never the measured data's black.
pub fn model_color(model: &str) -> RGBColor {
    let names = frictionid_models::names();
    let others = names.iter().filter(|n| !COLOUR_ORDER.contains(&n.as_str()));
    let index = COLOUR_ORDER
        .iter()
        .position(|n| *n == model)
        .or_else(|| {
            others
                .clone()
                .position(|n| n == model)
                .map(|i| COLOUR_ORDER.len() + i)
        })
        .unwrap_or(COLOUR_ORDER.len() + others.count());
    let colours: Vec<RGBColor> = PALETTE.into_iter().filter(|c| *c != MEASURED).collect();
    colours[index % colours.len()]
}

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
    /// Colour; `None`: the palette colour of the series' position.
    pub color: Option<RGBColor>,
    /// Opacity, 1 opaque: a noisy trace under a model's line is drawn see-through.
    pub alpha: f64,
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
            color: None,
            alpha: 1.0,
        }
    }

    /// The same line drawn with opacity `alpha` (0 to 1).
    pub fn alpha(self, alpha: f64) -> Self {
        Self {
            alpha: alpha.clamp(0.0, 1.0),
            ..self
        }
    }

    /// The same line in `color`.
    pub fn color(self, color: RGBColor) -> Self {
        Self {
            color: Some(color),
            ..self
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

/// How marked samples are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MarkShape {
    /// A small filled circle in [`MARKED`] (samples a fit left out of its comparison).
    #[default]
    Circle,
    /// A small filled triangle in [`DOWN_WEIGHTED`] (samples a robust loss down-weighted).
    Triangle,
}

/// Samples marked on a panel at one level, each by a small filled shape (e.g. the samples a
/// fit left out of its comparison).
#[derive(Debug, Clone)]
pub struct Marks<'a> {
    /// Legend label.
    pub label: String,
    /// How each is drawn.
    pub shape: MarkShape,
    /// Abscissa of each marked sample.
    pub x: &'a [f64],
    /// The level they are marked at on the panel's y axis.
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
    /// Marked samples.
    pub marks: Vec<Marks<'a>>,
}

impl<'a> Panel<'a> {
    /// A panel with a y label and unit and no lines yet.
    pub fn new(y_label: impl Into<String>, y_unit: impl Into<String>) -> Self {
        Self {
            y_label: y_label.into(),
            y_unit: y_unit.into(),
            series: Vec::new(),
            reference: Vec::new(),
            marks: Vec::new(),
        }
    }

    /// Adds a line.
    pub fn with(mut self, s: Series<'a>) -> Self {
        self.series.push(s);
        self
    }

    /// Marks the samples at abscissae `x` at the level `y` (nothing when `x` is empty).
    pub fn with_marks(self, label: impl Into<String>, x: &'a [f64], y: f64) -> Self {
        self.with_shaped_marks(label, MarkShape::Circle, x, y)
    }

    /// Marks the samples at abscissae `x` at the level `y`, each drawn as `shape` (nothing
    /// when `x` is empty).
    pub fn with_shaped_marks(
        mut self,
        label: impl Into<String>,
        shape: MarkShape,
        x: &'a [f64],
        y: f64,
    ) -> Self {
        if !x.is_empty() {
            self.marks.push(Marks {
                label: label.into(),
                shape,
                x,
                y,
            });
        }
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

/// How the x axis is labelled.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum XTicks {
    /// Linear values.
    #[default]
    Linear,
    /// The x values are [`symlog`] coordinates with this linear width: ticks at the decades
    /// (integer coordinates) labelled with the velocity they stand for.
    SymLog {
        /// The half-width of the linear region around zero.
        linear_width: f64,
    },
}

/// The symmetric-log coordinate of `v`: linear (`v / w`) for |v| <= w, then one unit per
/// decade, `sign(v) (1 + log10(|v| / w))`; continuous and odd.
pub fn symlog(v: f64, w: f64) -> f64 {
    let a = v.abs() / w;
    if a <= 1.0 {
        v / w
    } else {
        v.signum() * (1.0 + a.log10())
    }
}

/// The inverse of [`symlog`].
pub fn symlog_inverse(u: f64, w: f64) -> f64 {
    if u.abs() <= 1.0 {
        u * w
    } else {
        u.signum() * w * 10f64.powf(u.abs() - 1.0)
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
    /// How the x axis is labelled.
    pub x_ticks: XTicks,
    /// The panels, top to bottom.
    pub panels: Vec<Panel<'a>>,
    /// The axis whose units the labels show: the figure's units are written for a linear
    /// axis and drawn on this one ([`Axis::unit`]: m/s is rad/s on a rotary axis).
    pub axis: Axis,
    /// The x range shown (`None`: the lines' whole range); lines are cut at its ends.
    pub x_window: Option<(f64, f64)>,
}

impl<'a> Figure<'a> {
    /// A figure of `panels` against time in seconds, its units shown as written.
    pub fn over_time(title: impl Into<String>, panels: Vec<Panel<'a>>) -> Self {
        Self {
            title: title.into(),
            x_label: "time".into(),
            x_unit: "s".into(),
            x_ticks: XTicks::Linear,
            panels,
            axis: Axis::Linear,
            x_window: None,
        }
    }

    /// The same figure with its units shown on `axis`.
    pub fn on(self, axis: Axis) -> Self {
        Self { axis, ..self }
    }

    /// The same figure showing only `window` of its x axis (when given).
    pub fn window(self, window: Option<(f64, f64)>) -> Self {
        Self {
            x_window: window.or(self.x_window),
            ..self
        }
    }
}

/// The share of a record's peak speed below which its motion counts as at rest.
pub const REST_SHARE: f64 = 0.03;

/// The time window of a record's motion: from its start to the last sample whose speed
/// exceeds [`REST_SHARE`] of the peak, plus a margin of a tenth of that span (at least 5 % of
/// the record); `None` when the motion fills the record (a driven axis, a tribometer), or
/// when it cannot tell (no finite speed).
pub fn motion_window(time: &[f64], velocity: &[f64]) -> Option<(f64, f64)> {
    if time.len() != velocity.len() || time.len() < 2 {
        return None;
    }
    let peak = velocity
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    if peak <= 0.0 {
        return None;
    }
    let last = velocity
        .iter()
        .rposition(|v| v.is_finite() && v.abs() > REST_SHARE * peak)?;
    let (t0, t_end) = (time[0], time[time.len() - 1]);
    let span = t_end - t0;
    let end = time[last] + (0.1 * (time[last] - t0)).max(0.05 * span);
    (end < t_end - 0.05 * span).then_some((t0, end))
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
        let x_range = fig.x_window.unwrap_or_else(|| {
            range(
                fig.panels
                    .iter()
                    .flat_map(|p| {
                        let lines = p.series.iter().flat_map(|s| s.x.iter());
                        lines.chain(p.marks.iter().flat_map(|m| m.x.iter()))
                    })
                    .copied(),
                false,
            )
        });
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

#[cfg(test)]
mod tests {
    use super::panel::{segments, tick};
    use super::*;

    #[test]
    fn symlog_is_odd_continuous_and_inverted() {
        let w = 1e-4;
        for v in [-0.3, -1e-3, -1e-4, -3e-5, 0.0, 2e-5, 1e-4, 5e-3, 0.28] {
            assert!((symlog(-v, w) + symlog(v, w)).abs() < 1e-12);
            assert!((symlog_inverse(symlog(v, w), w) - v).abs() < 1e-12 * v.abs().max(1e-9));
        }
        assert!(
            (symlog(1e-2, w) - 3.0).abs() < 1e-12,
            "decades are integers"
        );
        assert!(
            (symlog(w * (1.0 + 1e-12), w) - 1.0).abs() < 1e-9,
            "continuous at w"
        );
    }

    #[test]
    fn models_keep_their_colour_and_colours_are_distinct() {
        assert_eq!(model_color("coulomb"), model_color("coulomb"));
        assert_ne!(model_color("coulomb"), MEASURED);
        let names = frictionid_models::names();
        let colors: Vec<RGBColor> = names.iter().map(|n| model_color(n)).collect();
        for i in 0..colors.len().min(PALETTE.len() - 1) {
            for j in 0..i {
                assert_ne!(colors[i], colors[j], "{} and {}", names[i], names[j]);
            }
        }
    }

    #[test]
    fn segments_split_at_non_finite_values() {
        let x = [0.0, 1.0, 2.0, 3.0, 4.0];
        let y = [1.0, f64::NAN, 2.0, 3.0, f64::INFINITY];
        assert_eq!(
            segments(&x, &y),
            vec![vec![(0.0, 1.0)], vec![(2.0, 2.0), (3.0, 3.0)]]
        );
    }

    /// A run longer than four points per drawn column is drawn by each chunk's first,
    /// lowest, highest and last point: at most four per column, the ends and every chunk's
    /// extremes kept, in order; a short run is drawn as it is.
    #[test]
    fn a_long_line_is_drawn_by_its_envelope() {
        use panel::{envelope, DRAWN_COLUMNS};
        let n: usize = 1_000_003;
        let points: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let t = i as f64 * 1e-5;
                (t, (200.0 * t).sin() + if i == 777_777 { 5.0 } else { 0.0 })
            })
            .collect();
        let drawn = envelope(points.clone());
        assert!(drawn.len() <= 4 * DRAWN_COLUMNS, "{}", drawn.len());
        assert_eq!(drawn.first(), points.first());
        assert_eq!(drawn.last(), points.last());
        assert!(drawn.windows(2).all(|w| w[0].0 < w[1].0), "in order");
        assert!(drawn.contains(&points[777_777]), "a spike is kept");
        let chunk = n.div_ceil(DRAWN_COLUMNS);
        for c in points.chunks(chunk) {
            let lowest = c.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
            let highest = c.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
            for extreme in [lowest, highest] {
                assert!(drawn.iter().any(|p| p.1 == extreme && p.0 >= c[0].0));
            }
        }
        let short: Vec<(f64, f64)> = points[..4 * DRAWN_COLUMNS].to_vec();
        assert_eq!(envelope(short.clone()), short);
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
            x_ticks: XTicks::Linear,
            axis: Axis::Linear,
            x_window: None,
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

    #[test]
    fn marked_samples_are_one_circle_each_and_widen_the_time_axis() {
        let t = [0.2, 0.5, 0.8];
        let y = [0.0, 1.0, 0.0];
        let circles = |marked: &[f64]| {
            let fig = Figure::over_time(
                "T",
                vec![Panel::new("friction force", "N")
                    .with(Series::solid("fitted", &t, &y))
                    .with_marks("left out", marked, 0.0)],
            );
            render(&fig).unwrap().matches("<circle").count()
        };
        // Two of them lie outside the lines' time span: the axis takes them in.
        assert_eq!(circles(&[0.0, 0.5, 0.51, 1.0]), 4);
        assert_eq!(circles(&[]), 0);
    }
    /// A figure drawn on a rotary axis labels its velocity in rad/s, its friction as a torque
    /// in N m and its displacement as an angle in rad.
    #[test]
    fn rotary_figures_label_angles_and_torques() {
        let t = [0.0, 0.5, 1.0];
        let y = [0.0, 1.0, 0.0];
        let fig = Figure::over_time(
            "T",
            vec![
                Panel::new("velocity", "m/s").with(Series::solid("v", &t, &y)),
                Panel::new("friction force", "N").with(Series::solid("F", &t, &y)),
                Panel::new("displacement", "m").with(Series::solid("x", &t, &y)),
            ],
        )
        .on(Axis::Rotary);
        let svg = render(&fig).unwrap();
        assert!(svg.contains("velocity [rad/s]"));
        assert!(svg.contains("friction torque [N m]"));
        assert!(svg.contains("angle [rad]"));
        assert!(!svg.contains("displacement"));
        assert!(!svg.contains("[m/s]"));
    }
}
