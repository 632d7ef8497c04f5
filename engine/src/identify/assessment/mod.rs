//! What a fit's optimum is worth, on the search's floor: the statistics ([`stats`]), which
//! parameters the records determine ([`identifiability`]), the checks that become findings
//! ([`diagnostics`]), the energy-balance check ([`energy_check`]), the residual against the noise floor
//! ([`goodness`]), the per-record fits
//! ([`record_fits`]), the sum-up into a `FitResult` ([`summary`]) and the refits under the
//! oscillator's property uncertainties ([`property_refits`], handed the refit by the fit).

pub(crate) mod diagnostics;
mod down_weighted;
pub(crate) mod energy_check;
#[cfg(test)]
mod fixtures;
pub(crate) mod goodness;
pub mod identifiability;
pub(crate) mod property_refits;
pub(crate) mod record_fits;
pub mod stats;
pub(crate) mod summary;

pub use energy_check::{energy_force_check, ForceReference};
