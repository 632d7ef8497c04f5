//! The report of `simulate`: one motion, free or driven by a measured input.

use super::format::{column, fmt_num, fmt_opt, on_axis};
use super::{render_files, render_opening, Render, Role, Sink, Table};
use crate::oscillator::Oscillator;
use crate::simulate::{Event, SimStats, Trajectory};
use frictionid_models::FrictionModel;
use serde::Serialize;

/// A simulated motion with its summary figures. The trajectory itself (for plots and
/// trajectory.csv) is not part of report.json.
#[derive(Debug, Clone, Serialize)]
pub struct SimulateReport {
    /// `"simulate"`.
    pub command: String,
    /// The configuration the run came from, as the front end names it.
    pub config: String,
    /// The oscillator.
    pub oscillator: Oscillator,
    /// The friction model.
    pub model: Box<dyn FrictionModel>,
    /// Release displacement \[m\].
    pub x0: f64,
    /// Release velocity \[m/s\].
    pub v0: f64,
    /// Simulated time \[s\].
    pub duration: f64,
    /// Output sample rate \[Hz\].
    pub sample_rate: f64,
    /// Output samples.
    pub samples: usize,
    /// Displacement at rest, or at the end \[m\].
    pub final_displacement: f64,
    /// Time the mass stuck for good \[s\], if it did.
    pub rest_time: Option<f64>,
    /// Half-cycles (turning points).
    pub half_cycles: usize,
    /// Turning points and sticks.
    pub events: Vec<Event>,
    /// Integrator statistics.
    pub stats: SimStats,
    /// Wall time of the simulation \[s\].
    pub wall_time_s: f64,
    /// Noise of the synthetic record \[m/s\], if one was made.
    pub noise: Option<f64>,
    /// Seed of the synthetic record's noise, if one was made.
    pub seed: Option<u64>,
    /// Files written with the report.
    pub files: Vec<String>,
    /// The sampled trajectory.
    #[serde(skip)]
    pub trajectory: Trajectory,
    /// dE/dt along the exact states \[W\].
    #[serde(skip)]
    pub energy_rate: Vec<f64>,
    /// The noisy velocity of the synthetic record \[m/s\], if one was made.
    #[serde(skip)]
    pub noisy_velocity: Option<Vec<f64>>,
    /// The measured input that drove the axis (`None`: free vibration); report.json names
    /// its file.
    #[serde(rename = "input_file", serialize_with = "input_file")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub input: Option<InputSeries>,
}

/// The measured input u(t) of a driven simulation, as read.
#[derive(Debug, Clone, PartialEq)]
pub struct InputSeries {
    /// The file it came from, as the configuration names it.
    pub file: String,
    /// Its sample times on the simulation's clock \[s\].
    pub time: Vec<f64>,
    /// u at those times \[N, or N m on a rotary axis\].
    pub values: Vec<f64>,
}

/// An input as its file's name in report.json.
fn input_file<S: serde::Serializer>(
    input: &Option<InputSeries>,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    match input {
        Some(i) => serializer.serialize_str(&i.file),
        None => serializer.serialize_none(),
    }
}

impl SimulateReport {
    /// The model as JSON text (for titles and file headers).
    pub fn model_json(&self) -> String {
        serde_json::to_string(&self.model).unwrap_or_else(|_| self.model.name().to_string())
    }

    fn summary_table(&self) -> Table {
        let axis = self.oscillator.axis;
        let row = |q: &str, v: String, u: &str| vec![q.to_string(), v, on_axis(axis, u)];
        let stats = &self.stats;
        Table::new(
            &["quantity", "value", "unit"],
            vec![
                row("model", self.model.name().to_string(), ""),
                row(
                    "input",
                    self.input
                        .as_ref()
                        .map_or("none (free vibration)".into(), |i| format!("`{}`", i.file)),
                    "",
                ),
                row("x0", fmt_num(self.x0), "m"),
                row("final displacement", fmt_num(self.final_displacement), "m"),
                row(
                    "rest time (- if still moving)",
                    fmt_opt(self.rest_time),
                    "s",
                ),
                row("half-cycles", self.half_cycles.to_string(), ""),
                row("events", self.events.len().to_string(), ""),
                row(
                    "steps (rejected)",
                    format!("{} ({})", stats.steps, stats.rejected_steps),
                    "",
                ),
                row("rhs evaluations", stats.rhs_evaluations.to_string(), ""),
                row("wall time", fmt_num(self.wall_time_s), "s"),
            ],
        )
    }

    fn event_table(&self) -> Table {
        let rows = self
            .events
            .iter()
            .map(|e| {
                let kind = serde_json::to_value(e.kind)
                    .ok()
                    .and_then(|k| k.as_str().map(str::to_string))
                    .unwrap_or_default();
                vec![fmt_num(e.time), kind, fmt_num(e.displacement)]
            })
            .collect();
        let displacement = column(self.oscillator.axis, "displacement", "m");
        Table::new(&["time [s]", "kind", &displacement], rows)
    }
}

impl Render for SimulateReport {
    fn render(&self, sink: &mut dyn Sink) {
        let summary = format!("Model: `{}`.", self.model_json());
        render_opening(sink, "simulate", &self.config, &summary);
        sink.table(&self.summary_table(), Role::Summary);
        sink.heading(2, "Events", Role::Detail);
        sink.table(&self.event_table(), Role::Detail);
        render_files(sink, &self.files);
    }
}
