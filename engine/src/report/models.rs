//! The report of `models`: every registered friction model.

use super::format::fmt_num;
use super::{Render, Role, Sink, Table};
use crate::axis::Axis;
use frictionid_models::ModelListing;
use serde::Serialize;

/// Every registered model with its parameters; serialized as the list itself.
#[derive(Debug, Clone, Serialize)]
#[serde(transparent)]
pub struct ModelsReport {
    /// The models, by name.
    pub models: Vec<ModelListing>,
}

impl ModelsReport {
    /// Every model registered in this program (built-in and linked plugins).
    pub fn registered() -> Self {
        Self::on_axis(Axis::Linear)
    }

    /// Every registered model with its parameters' units on `axis` (a law declares them for
    /// a linear axis: "N s/m" is "N m s/rad" on a rotary one).
    pub fn on_axis(axis: Axis) -> Self {
        let mut models = frictionid_models::listings();
        for p in models.iter_mut().flat_map(|m| m.parameters.iter_mut()) {
            p.unit = super::format::on_axis(axis, &p.unit);
        }
        Self { models }
    }
}

fn states_text(states: usize) -> String {
    match states {
        0 => String::new(),
        1 => " (1 internal state)".to_string(),
        n => format!(" ({n} internal states)"),
    }
}

fn parameter_table(m: &ModelListing) -> Table {
    let rows = m
        .parameters
        .iter()
        .map(|p| {
            vec![
                p.name.clone(),
                p.unit.clone(),
                fmt_num(p.default),
                format!(
                    "{}{}, {}]",
                    if p.lower_exclusive { "(" } else { "[" },
                    fmt_num(p.lower),
                    fmt_num(p.upper)
                ),
                if p.fixed_by_default { "fixed" } else { "free" }.to_string(),
                p.description.clone(),
            ]
        })
        .collect();
    Table::new(
        &["parameter", "unit", "default", "bounds", "fit", "meaning"],
        rows,
    )
}

impl Render for ModelsReport {
    fn render(&self, sink: &mut dyn Sink) {
        sink.title("frictionid models");
        for m in &self.models {
            sink.heading(
                2,
                &format!("{}{}", m.name, states_text(m.states)),
                Role::Summary,
            );
            sink.paragraph(&m.equation, Role::Summary);
            if m.parameters.is_empty() {
                sink.paragraph("(no parameters)", Role::Summary);
            } else {
                sink.table(&parameter_table(m), Role::Summary);
            }
        }
    }
}
