//! What a data file says about itself, for `frictionid init`: its layout (delimiter, decimal
//! mark, preamble, header row), the role of each column from its name and unit (time,
//! velocity, displacement, acceleration, friction force, normal force, input), each column's
//! scale to SI, the axis its units belong to, the sample rate, a pre-trigger rest and, for a
//! free vibration measured by its velocity, an estimate of the release displacement. What
//! the file cannot decide is listed with the key that decides it, never guessed.

use super::layout::{sniff_layout, DecimalMark, Delimiter, Layout, SNIFF_LINES};
use super::units::{split_unit, unit_of, Quantity, Unit};
use super::{
    into_text, read_bytes, read_delimited, resolve_format, Channel, DataError, DataFormat,
    ReadOptions,
};
use crate::axis::Axis;
use crate::record::{detect_release, Record};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// What a column holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// The time stamps.
    Time,
    /// A channel.
    Channel(Channel),
}

impl Role {
    /// The role's key prefix in a `[[records]]` entry (`time`, `velocity`, ...).
    pub fn key(self) -> &'static str {
        match self {
            Role::Time => "time",
            Role::Channel(c) => c.name(),
        }
    }

    /// The SI unit of its values (on `axis`).
    pub fn si_unit(self, axis: Axis) -> &'static str {
        match (self, axis.is_linear()) {
            (Role::Time, _) => "s",
            (Role::Channel(c), true) => c.unit(),
            (Role::Channel(Channel::Velocity), false) => "rad/s",
            (Role::Channel(Channel::Displacement), false) => "rad",
            (Role::Channel(Channel::Acceleration), false) => "rad/s^2",
            (Role::Channel(Channel::InputForce), false) => "N m",
            (Role::Channel(c), false) => c.unit(),
        }
    }
}

/// One column of the header row as read.
#[derive(Debug, Clone, PartialEq)]
pub struct SurveyColumn {
    /// The name as written.
    pub name: String,
    /// The unit text in its name, if any.
    pub unit: Option<String>,
    /// Its role, when the name or the unit says it and no other column claims it.
    pub role: Option<Role>,
    /// The factor from its unit to SI: 1 without a unit, `None` for a unit not recognised.
    pub scale: Option<f64>,
}

/// A setting the file does not decide: the key that decides it and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Undecided {
    /// The configuration key (`velocity_scale`, `force_column`, `axis`, ...).
    pub key: String,
    /// What is unknown, in a sentence.
    pub reason: String,
}

/// What [`survey`] found in a data file.
#[derive(Debug, Clone, PartialEq)]
pub struct Survey {
    /// The file.
    pub file: PathBuf,
    /// How its fields are separated.
    pub delimiter: Delimiter,
    /// Its decimal mark (point or comma).
    pub decimal: DecimalMark,
    /// The header row's line (1-based).
    pub header_line: usize,
    /// Lines before the header row that are not blank (comments and other text).
    pub preamble_lines: usize,
    /// Every column of the header row.
    pub columns: Vec<SurveyColumn>,
    /// The axis the units belong to (`None`: no unit says).
    pub axis: Option<Axis>,
    /// Samples read.
    pub samples: usize,
    /// The sample rate \[Hz\] (from the median time step).
    pub sample_rate: f64,
    /// The time span of the record \[s\].
    pub duration: f64,
    /// The end of a pre-trigger rest \[s\], when the velocity shows one.
    pub release: Option<f64>,
    /// The release displacement estimated from the velocity \[m or rad\] (a free vibration):
    /// the mean of the positions of its first two velocity peaks is the equilibrium.
    pub x0_estimate: Option<f64>,
    /// What the file does not decide.
    pub undecided: Vec<Undecided>,
}

impl Survey {
    /// The column of `role`, if one was assigned.
    pub fn column(&self, role: Role) -> Option<&SurveyColumn> {
        self.columns.iter().find(|c| c.role == Some(role))
    }

    /// The channels found, in [`Channel::ALL`] order.
    pub fn channels(&self) -> Vec<Channel> {
        Channel::ALL
            .into_iter()
            .filter(|&c| self.column(Role::Channel(c)).is_some())
            .collect()
    }
}

