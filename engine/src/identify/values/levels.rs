//! Whether a friction law's levels are coefficients of the normal force or forces: the one
//! place of the rule for a fit without a normal force.
//!
//! A law's levels (`mu`, `mu_c`, `mu_s`: dimensionless, multiplied by the normal force N) are
//! coefficients when the configuration or a record gives N. When neither does, N is taken as
//! [`UNIT_NORMAL_FORCE`] and a level is the friction force itself: its unit is N in every
//! report (N m on a rotary axis) and its bounds come from the data (the largest |friction
//! force| the records show), not from the dimensionless bound of 10, which a 20 N Coulomb
//! level would sit at. The rule holds for every fit: replayed along the measured motion (the
//! force domain: the largest force compared) or simulated (the velocity domain: the largest
//! force the records' balance allows, and the oscillator carries N = 1).

use crate::axis::Axis;
use crate::oscillator::{Oscillator, OscillatorProperty};
use crate::record::{NormalForce, Record};
use frictionid_models::{clone_model, FrictionModel, ParamInfo};

/// The normal force a fit without one multiplies its levels by \[N\].
pub(crate) const UNIT_NORMAL_FORCE: f64 = 1.0;

/// A level's upper bound without a normal force, in multiples of the largest |force| the fit
/// compares: a friction force above every force that moves the axis cannot fit the records.
pub(crate) const LEVEL_BOUND_FACTOR: f64 = 5.0;

/// Dimensionless `mu_*` parameters that are no level: `coulomb_load`'s growth of its level
/// per unit of load (a ratio of forces, multiplied by |load|, not by N), which neither a
/// report's unit nor a simulation's scaling of the levels touches.
const NOT_LEVELS: [&str; 1] = ["mu_load"];

/// How a fit reads the friction levels of its law.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum FrictionLevels {
    /// Coefficients (unit 1) of the normal force the configuration or the records give.
    #[default]
    Coefficients,
    /// Forces \[N\]: no normal force given; `largest` is the largest |friction force| the
    /// records show \[N\]: the measured, Eq. 7 or inverse-dynamics force a force-domain fit
    /// compares, or the bound a velocity fit reads off the balance of its records.
    Forces {
        /// The largest |friction force| \[N\].
        largest: f64,
    },
}

impl FrictionLevels {
    /// Whether a fit of `records` reads the levels as forces: the configuration gives no
    /// normal force (`unknown`, the `[oscillator]` properties not given, holds it) and no
    /// record has one of its own (a constant or a channel). One record's own normal force
    /// keeps them coefficients, and then every record needs one
    /// ([`FrictionLevels::record_normal_force`]).
    pub fn read_as_forces(unknown: &[OscillatorProperty], records: &[Record]) -> bool {
        unknown.contains(&OscillatorProperty::NormalForce)
            && records.iter().all(|r| r.normal_force().is_none())
    }

    /// The normal force `record` is fitted under: its own; else [`UNIT_NORMAL_FORCE`] when
    /// the levels are read as forces (`as_forces`); else the oscillator's, unless that is not
    /// given either (an error: other records have one, so the levels are coefficients).
    pub fn record_normal_force(
        record: &Record,
        osc: &Oscillator,
        unknown: &[OscillatorProperty],
        as_forces: bool,
    ) -> Result<NormalForce, String> {
        match record.normal_force() {
            Some(n) => Ok(n.clone()),
            None if as_forces => Ok(NormalForce::Constant(UNIT_NORMAL_FORCE)),
            None if unknown.contains(&OscillatorProperty::NormalForce) => Err(
                "no normal force: give [oscillator] normal_force, the record's `normal_force` \
                 or a normal_force channel (other records have one)"
                    .into(),
            ),
            None => Ok(NormalForce::Constant(osc.normal_force)),
        }
    }

    /// The mean over `records` of the normal force each is fitted under
    /// ([`FrictionLevels::record_normal_force`], its mean over its samples); `None` when a
    /// record has none or there are no records.
    pub fn mean_normal_force(
        records: &[Record],
        osc: &Oscillator,
        unknown: &[OscillatorProperty],
    ) -> Option<f64> {
        let as_forces = Self::read_as_forces(unknown, records);
        let each: Option<Vec<f64>> = records
            .iter()
            .map(|r| Self::record_normal_force(r, osc, unknown, as_forces).ok())
            .map(|n| n.map(|n| n.mean()))
            .collect();
        let each = each.filter(|e| !e.is_empty())?;
        Some(each.iter().sum::<f64>() / each.len() as f64)
    }

