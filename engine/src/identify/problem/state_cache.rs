//! The states behind recent force-domain predictions, kept for the fit's next evaluations.
//!
//! Along a given motion a model's states depend only on the parameters of its states'
//! equation: the finite-difference column of a force-only parameter
//! ([`InternalStates::force_only_params`](frictionid_models::InternalStates::force_only_params): a damping on the rate, a viscous drag) needs the
//! states of the point it differs from, and only a new force. The cache keys states by record
//! and by the exact values of the other parameters, so a hit returns what the integration
//! would, bit for bit.

use frictionid_models::FrictionModel;
use std::collections::VecDeque;
use std::sync::{Arc, Mutex};

/// Entries kept: a Jacobian's worth of trial points (each state parameter's column adds one)
/// for a few records, so the point a Jacobian is taken at is still there for its force-only
/// columns.
const CAPACITY: usize = 64;

/// What the states were computed for: the record and the model's state parameters.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Key {
    record: usize,
    model: &'static str,
    state_params: Vec<u64>,
}

impl Key {
    /// The key of `model` on record `record`: its name and the bits of every parameter that
    /// is not force-only.
    fn of(record: usize, model: &dyn FrictionModel) -> Self {
        let force_only = model
            .states()
            .map_or_else(Vec::new, |s| s.force_only_params());
        let state_params = model
            .params()
            .iter()
            .enumerate()
            .filter(|(i, _)| !force_only.contains(i))
            .map(|(_, x)| x.to_bits())
            .collect();
        Self {
            record,
            model: model.name(),
            state_params,
        }
    }
}

/// Recently integrated states, shared by the threads of a fit.
#[derive(Debug, Default)]
pub struct StateCache {
    entries: Mutex<VecDeque<(Key, Arc<Vec<f64>>)>>,
}

impl Clone for StateCache {
    /// A fresh, empty cache (a cloned producer starts its own).
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl StateCache {
    /// The states of `model` on record `record`: cached when a model with the same state
    /// parameters was integrated there, else from `integrate` (and kept).
    pub fn states<E>(
        &self,
        record: usize,
        model: &dyn FrictionModel,
        integrate: impl FnOnce() -> Result<Vec<f64>, E>,
    ) -> Result<Arc<Vec<f64>>, E> {
        let key = Key::of(record, model);
        if let Some(states) = self.find(&key) {
            return Ok(states);
        }
        let states = Arc::new(integrate()?);
        self.keep(key, states.clone());
        Ok(states)
    }

    fn find(&self, key: &Key) -> Option<Arc<Vec<f64>>> {
        let entries = self.entries.lock().ok()?;
        entries
            .iter()
            .rev()
            .find(|(k, _)| k == key)
            .map(|(_, s)| s.clone())
    }

    fn keep(&self, key: Key, states: Arc<Vec<f64>>) {
        if let Ok(mut entries) = self.entries.lock() {
            if entries.len() >= CAPACITY {
                entries.pop_front();
            }
            entries.push_back((key, states));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use frictionid_models::LuGre;

    /// A force-only parameter (LuGre's sigma1) keeps the key, a state parameter (sigma0)
    /// does not; another record does not share states.
    #[test]
    fn only_force_only_parameters_share_states() {
        let cache = StateCache::default();
        let base = LuGre::default();
        let computed = |x: f64| move || Ok::<_, ()>(vec![x]);
        assert_eq!(*cache.states(0, &base, computed(1.0)).unwrap(), [1.0]);
        let damped = LuGre {
            sigma1: base.sigma1 * 2.0,
            sigma2: base.sigma2 + 1.0,
            ..base.clone()
        };
        assert_eq!(*cache.states(0, &damped, computed(2.0)).unwrap(), [1.0]);
        let stiffer = LuGre {
            sigma0: base.sigma0 * 2.0,
            ..base.clone()
        };
        assert_eq!(*cache.states(0, &stiffer, computed(3.0)).unwrap(), [3.0]);
        assert_eq!(*cache.states(1, &base, computed(4.0)).unwrap(), [4.0]);
        assert_eq!(*cache.states(0, &base, computed(5.0)).unwrap(), [1.0]);
        assert!(cache.clone().find(&Key::of(0, &base)).is_none());
    }
}