/// Reads the delimited text file at `path` and says what it holds (see the module docs).
/// Errors: the file cannot be read, is not delimited text, has no header row over rows of
/// numbers, no time column, or its rows do not read.
pub fn survey(path: &Path) -> Result<Survey, DataError> {
    refuse_binary(path)?;
    let text = into_text(read_bytes(path)?);
    let (all, content) = first_lines(&text);
    let layout = sniff_layout(
        &content,
        DataFormat::Auto,
        Delimiter::Auto,
        DecimalMark::Auto,
    );
    let header = content.get(layout.header).filter(|_| layout.found);
    let Some(&(header_line, header_text)) = header else {
        return Err(refused(
            path,
            format!(
                "no header row of column names above rows of numbers in the first \
                 {SNIFF_LINES} lines; give `delimiter` and `decimal` in a [[records]] entry"
            ),
        ));
    };
    let names = layout.separator.split(header_text);
    let mut undecided = Vec::new();
    let columns = assign_roles(&names, &mut undecided);
    let opts = read_options(path, &layout, &columns, header_line, &names)?;
    let record = read_delimited(path, &text, DataFormat::Auto, &opts)?;
    let axis = axis_of(&columns, &mut undecided);
    let preamble_lines = all.iter().take_while(|(l, _)| *l < header_line).count();
    Ok(motion_facts(
        Survey {
            file: path.to_path_buf(),
            delimiter: layout.separator.delimiter(),
            decimal: layout.decimal,
            header_line,
            preamble_lines,
            columns,
            axis,
            samples: record.len(),
            sample_rate: 0.0,
            duration: 0.0,
            release: None,
            x0_estimate: None,
            undecided,
        },
        &record,
    ))
}

/// The survey's refusal of `path` for `reason`.
fn refused(path: &Path, reason: String) -> DataError {
    DataError::Empty {
        file: path.to_path_buf(),
        reason,
    }
}

/// MAT-files and UFF files are not surveyed: their variables are named by hand.
fn refuse_binary(path: &Path) -> Result<(), DataError> {
    if matches!(
        resolve_format(path, DataFormat::Auto),
        DataFormat::Mat | DataFormat::Uff58
    ) {
        return Err(refused(
            path,
            "init reads delimited text; write the [[records]] entry of a MAT-file or UFF file \
             by hand (docs/config.md)"
                .into(),
        ));
    }
    Ok(())
}

/// Lines with their numbers in the file, counted from 1.
type NumberedLines<'a> = Vec<(usize, &'a str)>;

/// The file's first non-blank lines, numbered from 1 (comments included, to count the
/// preamble), and the first [`SNIFF_LINES`] of them that are not `#` comments (to sniff).
fn first_lines(text: &str) -> (NumberedLines<'_>, NumberedLines<'_>) {
    let all: NumberedLines<'_> = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
        .filter(|(_, l)| !l.trim().is_empty())
        .take(4 * SNIFF_LINES)
        .collect();
    let content = all
        .iter()
        .copied()
        .filter(|(_, l)| !l.trim_start().starts_with('#'))
        .take(SNIFF_LINES)
        .collect();
    (all, content)
}

/// How to read the file: its layout, the time column and each channel's column and scale;
/// an error naming the header line when there is no time column or no channel.
fn read_options(
    path: &Path,
    layout: &Layout,
    columns: &[SurveyColumn],
    header_line: usize,
    names: &[&str],
) -> Result<ReadOptions, DataError> {
    let time = columns
        .iter()
        .find(|c| c.role == Some(Role::Time))
        .ok_or_else(|| {
            refused(
                path,
                format!(
                    "line {header_line}: no time column among {}; name it with `time_column`",
                    names.join(", ")
                ),
            )
        })?;
    if !columns
        .iter()
        .any(|c| matches!(c.role, Some(Role::Channel(_))))
    {
        return Err(refused(
            path,
            format!(
                "line {header_line}: no column's name or unit says velocity, displacement, \
                 acceleration or force among {}; name it with `velocity_column` (or another \
                 channel's `*_column`)",
                names.join(", ")
            ),
        ));
    }
    let mut opts = ReadOptions {
        delimiter: layout.separator.delimiter(),
        decimal: layout.decimal,
        channels: BTreeMap::new(),
        ..ReadOptions::default()
    };
    opts.time.column = time.name.clone();
    opts = opts.with_time_scale(time.scale.unwrap_or(1.0));
    for c in columns {
        if let Some(Role::Channel(channel)) = c.role {
            opts = opts
                .with_column(channel, c.name.clone())
                .with_scale(channel, c.scale.unwrap_or(1.0));
        }
    }
    Ok(opts)
}

