//! `[oscillator]`: the oscillator's properties as written, checked, with their standard
//! deviations and the keys not given.

use super::error::SpecError;
use crate::axis::{Axis, NoRestoring, Restoring, WrittenRestoring};
use crate::identify::PropertyUncertainty;
use crate::oscillator::{Oscillator, OscillatorProperty, PartialOscillator};
use serde::{Deserialize, Serialize};

/// `[oscillator]`: the oscillator's properties and, optionally, one standard deviation of
/// each (`mass_std`, `damping_std`, `stiffness_std`, `normal_force_std`; SI units, 0 when
/// absent: known exactly), which the uncertainty budget propagates into every fitted
/// parameter. Deserialized through [`OscillatorTable`], which checks every value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "OscillatorTable", into = "OscillatorTable")]
pub struct OscillatorSpec {
    /// The nominal properties (placeholders for the keys in `unknown`).
    pub oscillator: Oscillator,
    /// Their standard deviations.
    pub uncertainty: PropertyUncertainty,
    /// The property keys not given: a force-domain fit on a measured force needs only the
    /// normal force; the analyses that need the others name them
    /// ([`crate::identify::require_mechanics`]).
    pub unknown: Vec<OscillatorProperty>,
    /// The properties not given whose value was assumed (damping: 0, no viscous damping),
    /// for the report to say so.
    pub assumed: Vec<OscillatorProperty>,
}

/// `[oscillator]` as written; [`OscillatorSpec`] is built from it.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OscillatorTable {
    /// `linear` (default) or `rotary`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    axis: Option<Axis>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    mass: Option<f64>,
    /// The rotary name of `mass` [kg m^2].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    inertia: Option<f64>,
    /// The restoring law (default: the linear spring of `stiffness`); a law that reads the
    /// stiffness may carry it in its table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    restoring: Option<WrittenRestoring>,
    /// The input's offset: a constant force (torque) in the balance [N or N m] (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    input_offset: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    damping: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    stiffness: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    normal_force: Option<f64>,
    /// One standard deviation of the mass (`inertia_std` on a rotary axis).
    #[serde(default, alias = "inertia_std")]
    mass_std: f64,
    #[serde(default)]
    damping_std: f64,
    #[serde(default)]
    stiffness_std: f64,
    #[serde(default)]
    normal_force_std: f64,
}

impl TryFrom<OscillatorTable> for OscillatorSpec {
    type Error = SpecError;

    fn try_from(o: OscillatorTable) -> Result<Self, SpecError> {
        let (axis, restoring) = axis_of(&o)?;
        // A linear spring of stiffness 0 is no spring at all: a free mass.
        let restoring = match (restoring, o.stiffness) {
            (r, Some(k)) if r.is_linear_spring() && k == 0.0 => Restoring::None(NoRestoring),
            (r, _) => r,
        };
        // No damping given: none (c = 0), said in the report.
        let assumed = if o.damping.is_none() {
            vec![OscillatorProperty::Damping]
        } else {
            Vec::new()
        };
        let (mut oscillator, mut unknown) = PartialOscillator {
            mass: o.mass.or(o.inertia),
            damping: o.damping.or(Some(0.0)),
            stiffness: stiffness_of(&o)?,
            normal_force: o.normal_force,
        }
        .resolve();
        oscillator.axis = axis;
        oscillator.restoring = restoring;
        oscillator.input_offset = o.input_offset.unwrap_or(0.0);
        if !restoring.law().reads_stiffness() {
            unknown.retain(|&p| p != OscillatorProperty::Stiffness);
        }
        let spec = Self {
            oscillator,
            uncertainty: PropertyUncertainty {
                mass: o.mass_std,
                damping: o.damping_std,
                stiffness: o.stiffness_std,
                normal_force: o.normal_force_std,
            },
            unknown,
            assumed,
        };
        spec.validate()?;
        Ok(spec)
    }
}

/// The stiffness k, given in `[oscillator]` or in the restoring law's table (not both).
fn stiffness_of(o: &OscillatorTable) -> Result<Option<f64>, SpecError> {
    match (o.stiffness, o.restoring.and_then(|r| r.stiffness)) {
        (Some(_), Some(_)) => Err(SpecError::Oscillator(
            "`stiffness` is given twice, in [oscillator] and in its `restoring` table: \
             keep one"
                .into(),
        )),
        (given, in_table) => Ok(given.or(in_table)),
    }
}

/// The axis and the restoring law of `[oscillator]`: the pendulum turns (a rotary axis
/// unless the axis is given, an error on a linear one); `inertia` belongs to a rotary
/// axis and names the same property as `mass`.
fn axis_of(o: &OscillatorTable) -> Result<(Axis, Restoring), SpecError> {
    let restoring = o.restoring.map(|r| r.law).unwrap_or_default();
    let turns = matches!(restoring, Restoring::Pendulum(_));
    let axis = match (o.axis, turns) {
        (Some(Axis::Linear), true) => {
            return Err(SpecError::Oscillator(
                "`restoring` = pendulum turns about an axis: set `axis = \"rotary\"`".into(),
            ))
        }
        (Some(axis), _) => axis,
        (None, true) => Axis::Rotary,
        (None, false) => Axis::Linear,
    };
    if o.mass.is_some() && o.inertia.is_some() {
        return Err(SpecError::Oscillator(
            "give `inertia` or `mass` (the same property), not both".into(),
        ));
    }
    if o.inertia.is_some() && axis.is_linear() {
        return Err(SpecError::Oscillator(
            "`inertia` is the rotary axis's name of `mass`: set `axis = \"rotary\"` or \
             write `mass`"
                .into(),
        ));
    }
    Ok((axis, restoring))
}

