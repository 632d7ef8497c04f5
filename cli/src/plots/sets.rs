//! The plots of each report: which charts a command draws from its report value, and their
//! file names in the output directory.

use super::{draw, Figure, Panel, Quantity, Series};
use crate::error::CliError;
use crate::report::{fmt_num, OutputDir};
use frictionid_engine::identify::{FitResult, RecordFit};
use frictionid_engine::record::{Channel, Record};
use frictionid_engine::report::{EnergyRecord, EnergyReport, SimulateReport};
use frictionid_engine::Axis;
use frictionid_models::FrictionModel;
use std::path::Path;

/// A file-name stem for a record's plots: its file name without extension.
pub fn plot_stem(record_name: &str) -> String {
    Path::new(record_name)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "record".into())
}

/// Plot stems of the records `names`, one per record and all distinct: the file stem where it
/// is unique; else the path as written with separators as `_` (`a/data.csv` -> `a_data`);
/// else that with the record's position appended (`data_2`).
pub fn unique_stems(names: &[&str]) -> Vec<String> {
    let stems: Vec<String> = names.iter().map(|n| plot_stem(n)).collect();
    let count = |list: &[String], s: &String| list.iter().filter(|t| *t == s).count();
    let with_path: Vec<String> = names
        .iter()
        .zip(&stems)
        .map(|(name, stem)| {
            if count(&stems, stem) == 1 {
                return stem.clone();
            }
            let parent = Path::new(name)
                .parent()
                .map(|p| p.to_string_lossy().into_owned());
            match parent.filter(|p| !p.is_empty()) {
                Some(p) => format!("{}_{stem}", p.replace(['/', '\\', ':', '.'], "_")),
                None => stem.clone(),
            }
        })
        .collect();
    with_path
        .iter()
        .enumerate()
        .map(|(i, s)| {
            if count(&with_path, s) == 1 {
                s.clone()
            } else {
                format!("{s}_{}", i + 1)
            }
        })
        .collect()
}

/// The model force where the energy-based force is defined (not masked), NaN elsewhere.
pub fn where_defined(model_force: &[f64], energy_force: &[f64]) -> Vec<f64> {
    model_force
        .iter()
        .zip(energy_force)
        .map(|(&m, e)| if e.is_finite() { m } else { f64::NAN })
        .collect()
}

/// `force` with a gap wherever the velocity `v` reverses between two samples, so that a
/// trace is never joined across a reversal (where Eq. 7 jumps from +F to -F). Unchanged
/// when the lengths differ.
pub fn break_at_reversals(force: &[f64], v: &[f64]) -> Vec<f64> {
    let mut out = force.to_vec();
    if force.len() != v.len() {
        return out;
    }
    for i in 1..v.len() {
        if v[i] * v[i - 1] < 0.0 {
            out[i] = f64::NAN;
        }
    }
    out
}

/// `simulate`: displacement and velocity; energies and their rate of change; the measured
/// input that drove the axis, when one did (`input.svg`).
pub fn simulate_plots(out: &OutputDir, report: &SimulateReport) -> Result<Vec<String>, CliError> {
    let traj = &report.trajectory;
    let axis = report.oscillator.axis;
    let title = format!(
        "{} from x0 = {} {}",
        report.model.name(),
        fmt_num(report.x0),
        axis.unit("m")
    );
    let motion = if report.input.is_some() {
        "Driven motion"
    } else {
        "Free vibration"
    };
    super::over_time(
        &out.path("displacement_velocity.svg"),
        &format!("{motion}: {title}"),
        &traj.time,
        &[Quantity::Displacement(&traj.x), Quantity::Velocity(&traj.v)],
        super::View {
            axis,
            window: super::motion_window(&traj.time, &traj.v),
        },
    )?;
    let t = &traj.time;
    draw(
        &out.path("energy.svg"),
        &Figure::over_time(
            format!("Energy: {title}"),
            vec![
                Panel::new("energy", "J")
                    .with(Series::solid("kinetic", t, &traj.mechanical.kinetic))
                    .with(Series::solid("potential", t, &traj.mechanical.potential))
                    .with(Series::solid("E = KE + PE", t, &traj.mechanical.energy)),
                Panel::new("dE/dt", "W").with(Series::solid(
                    if report.input.is_some() {
                        "dE/dt = (u - c v - F) v"
                    } else {
                        "dE/dt = -(c v + F) v"
                    },
                    t,
                    &report.energy_rate,
                )),
            ],
        )
        .window(super::motion_window(&traj.time, &traj.v)),
    )?;
    let mut files = vec!["displacement_velocity.svg".to_string(), "energy.svg".into()];
    if let Some(input) = &report.input {
        super::input_force(
            &out.path("input.svg"),
            &input.file,
            &input.time,
            &input.values,
            axis,
        )?;
        files.push("input.svg".into());
    }
    Ok(files)
}

