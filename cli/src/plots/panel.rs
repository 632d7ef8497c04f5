//! Drawing one panel of a figure: axes, lines, reference levels and the legend.

use super::{
    symlog_inverse, Figure, MarkShape, Panel, XTicks, DOWN_WEIGHTED, MARKED, MARK_RADIUS, PALETTE,
    REFERENCE_GREY,
};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

/// An axis's description `label [unit]`, the label and unit (written for a linear axis) shown
/// on the figure's axis: the one place a plot's units pass through
/// [`frictionid_engine::Axis::unit`] and its quantities through [`quantity_on`].
fn axis_text(fig: &Figure<'_>, label: &str, unit: &str) -> String {
    let label = quantity_on(fig.axis, label);
    if unit.is_empty() {
        label
    } else {
        format!("{label} [{}]", fig.axis.unit(unit))
    }
}

/// `label`, written for a linear axis, on `axis`: on a rotary one a displacement is an angle
/// and a force a torque ("friction force" -> "friction torque").
fn quantity_on(axis: frictionid_engine::Axis, label: &str) -> String {
    if axis.is_linear() {
        return label.to_string();
    }
    label
        .split(' ')
        .map(|word| match word {
            "displacement" => "angle",
            "force" => "torque",
            other => other,
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// Tick label for `v` on an axis spanning `span`: round-off next to zero shows as 0, and the
/// number of decimals follows the span.
pub(super) fn tick(v: f64, span: f64) -> String {
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

/// Tick label of an x coordinate: linear, or on a symmetric-log axis the velocity of a
/// decade (`1e-3`) and nothing between decades.
fn x_tick(u: f64, span: f64, ticks: XTicks) -> String {
    match ticks {
        XTicks::Linear => tick(u, span),
        XTicks::SymLog { linear_width } => {
            if (u - u.round()).abs() > 1e-6 {
                return String::new();
            }
            let v = symlog_inverse(u.round(), linear_width);
            if v == 0.0 {
                "0".into()
            } else {
                format!("{v:.0e}")
            }
        }
    }
}

/// The finite range of `values`, padded by 5 %; [0, 1] if there is none.
pub(super) fn range(values: impl Iterator<Item = f64>, pad: bool) -> (f64, f64) {
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

/// Runs of consecutive finite points, each as drawn ([`envelope`]).
#[cfg(test)]
pub(super) fn segments(x: &[f64], y: &[f64]) -> Vec<Vec<(f64, f64)>> {
    segments_within(x, y, (f64::NEG_INFINITY, f64::INFINITY))
}

/// Runs of consecutive finite points whose x lies in `window`, each as drawn.
pub(super) fn segments_within(x: &[f64], y: &[f64], window: (f64, f64)) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut cur = Vec::new();
    for (&a, &b) in x.iter().zip(y) {
        if a.is_finite() && b.is_finite() && a >= window.0 && a <= window.1 {
            cur.push((a, b));
        } else if !cur.is_empty() {
            out.push(envelope(std::mem::take(&mut cur)));
        }
    }
    if !cur.is_empty() {
        out.push(envelope(cur));
    }
    out
}

/// Columns a drawn line is reduced to at most: twice the widest plot's pixels (960).
pub(super) const DRAWN_COLUMNS: usize = 2000;

/// A run of points as drawn: up to four points per column of [`DRAWN_COLUMNS`] as they are,
/// a longer run (a long record) cut into that many consecutive chunks, each drawn by its
/// first, lowest, highest and last point in their order: every pixel column still spans the
/// line's extremes there, and a million-sample record's plot is not a file of 50 MB.
pub(super) fn envelope(points: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    if points.len() <= 4 * DRAWN_COLUMNS {
        return points;
    }
    let chunk = points.len().div_ceil(DRAWN_COLUMNS);
    let mut out = Vec::with_capacity(4 * DRAWN_COLUMNS);
    for c in points.chunks(chunk) {
        let by_y = |a: &&(f64, f64), b: &&(f64, f64)| a.1.total_cmp(&b.1);
        let lowest = c.iter().enumerate().min_by(|a, b| by_y(&a.1, &b.1));
        let highest = c.iter().enumerate().max_by(|a, b| by_y(&a.1, &b.1));
        let mut picks = [
            0,
            lowest.map_or(0, |p| p.0),
            highest.map_or(0, |p| p.0),
            c.len() - 1,
        ];
        picks.sort_unstable();
        let mut last = None;
        for i in picks {
            if last != Some(i) {
                out.push(c[i]);
                last = Some(i);
            }
        }
    }
    out
}

type PlotResult<T> = Result<T, String>;

type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Labelled entries of the panel's legend.
fn legend_entries(panel: &Panel<'_>) -> usize {
    panel.series.iter().filter(|s| !s.label.is_empty()).count()
        + panel
            .reference
            .iter()
            .filter(|r| !r.label.is_empty())
            .count()
        + panel.marks.len()
}

/// A legend is drawn for more than one labelled line, or any labelled reference line.
fn shows_legend(panel: &Panel<'_>) -> bool {
    legend_entries(panel) > 1
        || panel.reference.iter().any(|r| !r.label.is_empty())
        || !panel.marks.is_empty()
}

/// The y range of the panel's lines (within the x range shown) and levels, padded. The
/// legend sits above the plotting area, so it needs no room among the data.
fn y_range(panel: &Panel<'_>, x_range: (f64, f64)) -> (f64, f64) {
    let shown = panel.series.iter().flat_map(|s| {
        s.x.iter()
            .zip(s.y)
            .filter(move |(x, _)| **x >= x_range.0 && **x <= x_range.1)
            .map(|(_, y)| *y)
    });
    range(shown.chain(panel.reference.iter().map(|r| r.y)), true)
}

/// Axes, grid, tick labels and axis descriptions (the x description on the last panel only).
fn draw_mesh(
    chart: &mut Chart<'_, '_>,
    fig: &Figure<'_>,
    panel: &Panel<'_>,
    spans: (f64, f64),
    is_last: bool,
) -> PlotResult<()> {
    let x_fmt = |v: &f64| x_tick(*v, spans.0, fig.x_ticks);
    let y_fmt = |v: &f64| tick(*v, spans.1);
    let mut mesh = chart.configure_mesh();
    if let XTicks::SymLog { .. } = fig.x_ticks {
        // One label per decade: integer coordinates only.
        mesh.x_labels(spans.0.ceil() as usize + 1);
    }
    mesh.y_desc(axis_text(fig, &panel.y_label, &panel.y_unit))
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .light_line_style(RGBColor(235, 235, 235));
    if is_last {
        mesh.x_desc(axis_text(fig, &fig.x_label, &fig.x_unit));
    }
    mesh.draw().map_err(|e| e.to_string())
}

/// Where the two strokes of a dashed legend swatch end and start, so that the swatch is
/// drawn like its line.
fn swatch_gap(dashed: bool) -> (i32, i32) {
    if dashed {
        (11, 17)
    } else {
        (SWATCH / 2, SWATCH / 2)
    }
}

/// A legend entry: its label and how its line is drawn.
struct Entry {
    label: String,
    style: ShapeStyle,
    dashed: bool,
}

/// The panel's legend entries, in drawing order: its labelled lines, then its labelled levels.
fn entries(panel: &Panel<'_>) -> Vec<Entry> {
    let lines = panel
        .series
        .iter()
        .enumerate()
        .filter(|(_, s)| !s.label.is_empty())
        .map(|(i, s)| Entry {
            label: s.label.clone(),
            style: line_style(i, s),
            dashed: s.dashed,
        });
    let levels = panel
        .reference
        .iter()
        .filter(|r| !r.label.is_empty())
        .map(|r| Entry {
            label: r.label.clone(),
            style: REFERENCE_GREY.stroke_width(1),
            dashed: true,
        });
    let marks = panel.marks.iter().map(|m| Entry {
        label: m.label.clone(),
        style: mark_color(m.shape).stroke_width(2),
        dashed: false,
    });
    lines.chain(levels).chain(marks).collect()
}

/// The stroke of the `i`-th line of a panel: its colour (else the palette's), opacity and
/// width.
fn line_style(i: usize, s: &super::Series<'_>) -> ShapeStyle {
    let color = s.color.unwrap_or(PALETTE[i % PALETTE.len()]);
    color.mix(s.alpha).stroke_width(s.width)
}

/// The panel's lines, broken at non-finite values and cut to the x range shown, in order
/// (a later line is drawn over an earlier one).
fn draw_lines<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    panel: &Panel<'_>,
    x_range: (f64, f64),
) -> PlotResult<()> {
    for (i, s) in panel.series.iter().enumerate() {
        let style = line_style(i, s);
        for seg in segments_within(s.x, s.y, x_range) {
            if s.dashed {
                chart
                    .draw_series(DashedLineSeries::new(seg, 8, 5, style))
                    .map_err(|e| e.to_string())?;
            } else {
                chart
                    .draw_series(LineSeries::new(seg, style))
                    .map_err(|e| e.to_string())?;
            }
        }
    }
    Ok(())
}

/// Dashed horizontal reference levels across the whole x range.
fn draw_references<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    panel: &Panel<'_>,
    x_range: (f64, f64),
) -> PlotResult<()> {
    for r in &panel.reference {
        let style = REFERENCE_GREY.stroke_width(1);
        let line = vec![(x_range.0, r.y), (x_range.1, r.y)];
        chart
            .draw_series(DashedLineSeries::new(line, 6, 4, style))
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// Height of one row of the legend above a panel [px].
const LEGEND_ROW: i32 = 22;
/// Where the legend starts: past the y labels, in line with the plotting area [px].
const LEGEND_LEFT: i32 = 92;
/// Width of a legend swatch [px].
const SWATCH: i32 = 28;

/// The width a legend entry takes at 14 px sans-serif (an estimate: 7.2 px a character).
fn entry_width(e: &Entry) -> i32 {
    SWATCH + 8 + (7.2 * e.label.chars().count() as f64) as i32 + 22
}

/// The legend's rows: entries laid left to right, a new row where one would pass `width`.
fn legend_rows(entries: &[Entry], width: i32) -> Vec<Vec<(i32, &Entry)>> {
    let mut rows: Vec<Vec<(i32, &Entry)>> = vec![Vec::new()];
    let mut x = LEGEND_LEFT;
    for e in entries {
        let w = entry_width(e);
        if x + w > width && x > LEGEND_LEFT {
            rows.push(Vec::new());
            x = LEGEND_LEFT;
        }
        if let Some(row) = rows.last_mut() {
            row.push((x, e));
        }
        x += w;
    }
    rows
}

/// The legend's height above a panel of `width` pixels (0 without a legend).
fn legend_height(panel: &Panel<'_>, width: i32) -> i32 {
    if !shows_legend(panel) {
        return 0;
    }
    let entries = entries(panel);
    LEGEND_ROW * legend_rows(&entries, width).len() as i32 + 6
}

/// The legend in a strip above the plotting area, off the data: each entry a swatch drawn
/// like its line (colour, width, dashes) and its label.
fn draw_legend(strip: &DrawingArea<SVGBackend<'_>, Shift>, panel: &Panel<'_>) -> PlotResult<()> {
    let width = strip.dim_in_pixel().0 as i32;
    let entries = entries(panel);
    let font = ("sans-serif", 14).into_font().color(&RGBColor(30, 30, 30));
    for (r, row) in legend_rows(&entries, width).iter().enumerate() {
        let y = 6 + LEGEND_ROW * r as i32 + LEGEND_ROW / 2;
        for (x, e) in row {
            let (end, start) = swatch_gap(e.dashed);
            let pieces = if e.dashed {
                vec![(*x, *x + end), (*x + start, *x + SWATCH)]
            } else {
                vec![(*x, *x + SWATCH)]
            };
            for (a, b) in pieces {
                strip
                    .draw(&PathElement::new(vec![(a, y), (b, y)], e.style))
                    .map_err(|e| e.to_string())?;
            }
            strip
                .draw(&Text::new(
                    e.label.clone(),
                    (*x + SWATCH + 8, y - 8),
                    font.clone(),
                ))
                .map_err(|e| e.to_string())?;
        }
    }
    Ok(())
}

/// Draws one panel of `fig` into `area` over the shared `x_range`.
pub(super) fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    fig: &Figure<'_>,
    panel: &Panel<'_>,
    x_range: (f64, f64),
    is_last: bool,
) -> PlotResult<()> {
    let y_range = y_range(panel, x_range);
    let spans = (x_range.1 - x_range.0, y_range.1 - y_range.0);
    let legend = legend_height(panel, area.dim_in_pixel().0 as i32);
    let (strip, area) = area.split_vertically(legend);
    if legend > 0 {
        draw_legend(&strip, panel)?;
    }
    let mut chart = ChartBuilder::on(&area)
        .margin(12)
        .x_label_area_size(if is_last { 45 } else { 30 })
        .y_label_area_size(80)
        .build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1)
        .map_err(|e| e.to_string())?;
    draw_mesh(&mut chart, fig, panel, spans, is_last)?;
    draw_references(&mut chart, panel, x_range)?;
    draw_lines(&mut chart, panel, x_range)?;
    draw_marks(&mut chart, panel, x_range)?;
    Ok(())
}

/// The colour of marks drawn as `shape`.
fn mark_color(shape: MarkShape) -> RGBColor {
    match shape {
        MarkShape::Circle => MARKED,
        MarkShape::Triangle => DOWN_WEIGHTED,
    }
}

/// The panel's marked samples within the x range shown, one filled shape each, over the
/// lines.
fn draw_marks<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    panel: &Panel<'_>,
    x_range: (f64, f64),
) -> PlotResult<()> {
    for m in &panel.marks {
        let shown =
            m.x.iter()
                .filter(|x| x.is_finite() && (x_range.0..=x_range.1).contains(*x))
                .copied();
        let style = mark_color(m.shape).filled();
        match m.shape {
            MarkShape::Circle => {
                chart.draw_series(shown.map(|x| Circle::new((x, m.y), MARK_RADIUS, style)))
            }
            MarkShape::Triangle => chart
                .draw_series(shown.map(|x| TriangleMarker::new((x, m.y), MARK_RADIUS + 1, style))),
        }
        .map_err(|e| e.to_string())?;
    }
    Ok(())
}
