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

/// Entries kept per record beyond one per state parameter: a Jacobian's worth (the point it
/// is taken at, refreshed by every column that reads it, and the trial point of each state
/// parameter's column computed since, so the force-only and offset columns find it) and one
/// more. Each entry is as long as the record (times its states): a Jacobian's worth, not
/// dozens, on a long record.
const SPARE_PER_RECORD: usize = 2;

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
pub(crate) struct StateCache {
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
    pub(crate) fn states<E>(
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

    /// The states kept for `key`, which become the most recently used.
    fn find(&self, key: &Key) -> Option<Arc<Vec<f64>>> {
        let mut entries = self.entries.lock().ok()?;
        let at = entries.iter().rposition(|(k, _)| k == key)?;
        let entry = entries.remove(at)?;
        let states = entry.1.clone();
        entries.push_back(entry);
        Some(states)
    }

    /// Keeps `states`, dropping the least recently used entry of its record beyond one per
    /// state parameter and [`SPARE_PER_RECORD`].
    fn keep(&self, key: Key, states: Arc<Vec<f64>>) {
        if let Ok(mut entries) = self.entries.lock() {
            let record = key.record;
            let same_record = entries.iter().filter(|(k, _)| k.record == record).count();
            if same_record >= key.state_params.len() + SPARE_PER_RECORD {
                if let Some(oldest) = entries.iter().position(|(k, _)| k.record == record) {
                    entries.remove(oldest);
                }
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

    /// A record keeps its few most recently used states: the point read last survives the
    /// trial points computed after it, the least recently used goes, and other records keep
    /// theirs.
    #[test]
    fn a_record_keeps_its_most_recently_used_states() {
        let cache = StateCache::default();
        let at = |sigma0: f64| LuGre {
            sigma0,
            ..LuGre::default()
        };
        let computed = |x: f64| move || Ok::<_, ()>(vec![x]);
        cache.states(1, &at(1.0), computed(-1.0)).unwrap();
        cache.states(0, &at(1.0), computed(1.0)).unwrap();
        let per_record = Key::of(0, &at(1.0)).state_params.len() + SPARE_PER_RECORD;
        for k in 2..=per_record {
            cache.states(0, &at(k as f64), computed(k as f64)).unwrap();
        }
        // Read again: the most recently used of record 0.
        assert_eq!(*cache.states(0, &at(1.0), computed(0.0)).unwrap(), [1.0]);
        cache.states(0, &at(10.0), computed(10.0)).unwrap();
        assert!(cache.find(&Key::of(0, &at(1.0))).is_some());
        assert!(
            cache.find(&Key::of(0, &at(2.0))).is_none(),
            "least recently used"
        );
        assert!(cache.find(&Key::of(1, &at(1.0))).is_some());
        let kept = cache.entries.lock().unwrap();
        assert_eq!(
            kept.iter().filter(|(k, _)| k.record == 0).count(),
            per_record
        );
    }
}