/// The survey with the record's sample rate, span, pre-trigger rest and x0 estimate.
fn motion_facts(mut survey: Survey, record: &Record) -> Survey {
    let time = record.time();
    let mut steps: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
    steps.sort_by(f64::total_cmp);
    let median = steps.get(steps.len() / 2).copied().unwrap_or(f64::NAN);
    survey.sample_rate = 1.0 / median;
    survey.duration = time.last().copied().unwrap_or(0.0) - time.first().copied().unwrap_or(0.0);
    if let Some(v) = record.channel(Channel::Velocity) {
        survey.release = detect_release(time, v);
        let start = survey
            .release
            .unwrap_or(time.first().copied().unwrap_or(0.0));
        survey.x0_estimate = release_displacement(time, v, start);
    }
    survey
}

/// Names (lower case, without unit) that say a column's role.
const NAMES: [(Role, &[&str]); 7] = [
    (
        Role::Time,
        &["time", "t", "zeit", "timestamp", "sec", "seconds"],
    ),
    (
        Role::Channel(Channel::Velocity),
        &[
            "velocity",
            "vel",
            "v",
            "speed",
            "omega",
            "angular velocity",
            "geschwindigkeit",
        ],
    ),
    (
        Role::Channel(Channel::Displacement),
        &[
            "displacement",
            "disp",
            "position",
            "pos",
            "x",
            "angle",
            "theta",
            "q",
            "weg",
        ],
    ),
    (
        Role::Channel(Channel::Acceleration),
        &["acceleration", "acc", "accel", "a"],
    ),
    (
        Role::Channel(Channel::NormalForce),
        &["normal force", "normal", "fn", "n", "load"],
    ),
    (
        Role::Channel(Channel::InputForce),
        &[
            "input",
            "input force",
            "u",
            "motor force",
            "drive force",
            "torque",
            "motor torque",
            "command",
        ],
    ),
    (
        Role::Channel(Channel::Force),
        &[
            "force",
            "f",
            "friction",
            "friction force",
            "ff",
            "friction torque",
        ],
    ),
];

/// The role a column's base name says, if any.
fn role_by_name(base: &str) -> Option<Role> {
    let key = base.to_lowercase().replace(['_', '-'], " ");
    let key = key.trim();
    NAMES
        .iter()
        .find(|(_, names)| names.contains(&key))
        .map(|(role, _)| *role)
}

/// The role a unit's quantity says, if it says one alone (a force does not: friction,
/// normal or input).
fn role_by_unit(quantity: Quantity) -> Option<Role> {
    match quantity {
        Quantity::Time => Some(Role::Time),
        Quantity::Velocity | Quantity::AngularVelocity => Some(Role::Channel(Channel::Velocity)),
        Quantity::Length | Quantity::Angle => Some(Role::Channel(Channel::Displacement)),
        Quantity::Acceleration | Quantity::AngularAcceleration => {
            Some(Role::Channel(Channel::Acceleration))
        }
        Quantity::Force | Quantity::Torque => None,
    }
}

/// Whether a unit of `quantity` can measure `role`.
fn unit_fits(role: Role, quantity: Quantity) -> bool {
    match role {
        Role::Channel(Channel::Force | Channel::NormalForce) => quantity == Quantity::Force,
        Role::Channel(Channel::InputForce) => {
            matches!(quantity, Quantity::Force | Quantity::Torque)
        }
        other => role_by_unit(quantity) == Some(other),
    }
}

/// Each column's role, unit and scale; a role claimed twice is given to none, and every
/// column that cannot be decided is listed in `undecided` with its key.
fn assign_roles(names: &[&str], undecided: &mut Vec<Undecided>) -> Vec<SurveyColumn> {
    let mut columns: Vec<SurveyColumn> = names
        .iter()
        .map(|name| column_of(name, undecided))
        .collect();
    for role in NAMES.iter().map(|(r, _)| *r) {
        let claimed: Vec<usize> = (0..columns.len())
            .filter(|&i| columns[i].role == Some(role))
            .collect();
        if claimed.len() > 1 {
            let list: Vec<String> = claimed
                .iter()
                .map(|&i| format!("`{}`", columns[i].name))
                .collect();
            undecided.push(Undecided {
                key: format!("{}_column", role.key()),
                reason: format!(
                    "{} columns could be the {}: {}",
                    claimed.len(),
                    role.key(),
                    list.join(", ")
                ),
            });
            for i in claimed {
                columns[i].role = None;
            }
        }
    }
    columns
}

