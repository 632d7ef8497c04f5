//! The trend plots of a campaign: one fitted parameter against one numeric condition, a
//! series of points (with standard-error bars) per value of the other conditions, and the
//! fitted straight line and power law.

use super::panel::{range, tick};
use super::PALETTE;
use crate::error::CliError;
use crate::report::{write_atomic, OutputDir};
use frictionid_engine::campaign::{CampaignRow, LineFit, RowVerdict, Trend};
use frictionid_engine::report::CampaignReport;
use plotters::prelude::*;

/// One point: condition, value, standard error.
type Point = (f64, f64, Option<f64>);

/// Writes one plot per trend of `report`; returns the file names.
pub fn trend_plots(out: &OutputDir, report: &CampaignReport) -> Result<Vec<String>, CliError> {
    let mut files = Vec::new();
    for trend in &report.trends {
        let name = file_name(trend);
        let series = series_of(report, trend);
        let path = out.path(&name);
        let svg = render(trend, &series).map_err(|reason| CliError::Plot {
            path: path.clone(),
            reason,
        })?;
        write_atomic(&path, svg.as_bytes())?;
        files.push(name);
    }
    Ok(files)
}

/// `trend_coulomb_mu_normal_force.svg`, in characters safe in a file name.
fn file_name(t: &Trend) -> String {
    let raw = format!("trend_{}_{}_{}", t.model, t.parameter, t.condition);
    let safe: String = raw
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("{safe}.svg")
}

/// The trend's points, one series per value of the other conditions (labelled by them).
fn series_of(report: &CampaignReport, t: &Trend) -> Vec<(String, Vec<Point>)> {
    let others: Vec<&String> = report
        .conditions
        .iter()
        .filter(|c| **c != t.condition)
        .collect();
    let mut series: Vec<(String, Vec<Point>)> = Vec::new();
    let rows = report
        .rows
        .iter()
        .filter(|r| r.model == t.model && r.converged && r.verdict != RowVerdict::Failed);
    for row in rows {
        let Some(point) = point(row, t) else { continue };
        let label = series_label(row, &others);
        match series.iter_mut().find(|(l, _)| *l == label) {
            Some((_, points)) => points.push(point),
            None => series.push((label, vec![point])),
        }
    }
    series
}

fn point(row: &CampaignRow, t: &Trend) -> Option<Point> {
    let x = row.condition(&t.condition)?.number()?;
    let p = row.param(&t.parameter)?;
    Some((x, p.value?, p.std_error))
}

/// `lubricant = oil, amplitude = 2` (the other conditions with a value in this group).
fn series_label(row: &CampaignRow, others: &[&String]) -> String {
    let parts: Vec<String> = others
        .iter()
        .filter_map(|c| row.condition(c).map(|v| format!("{c} = {}", v.text())))
        .collect();
    if parts.is_empty() {
        "groups".into()
    } else {
        parts.join(", ")
    }
}

/// The trend's SVG.
fn render(t: &Trend, series: &[(String, Vec<Point>)]) -> Result<String, String> {
    let all: Vec<Point> = series.iter().flat_map(|(_, p)| p.iter().copied()).collect();
    let x_range = range(all.iter().map(|p| p.0), true);
    let y_range = range(
        all.iter()
            .flat_map(|&(_, y, s)| [y - s.unwrap_or(0.0), y + s.unwrap_or(0.0)]),
        true,
    );
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (800, 520)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let title = format!("{}: {} against {}", t.model, t.parameter, t.condition);
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(80)
            .build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1)
            .map_err(|e| e.to_string())?;
        let (x_span, y_span) = (x_range.1 - x_range.0, y_range.1 - y_range.0);
        chart
            .configure_mesh()
            .x_desc(t.condition.as_str())
            .y_desc(t.parameter.as_str())
            .x_label_formatter(&|v| tick(*v, x_span))
            .y_label_formatter(&|v| tick(*v, y_span))
            .draw()
            .map_err(|e| e.to_string())?;
        draw_points(&mut chart, series)?;
        for (fit, label) in [(&t.linear, "linear trend"), (&t.power_law, "power law")] {
            if let Some(f) = fit {
                draw_fit(&mut chart, f, label, x_range)?;
            }
        }
        super::finish_with_legend(&mut chart, &root)?;
    }
    Ok(buf)
}

type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// Each series' points as dots with vertical error bars of one standard error.
fn draw_points(chart: &mut Chart<'_, '_>, series: &[(String, Vec<Point>)]) -> Result<(), String> {
    for (i, (label, points)) in series.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        let bars = points.iter().filter_map(|&(x, y, s)| {
            s.map(|s| PathElement::new(vec![(x, y - s), (x, y + s)], color.stroke_width(1)))
        });
        chart.draw_series(bars).map_err(|e| e.to_string())?;
        chart
            .draw_series(
                points
                    .iter()
                    .map(|&(x, y, _)| Circle::new((x, y), 4, color.filled())),
            )
            .map_err(|e| e.to_string())?
            .label(label.as_str())
            .legend(move |(x, y)| Circle::new((x + 10, y), 4, color.filled()));
    }
    Ok(())
}

/// A fitted trend as a line over the plot's x range (a power law only where x > 0).
fn draw_fit(
    chart: &mut Chart<'_, '_>,
    fit: &LineFit,
    label: &str,
    (lo, hi): (f64, f64),
) -> Result<(), String> {
    let dashed = label == "power law";
    let color = if dashed { PALETTE[7] } else { PALETTE[6] };
    let line: Vec<(f64, f64)> = (0..=100)
        .map(|i| lo + (hi - lo) * i as f64 / 100.0)
        .map(|x| (x, fit.at(x)))
        .filter(|(_, y)| y.is_finite())
        .collect();
    let style = color.stroke_width(if dashed { 1 } else { 2 });
    chart
        .draw_series(LineSeries::new(line, style))
        .map_err(|e| e.to_string())?
        .label(label)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
    Ok(())
}
