//! One typed value per oscillator property: its `[oscillator]` key, its name and unit on
//! each axis, how to read and write it on an [`Oscillator`] and its domain. Every list of
//! property keys, every get and set of a property by a fit, is read from here: a new
//! property is one variant and its facts below.

use super::Oscillator;
use crate::axis::{Axis, Restoring};
use serde::{Deserialize, Serialize};

/// An oscillator property: one a fit may vary ([`OscillatorProperty::FITTED`]), or the normal
/// force, which a fit reads but does not vary.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OscillatorProperty {
    /// m [kg] (J [kg m^2] on a rotary axis, where it is called `inertia`).
    #[serde(alias = "inertia")]
    Mass,
    /// c [N s/m].
    Damping,
    /// k [N/m].
    Stiffness,
    /// The pendulum's gravity moment m g l [N m] (`restoring = { type = "pendulum" }`).
    GravityMoment,
    /// The input's offset F_0 [N] (see [`Oscillator::input_offset`]).
    InputOffset,
    /// The quadratic stiffness k2 [N/m^2] of the polynomial spring
    /// (`restoring = { type = "polynomial" }`).
    QuadraticStiffness,
    /// The cubic stiffness k3 [N/m^3] of the polynomial or the cubic spring.
    CubicStiffness,
    /// The normal force N [N] on the friction contact: known or not, never fitted (and
    /// refused as a fitted property by `[fit.options] oscillator`).
    #[serde(skip_deserializing)]
    NormalForce,
}

/// Where a property's values lie.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PropertyDomain {
    /// > 0: fitted in log coordinates.
    Positive,
    /// >= 0.
    NonNegative,
    /// Any finite value.
    Any,
}

impl OscillatorProperty {
    /// The properties a fit may vary, in the order of their keys.
    pub const FITTED: [Self; 7] = [
        Self::Mass,
        Self::Damping,
        Self::Stiffness,
        Self::GravityMoment,
        Self::InputOffset,
        Self::QuadraticStiffness,
        Self::CubicStiffness,
    ];

    /// Every property: the fitted ones, then the normal force.
    pub const ALL: [Self; 8] = {
        let mut all = [Self::NormalForce; 8];
        let mut i = 0;
        while i < Self::FITTED.len() {
            all[i] = Self::FITTED[i];
            i += 1;
        }
        all
    };

