//! Units written in column names: `Velocity [mm/s]`, `Angle [deg]`, `Time (ms)`. A column's
//! name is split into its base (`Velocity`) and its unit (`mm/s`); a recognised unit gives the
//! quantity it measures and the factor that turns it into SI.

use std::f64::consts::PI;

/// What a unit measures (a rotary axis's quantities apart from a linear one's).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// s.
    Time,
    /// m.
    Length,
    /// m/s.
    Velocity,
    /// m/s^2.
    Acceleration,
    /// N.
    Force,
    /// rad.
    Angle,
    /// rad/s.
    AngularVelocity,
    /// rad/s^2.
    AngularAcceleration,
    /// N m.
    Torque,
}

impl Quantity {
    /// Whether it is a quantity of a rotary axis.
    pub fn is_rotary(self) -> bool {
        matches!(
            self,
            Quantity::Angle
                | Quantity::AngularVelocity
                | Quantity::AngularAcceleration
                | Quantity::Torque
        )
    }
}

/// A recognised unit: what it measures and its factor to SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unit {
    /// The quantity.
    pub quantity: Quantity,
    /// The factor from the unit to SI (1e-3 for mm/s, pi/180 for deg).
    pub factor: f64,
}

/// The column name split into its base and the unit text in its last brackets or
/// parentheses (`("Velocity", Some("mm/s"))` for `Velocity [mm/s]`), both trimmed.
pub fn split_unit(name: &str) -> (&str, Option<&str>) {
    let name = name.trim();
    for (open, close) in [('[', ']'), ('(', ')')] {
        if let Some(body) = name.strip_suffix(close) {
            if let Some(at) = body.rfind(open) {
                let base = body[..at]
                    .trim_end()
                    .trim_end_matches(['_', '-'])
                    .trim_end();
                let unit = body[at + open.len_utf8()..].trim();
                if !base.is_empty() && !unit.is_empty() {
                    return (base, Some(unit));
                }
            }
        }
    }
    (name, None)
}

/// The unit of a column name, if it has one and it is recognised.
pub fn unit_of(name: &str) -> Option<Unit> {
    split_unit(name).1.and_then(parse_unit)
}

/// Unit names and their factors to SI.
type Spellings = &'static [(&'static str, f64)];

/// Length prefixes: the unit text's prefix and its factor.
const LENGTHS: [(&str, f64); 7] = [
    ("m", 1.0),
    ("mm", 1e-3),
    ("um", 1e-6),
    ("µm", 1e-6),
    ("μm", 1e-6),
    ("nm", 1e-9),
    ("cm", 1e-2),
];

/// Angles: the unit text and its factor to rad.
const ANGLES: [(&str, f64); 5] = [
    ("rad", 1.0),
    ("mrad", 1e-3),
    ("deg", PI / 180.0),
    ("°", PI / 180.0),
    ("degree", PI / 180.0),
];

/// A unit's text recognised (case matters only where SI says so: `mm` and `Mm` are not
/// both accepted; `MM`-style exports are read in lower case), or `None`.
pub fn parse_unit(text: &str) -> Option<Unit> {
    let t: String = text
        .trim()
        .chars()
        .filter(|c| !c.is_whitespace() && *c != '·' && *c != '*' && *c != '.')
        .collect();
    let t = t.replace('²', "^2").replace("s2", "s^2");
    let lower = t.to_lowercase();
    let unit = |quantity, factor| Some(Unit { quantity, factor });
    match lower.as_str() {
        "s" | "sec" => return unit(Quantity::Time, 1.0),
        "ms" => return unit(Quantity::Time, 1e-3),
        "us" | "µs" | "μs" => return unit(Quantity::Time, 1e-6),
        "min" => return unit(Quantity::Time, 60.0),
        "n" => return unit(Quantity::Force, 1.0),
        "kn" => return unit(Quantity::Force, 1e3),
        "mn" if t == "mN" => return unit(Quantity::Force, 1e-3),
        "nm" if t == "Nm" => return unit(Quantity::Torque, 1.0),
        "mnm" => return unit(Quantity::Torque, 1e-3),
        "g" => return unit(Quantity::Acceleration, 9.80665),
        "rpm" | "1/min" => return unit(Quantity::AngularVelocity, 2.0 * PI / 60.0),
        _ => {}
    }
    let families: [(Spellings, [Quantity; 3]); 2] = [
        (
            &LENGTHS,
            [Quantity::Length, Quantity::Velocity, Quantity::Acceleration],
        ),
        (
            &ANGLES,
            [
                Quantity::Angle,
                Quantity::AngularVelocity,
                Quantity::AngularAcceleration,
            ],
        ),
    ];
    for (units, [position, velocity, acceleration]) in families {
        for &(name, factor) in units {
            for (spelled, quantity) in [
                (name.to_string(), position),
                (format!("{name}/s"), velocity),
                (format!("{name}/s^2"), acceleration),
            ] {
                if lower == spelled {
                    return unit(quantity, factor);
                }
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_split_into_base_and_unit() {
        assert_eq!(split_unit("Velocity [mm/s]"), ("Velocity", Some("mm/s")));
        assert_eq!(split_unit(" t (ms) "), ("t", Some("ms")));
        assert_eq!(split_unit("angle_[deg]"), ("angle", Some("deg")));
        assert_eq!(split_unit("velocity"), ("velocity", None));
        assert_eq!(split_unit("[s]"), ("[s]", None));
    }

    #[test]
    fn units_give_their_quantity_and_factor() {
        let cases = [
            ("s", Quantity::Time, 1.0),
            ("ms", Quantity::Time, 1e-3),
            ("mm/s", Quantity::Velocity, 1e-3),
            ("µm/s", Quantity::Velocity, 1e-6),
            ("m/s²", Quantity::Acceleration, 1.0),
            ("g", Quantity::Acceleration, 9.80665),
            ("mm", Quantity::Length, 1e-3),
            ("deg", Quantity::Angle, PI / 180.0),
            ("deg/s", Quantity::AngularVelocity, PI / 180.0),
            ("N", Quantity::Force, 1.0),
            ("mN", Quantity::Force, 1e-3),
            ("N m", Quantity::Torque, 1.0),
            ("N·m", Quantity::Torque, 1.0),
            ("rpm", Quantity::AngularVelocity, 2.0 * PI / 60.0),
        ];
        for (text, quantity, factor) in cases {
            let u = parse_unit(text).unwrap_or_else(|| panic!("{text}"));
            assert_eq!(u.quantity, quantity, "{text}");
            assert!((u.factor - factor).abs() <= 1e-15 * factor, "{text}");
        }
        assert_eq!(parse_unit("V"), None);
        assert_eq!(parse_unit("bar"), None);
    }
}
