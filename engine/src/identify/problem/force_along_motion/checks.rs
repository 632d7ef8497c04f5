//! The option checks of a force-domain fit: keys that only a velocity fit has, and what inverse
//! dynamics needs.

use crate::error::EngineError;
use crate::identify::values::fit_options::FitOptions;
use crate::identify::values::target_options::{FitDomain, ForceTarget};
use crate::oscillator::OscillatorProperty;

/// Options that only a velocity fit has, as the `[fit.options]` keys they are.
fn velocity_only_options(opts: &FitOptions) -> Vec<&'static str> {
    let mut keys = Vec::new();
    for (on, key) in [
        (opts.params.velocity_offset, "velocity_offset"),
        (opts.params.time_shift, "time_shift"),
        (opts.params.x0, "x0"),
        (
            !opts.params.oscillator.is_empty()
                && opts.target.force_target != ForceTarget::InverseDynamics,
            "oscillator",
        ),
    ] {
        if on {
            keys.push(key);
        }
    }
    keys
}

/// The options fit the force domain: `domain = "force"`, and none of the options only a
/// velocity fit has (the oscillator properties are fitted in the force domain by inverse
/// dynamics only).
pub fn check_force_domain(opts: &FitOptions) -> Result<(), EngineError> {
    let velocity_keys = velocity_only_options(opts);
    if !velocity_keys.is_empty() {
        return Err(EngineError::InvalidInput(format!(
            "[fit.options] {} apply to velocity fits only, not with domain = \"force\"",
            velocity_keys.join(", ")
        )));
    }
    if opts.target.domain != FitDomain::Force {
        return Err(EngineError::InvalidInput(
            "fit_force needs [fit.options] domain = \"force\"".into(),
        ));
    }
    check_inverse_dynamics(opts)
}

/// Inverse dynamics knows the mass (the inertia): given in `[oscillator]` or fitted.
fn check_inverse_dynamics(opts: &FitOptions) -> Result<(), EngineError> {
    let mass_unknown = opts.target.is_unknown(OscillatorProperty::Mass)
        && !opts.params.oscillator.contains(&OscillatorProperty::Mass);
    if opts.target.force_target == ForceTarget::InverseDynamics && mass_unknown {
        return Err(EngineError::InvalidInput(
            "[oscillator]: force_target = \"inverse_dynamics\" needs the mass (the inertia): \
             give `mass`, or fit it with [fit.options] oscillator = [\"mass\"]"
                .into(),
        ));
    }
    Ok(())
}
