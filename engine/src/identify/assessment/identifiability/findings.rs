//! The findings of identifiability: a parameter the records do not determine, a physical
//! inconsistency of the fitted law.

use super::Standing;
use crate::identify::values::levels::FrictionLevels;
use crate::identify::values::outcome::{Check, Finding};
use crate::identify::values::result::Identifiability;
use frictionid_models::{FrictionModel, ModelError};

/// A warning per parameter the records do not determine, with its 95 % bound.
pub fn findings(names: &[(String, String)], standings: &[Standing]) -> Vec<Finding> {
    names
        .iter()
        .zip(standings)
        .filter(|(_, s)| !s.determined())
        .map(|((name, unit), s)| {
            let message = match (s.class, s.bound) {
                (Identifiability::LowerBound, Some(b)) => format!(
                    "{name} > {b:.2e} {unit} at 95 %: the records bound it only from below (a larger value fits as well, e.g. presliding the records do not resolve); no standard error"
                ),
                (Identifiability::UpperBound, Some(b)) => format!(
                    "{name} < {b:.2e} {unit} at 95 %: the records bound it only from above; no standard error"
                ),
                _ => format!(
                    "`{name}` is not identifiable from these records: the cost stays within chi²/2 of its minimum on both sides; no standard error"
                ),
            };
            Finding::warn(Check::Identifiability, s.bound, message)
        })
        .collect()
}

/// A warning for each physical inconsistency the fitted model reports (e.g. mu_s < mu_c).
/// A level read as a force (`levels`) beyond the declared bound of its coefficient is no
/// inconsistency: its bounds are the data's.
pub fn consistency_findings(model: &dyn FrictionModel, levels: FrictionLevels) -> Vec<Finding> {
    match model.check() {
        Ok(warnings) => warnings
            .into_iter()
            .map(|w| Finding::warn(Check::PhysicalConsistency, None, w))
            .collect(),
        Err(ModelError::OutOfBounds { param, .. })
            if levels.are_forces()
                && model
                    .param_info()
                    .iter()
                    .any(|p| p.name == param && FrictionLevels::is_level(p)) =>
        {
            Vec::new()
        }
        Err(e) => vec![Finding::warn(
            Check::PhysicalConsistency,
            None,
            e.to_string(),
        )],
    }
}