/// The energy-based against the fitted model's friction force of one fitted record.
fn fit_force_plot(
    out: &OutputDir,
    name: &str,
    fit: &FitResult,
    r: &RecordFit,
) -> Result<(), CliError> {
    let energy = break_at_reversals(&r.series.energy_based_force, &r.series.measured);
    let shown = where_defined(&r.series.model_force, &energy);
    let label = format!("model ({})", fit.model);
    let reference = r.energy_force.as_ref().map(|e| e.reference);
    let axis = fit.oscillator.axis;
    let ref_label = reference
        .map(|x| format!("model mean |F| ±{} {}", fmt_num(x), axis.unit("N")))
        .unwrap_or_default();
    super::friction_force(
        &out.path(name),
        &format!("{}: energy-based and model friction force", r.file),
        &r.axes.time,
        &energy,
        Some((
            label.as_str(),
            shown.as_slice(),
            super::model_color(&fit.model),
        )),
        reference
            .filter(|x| x.is_finite())
            .map(|x| (ref_label.as_str(), x)),
        super::View {
            axis,
            window: record_window(r),
        },
    )
}

/// The time window of a fitted record's motion ([`super::motion_window`]): its velocity, or
/// the compared velocity itself.
fn record_window(r: &RecordFit) -> Option<(f64, f64)> {
    let v = if r.axes.velocity.len() == r.axes.time.len() {
        &r.axes.velocity
    } else if r.channel == "velocity" {
        &r.series.measured
    } else {
        return None;
    };
    super::motion_window(&r.axes.time, v)
}

/// `fit` and `compare`: the response fit and the friction-force check of every record;
/// `prefix` starts every file name.
pub fn fit_record_plots(
    out: &OutputDir,
    fit: &FitResult,
    prefix: &str,
) -> Result<Vec<String>, CliError> {
    let mut files = Vec::new();
    let names: Vec<&str> = fit.records.iter().map(|r| r.file.as_str()).collect();
    for (r, stem) in fit.records.iter().zip(unique_stems(&names)) {
        if !r.axes.displacement.is_empty() {
            files.extend(force_record_plots(out, fit, r, &format!("{prefix}{stem}"))?);
            continue;
        }
        let vf = format!("{prefix}{stem}_{}_fit.svg", r.channel);
        super::response_fit(
            &out.path(&vf),
            &r.file,
            (&r.channel, &fit.residual_unit),
            &r.axes.time,
            (&r.series.measured, &r.series.fitted),
            (&fit.model, record_window(r)),
            down_weighted(r),
        )?;
        files.push(vf);
        if !r.series.energy_based_force.is_empty() {
            let ff = format!("{prefix}{stem}_friction_force.svg");
            fit_force_plot(out, &ff, fit, r)?;
            files.push(ff);
        }
    }
    Ok(files)
}

/// The times of the samples of `r` a robust loss down-weighted (none under least squares).
fn down_weighted(r: &RecordFit) -> &[f64] {
    r.robust_weights.as_ref().map_or(&[][..], |w| &w.times)
}

/// A gap (NaN) in `values` wherever the time step exceeds 1.5 times the smallest one, so a
/// line is not drawn across masked samples. Unchanged when the lengths differ.
pub fn break_at_gaps(time: &[f64], values: &[f64]) -> Vec<f64> {
    let mut out = values.to_vec();
    if time.len() != values.len() {
        return out;
    }
    let step = time
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min);
    for i in 1..time.len() {
        if time[i] - time[i - 1] > 1.5 * step {
            out[i] = f64::NAN;
        }
    }
    out
}