    /// Its `[oscillator]` key (the linear axis's name).
    pub fn key(self) -> &'static str {
        match self {
            Self::Mass => "mass",
            Self::Damping => "damping",
            Self::Stiffness => "stiffness",
            Self::GravityMoment => "gravity_moment",
            Self::InputOffset => "input_offset",
            Self::QuadraticStiffness => "quadratic_stiffness",
            Self::CubicStiffness => "cubic_stiffness",
            Self::NormalForce => "normal_force",
        }
    }

    /// Every name a config may give it: its key, and `inertia` for the mass.
    pub fn keys(self) -> &'static [&'static str] {
        match self {
            Self::Mass => &["mass", "inertia"],
            Self::Damping => &["damping"],
            Self::Stiffness => &["stiffness"],
            Self::GravityMoment => &["gravity_moment"],
            Self::InputOffset => &["input_offset"],
            Self::QuadraticStiffness => &["quadratic_stiffness"],
            Self::CubicStiffness => &["cubic_stiffness"],
            Self::NormalForce => &["normal_force"],
        }
    }

    /// Its name in reports on `axis`: the key, `inertia` for the mass of a rotary axis.
    pub fn name_on(self, axis: Axis) -> &'static str {
        match self {
            Self::Mass => axis.inertia_name(),
            other => other.key(),
        }
    }

    /// Its unit written for a linear axis ([`Axis::unit`] gives the rotary one): the
    /// gravity moment, a torque on the rotary axis it belongs to, is written as the force N.
    pub fn unit(self) -> &'static str {
        match self {
            Self::Mass => "kg",
            Self::Damping => "N s/m",
            Self::Stiffness => "N/m",
            Self::QuadraticStiffness => "N/m^2",
            Self::CubicStiffness => "N/m^3",
            Self::GravityMoment | Self::InputOffset | Self::NormalForce => "N",
        }
    }

    /// Its unit on `axis`.
    pub fn unit_on(self, axis: Axis) -> String {
        axis.unit(self.unit())
    }

    /// Parses a fitted property's config name (either name of the mass).
    pub fn parse(name: &str) -> Option<Self> {
        Self::FITTED.into_iter().find(|p| p.keys().contains(&name))
    }

    /// Every key a `[fit]` bound may name for an oscillator property.
    pub fn bound_keys() -> impl Iterator<Item = &'static str> {
        Self::FITTED
            .into_iter()
            .flat_map(|p| p.keys().iter().copied())
    }

    /// Whether a fit may vary it.
    pub fn is_fitted(self) -> bool {
        self != Self::NormalForce
    }

    /// Where its values lie.
    pub fn domain(self) -> PropertyDomain {
        match self {
            Self::Mass | Self::Stiffness | Self::GravityMoment => PropertyDomain::Positive,
            Self::Damping | Self::NormalForce => PropertyDomain::NonNegative,
            Self::InputOffset | Self::QuadraticStiffness | Self::CubicStiffness => {
                PropertyDomain::Any
            }
        }
    }

    /// The bounds of a fit that gives none: [0, inf), unbounded where any value is valid.
    pub fn default_bounds(self) -> (f64, f64) {
        match self.domain() {
            PropertyDomain::Any => (f64::NEG_INFINITY, f64::INFINITY),
            PropertyDomain::Positive | PropertyDomain::NonNegative => (0.0, f64::INFINITY),
        }
    }

    /// Whether a fit varies it in log coordinates (the strictly positive properties).
    pub fn log_coordinates(self) -> bool {
        self.domain() == PropertyDomain::Positive
    }

    /// An estimate within the domain: a non-positive estimate of a positive property is
    /// none, a negative one of a non-negative property is 0.
    pub fn admissible(self, estimate: f64) -> Option<f64> {
        match self.domain() {
            PropertyDomain::Positive => (estimate > 0.0).then_some(estimate),
            PropertyDomain::NonNegative => Some(estimate.max(0.0)),
            PropertyDomain::Any => Some(estimate),
        }
    }

    /// Whether it is a parameter of the restoring force R(q).
    pub fn is_restoring(self) -> bool {
        matches!(
            self,
            Self::Stiffness | Self::GravityMoment | Self::QuadraticStiffness | Self::CubicStiffness
        )
    }

    /// Where it is a parameter of a restoring law other than the spring: the
    /// `[oscillator] restoring` table of a law that has it.
    pub fn restoring_table(self) -> Option<&'static str> {
        match self {
            Self::GravityMoment => Some(r#"{ type = "pendulum", gravity_moment = ... }"#),
            Self::QuadraticStiffness => {
                Some(r#"{ type = "polynomial", quadratic_stiffness = ... }"#)
            }
            Self::CubicStiffness => Some(r#"{ type = "polynomial", cubic_stiffness = ... }"#),
            _ => None,
        }
    }

    /// Its value on `osc`; `None` for a restoring law's parameter the law does not have.
    pub fn value(self, osc: &Oscillator) -> Option<f64> {
        match self {
            Self::Mass => Some(osc.mass),
            Self::Damping => Some(osc.damping),
            Self::Stiffness => Some(osc.stiffness),
            Self::GravityMoment | Self::QuadraticStiffness | Self::CubicStiffness => {
                osc.restoring.parameter(self.key())
            }
            Self::InputOffset => Some(osc.input_offset),
            Self::NormalForce => Some(osc.normal_force),
        }
    }

    /// Sets it on `osc` (a restoring law's parameter only where the law has it).
    pub fn set(self, osc: &mut Oscillator, value: f64) {
        match self {
            Self::Mass => osc.mass = value,
            Self::Damping => osc.damping = value,
            Self::Stiffness => osc.stiffness = value,
            Self::GravityMoment | Self::QuadraticStiffness | Self::CubicStiffness => {
                osc.restoring.set_parameter(self.key(), value);
            }
            Self::InputOffset => osc.input_offset = value,
            Self::NormalForce => osc.normal_force = value,
        }
    }

    /// `osc` with it moved by `by` (as it is where `osc` has no such property).
    pub fn shifted(self, osc: &Oscillator, by: f64) -> Oscillator {
        let mut o = *osc;
        if let Some(value) = self.value(osc) {
            self.set(&mut o, value + by);
        }
        o
    }

    /// Its column in the balance J a + c v + R(q) + F_0 of an axis at acceleration `a`,
    /// velocity `v` and coordinate `q`, on the law it belongs to (the stiffness on the
    /// linear spring k q, the gravity moment on the pendulum M_g sin q, k2 q^2 and k3 q^3 on
    /// the polynomial spring): the balance's
    /// derivative with respect to it (0 for the normal force, which is not in it).
    pub fn balance_column(self, a: f64, v: f64, q: f64) -> f64 {
        match self {
            Self::Mass => a,
            Self::Damping => v,
            Self::Stiffness => q,
            Self::GravityMoment => q.sin(),
            Self::InputOffset => 1.0,
            Self::QuadraticStiffness => q * q,
            Self::CubicStiffness => q * q * q,
            Self::NormalForce => 0.0,
        }
    }

    /// The derivative of [`Self::balance_column`] in the acceleration `a`: 1 for the
    /// inertia (its column is a), 0 for every other property (whose columns do not read
    /// it). The columns are affine in a, so this is exact at every state.
    pub fn balance_column_acceleration_slope(self) -> f64 {
        match self {
            Self::Mass => 1.0,
            _ => 0.0,
        }
    }

    /// Whether [`Self::balance_column`] is the balance's exact derivative on `osc`'s
    /// restoring law (the stiffness only on the linear and polynomial springs, the polynomial
    /// terms where the law has them; not the gravity moment,
    /// whose column a fit takes by differences).
    pub fn balance_column_exact(self, osc: &Oscillator) -> bool {
        match self {
            Self::Mass | Self::Damping | Self::InputOffset => true,
            Self::Stiffness => {
                osc.restoring.is_linear_spring()
                    || matches!(osc.restoring, Restoring::Polynomial(_))
            }
            Self::QuadraticStiffness | Self::CubicStiffness => {
                osc.restoring.parameter(self.key()).is_some()
            }
            Self::GravityMoment | Self::NormalForce => false,
        }
    }

    /// The scale of its linear coordinate when its value is 0: an offset's a newton, a
    /// polynomial term's the small-motion stiffness (at least 1) per unit of q^n, any
    /// other's 2e-3 of the critical damping of `osc`'s small motions (of a kilogram-second
    /// without a restoring force).
    pub fn typical(self, osc: &Oscillator) -> f64 {
        match self {
            Self::InputOffset => 1.0,
            Self::QuadraticStiffness | Self::CubicStiffness => {
                osc.small_motion_stiffness().abs().max(1.0)
            }
            _ if osc.small_motion_stiffness() > 0.0 => {
                2e-3 * (osc.mass * osc.small_motion_stiffness()).sqrt()
            }
            _ => 2e-3 * osc.mass,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rotary axis names its mass `inertia`: `[fit.options] oscillator = ["inertia"]` asks
    /// for the same property as `"mass"`, and reports name it after the axis.
    #[test]
    fn inertia_is_the_rotary_name_of_the_mass() {
        let asked: Vec<OscillatorProperty> =
            serde_json::from_value(serde_json::json!(["inertia", "mass", "gravity_moment"]))
                .unwrap();
        assert_eq!(
            asked,
            [
                OscillatorProperty::Mass,
                OscillatorProperty::Mass,
                OscillatorProperty::GravityMoment
            ]
        );
        assert_eq!(
            OscillatorProperty::parse("inertia"),
            Some(OscillatorProperty::Mass)
        );
        assert_eq!(OscillatorProperty::Mass.key(), "mass");
        assert_eq!(OscillatorProperty::Mass.name_on(Axis::Rotary), "inertia");
        assert_eq!(OscillatorProperty::Mass.name_on(Axis::Linear), "mass");
        assert_eq!(OscillatorProperty::Damping.name_on(Axis::Rotary), "damping");
    }

    /// The normal force is a property of the oscillator but not one a fit varies.
    #[test]
    fn the_normal_force_is_not_fitted() {
        assert_eq!(OscillatorProperty::parse("normal_force"), None);
        let asked: Result<Vec<OscillatorProperty>, _> =
            serde_json::from_value(serde_json::json!(["normal_force"]));
        assert!(asked.is_err());
        assert!(!OscillatorProperty::bound_keys().any(|k| k == "normal_force"));
    }

    /// Each property's unit on a rotary axis.
    #[test]
    fn units_on_each_axis() {
        let rotary: Vec<String> = OscillatorProperty::ALL
            .iter()
            .map(|p| p.unit_on(Axis::Rotary))
            .collect();
        assert_eq!(
            rotary,
            [
                "kg m^2",
                "N m s/rad",
                "N m/rad",
                "N m",
                "N m",
                "N m/rad^2",
                "N m/rad^3",
                "N m"
            ]
        );
    }

    /// What is set is read back.
    #[test]
    fn set_then_value() {
        let mut osc = Oscillator::fmm();
        for (i, p) in OscillatorProperty::ALL.into_iter().enumerate() {
            p.set(&mut osc, 1.5 + i as f64);
            let expected = p.restoring_table().is_none().then_some(1.5 + i as f64);
            assert_eq!(p.value(&osc), expected, "{p:?}");
        }
    }
}