/// One column's role, unit and scale from its name.
fn column_of(name: &str, undecided: &mut Vec<Undecided>) -> SurveyColumn {
    let (base, unit_text) = split_unit(name);
    let unit: Option<Unit> = unit_of(name);
    let by_name = role_by_name(base);
    let mut role = by_name.or_else(|| unit.and_then(|u| role_by_unit(u.quantity)));
    if let (Some(r), Some(u)) = (role, unit) {
        if !unit_fits(r, u.quantity) {
            undecided.push(Undecided {
                key: format!("{}_column", r.key()),
                reason: format!(
                    "`{name}` is named like the {} but its unit is not one of it",
                    r.key()
                ),
            });
            role = None;
        }
    }
    if role.is_none()
        && unit.is_some_and(|u| matches!(u.quantity, Quantity::Force | Quantity::Torque))
    {
        undecided.push(Undecided {
            key: "force_column".into(),
            reason: format!(
                "`{name}` is a force: name it as `force_column` (the friction force), \
                 `normal_force_column` or `input_force_column` (the drive's force)"
            ),
        });
    }
    let scale = match (unit_text, unit) {
        (None, _) => Some(1.0),
        (Some(_), Some(u)) => Some(u.factor),
        (Some(text), None) => {
            if let Some(r) = role {
                undecided.push(Undecided {
                    key: format!("{}_scale", r.key()),
                    reason: format!(
                        "`{name}`: the unit `{text}` is not known; give the factor to SI"
                    ),
                });
            }
            None
        }
    };
    SurveyColumn {
        name: name.to_string(),
        unit: unit_text.map(str::to_string),
        role,
        scale,
    }
}

/// The axis the channels' units belong to; units of both kinds are undecided.
fn axis_of(columns: &[SurveyColumn], undecided: &mut Vec<Undecided>) -> Option<Axis> {
    let kinds: Vec<bool> = columns
        .iter()
        .filter(|c| matches!(c.role, Some(Role::Channel(_))))
        .filter_map(|c| unit_of(&c.name))
        .filter(|u| u.quantity != Quantity::Force)
        .map(|u| u.quantity.is_rotary())
        .collect();
    match (kinds.contains(&true), kinds.contains(&false)) {
        (true, false) => Some(Axis::Rotary),
        (false, true) => Some(Axis::Linear),
        (true, true) => {
            undecided.push(Undecided {
                key: "axis".into(),
                reason: "the columns' units are both linear and rotary".into(),
            });
            None
        }
        (false, false) => None,
    }
}

/// The release displacement of a free vibration from its velocity after `release`: the
/// positions of the first two velocity peaks (where the spring balances friction, F/k on
/// either side of the equilibrium) straddle the equilibrium, so x0 = -(X1 + X2) / 2 with X
/// the velocity integrated from the release. Each peak's instant is the vertex of a parabola
/// through its top tenth (the position moves fastest there: a sample's error in the instant
/// would cost v dt). `None` without two half-cycles.
pub fn release_displacement(time: &[f64], velocity: &[f64], release: f64) -> Option<f64> {
    let start = time.partition_point(|&t| t < release);
    let (t, v) = (time.get(start..)?, velocity.get(start..)?);
    let peak = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if peak.is_nan() || peak <= 0.0 {
        return None;
    }
    let level = 0.2 * peak;
    let first = v.iter().position(|x| x.abs() > level)?;
    let sign = v[first].signum();
    // The velocity integrated from the release (the release lies before the first sample).
    let mut x = vec![0.5 * v[0] * (t[0] - release).max(0.0); v.len()];
    for i in 1..v.len() {
        x[i] = x[i - 1] + 0.5 * (v[i] + v[i - 1]) * (t[i] - t[i - 1]);
    }
    let (x1, end1) = peak_position(t, v, &x, first, sign, level)?;
    let (x2, _) = peak_position(t, v, &x, end1, -sign, level)?;
    Some(-(x1 + x2) / 2.0)
}