/// A force-domain fit of one record: measured (or energy-based, or from the inverse-dynamics
/// balance) and fitted friction force against displacement (hysteresis loops) and against
/// velocity, and for inverse dynamics the force balance over time; `stem` starts the names.
fn force_record_plots(
    out: &OutputDir,
    fit: &FitResult,
    r: &RecordFit,
    stem: &str,
) -> Result<Vec<String>, CliError> {
    // Inverse dynamics compares the input force; its plots show the friction forces.
    let (measured, fitted, label) = match &r.series.balance {
        Some(b) => (&b.friction_balance, &b.friction_fitted, "from the balance"),
        None if r.channel == "energy_based_force" => {
            (&r.series.measured, &r.series.fitted, "energy-based (Eq. 7)")
        }
        None => (&r.series.measured, &r.series.fitted, "measured"),
    };
    let measured = break_at_gaps(&r.axes.time, measured);
    let fitted = break_at_gaps(&r.axes.time, fitted);
    let mut files = Vec::new();
    // mm and mm/s on a linear axis; rad and rad/s (as m and m/s, shown on the axis) on a
    // rotary one.
    let (position, speed, factor) = if fit.oscillator.axis.is_linear() {
        ("mm", "mm/s", 1e3)
    } else {
        ("m", "m/s", 1.0)
    };
    if let Some(balance) = &r.series.balance {
        let file = format!("{stem}_force_balance.svg");
        super::force_balance(
            &out.path(&file),
            &format!("{}: force balance", r.file),
            &r.axes.time,
            balance,
            super::SampleMarks {
                excluded: r.unreliable_target.as_ref().map_or(&[][..], |u| &u.times),
                down_weighted: down_weighted(r),
            },
            &fit.model,
            fit.oscillator.axis,
        )?;
        files.push(file);
    }
    for (name, what, motion, axis) in [
        (
            "force_displacement",
            "hysteresis loops",
            &r.axes.displacement,
            super::MotionAxis {
                quantity: "displacement",
                unit: position,
                factor,
            },
        ),
        (
            "force_velocity",
            "friction force against velocity",
            &r.axes.velocity,
            super::MotionAxis {
                quantity: "velocity",
                unit: speed,
                factor,
            },
        ),
    ] {
        let file = format!("{stem}_{name}.svg");
        super::force_against_motion(
            &out.path(&file),
            &format!("{}: {what}", r.file),
            (axis, motion),
            (label, &measured),
            &fitted,
            &fit.model,
            fit.oscillator.axis,
        )?;
        files.push(file);
    }
    Ok(files)
}

/// The largest speed of the records' motion (for steady-state plots): the velocity of a
/// force-domain fit, else the measured velocity.
pub fn peak_speed(fit: &FitResult) -> f64 {
    fit.records
        .iter()
        .flat_map(|r| {
            if r.axes.velocity.is_empty() {
                r.series.measured.iter()
            } else {
                r.axes.velocity.iter()
            }
        })
        .fold(0.0f64, |m, v| m.max(v.abs()))
}

/// The steady-state curves of `fits` (the first sets the normal force and the speed range)
/// in file `name`.
pub fn steady_state_plot(
    out: &OutputDir,
    name: &str,
    fits: &[FitResult],
) -> Result<Vec<String>, CliError> {
    let Some(first) = fits.first() else {
        return Ok(Vec::new());
    };
    let curves: Vec<(&str, &dyn FrictionModel)> = fits
        .iter()
        .map(|f| (f.model.as_str(), f.fitted_model.as_ref()))
        .collect();
    let normal_force = (!levels_are_forces(first)).then_some(first.oscillator.normal_force);
    super::steady_state_curves(
        &out.path(name),
        &curves,
        normal_force,
        peak_speed(first),
        first.oscillator.axis,
    )?;
    Ok(vec![name.to_string()])
}

/// Whether a fit read its friction levels as forces (no normal force given): a level
/// (`mu`, `mu_*`) carries a force's unit instead of 1.
pub fn levels_are_forces(fit: &FitResult) -> bool {
    fit.parameters
        .iter()
        .any(|p| (p.name == "mu" || p.name.starts_with("mu_")) && p.unit != "1")
}

