//! The Eq. 7 energy analyses of a fit's records, each computed once: the data-driven guess
//! reads its friction level from the analysis the energy check needs at the end, when nothing
//! that analysis depends on (the oscillator's m, c and k, the release displacement, the
//! velocity offset) was fitted.

use crate::energy::{analyze_record, EnergyAnalysis, EnergyOptions};
use crate::error::EngineError;
use crate::oscillator::Oscillator;
use crate::record::Record;
use std::sync::{Arc, Mutex};

/// What an analysis of a record depends on besides its samples.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Key {
    index: usize,
    /// The whole oscillator: its inertia, damping and restoring law enter the analysis.
    oscillator: Oscillator,
    x0: f64,
    options: EnergyOptions,
}

/// An energy analysis asked for: the fit's record `index` (`record`, its velocity as
/// measured) under `osc` and `options`.
#[derive(Debug, Clone, Copy)]
pub struct AnalysisRequest<'a> {
    pub index: usize,
    pub record: &'a Record,
    pub osc: &'a Oscillator,
    pub options: &'a EnergyOptions,
}

impl AnalysisRequest<'_> {
    /// The analysis computed afresh ([`analyze_record`]).
    pub fn compute(&self) -> Result<Arc<EnergyAnalysis>, EngineError> {
        Ok(Arc::new(analyze_record(
            self.record,
            self.osc,
            self.options,
        )?))
    }

    fn key(&self) -> Key {
        Key {
            index: self.index,
            oscillator: *self.osc,
            x0: self.record.x0,
            options: *self.options,
        }
    }
}

/// The analyses of the records of one fit, by record index (the fit's records never change
/// their samples; a velocity corrected by a fitted offset is not asked for here).
#[derive(Debug, Default)]
pub struct AnalysisCache(Mutex<Vec<(Key, Arc<EnergyAnalysis>)>>);

impl AnalysisCache {
    /// The energy analysis `request` asks for: kept from an earlier request with the same
    /// record index, oscillator, release displacement and options, else computed.
    pub fn analysis(
        &self,
        request: AnalysisRequest<'_>,
    ) -> Result<Arc<EnergyAnalysis>, EngineError> {
        let key = request.key();
        if let Some(kept) = self.find(&key) {
            return Ok(kept);
        }
        let analysis = request.compute()?;
        if let Ok(mut entries) = self.0.lock() {
            entries.push((key, analysis.clone()));
        }
        Ok(analysis)
    }

    fn find(&self, key: &Key) -> Option<Arc<EnergyAnalysis>> {
        let entries = self.0.lock().ok()?;
        entries
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, a)| a.clone())
    }
}

impl Clone for AnalysisCache {
    /// A clone starts empty (it may serve other records).
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl PartialEq for AnalysisCache {
    /// A cache never makes two producers differ.
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::release_records;
    use frictionid_models::Coulomb;

    /// The same analysis value (its masked samples are NaN, so compared as written out).
    fn same(a: &EnergyAnalysis, b: &EnergyAnalysis) -> bool {
        serde_json::to_string(a).ok() == serde_json::to_string(b).ok()
    }

    #[test]
    fn an_analysis_is_kept_for_the_same_inputs_only() {
        let osc = Oscillator::fmm();
        let records =
            release_records(&osc, &Coulomb { mu: 0.24 }, &[0.014], 2.0, 1000.0, 2e-4, 3).unwrap();
        let rec = &records[0];
        let options = EnergyOptions::default();
        let cache = AnalysisCache::default();
        let request = |record, osc| AnalysisRequest {
            index: 0,
            record,
            osc,
            options: &options,
        };
        let first = cache.analysis(request(rec, &osc)).unwrap();
        assert!(same(&first, &analyze_record(rec, &osc, &options).unwrap()));
        let again = cache.analysis(request(rec, &osc)).unwrap();
        assert!(Arc::ptr_eq(&first, &again));
        let heavier = Oscillator {
            mass: osc.mass * 1.01,
            ..osc
        };
        let other = cache.analysis(request(rec, &heavier)).unwrap();
        assert!(!Arc::ptr_eq(&first, &other));
        assert!(same(
            &other,
            &analyze_record(rec, &heavier, &options).unwrap()
        ));
        let mut moved = rec.clone();
        moved.x0 += 1e-3;
        let shifted = cache.analysis(request(&moved, &osc)).unwrap();
        assert!(same(
            &shifted,
            &analyze_record(&moved, &osc, &options).unwrap()
        ));
        assert!(!Arc::ptr_eq(&first, &shifted));
    }
}