/// The integrated position `x` at the velocity peak of the half-cycle of sign `s` from
/// `from`, and the index where that half-cycle ends; `None` when it does not end.
fn peak_position(
    t: &[f64],
    v: &[f64],
    x: &[f64],
    from: usize,
    s: f64,
    level: f64,
) -> Option<(f64, usize)> {
    let end = (from..v.len()).find(|&i| s * v[i] < -level)?;
    let at = (from..end).max_by(|&a, &b| (s * v[a]).total_cmp(&(s * v[b])))?;
    let top = 0.9 * s * v[at];
    let lo = (from..=at).rev().find(|&i| s * v[i] < top).unwrap_or(from);
    let hi = (at..end).find(|&i| s * v[i] < top).unwrap_or(end - 1);
    let offset = vertex_offset(&t[lo..=hi], &v[lo..=hi], t[at]).unwrap_or(0.0);
    Some((x[at] + v[at] * offset, end))
}

/// The vertex of the least-squares parabola through (`t`, `v`), as an offset from `t0`,
/// when it lies within the samples.
fn vertex_offset(t: &[f64], v: &[f64], t0: f64) -> Option<f64> {
    if t.len() < 5 {
        return None;
    }
    let a = nalgebra::DMatrix::from_fn(t.len(), 3, |i, j| (t[i] - t0).powi(j as i32));
    let b = nalgebra::DVector::from_column_slice(v);
    let c = a.svd(true, true).solve(&b, 1e-14).ok()?;
    let offset = -c[1] / (2.0 * c[2]);
    let (first, last) = (t[0] - t0, t[t.len() - 1] - t0);
    (offset.is_finite() && offset >= first && offset <= last).then_some(offset)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roles_come_from_names_and_units() {
        let mut u = Vec::new();
        let cols = assign_roles(
            &[
                "Time [s]",
                "Velocity [mm/s]",
                "Pos (mm)",
                "F_friction [N]",
                "Motor torque [N m]",
            ],
            &mut u,
        );
        let roles: Vec<Option<Role>> = cols.iter().map(|c| c.role).collect();
        assert_eq!(
            roles,
            vec![
                Some(Role::Time),
                Some(Role::Channel(Channel::Velocity)),
                Some(Role::Channel(Channel::Displacement)),
                None,
                Some(Role::Channel(Channel::InputForce)),
            ]
        );
        assert_eq!(cols[1].scale, Some(1e-3));
        assert_eq!(u.len(), 1, "{u:?}");
        assert_eq!(u[0].key, "force_column");
    }

    #[test]
    fn what_cannot_be_told_is_named_with_its_key() {
        let mut u = Vec::new();
        let cols = assign_roles(&["t", "v1 [m/s]", "v2 [m/s]", "speed [V]"], &mut u);
        assert!(cols[1].role.is_none() && cols[2].role.is_none() && cols[3].role.is_none());
        let keys: Vec<&str> = u.iter().map(|x| x.key.as_str()).collect();
        assert!(keys.contains(&"velocity_column"), "{u:?}");
        assert!(keys.contains(&"velocity_scale"), "{u:?}");
    }

    /// Coulomb friction from x0: the exact solution's velocity (piecewise sines about +-F/k)
    /// gives x0 back.
    #[test]
    fn the_release_displacement_comes_back_from_a_coulomb_velocity() {
        let (omega, x0, d) = (2.0 * std::f64::consts::PI * 5.0, 0.01, 0.0012);
        let dt = 1e-4;
        let t: Vec<f64> = (0..4000).map(|i| i as f64 * dt).collect();
        let v: Vec<f64> = t
            .iter()
            .map(|&t| {
                let half = (omega * t / std::f64::consts::PI).floor();
                let amp = x0 - d - 2.0 * d * half;
                if amp <= 0.0 {
                    return 0.0;
                }
                let s = if half as i64 % 2 == 0 { -1.0 } else { 1.0 };
                s * amp * omega * (omega * t - half * std::f64::consts::PI).sin().abs()
            })
            .collect();
        let x = release_displacement(&t, &v, 0.0).unwrap();
        assert!((x - x0).abs() < 2e-3 * x0, "{x}");
    }
}