/// `energy`: displacement and acceleration, energy and its rate, and the friction force
/// against the reference of one record.
fn energy_record_plots(
    out: &OutputDir,
    report: &EnergyReport,
    r: &EnergyRecord,
    stem: &str,
) -> Result<Vec<String>, CliError> {
    let a = &r.analysis;
    let axis = report.oscillator.axis;
    let mut files = Vec::new();
    for (kind, what, quantities) in [
        (
            "displacement_acceleration",
            "displacement and acceleration",
            [Quantity::Displacement(&a.x), Quantity::Acceleration(&a.a)],
        ),
        (
            "energy",
            "energy and dissipation rate",
            [
                Quantity::Energy(&a.mechanical.energy),
                Quantity::EnergyRate(&a.de_dt),
            ],
        ),
    ] {
        let file = format!("{stem}_{kind}.svg");
        let title = format!("{}: {what}", r.file);
        let view = super::View {
            axis,
            window: super::motion_window(&a.time, &a.v),
        };
        super::over_time(&out.path(&file), &title, &a.time, &quantities, view)?;
        files.push(file);
    }
    let ff = format!("{stem}_friction_force.svg");
    let model_label = report
        .reference_model
        .as_ref()
        .map(|m| format!("model ({m})"));
    let energy = break_at_reversals(&a.friction, &a.v);
    let model_shown = r.model_force.as_ref().map(|f| where_defined(f, &energy));
    let ref_label = format!("reference ±{} {}", fmt_num(r.reference), axis.unit("N"));
    let model_color = report
        .reference_model
        .as_deref()
        .map_or(super::PALETTE[0], super::model_color);
    super::friction_force(
        &out.path(&ff),
        &format!("{}: friction force", r.file),
        &a.time,
        &energy,
        model_label
            .as_deref()
            .zip(model_shown.as_deref())
            .map(|(label, f)| (label, f, model_color)),
        Some((ref_label.as_str(), r.reference)).filter(|(_, v)| v.is_finite()),
        super::View {
            axis,
            window: super::motion_window(&a.time, &a.v),
        },
    )?;
    files.push(ff);
    Ok(files)
}

/// The measured input of every record that has an `input_force` channel, against time:
/// `<stem>_input.svg`, and the named channels of every record that has some (a load, a
/// temperature: what a law beyond speed reads), `<stem>_channels.svg`, with the stems the
/// records' other plots have ([`unique_stems`]).
pub fn input_plots(
    out: &OutputDir,
    records: &[Record],
    axis: Axis,
) -> Result<Vec<String>, CliError> {
    let names: Vec<&str> = records.iter().map(|r| r.name.as_str()).collect();
    let mut files = Vec::new();
    for (record, stem) in records.iter().zip(unique_stems(&names)) {
        let named: Vec<(&str, &[f64])> = record
            .named_channels()
            .into_iter()
            .filter_map(|n| Some((n, record.named_channel(n)?)))
            .collect();
        if !named.is_empty() {
            let file = format!("{stem}_channels.svg");
            super::named_channels(&out.path(&file), &record.name, record.time(), &named)?;
            files.push(file);
        }
        let Some(input) = record.channel(Channel::InputForce) else {
            continue;
        };
        let file = format!("{stem}_input.svg");
        super::input_force(&out.path(&file), &record.name, record.time(), input, axis)?;
        files.push(file);
    }
    Ok(files)
}

/// `energy`: the plots of every record.
pub fn energy_plots(out: &OutputDir, report: &EnergyReport) -> Result<Vec<String>, CliError> {
    let mut files = Vec::new();
    let names: Vec<&str> = report.records.iter().map(|r| r.file.as_str()).collect();
    for (r, stem) in report.records.iter().zip(unique_stems(&names)) {
        files.extend(energy_record_plots(out, report, r, &stem)?);
    }
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plot_stems_come_from_file_names() {
        assert_eq!(plot_stem("data/x14mm.csv"), "x14mm");
        assert_eq!(plot_stem("x14mm.uff"), "x14mm");
    }

    #[test]
    fn record_stems_stay_distinct_when_file_names_collide() {
        assert_eq!(
            unique_stems(&["x10mm.csv", "x14mm.csv"]),
            ["x10mm", "x14mm"]
        );
        assert_eq!(
            unique_stems(&["a/data.csv", "b/data.csv", "c.csv"]),
            ["a_data", "b_data", "c"]
        );
        assert_eq!(
            unique_stems(&["data.csv", "data.csv"]),
            ["data_1", "data_2"]
        );
    }

    #[test]
    fn traces_break_at_velocity_reversals() {
        let f = [1.0, 1.0, -1.0, -1.0, 1.0];
        let v = [0.2, 0.1, -0.1, -0.2, 0.1];
        let b = break_at_reversals(&f, &v);
        assert_eq!(b[..2], [1.0, 1.0]);
        assert!(b[2].is_nan() && b[4].is_nan());
        assert_eq!(b[3], -1.0);
    }

    #[test]
    fn model_force_is_hidden_where_the_energy_force_is_masked() {
        let shown = where_defined(&[1.0, 2.0, 3.0], &[0.5, f64::NAN, -1.0]);
        assert_eq!(shown[0], 1.0);
        assert!(shown[1].is_nan());
        assert_eq!(shown[2], 3.0);
    }
}
