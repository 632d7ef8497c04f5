//! The axis's kind and its units: a linear axis in m, N, kg; a rotary axis in rad, N m,
//! kg m^2. Every unit the engine writes for a linear axis is translated by [`Axis::unit`].

use serde::{Deserialize, Serialize};

/// Linear (the default) or rotary.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    /// q in m, forces in N, the inertia a mass in kg.
    #[default]
    Linear,
    /// q in rad, torques in N m, the inertia a moment of inertia in kg m^2.
    Rotary,
}

impl std::str::FromStr for Axis {
    type Err = String;

    /// `linear` or `rotary` (a front end's `--axis` or `axis=` argument); an error naming
    /// both otherwise.
    fn from_str(text: &str) -> Result<Self, String> {
        match text {
            "linear" => Ok(Axis::Linear),
            "rotary" => Ok(Axis::Rotary),
            other => Err(format!("unknown axis `{other}`: `linear` or `rotary`")),
        }
    }
}

impl Axis {
    /// Whether this is the default linear axis.
    pub fn is_linear(&self) -> bool {
        *self == Axis::Linear
    }

    /// The name of the inertia: `mass` or `inertia`.
    pub fn inertia_name(self) -> &'static str {
        match self {
            Axis::Linear => "mass",
            Axis::Rotary => "inertia",
        }
    }

    /// What q is: `displacement` or `angle`.
    pub fn coordinate_name(self) -> &'static str {
        match self {
            Axis::Linear => "displacement",
            Axis::Rotary => "angle",
        }
    }

    /// The unit of q.
    pub fn displacement_unit(self) -> &'static str {
        match self {
            Axis::Linear => "m",
            Axis::Rotary => "rad",
        }
    }

    /// The unit of a force along the axis.
    pub fn force_unit(self) -> &'static str {
        match self {
            Axis::Linear => "N",
            Axis::Rotary => "N m",
        }
    }

    /// `unit`, written for a linear axis (m, N, kg and their products and quotients), on
    /// this axis: on a rotary one m becomes rad, N becomes N m and kg becomes kg m^2
    /// ("N s/m" -> "N m s/rad", "m/s^2" -> "rad/s^2", "mm" -> "mrad"). A linear axis keeps it
    /// as it is. Translate a unit once: "N m" is not a linear unit.
    pub fn unit(self, unit: &str) -> String {
        if self.is_linear() {
            return unit.to_string();
        }
        let mut out = String::with_capacity(unit.len() + 8);
        let mut token = String::new();
        for ch in unit.chars().chain(std::iter::once('\0')) {
            if ch == ' ' || ch == '/' || ch == '\0' {
                out.push_str(&rotary_token(&token));
                token.clear();
                if ch != '\0' {
                    out.push(ch);
                }
            } else {
                token.push(ch);
            }
        }
        out
    }
}

/// One factor of a linear unit on a rotary axis.
fn rotary_token(token: &str) -> String {
    match token {
        "N" => "N m".into(),
        "kg" => "kg m^2".into(),
        "m" => "rad".into(),
        "mm" => "mrad".into(),
        _ => match token.strip_prefix("m^") {
            Some(power) => format!("rad^{power}"),
            None => token.into(),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_units_become_rotary_ones() {
        let r = Axis::Rotary;
        for (linear, rotary) in [
            ("m", "rad"),
            ("m/s", "rad/s"),
            ("m/s^2", "rad/s^2"),
            ("mm", "mrad"),
            ("mm/s", "mrad/s"),
            ("m/s²", "rad/s²"),
            ("N", "N m"),
            ("N/m", "N m/rad"),
            ("N s/m", "N m s/rad"),
            ("N s^2/m^2", "N m s^2/rad^2"),
            ("kg", "kg m^2"),
            ("J", "J"),
            ("s", "s"),
            ("1", "1"),
        ] {
            assert_eq!(r.unit(linear), rotary);
            assert_eq!(Axis::Linear.unit(linear), linear);
        }
    }
}