impl From<OscillatorSpec> for OscillatorTable {
    fn from(o: OscillatorSpec) -> Self {
        let (p, u) = (o.oscillator, o.uncertainty);
        let given = |property: OscillatorProperty, value: f64| {
            (!o.unknown.contains(&property)).then_some(value)
        };
        let rotary = !p.axis.is_linear();
        Self {
            axis: rotary.then_some(p.axis),
            inertia: given(OscillatorProperty::Mass, p.mass).filter(|_| rotary),
            restoring: (!p.restoring.is_linear_spring()).then_some(p.restoring.into()),
            input_offset: (p.input_offset != 0.0).then_some(p.input_offset),
            mass: given(OscillatorProperty::Mass, p.mass).filter(|_| !rotary),
            damping: given(OscillatorProperty::Damping, p.damping),
            stiffness: given(OscillatorProperty::Stiffness, p.stiffness)
                .filter(|_| p.restoring.law().reads_stiffness()),
            normal_force: given(OscillatorProperty::NormalForce, p.normal_force),
            mass_std: u.mass,
            damping_std: u.damping,
            stiffness_std: u.stiffness,
            normal_force_std: u.normal_force,
        }
    }
}

impl From<Oscillator> for OscillatorSpec {
    /// Properties known exactly.
    fn from(oscillator: Oscillator) -> Self {
        Self {
            oscillator,
            uncertainty: PropertyUncertainty::default(),
            unknown: Vec::new(),
            assumed: Vec::new(),
        }
    }
}

impl OscillatorSpec {
    /// Checks the properties and their standard deviations.
    pub fn validate(&self) -> Result<(), SpecError> {
        self.oscillator
            .validate()
            .and_then(|()| self.uncertainty.validate())
            .map_err(|e| SpecError::Oscillator(e.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(json: serde_json::Value) -> Result<OscillatorSpec, String> {
        serde_json::from_value(json).map_err(|e| e.to_string())
    }

    /// The polynomial spring's k1 is the oscillator's stiffness, written in its table or in
    /// `[oscillator]`, not in both; it round-trips through `[oscillator]`.
    #[test]
    fn the_polynomial_spring_takes_its_stiffness_from_either_place() {
        let in_table = parse(serde_json::json!({
            "mass": 0.01, "damping": 0.002, "normal_force": 1.0, "axis": "rotary",
            "restoring": {"type": "polynomial", "stiffness": 0.5, "quadratic_stiffness": 0.4},
        }))
        .unwrap_or_else(|e| panic!("{e}"));
        let osc = in_table.oscillator;
        assert_eq!(osc.stiffness, 0.5);
        assert!(in_table.unknown.is_empty());
        // R(0.2) = 0.5 * 0.2 + 0.4 * 0.04.
        assert!((osc.restoring_force(0.2) - 0.116).abs() < 1e-15);
        let written = serde_json::to_value(&in_table).unwrap_or_default();
        assert_eq!(parse(written).ok(), Some(in_table));

        let twice = parse(serde_json::json!({
            "mass": 1.0, "stiffness": 2.0, "normal_force": 1.0,
            "restoring": {"type": "polynomial", "stiffness": 0.5},
        }));
        assert!(twice.is_err_and(|e| e.contains("`stiffness` is given twice")));
    }

    fn spec(json: serde_json::Value) -> Result<OscillatorSpec, serde_json::Error> {
        serde_json::from_value(json)
    }

    /// Only the keys the equation uses: a spring of stiffness 0 is none, and damping not
    /// given is 0, said as an assumption; a negative stiffness is still refused.
    #[test]
    fn a_free_mass_and_an_assumed_damping() {
        let free = spec(serde_json::json!({"mass": 2.0, "stiffness": 0.0})).unwrap();
        assert!(!free.oscillator.has_restoring_force());
        assert_eq!(free.oscillator.damping, 0.0);
        assert_eq!(free.assumed, vec![OscillatorProperty::Damping]);
        assert_eq!(free.unknown, vec![OscillatorProperty::NormalForce]);
        let none = spec(serde_json::json!({"mass": 2.0, "restoring": {"type": "none"}})).unwrap();
        assert!(!none.oscillator.has_restoring_force());
        assert!(!none.unknown.contains(&OscillatorProperty::Stiffness));
        let given =
            spec(serde_json::json!({"mass": 2.0, "damping": 0.5, "stiffness": 10.0})).unwrap();
        assert!(given.assumed.is_empty() && given.oscillator.has_restoring_force());
        let e = spec(serde_json::json!({"mass": 2.0, "stiffness": -1.0})).unwrap_err();
        assert!(e.to_string().contains("`stiffness` must be > 0"), "{e}");
    }
}
