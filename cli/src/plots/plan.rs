//! The plot of `plan`: each parameter's relative predicted standard error (log scale)
//! against the candidates, the recommended ones marked, the reach as a dashed line.

use super::PALETTE;
use crate::error::CliError;
use crate::report::{write_atomic, OutputDir};
use frictionid_engine::report::PlanReport;
use plotters::prelude::*;

/// The plot's file name.
pub const PLAN_PLOT: &str = "predicted_std.svg";

/// Writes the plot of `report`; returns its file name (none when no candidate identifies any
/// parameter).
pub fn plan_plots(out: &OutputDir, report: &PlanReport) -> Result<Vec<String>, CliError> {
    let path = out.path(PLAN_PLOT);
    let Some(svg) = render(report).map_err(|reason| CliError::Plot {
        path: path.clone(),
        reason,
    })?
    else {
        return Ok(Vec::new());
    };
    write_atomic(&path, svg.as_bytes())?;
    Ok(vec![PLAN_PLOT.to_string()])
}

/// Each parameter's (candidate index, relative std in %) points.
fn points(report: &PlanReport) -> Vec<(String, Vec<(f64, f64)>)> {
    report
        .parameters
        .iter()
        .map(|p| {
            let pts = report
                .candidates
                .iter()
                .filter_map(|c| {
                    let r = c.relative_std.get(&p.name).copied().flatten()?;
                    (r.is_finite() && r > 0.0).then_some((c.index as f64, 100.0 * r))
                })
                .collect();
            (p.name.clone(), pts)
        })
        .collect()
}

/// The SVG, `None` when there is nothing to draw.
fn render(report: &PlanReport) -> Result<Option<String>, String> {
    let series = points(report);
    let ys: Vec<f64> = series
        .iter()
        .flat_map(|(_, p)| p.iter().map(|q| q.1))
        .collect();
    if ys.is_empty() {
        return Ok(None);
    }
    let reach = 100.0 * report.reach;
    let lo = ys.iter().copied().fold(reach, f64::min) / 2.0;
    let hi = ys.iter().copied().fold(reach, f64::max) * 2.0;
    let n = report.candidates.len() as f64;
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (800, 520)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let mut chart = ChartBuilder::on(&root)
            .caption("predicted standard error per candidate", ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(-0.5..(n - 0.5), (lo..hi).log_scale())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("candidate")
            .y_desc("relative standard error (%)")
            .x_labels(report.candidates.len().min(20))
            .x_label_formatter(&|v| format!("{}", v.round()))
            .draw()
            .map_err(|e| e.to_string())?;
        for &i in &report.recommended {
            let x = i as f64;
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(x, lo), (x, hi)],
                    RGBColor(200, 200, 200).stroke_width(6),
                )))
                .map_err(|e| e.to_string())?;
        }
        let reach_style = BLACK.stroke_width(1);
        chart
            .draw_series(DashedLineSeries::new(
                vec![(-0.5, reach), (n - 0.5, reach)],
                6,
                4,
                reach_style,
            ))
            .map_err(|e| e.to_string())?
            .label(format!("reach ({reach:.0} %)"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], reach_style));
        for (k, (name, pts)) in series.iter().enumerate() {
            let color = PALETTE[k % PALETTE.len()];
            chart
                .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(name.as_str())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                });
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 4, color.filled())))
                .map_err(|e| e.to_string())?;
        }
        super::finish_with_legend(&mut chart, &root)?;
    }
    Ok(Some(buf))
}
