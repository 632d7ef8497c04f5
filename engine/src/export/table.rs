//! The compensation table: the law's steady-state friction force on a velocity grid, for a
//! feedforward that looks the force up rather than evaluating the law.
//!
//! The grid spans the records' speed range (±the largest speed, `max_speed` in report.json)
//! on both sides of zero: zero itself, a geometric sweep from 1e-4 of the largest speed up to
//! it (dense near zero, where friction changes fastest), and points around the law's
//! breakpoints (the Stribeck velocity v_s; Makkar's 1/g2, 1/g3, 1/g5).

use super::description::{literal, LawDescription};
use super::ExportError;

/// Points of the geometric sweep on each side of zero.
const SWEEP_POINTS: usize = 60;
/// The sweep starts at this share of the largest speed.
const SWEEP_START: f64 = 1e-4;
/// Multiples of a breakpoint added to the grid.
const AROUND_BREAKPOINT: [f64; 11] = [0.25, 0.5, 0.7, 0.85, 0.95, 1.0, 1.05, 1.2, 1.5, 2.0, 3.0];
/// The largest speed when the report gives none, in multiples of the largest breakpoint.
const FALLBACK_BREAKPOINTS: f64 = 20.0;
/// The largest speed when the report gives none and the law has no breakpoint \[m/s\].
const FALLBACK_SPEED: f64 = 1.0;

/// The law's breakpoints \[m/s\]: where its steady-state curve bends.
fn breakpoints(desc: &LawDescription) -> Vec<f64> {
    let value = |name: &str| desc.params.iter().find(|p| p.name == name).map(|p| p.value);
    let mut out: Vec<f64> = value("v_s").into_iter().collect();
    if desc.model == "makkar" {
        out.extend(
            ["g2", "g3", "g5"]
                .iter()
                .filter_map(|g| value(g))
                .map(|g| 1.0 / g),
        );
    }
    out.retain(|b| b.is_finite() && *b > 0.0);
    out
}

/// The velocity grid, ascending, symmetric about zero.
pub(crate) fn grid(desc: &LawDescription) -> (Vec<f64>, bool) {
    let bends = breakpoints(desc);
    let (top, given) = match desc.max_speed.filter(|s| *s > 0.0) {
        Some(s) => (s, true),
        None => (
            bends
                .iter()
                .copied()
                .reduce(f64::max)
                .map_or(FALLBACK_SPEED, |b| FALLBACK_BREAKPOINTS * b),
            false,
        ),
    };
    let mut positive: Vec<f64> = (0..SWEEP_POINTS)
        .map(|k| top * SWEEP_START.powf(1.0 - k as f64 / (SWEEP_POINTS - 1) as f64))
        .collect();
    for b in bends {
        positive.extend(
            AROUND_BREAKPOINT
                .iter()
                .map(|m| m * b)
                .filter(|v| *v <= top),
        );
    }
    positive.sort_by(f64::total_cmp);
    positive.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * b.abs());
    let mut all: Vec<f64> = positive.iter().rev().map(|v| -v).collect();
    all.push(0.0);
    all.extend(positive);
    (all, given)
}

/// The table as CSV: `#` comment lines, then a header naming the units, then one row per
/// grid velocity.
pub(crate) fn emit(
    desc: &LawDescription,
    normal_force: Option<f64>,
) -> Result<String, ExportError> {
    let n = match (normal_force, desc.levels_as_forces, desc.normal_force) {
        (Some(n), _, _) if !(n.is_finite() && n >= 0.0) => {
            return Err(ExportError::Options(format!(
                "--normal-force must be finite and >= 0, got {n}"
            )))
        }
        (Some(n), _, _) => n,
        (None, true, _) => 1.0,
        (None, false, Some(n)) => n,
        (None, false, None) => {
            return Err(ExportError::Options(
                "the report gives no single normal force (the records carry their own): \
                 name the table's with --normal-force N"
                    .into(),
            ))
        }
    };
    let (vu, fu, nu) = desc.units();
    let (grid, given) = grid(desc);
    let mut out = format!(
        "# Steady-state friction force of `{}` (frictionid {}), the compensation table of a feedforward.\n",
        desc.model, desc.version
    );
    out.push_str(&format!("# Equation: {}\n", desc.equation));
    out.push_str(&format!(
        "# Fitted to: {} ({})\n",
        desc.records.join(", "),
        desc.source
    ));
    for p in &desc.params {
        out.push_str(&format!(
            "# {} = {} {}\n",
            p.name,
            literal(p.value),
            LawDescription::param_comment(p)
        ));
    }
    out.push_str(&if desc.levels_as_forces {
        format!("# Normal force: none in the fit, the levels are forces (n = {n})\n")
    } else {
        format!("# Normal force: n = {n} {nu}\n")
    });
    out.push_str(&if given {
        "# Grid: the records' speed range, dense near zero and around the law's breakpoints\n"
            .to_string()
    } else {
        "# Grid: the report gives no speed range; the grid spans 20 breakpoints (or 1 m/s)\n"
            .to_string()
    });
    out.push_str(&format!("v [{vu}],F [{fu}]\n"));
    for v in grid {
        let f = desc.law.steady_state(v, n);
        out.push_str(&format!("{},{}\n", literal(v), literal(f)));
    }
    Ok(out)
}
