//! What the force domain needs of the oscillator: the properties each route reads, and the
//! message naming the missing ones on the record's axis.

use crate::axis::Axis;
use crate::error::EngineError;
use crate::oscillator::OscillatorProperty;

/// The oscillator properties a force-domain fit on the energy-based force, a velocity fit or
/// an energy analysis needs, and the message (naming them on `axis`) when `missing` holds
/// any of them. The one place of this rule.
pub fn require_mechanics(
    missing: &[OscillatorProperty],
    axis: Axis,
    purpose: &str,
) -> Result<(), EngineError> {
    use OscillatorProperty::{Damping, Mass, Stiffness};
    require_properties(missing, axis, &[Mass, Damping, Stiffness], purpose)
}

/// Every oscillator property, the normal force included, is given: what a simulation of the
/// oscillator needs (a placeholder N = 0 would silently simulate no friction at all).
pub fn require_oscillator(
    missing: &[OscillatorProperty],
    axis: Axis,
    purpose: &str,
) -> Result<(), EngineError> {
    use OscillatorProperty::{Damping, Mass, NormalForce, Stiffness};
    require_properties(
        missing,
        axis,
        &[Mass, Damping, Stiffness, NormalForce],
        purpose,
    )
}

/// `a, b and c`.
fn spoken_list(items: &[&str]) -> String {
    match items.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => items.join(""),
    }
}

/// None of the `needed` properties is among the `missing` ones; otherwise an error naming
/// those that are, as `axis` names them.
fn require_properties(
    missing: &[OscillatorProperty],
    axis: Axis,
    needed: &[OscillatorProperty],
    purpose: &str,
) -> Result<(), EngineError> {
    let absent: Vec<&str> = needed
        .iter()
        .filter(|p| missing.contains(p))
        .map(|p| p.name_on(axis))
        .collect();
    if absent.is_empty() {
        return Ok(());
    }
    let needed: Vec<&str> = needed.iter().map(|p| p.name_on(axis)).collect();
    Err(EngineError::InvalidInput(format!(
        "[oscillator]: {purpose} needs {}; `{}` not given (only a force-domain fit on a \
         measured force channel does without mass, damping and stiffness)",
        spoken_list(&needed),
        absent.join("`, `")
    )))
}
