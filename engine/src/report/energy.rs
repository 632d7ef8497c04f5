//! The report of `energy`: the energy-based friction force of each record (the paper's
//! Eq. 7) against a reference force.

use super::format::{column, fmt_num, fmt_percent};
use super::{render_files, Render, Role, Sink, Table};
use crate::energy::{EnergyAnalysis, EnergyOptions, HalfCycle, SeriesSources};
use crate::oscillator::Oscillator;
use frictionid_models::FrictionModel;
use serde::Serialize;

/// The energy analysis of every record.
#[derive(Debug, Clone, Serialize)]
pub struct EnergyReport {
    /// `"energy"`.
    pub command: String,
    /// The configuration the run came from, as the front end names it.
    pub config: String,
    /// The oscillator.
    pub oscillator: Oscillator,
    /// The model given in the spec (not a reference fitted for the occasion).
    pub model: Option<Box<dyn FrictionModel>>,
    /// The analysis options.
    pub options: EnergyOptions,
    /// Per record, in input order.
    pub records: Vec<EnergyRecord>,
    /// Files written with the report.
    pub files: Vec<String>,
    /// Name of the model whose force is the reference (given or fitted), if any.
    #[serde(skip)]
    pub reference_model: Option<String>,
}

/// The energy analysis of one record against its reference force.
#[derive(Debug, Clone, Serialize)]
pub struct EnergyRecord {
    /// Record name (file as written).
    pub file: String,
    /// The release instant the record was cut at (`release = "auto"` or a time) \[s\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub release_time: Option<f64>,
    /// Mean |F_f| of Eq. 7 over the unmasked samples \[N\].
    pub mean_abs_force: f64,
    /// The reference force \[N\] (NaN when there is none).
    pub reference: f64,
    /// 100 (mean_abs_force - reference) / reference.
    pub percent_difference: f64,
    /// Friction force of each half-cycle (energy balance) \[N\].
    pub half_cycle_forces: Vec<f64>,
    /// Mean of the half-cycle forces \[N\].
    pub half_cycle_mean: f64,
    /// Standard deviation of the half-cycle forces \[N\].
    pub half_cycle_std: f64,
    /// The half-cycles.
    pub half_cycles: Vec<HalfCycle>,
    /// Samples masked in Eq. 7.
    pub masked: usize,
    /// Samples analysed.
    pub samples: usize,
    /// Whether x, v and a were measured, or integrated / differentiated.
    pub sources: SeriesSources,
    /// The analysis (for plots).
    #[serde(skip)]
    pub analysis: EnergyAnalysis,
    /// The reference model's force along the measured motion, if there is a model.
    #[serde(skip)]
    pub model_force: Option<Vec<f64>>,
}

impl EnergyReport {
    /// The per-record table.
    pub fn record_table(&self) -> Table {
        let rows = self
            .records
            .iter()
            .map(|r| {
                vec![
                    r.file.clone(),
                    fmt_num(r.mean_abs_force),
                    fmt_num(r.half_cycle_mean),
                    fmt_num(r.reference),
                    fmt_percent(r.percent_difference),
                    r.half_cycles.len().to_string(),
                    format!(
                        "{} / {} / {}",
                        r.sources.displacement.name(),
                        r.sources.velocity.name(),
                        r.sources.acceleration.name()
                    ),
                ]
            })
            .collect();
        let axis = self.oscillator.axis;
        Table::new(
            &[
                "record",
                &column(axis, "mean |F|", "N"),
                &column(axis, "half-cycle mean", "N"),
                &column(axis, "reference", "N"),
                "difference [%]",
                "half-cycles",
                "x / v / a",
            ],
            rows,
        )
    }
}

impl Render for EnergyReport {
    fn render(&self, sink: &mut dyn Sink) {
        sink.title("frictionid energy");
        sink.paragraph(
            &format!(
                "Config: `{}`. Energy-based friction force (Eq. 7) of each record against the reference force.",
                self.config
            ),
            Role::Detail,
        );
        sink.table(&self.record_table(), Role::Summary);
        render_files(sink, &self.files);
    }
}