    /// Whether `info` declares a friction level: dimensionless, named `mu` or `mu_*`, except
    /// the ratios of forces a law does not multiply by N ([`NOT_LEVELS`]).
    pub fn is_level(info: &ParamInfo) -> bool {
        info.unit == "1"
            && (info.name == "mu" || info.name.starts_with("mu_"))
            && !NOT_LEVELS.contains(&info.name.as_str())
    }

    /// Whether the levels are forces.
    pub fn are_forces(self) -> bool {
        matches!(self, Self::Forces { .. })
    }

    /// The law and the normal force a simulation runs `model` under. A simulation checks every
    /// parameter against its declared bounds, and a level read as a force (a 20 N Coulomb
    /// level over N = 1) may lie beyond its coefficient's bound of 10: then the levels are
    /// divided by the power of two that brings them within, and N is that power. A level is a
    /// coefficient of N (the law reads it as mu N), so the force is the same to the bit (a
    /// power of two scales exactly). `None`: the law runs as it is, under N = 1.
    pub fn scaled_for_simulation(
        self,
        model: &(dyn FrictionModel + 'static),
    ) -> Option<(Box<dyn FrictionModel>, f64)> {
        if !self.are_forces() {
            return None;
        }
        let info = model.param_info();
        let mut values = model.params();
        let excess = info
            .iter()
            .zip(&values)
            .filter(|(p, _)| Self::is_level(p) && p.upper > 0.0)
            .map(|(p, &v)| v / p.upper)
            .fold(0.0, f64::max);
        if !(excess > 1.0 && excess.is_finite()) {
            return None;
        }
        let scale = excess.log2().ceil().exp2();
        for (p, v) in info.iter().zip(values.iter_mut()) {
            if Self::is_level(p) {
                *v /= scale;
            }
        }
        let mut scaled = clone_model(model);
        scaled.set_params(&values).ok()?;
        Some((scaled, UNIT_NORMAL_FORCE * scale))
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

    /// A 30 N Coulomb level (beyond a coefficient's bound of 10) runs as 30 / 4 = 7.5 under
    /// N = 4, the same force to the bit; 3 N runs as it is; coefficients always do.
    #[test]
    fn levels_beyond_a_coefficients_bound_are_simulated_under_a_scaled_normal_force() {
        use frictionid_models::{Coulomb, Stribeck};
        let forces = FrictionLevels::Forces { largest: 30.0 };
        let (scaled, normal) = forces
            .scaled_for_simulation(&Coulomb { mu: 30.0 })
            .expect("a scaled law");
        assert_eq!((scaled.params(), normal), (vec![7.5], 4.0));
        assert_eq!(scaled.force(0.1, &[], normal), 30.0);
        assert!(forces.scaled_for_simulation(&Coulomb { mu: 3.0 }).is_none());
        let coefficients = FrictionLevels::Coefficients;
        assert!(coefficients
            .scaled_for_simulation(&Coulomb { mu: 20.0 })
            .is_none());
        // Every level divides, nothing else: mu_c 12 and mu_s 16 run as 6 and 8 under N = 2.
        let stribeck = Stribeck {
            mu_c: 12.0,
            mu_s: 16.0,
            ..Stribeck::default()
        };
        let (scaled, normal) = forces
            .scaled_for_simulation(&stribeck)
            .expect("a scaled law");
        assert_eq!(normal, 2.0);
        let expected: Vec<f64> = stribeck
            .params()
            .iter()
            .zip(stribeck.param_info())
            .map(|(v, p)| {
                if p.name.starts_with("mu") {
                    v / 2.0
                } else {
                    *v
                }
            })
            .collect();
        assert_eq!(scaled.params(), expected);
        for v in [-0.5, -1e-3, 2e-3, 0.3] {
            assert_eq!(scaled.force(v, &[], normal), stribeck.force(v, &[], 1.0));
        }
    }

    /// A load law's growth per unit load is a ratio of forces: a 24 N level runs as 6 under
    /// N = 4 while the ratio stays, the same force at every load.
    #[test]
    fn a_load_ratio_is_no_level() {
        use frictionid_models::CoulombLoad;
        let forces = FrictionLevels::Forces { largest: 30.0 };
        let law = CoulombLoad {
            mu: 24.0,
            mu_load: 0.5,
            viscous: 2.0,
        };
        let (scaled, normal) = forces.scaled_for_simulation(&law).expect("a scaled law");
        assert_eq!((scaled.params(), normal), (vec![6.0, 0.5, 2.0], 4.0));
        for load in [-20.0, 0.0, 3.0] {
            assert_eq!(
                scaled.force_in(0.1, &[], normal, &[load]),
                law.force_in(0.1, &[], 1.0, &[load])
            );
        }
        let ratio = law.param_info().into_iter().nth(1).expect("mu_load");
        assert_eq!(forces.unit(&ratio, Axis::Linear), "1");
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
