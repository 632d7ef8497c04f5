//! Whether a friction law's levels are coefficients of the normal force or forces: the one
//! place of the rule for a fit without a normal force.
//!
//! A law's levels (`mu`, `mu_c`, `mu_s`: dimensionless, multiplied by the normal force N) are
//! coefficients when the configuration or a record gives N. When neither does, N is taken as
//! [`UNIT_NORMAL_FORCE`] and a level is the friction force itself: its unit is N in every
//! report and its bounds come from the data (the largest |force| the fit compares), not from
//! the dimensionless bound of 10, which a 20 N Coulomb level would sit at.

use crate::axis::Axis;
use frictionid_models::ParamInfo;

/// The normal force a fit without one multiplies its levels by \[N\].
pub const UNIT_NORMAL_FORCE: f64 = 1.0;

/// A level's upper bound without a normal force, in multiples of the largest |force| the fit
/// compares: a friction force above every force that moves the axis cannot fit the records.
pub const LEVEL_BOUND_FACTOR: f64 = 5.0;

/// How a fit reads the friction levels of its law.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum FrictionLevels {
    /// Coefficients (unit 1) of the normal force the configuration or the records give.
    #[default]
    Coefficients,
    /// Forces \[N\]: no normal force given; `largest` is the largest |force| the fit compares
    /// \[N\] (the measured, Eq. 7 or inverse-dynamics force).
    Forces {
        /// The largest |force| compared \[N\].
        largest: f64,
    },
}

impl FrictionLevels {
    /// Whether `info` declares a friction level: dimensionless, named `mu` or `mu_*`.
    pub fn is_level(info: &ParamInfo) -> bool {
        info.unit == "1" && (info.name == "mu" || info.name.starts_with("mu_"))
    }

    /// Whether the levels are forces.
    pub fn are_forces(self) -> bool {
        matches!(self, Self::Forces { .. })
    }

    /// The unit a report gives `info` on `axis`: N (N m on a rotary axis) for a level read as
    /// a force, else the declared one on that axis (a law declares its units for a linear
    /// axis: "N s/m" is "N m s/rad" on a rotary one).
    pub fn unit(self, info: &ParamInfo, axis: Axis) -> String {
        if self.are_forces() && Self::is_level(info) {
            axis.unit("N")
        } else {
            axis.unit(&info.unit)
        }
    }

    /// The bounds of `info` when the options give none: for a level read as a force,
    /// `[lower, LEVEL_BOUND_FACTOR * largest]`; else the declared ones.
    pub fn bounds(self, info: &ParamInfo) -> (f64, f64) {
        match self {
            Self::Forces { largest } if Self::is_level(info) && largest > 0.0 => {
                (info.lower.max(0.0), LEVEL_BOUND_FACTOR * largest)
            }
            _ => (info.lower, info.upper),
        }
    }

    /// A data-driven friction level (force over normal force) clipped to where a start may
    /// lie: `[1e-4, 5]` for a coefficient, `[1e-4, 1]` times the largest force for a force.
    pub fn clamp_guess(self, level: f64) -> f64 {
        match self {
            Self::Forces { largest } if largest > 0.0 => level.clamp(1e-4 * largest, largest),
            _ => level.clamp(1e-4, 5.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use frictionid_models::ParamSpec;

    /// A 20 N Coulomb level with a largest force of 30 N: bounds [0, 150] N and unit N; the
    /// viscous coefficient and a dimensionless exponent keep their declarations.
    #[test]
    fn levels_read_as_forces_take_their_bounds_from_the_data() {
        let mu = ParamSpec::new("mu", "1", 0.2, (0.0, 10.0), "level").info();
        let delta = ParamSpec::positive("delta", "1", 2.0, 10.0, "exponent").info();
        let viscous = ParamSpec::non_negative("viscous", "N s/m", 0.5, "viscous").info();
        let forces = FrictionLevels::Forces { largest: 30.0 };
        assert_eq!(forces.bounds(&mu), (0.0, 150.0));
        assert_eq!(forces.unit(&mu, Axis::Linear), "N");
        assert_eq!(forces.bounds(&delta), (0.0, 10.0));
        assert_eq!(forces.unit(&delta, Axis::Linear), "1");
        assert_eq!(forces.unit(&viscous, Axis::Linear), "N s/m");
        assert_eq!(forces.clamp_guess(20.0), 20.0);
        let coefficients = FrictionLevels::Coefficients;
        assert_eq!(coefficients.bounds(&mu), (0.0, 10.0));
        assert_eq!(coefficients.unit(&mu, Axis::Linear), "1");
        assert_eq!(coefficients.clamp_guess(20.0), 5.0);
    }

    /// On a rotary axis a level read as a force is a torque in N m and a viscous coefficient
    /// is in N m s/rad; a coefficient of the normal force stays dimensionless.
    #[test]
    fn levels_on_a_rotary_axis_are_torques() {
        let mu = ParamSpec::new("mu", "1", 0.2, (0.0, 10.0), "level").info();
        let viscous = ParamSpec::non_negative("viscous", "N s/m", 0.5, "viscous").info();
        let forces = FrictionLevels::Forces { largest: 30.0 };
        assert_eq!(forces.unit(&mu, Axis::Rotary), "N m");
        assert_eq!(forces.unit(&viscous, Axis::Rotary), "N m s/rad");
        assert_eq!(FrictionLevels::Coefficients.unit(&mu, Axis::Rotary), "1");
    }
}
