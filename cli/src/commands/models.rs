//! `frictionid models`: every registered friction model with its parameters.

use crate::report::{fmt_num, text_table};
use frictionid_models::{listings, ModelListing};
use std::io::Write;

/// The listing as JSON: a list of {name, equation, states, parameters [{name, unit, default,
/// lower, upper, lower_exclusive, description, fixed_by_default}]}.
pub fn listing_json(list: &[ModelListing]) -> anyhow::Result<serde_json::Value> {
    Ok(serde_json::to_value(list)?)
}

/// The listing as text: per model a heading with the equation and a parameter table.
pub fn listing_text(list: &[ModelListing]) -> String {
    let mut out = String::new();
    for (i, m) in list.iter().enumerate() {
        if i > 0 {
            out.push('\n');
        }
        let states = match m.states {
            0 => String::new(),
            1 => " (1 internal state)".to_string(),
            n => format!(" ({n} internal states)"),
        };
        out.push_str(&format!("{}{states}\n  {}\n", m.name, m.equation));
        if m.parameters.is_empty() {
            out.push_str("  (no parameters)\n");
            continue;
        }
        let rows: Vec<Vec<String>> = m
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
        for line in text_table(
            &["parameter", "unit", "default", "bounds", "fit", "meaning"],
            &rows,
        )
        .lines()
        {
            out.push_str("  ");
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// Runs `frictionid models [--json]`.
pub fn run(json: bool) -> anyhow::Result<()> {
    let list = listings();
    let text = if json {
        serde_json::to_string_pretty(&listing_json(&list)?)? + "\n"
    } else {
        listing_text(&list)
    };
    let _ = std::io::stdout().write_all(text.as_bytes());
    Ok(())
}
