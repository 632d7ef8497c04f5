//! Identifiability, stated: which fitted parameters the records determine, and which they
//! only bound from one side.
//!
//! A free model parameter whose standard error in the solver's coordinates exceeds
//! [`FLAT_INTERNAL_SE`] (a factor e for a log parameter) or has none is profiled: stepped
//! outward on each side (a decade per step for log parameters) with the other parameters
//! re-optimised at each step, until the cost rises by more than [`PROFILE_DELTA`] residual
//! variances (chi²(1 dof) at 95 %, halved because the cost is half the sum of squares). A side
//! where it rises is bounded there; the parameter is `determined` (both sides), a
//! `lower_bound` (only values below are excluded, e.g. sigma0 on Coulomb-like records), an
//! `upper_bound`, or `not_identifiable`. Each step's re-optimisation is wanted only to a
//! twentieth of that rise ([`PROFILE_RESOLUTION`]): it stops when the Gauss-Newton step
//! promises less.
//!
//! A fit that hit the iteration limit only because such a parameter kept running on is
//! settled: the unbounded parameters are pinned where they are and the others re-optimised;
//! when that converges the fit counts as converged for them.
//!
//! The rooms: which parameters to profile (`flat.rs`), the profiles themselves
//! (`profiles.rs`), the rigid-contact limit's likelihood-ratio test (`rigid_limit.rs`), refits
//! with some parameters pinned (`pinned.rs`), the settling of a best run (`settle.rs`, the
//! entry [`settle`]), the covariance of the determined parameters (`covariance.rs`), the
//! parameters that share an undetermined one's column (`shared.rs`) and the findings
//! (`findings.rs`).

mod covariance;
mod findings;
mod flat;
mod pinned;
mod profiles;
mod rigid_limit;
mod settle;
mod shared;

pub use covariance::covariance_of_determined;
pub use findings::{consistency_findings, findings};
pub(crate) use flat::slots_without_effect;
pub use flat::{FLAT_INTERNAL_SE, NOISY_COLUMN};
pub use profiles::{
    LIMIT_PROFILE_ITERATIONS, PROFILE_DELTA, PROFILE_HALVINGS, PROFILE_ITERATIONS,
    PROFILE_RESOLUTION, PROFILE_STEPS,
};
pub use rigid_limit::{LIMIT_APPROACH_DECADES, NARROW_REJECTION};
pub(crate) use settle::settle;
pub use settle::PROFILE_RESTARTS;
pub use shared::{
    not_identifiable, redundant_columns, redundant_findings, shared_columns, shared_findings,
    with_shared, SharedColumn, REDUNDANT_REMAINDER, SHARED_CORRELATION,
};

use crate::identify::values::result::Identifiability;

/// One free parameter's standing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Standing {
    /// What the records say.
    pub class: Identifiability,
    /// The 95 % bound (physical) of a one-sided parameter.
    pub bound: Option<f64>,
}

impl Standing {
    const DETERMINED: Self = Self {
        class: Identifiability::Determined,
        bound: None,
    };

    /// Whether the value and its standard error stand.
    pub fn determined(&self) -> bool {
        self.class == Identifiability::Determined
    }
}
